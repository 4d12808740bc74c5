#include "vc/plan/exact_selector.h"

#include <CbcEventHandler.hpp>
#include <CbcHeuristic.hpp>
#include <CbcHeuristicFPump.hpp>
#include <CbcHeuristicLocal.hpp>
#include <CbcModel.hpp>
#include <CglClique.hpp>
#include <CglGomory.hpp>
#include <CglKnapsackCover.hpp>
#include <CglMixedIntegerRounding2.hpp>
#include <CglProbing.hpp>
#include <CglZeroHalf.hpp>
#include <ClpEventHandler.hpp>
#include <CoinPackedMatrix.hpp>
#include <OsiClpSolverInterface.hpp>
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "vc/plan/greedy.h"
#include "vc/plan/scan_graph.h"

namespace vc::planner {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Calls f(v) for every set bit v of s.
template <typename F>
void ForEachBit(const VoxelSet& s, F&& f) {
  s.ForEach(f);
}

// The smallest voxel count k with k >= target * coverable (the greedy's stopping test).
uint64_t TargetVoxels(double target, uint64_t coverable) {
  const double t = target * static_cast<double>(coverable);
  uint64_t k = static_cast<uint64_t>(std::max(0.0, std::ceil(t)));
  while (k > 0 && static_cast<double>(k - 1) >= t) --k;
  while (static_cast<double>(k) < t) ++k;
  return std::min(k, coverable);
}

// The coverable voxels partitioned into classes seen by exactly the same candidates (partition
// refinement: each candidate splits the classes it touches), with each class's candidates.
struct Classes {
  std::vector<uint64_t> weight;           // voxels per class
  std::vector<std::vector<int>> seen_by;  // per class: candidates seeing it, ascending
  std::vector<std::vector<int>> sees;     // per candidate: classes it sees, ascending
};

Result<Classes> BuildClasses(const std::vector<VoxelSet>& sets, const JobContext& ctx) {
  const size_t n_voxels = sets.empty() ? 0 : sets[0].size();
  // Class 0 = seen by no candidate so far; ids grow as candidates split classes.
  std::vector<int32_t> cls(n_voxels, 0);
  std::vector<int32_t> remap(1, -1), stamp(1, -1);
  int32_t next = 1;
  for (size_t c = 0; c < sets.size(); ++c) {
    if (c % 64 == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (voxel classes)"));
    ForEachBit(sets[c], [&](size_t v) {
      const int32_t old = cls[v];
      if (stamp[old] != static_cast<int32_t>(c)) {
        stamp[old] = static_cast<int32_t>(c);
        remap[old] = next++;
        remap.push_back(-1);
        stamp.push_back(-1);
      }
      cls[v] = remap[old];
    });
  }
  // Compact the ids that still hold voxels (class 0 holds the uncoverable ones).
  std::vector<int32_t> compact(next, -1);
  Classes out;
  for (size_t v = 0; v < n_voxels; ++v) {
    const int32_t k = cls[v];
    if (k == 0) continue;
    if (compact[k] < 0) {
      compact[k] = static_cast<int32_t>(out.weight.size());
      out.weight.push_back(0);
    }
    ++out.weight[compact[k]];
  }
  out.seen_by.resize(out.weight.size());
  out.sees.resize(sets.size());
  std::vector<int32_t> last(out.weight.size(), -1);
  for (size_t c = 0; c < sets.size(); ++c) {
    ForEachBit(sets[c], [&](size_t v) {
      const int32_t k = compact[cls[v]];
      if (last[k] == static_cast<int32_t>(c)) return;
      last[k] = static_cast<int32_t>(c);
      out.seen_by[k].push_back(static_cast<int>(c));
      out.sees[c].push_back(k);
    });
    std::sort(out.sees[c].begin(), out.sees[c].end());
  }
  return out;
}

// The model after reduction: classes still to cover (merged again), the candidate columns, the
// candidates forced to 1 and where each dropped candidate's role goes.
struct ReducedModel {
  std::vector<uint64_t> weight;           // per class
  std::vector<std::vector<int>> seen_by;  // per class: column indices (into columns)
  std::vector<int> columns;               // candidate index per column
  std::vector<int> forced;                // candidates fixed to 1 (the fixed stations first)
  uint64_t forced_covered = 0;            // voxels the forced candidates cover
  std::vector<int> stand_in;              // per candidate: the candidate that replaces it, or -1
  int dominated = 0;
  int forced_sole_view = 0;
};

// keep_all (connectivity): every candidate that sees something, and every fixed one, stays a
// column (a dominated candidate may be the link the scan graph needs); only the classes merge.
Result<ReducedModel> Reduce(const Classes& cl, int n_candidates, int fixed, bool fix_sole_views, bool keep_all,
                            const JobContext& ctx) {
  const int n_classes = static_cast<int>(cl.weight.size());
  ReducedModel m;
  std::vector<char> active_class(n_classes, 1), active(n_candidates, 1);
  m.stand_in.assign(n_candidates, -1);
  for (int c = 0; c < n_candidates; ++c) m.stand_in[c] = c;
  auto force = [&](int c) {
    active[c] = 0;
    m.forced.push_back(c);
    for (int k : cl.sees[c]) {
      if (active_class[k]) {
        active_class[k] = 0;
        m.forced_covered += cl.weight[k];
      }
    }
  };
  if (!keep_all) {
    for (int c = 0; c < fixed; ++c) force(c);
  }
  std::vector<int> active_sees(n_candidates, 0);
  std::vector<int32_t> mark(n_classes, -1);
  bool changed = true;
  while (changed) {
    changed = false;
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (model reduction)"));
    // Candidates that see no class still to cover add nothing.
    for (int c = 0; c < n_candidates; ++c) {
      if (!active[c]) continue;
      active_sees[c] = 0;
      for (int k : cl.sees[c]) active_sees[c] += active_class[k];
      if (active_sees[c] == 0 && !(keep_all && c < fixed)) {
        active[c] = 0;
        m.stand_in[c] = -1;
      }
    }
    if (keep_all) break;
    if (fix_sole_views) {
      for (int k = 0; k < n_classes; ++k) {
        if (!active_class[k]) continue;
        int only = -1, views = 0;
        for (int c : cl.seen_by[k]) {
          if (active[c]) {
            only = c;
            if (++views > 1) break;
          }
        }
        if (views == 1) {
          force(only);
          ++m.forced_sole_view;
          changed = true;
        }
      }
      if (changed) continue;
    }
    // Domination: a's classes still to cover are a subset of b's (on equal sets the higher index goes).
    std::vector<int> order;
    for (int c = 0; c < n_candidates; ++c) {
      if (active[c]) order.push_back(c);
    }
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return active_sees[a] != active_sees[b] ? active_sees[a] < active_sees[b] : a > b; });
    for (size_t i = 0; i < order.size(); ++i) {
      if (i % 256 == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (model reduction)"));
      const int a = order[i];
      // The class of a with the fewest candidates still active bounds who can dominate a.
      int rarest = -1;
      size_t rarest_views = SIZE_MAX;
      for (int k : cl.sees[a]) {
        if (active_class[k] && cl.seen_by[k].size() < rarest_views) {
          rarest = k;
          rarest_views = cl.seen_by[k].size();
        }
      }
      for (int k : cl.sees[a]) {
        if (active_class[k]) mark[k] = a;
      }
      for (int b : cl.seen_by[rarest]) {
        if (b == a || !active[b] || active_sees[b] < active_sees[a]) continue;
        if (active_sees[b] == active_sees[a] && b > a) continue;  // equal sets: the lower index stays
        int inside = 0;
        for (int k : cl.sees[b]) inside += (mark[k] == a);
        if (inside == active_sees[a]) {
          active[a] = 0;
          m.stand_in[a] = b;
          ++m.dominated;
          changed = true;
          break;
        }
      }
    }
  }
  // Resolve chains of stand-ins to a column or a forced candidate.
  for (int c = 0; c < n_candidates; ++c) {
    int s = c;
    for (int hops = 0; s >= 0 && m.stand_in[s] != s && hops <= n_candidates; ++hops) s = m.stand_in[s];
    m.stand_in[c] = s;
  }
  std::vector<int> column_of(n_candidates, -1);
  for (int c = 0; c < n_candidates; ++c) {
    if (active[c]) {
      column_of[c] = static_cast<int>(m.columns.size());
      m.columns.push_back(c);
    }
  }
  // Classes left, merged again by their (now smaller) sets of columns.
  std::map<std::vector<int>, int> index;
  for (int k = 0; k < n_classes; ++k) {
    if (!active_class[k]) continue;
    std::vector<int> cols;
    for (int c : cl.seen_by[k]) {
      if (active[c]) cols.push_back(column_of[c]);
    }
    auto [it, inserted] = index.emplace(std::move(cols), static_cast<int>(m.weight.size()));
    if (inserted) {
      m.weight.push_back(cl.weight[k]);
      m.seen_by.push_back(it->first);
    } else {
      m.weight[it->second] += cl.weight[k];
    }
  }
  return m;
}

// The counting bound on the columns needed: each covers at most the widest column's weight.
double CountingBound(const ReducedModel& m, uint64_t need) {
  std::vector<uint64_t> width(m.columns.size(), 0);
  for (size_t k = 0; k < m.weight.size(); ++k) {
    for (int j : m.seen_by[k]) width[j] += m.weight[k];
  }
  const uint64_t widest = std::max<uint64_t>(1, width.empty() ? 1 : *std::max_element(width.begin(), width.end()));
  return std::ceil(double(need) / double(widest) - 1e-9);
}

// Voxels covered by the union of `picks`.
uint64_t Covered(const std::vector<VoxelSet>& sets, const std::vector<int>& picks) {
  if (sets.empty()) return 0;
  VoxelSet u(sets[0].size());
  for (int p : picks) UnionInto(u, sets[p]);
  return CountBits(u);
}

// Whether `a` and `b` hold the same candidates (in any order).
bool SameSet(std::vector<int> a, std::vector<int> b) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  return a == b;
}

// The fixed stations in order, then the other picks in greedy order among themselves (largest
// marginal gain first, ties to the lowest index).
std::vector<int> SortByMarginalGain(const std::vector<VoxelSet>& sets, std::vector<int> picks, int fixed) {
  std::vector<int> out;
  std::sort(picks.begin(), picks.end());
  picks.erase(std::unique(picks.begin(), picks.end()), picks.end());
  if (sets.empty()) return picks;
  VoxelSet so_far(sets[0].size());
  std::vector<int> rest;
  for (int p : picks) {
    if (p < fixed) {
      out.push_back(p);
      UnionInto(so_far, sets[p]);
    } else {
      rest.push_back(p);
    }
  }
  while (!rest.empty()) {
    size_t best = 0;
    uint64_t best_gain = 0;
    for (size_t i = 0; i < rest.size(); ++i) {
      const uint64_t gain = CountBits(sets[rest[i]]) - CountAnd(sets[rest[i]], so_far);
      if (i == 0 || gain > best_gain) {
        best = i;
        best_gain = gain;
      }
    }
    out.push_back(rest[best]);
    UnionInto(so_far, sets[rest[best]]);
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return out;
}

// What the event handler shares with Select (the handler is cloned into CBC's own model).
struct SolveWatch {
  const JobContext* ctx = nullptr;
  Clock::time_point start;
  double time_limit_s = 0;
  bool max_mode = false;
  double offset = 0;  // added to CBC's objective for reporting (forced stations, or their coverage)
  Status cancelled = Status::Ok();
  Clock::time_point last_report;
  bool lp_stopped = false;  // an LP solve was cut off at the deadline
};

// Stops an LP solve (Clp) at the deadline or on cancellation: CBC checks its time limit only
// between nodes, and the root LP of a large model alone can take minutes.
class LpWatchHandler final : public ClpEventHandler {
 public:
  explicit LpWatchHandler(SolveWatch* watch) : watch_(watch) {}
  ClpEventHandler* clone() const override { return new LpWatchHandler(*this); }
  int event(Event which) override {
    if (which != endOfIteration) return -1;
    Status s = watch_->ctx->CheckCancelled("exact selection");
    if (!s.ok()) {
      if (watch_->cancelled.ok()) watch_->cancelled = std::move(s);
      return 0;
    }
    if (SecondsSince(watch_->start) > watch_->time_limit_s) {
      watch_->lp_stopped = true;
      return 0;
    }
    return -1;
  }

 private:
  SolveWatch* watch_;
};

// Stops CBC when the job is cancelled and reports the incumbent and the bound as progress.
class WatchHandler final : public CbcEventHandler {
 public:
  explicit WatchHandler(SolveWatch* watch) : watch_(watch) {}
  CbcEventHandler* clone() const override { return new WatchHandler(*this); }
  CbcAction event(CbcEvent which) override {
    Status s = watch_->ctx->CheckCancelled("exact selection");
    if (!s.ok()) {
      if (watch_->cancelled.ok()) watch_->cancelled = std::move(s);
      return stop;
    }
    const Clock::time_point now = Clock::now();
    if (now - watch_->last_report > std::chrono::milliseconds(250) && model_ != nullptr &&
        model_->bestSolution() != nullptr && model_->getObjValue() < 1e30) {
      watch_->last_report = now;
      const double elapsed = std::chrono::duration<double>(now - watch_->start).count();
      char note[160];
      if (watch_->max_mode) {
        std::snprintf(note, sizeof note, "exact: incumbent %.0f voxels, bound %.0f",
                      watch_->offset - model_->getObjValue(), watch_->offset - model_->getBestPossibleObjValue());
      } else {
        std::snprintf(note, sizeof note, "exact: incumbent %.0f stations, bound %.2f",
                      watch_->offset + model_->getObjValue(), watch_->offset + model_->getBestPossibleObjValue());
      }
      watch_->ctx->Report(Stage::kSelection, std::min(0.99, elapsed / watch_->time_limit_s), note);
    }
    return noAction;
  }

 private:
  SolveWatch* watch_;
};

// The covered weight of class-level picks: per class, how many picks see it.
struct SwapState {
  const Classes* cl;
  std::vector<int> count;  // per class
  uint64_t covered = 0;
  void Add(int c) {
    for (int k : cl->sees[c]) {
      if (count[k]++ == 0) covered += cl->weight[k];
    }
  }
  void Remove(int c) {
    for (int k : cl->sees[c]) {
      if (--count[k] == 0) covered -= cl->weight[k];
    }
  }
  uint64_t Gain(int c) const {
    uint64_t g = 0;
    for (int k : cl->sees[c]) g += count[k] == 0 ? cl->weight[k] : 0;
    return g;
  }
};

// Greedy's picks improved by exchanges that keep the covered weight at or above `target`: drop a
// pick, replace two picks by one candidate, or swap one pick for a candidate that covers more.
// Stops when none applies or at the deadline.
Result<std::vector<int>> SwapLocalSearch(const Classes& cl, std::vector<int> picks, int fixed, int n_candidates,
                                         uint64_t target, bool max_mode, Clock::time_point deadline,
                                         const JobContext& ctx) {
  SwapState st{&cl, std::vector<int>(cl.weight.size(), 0), 0};
  std::vector<char> picked(n_candidates, 0);
  for (int p : picks) {
    st.Add(p);
    picked[p] = 1;
  }
  const uint64_t floor = max_mode ? st.covered : std::min(target, st.covered);
  auto remove_pick = [&](size_t i) {
    st.Remove(picks[i]);
    picked[picks[i]] = 0;
    picks.erase(picks.begin() + static_cast<std::ptrdiff_t>(i));
  };
  bool improved = true;
  while (improved && Clock::now() < deadline) {
    improved = false;
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("swap local search"));
    // Drop a pick the others cover well enough.
    for (size_t i = 0; i < picks.size() && !improved; ++i) {
      if (picks[i] < fixed) continue;
      st.Remove(picks[i]);
      if (st.covered >= floor) {
        picked[picks[i]] = 0;
        picks.erase(picks.begin() + static_cast<std::ptrdiff_t>(i));
        improved = true;
      } else {
        st.Add(picks[i]);
      }
    }
    // 2-for-1.
    for (size_t i = 0; i < picks.size() && !improved && Clock::now() < deadline; ++i) {
      if (picks[i] < fixed) continue;
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("swap local search"));
      st.Remove(picks[i]);
      for (size_t j = i + 1; j < picks.size() && !improved; ++j) {
        if (picks[j] < fixed) continue;
        st.Remove(picks[j]);
        for (int c = fixed; c < n_candidates; ++c) {
          if (picked[c] || st.covered + st.Gain(c) < floor) continue;
          st.Add(picks[i]);  // restore, then replace properly
          st.Add(picks[j]);
          remove_pick(j);
          remove_pick(i);
          picks.push_back(c);
          picked[c] = 1;
          st.Add(c);
          improved = true;
          break;
        }
        if (!improved) st.Add(picks[j]);
      }
      if (!improved) st.Add(picks[i]);
    }
    // 1-for-1 that covers more.
    for (size_t i = 0; i < picks.size() && !improved && Clock::now() < deadline; ++i) {
      if (picks[i] < fixed) continue;
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("swap local search"));
      const uint64_t before = st.covered;
      st.Remove(picks[i]);
      int best = -1;
      uint64_t best_covered = before;
      for (int c = fixed; c < n_candidates; ++c) {
        if (picked[c]) continue;
        const uint64_t with = st.covered + st.Gain(c);
        if (with > best_covered) {
          best = c;
          best_covered = with;
        }
      }
      st.Add(picks[i]);
      if (best >= 0) {
        remove_pick(i);
        picks.push_back(best);
        picked[best] = 1;
        st.Add(best);
        improved = true;
      }
    }
  }
  return picks;
}

}  // namespace

std::string_view OptimalityStatusName(OptimalityStatus status) {
  switch (status) {
    case OptimalityStatus::kHeuristic:
      return "heuristic";
    case OptimalityStatus::kFeasible:
      return "feasible";
    case OptimalityStatus::kOptimal:
      return "optimal";
  }
  return "unknown";
}

Result<Selection> ExactSelector::Select(const std::vector<VoxelSet>& sets, int fixed, const JobContext& ctx) const {
  const Clock::time_point start = Clock::now();
  if (!(options_.time_limit_s > 0) || !std::isfinite(options_.time_limit_s)) {
    return InvalidArgumentError("exact selection: time_limit_s must be positive, got " +
                                std::to_string(options_.time_limit_s));
  }
  // The greedy plan: the warm start, the floor, and the argument checks.
  VC_ASSIGN_OR_RETURN(Selection out, GreedySelector(options_.greedy).Select(sets, fixed, ctx));
  const int n = static_cast<int>(sets.size());
  const bool max_mode = options_.greedy.max_stations > 0;
  const uint64_t coverable = out.coverable;
  const uint64_t target = TargetVoxels(options_.greedy.target_coverage, coverable);
  Optimality& opt = out.optimality;
  opt.solver = "exact";
  opt.before = {n, static_cast<int>(coverable), static_cast<int>(coverable) + (target < coverable ? 1 : 0)};
  const std::vector<int> greedy_picks = out.picks;
  const uint64_t greedy_covered = Covered(sets, greedy_picks);
  const uint64_t greedy_pass_covered = out.covered;
  const StopReason greedy_stop = out.stop;

  // Whether `picks` is strictly better than greedy's plan: greedy's is not connected where it must
  // be (the integer program's plans are), or (reaches the target with fewer stations, or greedy's
  // does not reach it) or, with max_stations, (more covered, capped at the target; or as much with
  // fewer stations).
  bool greedy_connected = true;  // set once the flow model has checked greedy's plan
  auto strictly_better = [&](const std::vector<int>& picks) {
    if (!greedy_connected) return true;
    const uint64_t covered = Covered(sets, picks);
    if (max_mode) {
      return std::make_pair(std::min(covered, target), -static_cast<int64_t>(picks.size())) >
             std::make_pair(std::min(greedy_covered, target), -static_cast<int64_t>(greedy_picks.size()));
    }
    return covered >= target && (greedy_covered < target || picks.size() < greedy_picks.size());
  };

  auto finish = [&](std::vector<int> picks) {
    if (options_.prefer_greedy && !strictly_better(picks)) picks = greedy_picks;
    if (options_.prefer_greedy && SameSet(picks, greedy_picks)) {
      // Greedy's plan as GreedySelector returned it: its order, its covered count and stop reason.
      out.picks = greedy_picks;
      out.covered = greedy_pass_covered;
      out.stop = greedy_stop;
    } else {
      const bool greedys = SameSet(picks, greedy_picks);
      out.picks = SortByMarginalGain(sets, std::move(picks), fixed);
      out.covered = Covered(sets, out.picks);
      out.stop = greedys                    ? greedy_stop  // e.g. kMinGain, which no recount can tell
                 : out.covered >= coverable ? StopReason::kExhausted
                 : out.covered >= target    ? StopReason::kTargetReached
                                            : StopReason::kMaxStations;
    }
    opt.stations = static_cast<int>(out.picks.size());
    if (max_mode) {
      opt.lower_bound = opt.stations;
      const uint64_t capped = std::min(out.covered, target);
      opt.gap = opt.covered_bound > 0
                    ? double(opt.covered_bound - std::min(capped, opt.covered_bound)) / opt.covered_bound
                    : 0.0;
      if (opt.status == OptimalityStatus::kHeuristic) opt.gap = 1;
    } else {
      opt.lower_bound = std::min<double>(opt.lower_bound, opt.stations);
      opt.gap = opt.stations > 0 ? (opt.stations - opt.lower_bound) / opt.stations : 0.0;
    }
    opt.seconds = SecondsSince(start);
    return out;
  };

  const bool connect = options_.greedy.min_overlap > 0;

  VC_ASSIGN_OR_RETURN(Classes cl, BuildClasses(sets, ctx));
  const bool full = !max_mode && target == coverable;
  VC_ASSIGN_OR_RETURN(ReducedModel m, Reduce(cl, n, fixed, full && !connect, connect, ctx));
  opt.forced = m.forced_sole_view;
  opt.dominated = m.dominated;
  const uint64_t need = target - std::min(target, m.forced_covered);  // voxels the columns must add
  const int n_cols = static_cast<int>(m.columns.size());
  const int n_classes = static_cast<int>(m.weight.size());
  const bool cover_rows = full;  // set-cover rows, no y variables
  const int cover_row_count = cover_rows ? n_classes : n_classes + 1 + (max_mode ? 1 : 0);
  // Connectivity (min_overlap > 0): the directed arcs of the candidates' scan graph.
  std::vector<std::pair<int, int>> arcs;
  if (connect) {
    for (int a = 0; a < n_cols; ++a) {
      if (a % 32 == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (scan graph)"));
      for (int b = a + 1; b < n_cols; ++b) {
        if (IsEdge(Overlap(sets[m.columns[a]], sets[m.columns[b]]), options_.greedy.min_overlap)) {
          arcs.emplace_back(a, b);
          arcs.emplace_back(b, a);
        }
      }
    }
  }
  const int n_arcs = static_cast<int>(arcs.size());
  const int n_rows = cover_row_count + (connect ? 1 + 3 * n_cols + 2 * n_arcs : 0);
  opt.model = {n_cols, n_classes, n_rows};

  // Nothing left to decide: the forced candidates reach the target (or there are no columns).
  if (n_cols == 0 || (!max_mode && need == 0)) {
    opt.status = OptimalityStatus::kOptimal;
    std::vector<int> picks = m.forced;
    if (!max_mode && need > 0) picks = greedy_picks;  // unreachable: columns would remain
    opt.lower_bound = static_cast<double>(picks.size());
    opt.covered_bound = max_mode ? std::min(Covered(sets, picks), target) : 0;
    return finish(std::move(picks));
  }

  // The memory estimate (CBC keeps row and column copies, the LP factorisation and cuts).
  uint64_t nnz = 0;
  for (const std::vector<int>& s : m.seen_by) nnz += s.size() + (cover_rows ? 0 : 2);
  const uint64_t estimate = nnz * 200 + uint64_t(n_rows + n_cols + (cover_rows ? 0 : n_classes)) * 1000;
  // Over the budget no integer program is built; at a station-count target the counting bound
  // (the forced candidates plus what the widest candidate would need) still says how far off the
  // plan can be, at no cost.
  const auto counting_bound_only = [&] {
    if (max_mode) return;
    opt.lower_bound = static_cast<double>(m.forced.size()) + CountingBound(m, need);
    if (opt.lower_bound > 0) opt.status = OptimalityStatus::kFeasible;
  };
  if (estimate > options_.memory_budget_bytes && !options_.swap_search) {
    opt.solver = "greedy";
    opt.status = OptimalityStatus::kHeuristic;
    opt.note = "the integer program (about " + std::to_string(estimate >> 20) + " MiB) exceeds the memory budget (" +
               std::to_string(options_.memory_budget_bytes >> 20) + " MiB); greedy plan, with the counting bound";
    counting_bound_only();
    return finish(greedy_picks);
  }
  if (estimate > options_.memory_budget_bytes) {
    VC_ASSIGN_OR_RETURN(std::vector<int> picks,
                        SwapLocalSearch(cl, greedy_picks, fixed, n, target, max_mode,
                                        start + std::chrono::duration_cast<Clock::duration>(
                                                    std::chrono::duration<double>(options_.time_limit_s)),
                                        ctx));
    opt.solver = "greedy+swap";
    opt.status = OptimalityStatus::kHeuristic;
    opt.note = "the integer program (about " + std::to_string(estimate >> 20) + " MiB) exceeds the memory budget (" +
               std::to_string(options_.memory_budget_bytes >> 20) +
               " MiB); greedy plus swap local search instead, with the counting bound";
    counting_bound_only();
    return finish(std::move(picks));
  }

  // Columns: x (one per candidate column), then y (one per class) unless cover_rows, then with
  // connectivity the single-commodity flow (Dehbi et al. 2021): a root r_c (binary, one of them),
  // the source's flow g_c <= N r_c into the root, and a flow f_a <= (N - 1) x on each arc of the
  // scan graph; every chosen station consumes one unit (g_c + in - out = x_c), so the chosen
  // stations are exactly those the root's flow reaches: the plan is connected.
  const int r0 = cover_rows ? n_cols : n_cols + n_classes, g0 = r0 + n_cols, f0 = g0 + n_cols;
  const int n_vars = connect ? f0 + n_arcs : r0;
  const double big_n = max_mode ? std::min<double>(n_cols, options_.greedy.max_stations + fixed) : n_cols;
  const int root_row = cover_row_count, rx_row = root_row + 1, gr_row = rx_row + n_cols, cons_row = gr_row + n_cols,
            cap_row = cons_row + n_cols;
  std::vector<std::vector<int>> arcs_at(n_cols);  // per column: the arcs it is an end of
  for (int a = 0; a < n_arcs; ++a) {
    arcs_at[arcs[a].first].push_back(a);
    arcs_at[arcs[a].second].push_back(a);
  }
  const double eps = 1.0 / (n_cols + 1.0);
  std::vector<double> col_lb(n_vars, 0.0), col_ub(n_vars, 1.0), obj(n_vars, 0.0);
  std::vector<double> row_lb(n_rows), row_ub(n_rows);
  std::vector<std::vector<int>> col_classes(n_cols);
  for (int k = 0; k < n_classes; ++k) {
    for (int j : m.seen_by[k]) col_classes[j].push_back(k);
  }
  const int weight_row = n_classes, budget_row = n_classes + 1;
  // The column-ordered matrix in one piece (appending column by column reallocates each time).
  std::vector<double> elements;
  std::vector<int> indices;
  std::vector<CoinBigIndex> starts;
  std::vector<int> lengths;
  elements.reserve(nnz + n_cols);
  indices.reserve(nnz + n_cols);
  auto add = [&](int row, double value) {
    indices.push_back(row);
    elements.push_back(value);
  };
  for (int j = 0; j < n_cols; ++j) {
    starts.push_back(static_cast<CoinBigIndex>(indices.size()));
    for (int k : col_classes[j]) add(k, cover_rows ? 1.0 : -1.0);
    if (max_mode) add(budget_row, 1.0);
    if (connect) {
      add(rx_row + j, -1.0);
      add(cons_row + j, -1.0);
      for (int a : arcs_at[j]) add(cap_row + 2 * a + (arcs[a].first == j ? 0 : 1), -(big_n - 1));
      if (m.columns[j] < fixed) col_lb[j] = 1.0;  // fixed stations are in the plan
    }
    lengths.push_back(static_cast<int>(indices.size()) - starts.back());
    obj[j] = max_mode ? eps : 1.0;
  }
  if (!cover_rows) {
    for (int k = 0; k < n_classes; ++k) {
      starts.push_back(static_cast<CoinBigIndex>(indices.size()));
      add(k, 1.0);
      add(weight_row, static_cast<double>(m.weight[k]));
      lengths.push_back(2);
      obj[n_cols + k] = max_mode ? -static_cast<double>(m.weight[k]) : 0.0;
    }
  }
  if (connect) {
    for (int j = 0; j < n_cols; ++j) {  // r_j
      starts.push_back(static_cast<CoinBigIndex>(indices.size()));
      add(root_row, 1.0);
      add(rx_row + j, 1.0);
      add(gr_row + j, -big_n);
      lengths.push_back(3);
    }
    for (int j = 0; j < n_cols; ++j) {  // g_j
      starts.push_back(static_cast<CoinBigIndex>(indices.size()));
      add(gr_row + j, 1.0);
      add(cons_row + j, 1.0);
      lengths.push_back(2);
      col_ub[g0 + j] = big_n;
    }
    for (int a = 0; a < n_arcs; ++a) {  // f_a, from arcs[a].first to arcs[a].second
      starts.push_back(static_cast<CoinBigIndex>(indices.size()));
      add(cons_row + arcs[a].second, 1.0);
      add(cons_row + arcs[a].first, -1.0);
      add(cap_row + 2 * a, 1.0);
      add(cap_row + 2 * a + 1, 1.0);
      lengths.push_back(4);
      col_ub[f0 + a] = big_n - 1;
    }
    row_lb[root_row] = row_ub[root_row] = 1.0;
    for (int j = 0; j < n_cols; ++j) {
      row_lb[rx_row + j] = row_lb[gr_row + j] = -COIN_DBL_MAX;
      row_ub[rx_row + j] = row_ub[gr_row + j] = 0.0;
      row_lb[cons_row + j] = row_ub[cons_row + j] = 0.0;
    }
    for (int a = 0; a < 2 * n_arcs; ++a) {
      row_lb[cap_row + a] = -COIN_DBL_MAX;
      row_ub[cap_row + a] = 0.0;
    }
  }
  const CoinPackedMatrix matrix(true, n_rows, n_vars, static_cast<CoinBigIndex>(indices.size()), elements.data(),
                                indices.data(), starts.data(), lengths.data());
  for (int k = 0; k < n_classes; ++k) {
    row_lb[k] = cover_rows ? 1.0 : -COIN_DBL_MAX;
    row_ub[k] = cover_rows ? COIN_DBL_MAX : 0.0;
  }
  if (!cover_rows) {
    row_lb[weight_row] = max_mode ? -COIN_DBL_MAX : static_cast<double>(need);
    row_ub[weight_row] = max_mode ? static_cast<double>(need) : COIN_DBL_MAX;
  }
  if (max_mode) {
    row_lb[budget_row] = -COIN_DBL_MAX;
    row_ub[budget_row] = options_.greedy.max_stations;
  }

  SolveWatch watch;
  watch.ctx = &ctx;
  watch.start = start;
  watch.time_limit_s = options_.time_limit_s;
  watch.max_mode = max_mode;
  watch.offset = max_mode ? double(m.forced_covered) : double(m.forced.size());
  watch.last_report = start - std::chrono::seconds(1);
  LpWatchHandler lp_handler(&watch);
  OsiClpSolverInterface solver;
  solver.messageHandler()->setLogLevel(0);
  solver.getModelPtr()->passInEventHandler(&lp_handler);
  solver.loadProblem(matrix, col_lb.data(), col_ub.data(), obj.data(), row_lb.data(), row_ub.data());
  for (int j = 0; j < n_cols; ++j) solver.setInteger(j);
  if (connect) {
    for (int j = 0; j < n_cols; ++j) solver.setInteger(r0 + j);
  }
  // Primal simplex: on geb079 (49,706 classes) the root LP takes 11 s with it and over 2 min with
  // the dual; with it in the resolves too, CBC proves 69 stations optimal in 67 s.
  solver.setHintParam(OsiDoDualInInitial, false, OsiHintDo);
  solver.setHintParam(OsiDoDualInResolve, false, OsiHintDo);
  // The root LP first, under the deadline (CbcModel copies the solved basis).
  solver.initialSolve();
  VC_RETURN_IF_ERROR(watch.cancelled);
  if (watch.lp_stopped) {
    opt.status = OptimalityStatus::kFeasible;
    opt.lower_bound = static_cast<double>(m.forced.size()) + CountingBound(m, need);
    opt.note = "the time limit cut off the LP relaxation; the bound is the counting bound";
    return finish(greedy_picks);
  }
  // The LP relaxation's optimum bounds the stations (min mode) from below.
  const double root_bound = solver.isProvenOptimal() ? solver.getObjValue() : -COIN_DBL_MAX;
  CbcModel model(solver);
  model.setLogLevel(0);
  model.messageHandler()->setLogLevel(0);
  model.setUseElapsedTime(true);
  model.setMaximumSeconds(std::max(0.01, options_.time_limit_s - SecondsSince(start)));
  if (!max_mode) model.setCutoffIncrement(1.0 - 1e-6);  // the objective is a station count
  CglProbing probing;
  probing.setUsingObjective(1);
  probing.setMaxPass(1);
  probing.setMaxProbe(10);
  probing.setMaxLook(10);
  CglGomory gomory;
  CglKnapsackCover knapsack;
  CglClique clique;
  clique.setStarCliqueReport(false);
  clique.setRowCliqueReport(false);
  CglMixedIntegerRounding2 mir;
  CglZeroHalf zero_half;
  model.addCutGenerator(&probing, -1, "Probing");
  model.addCutGenerator(&gomory, -1, "Gomory");
  model.addCutGenerator(&knapsack, -1, "Knapsack");
  model.addCutGenerator(&clique, -1, "Clique");
  model.addCutGenerator(&mir, -1, "MIR2");
  model.addCutGenerator(&zero_half, -1, "ZeroHalf");
  CbcRounding rounding(model);
  model.addHeuristic(&rounding);
  CbcHeuristicLocal local(model);
  model.addHeuristic(&local);
  CbcHeuristicFPump pump(model);
  model.addHeuristic(&pump);

  // The warm start: greedy's picks, each dropped candidate replaced by its stand-in.
  std::vector<char> in_plan(n, 0);
  for (int p : greedy_picks) {
    if (m.stand_in[p] >= 0) in_plan[m.stand_in[p]] = 1;
  }
  std::vector<double> warm(n_vars, 0.0);
  int warm_stations = 0;
  for (int j = 0; j < n_cols; ++j) {
    warm[j] = in_plan[m.columns[j]] ? 1.0 : 0.0;
    warm_stations += in_plan[m.columns[j]];
  }
  uint64_t warm_covered = 0;
  for (int k = 0; k < n_classes; ++k) {
    bool seen = false;
    for (int j : m.seen_by[k]) seen = seen || warm[j] > 0.5;
    if (!seen) continue;
    if (!cover_rows) {
      const uint64_t room = max_mode ? need - std::min(need, warm_covered) : m.weight[k];
      warm[n_cols + k] = std::min(1.0, double(room) / double(m.weight[k]));
    }
    warm_covered += m.weight[k];
  }
  // With connectivity: a spanning tree of the warm start's stations from its first one, each tree
  // arc carrying the stations below it; no warm start when greedy's plan is not connected.
  bool warm_connected = true;
  if (connect && warm_stations > 0) {
    int root = -1;
    for (int j = 0; j < n_cols && root < 0; ++j) {
      if (warm[j] > 0.5) root = j;
    }
    std::vector<int> parent_arc(n_cols, -2), order{root};
    parent_arc[root] = -1;
    for (size_t q = 0; q < order.size(); ++q) {
      for (int a : arcs_at[order[q]]) {
        const int to = arcs[a].second;
        if (arcs[a].first == order[q] && warm[to] > 0.5 && parent_arc[to] == -2) {
          parent_arc[to] = a;
          order.push_back(to);
        }
      }
    }
    warm_connected = static_cast<int>(order.size()) == warm_stations;
    if (warm_connected) {
      std::vector<double> below(n_cols, 1.0);
      for (size_t q = order.size(); q-- > 1;) {
        const int a = parent_arc[order[q]];
        warm[f0 + a] = below[order[q]];
        below[arcs[a].first] += below[order[q]];
      }
      warm[r0 + root] = 1.0;
      warm[g0 + root] = warm_stations;
    }
  }
  greedy_connected = warm_connected;
  const bool warm_ok =
      warm_connected && (max_mode ? warm_stations <= options_.greedy.max_stations : warm_covered >= need);
  if (warm_ok) {
    const double warm_obj = max_mode ? -double(std::min(warm_covered, need)) + eps * warm_stations : warm_stations;
    model.setBestSolution(warm.data(), n_vars, warm_obj, true);
  }

  WatchHandler handler(&watch);
  model.passInEventHandler(&handler);
  model.branchAndBound();
  VC_RETURN_IF_ERROR(watch.cancelled);
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection"));
  if (connect && !watch.lp_stopped && model.isProvenInfeasible()) {
    opt.solver = "greedy";
    opt.status = OptimalityStatus::kHeuristic;
    opt.note = "no connected plan over these candidates reaches the target at min_overlap " +
               std::to_string(options_.greedy.min_overlap) + "; greedy plan";
    return finish(greedy_picks);
  }
  if (!watch.lp_stopped && (model.status() == 2 || model.isProvenInfeasible())) {
    return InternalError("exact selection: CBC could not solve the station problem (status " +
                         std::to_string(model.status()) + "/" + std::to_string(model.secondaryStatus()) + ")");
  }
  // An LP cut off at the deadline proves nothing; CBC's bound is then only kept when a node was
  // solved (its bound stays valid).
  const bool proven = model.isProvenOptimal() && !watch.lp_stopped;
  const bool cbc_bound = !watch.lp_stopped || model.getNodeCount() > 0;
  const double bound = model.getBestPossibleObjValue();

  std::vector<int> picks = m.forced;
  const double* best = model.bestSolution();
  if (best != nullptr) {
    for (int j = 0; j < n_cols; ++j) {
      if (best[j] > 0.5) picks.push_back(m.columns[j]);
    }
  }
  // Never worse than greedy: (reaches the target, fewer stations) or (more covered, fewer stations).
  const uint64_t ilp_covered = best != nullptr ? Covered(sets, picks) : 0;
  const bool ilp_better =
      best != nullptr &&
      (max_mode ? (!warm_connected ||
                   std::make_pair(std::min(ilp_covered, target), -static_cast<int64_t>(picks.size())) >=
                       std::make_pair(std::min(greedy_covered, target), -static_cast<int64_t>(greedy_picks.size())))
                : (ilp_covered >= target &&
                   (greedy_covered < target || picks.size() <= greedy_picks.size() || !warm_connected)));
  if (!ilp_better) picks = greedy_picks;
  opt.status = proven ? OptimalityStatus::kOptimal : OptimalityStatus::kFeasible;
  if (max_mode) {
    const double b = std::max(cbc_bound ? bound : -COIN_DBL_MAX, root_bound);
    const double bound_covered = b <= -1e30 ? double(need) : std::floor(-b + eps * options_.greedy.max_stations + 1e-6);
    opt.covered_bound =
        std::min<uint64_t>(target, m.forced_covered + static_cast<uint64_t>(std::max(0.0, bound_covered)));
    if (proven) opt.covered_bound = std::min(Covered(sets, picks), target);
  } else {
    const double counting = CountingBound(m, need);
    const double ilp = std::max(0.0, std::ceil(std::max(cbc_bound ? bound : 0.0, root_bound) - 1e-6));
    opt.lower_bound = static_cast<double>(m.forced.size()) + std::max(counting, ilp);
    if (proven) opt.lower_bound = static_cast<double>(picks.size());
    if (watch.lp_stopped)
      opt.note = "the time limit cut off an LP in the search; the bound is the root LP's or CBC's last";
  }
  return finish(std::move(picks));
}

}  // namespace vc::planner
