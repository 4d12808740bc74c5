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
#include <OsiClpSolverInterface.hpp>
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cover_model.h"
#include "progress_pacer.h"
#include "vc/plan/greedy.h"
#include "vc/plan/lagrangian_bound.h"
#include "vc/plan/scan_graph.h"
#include "vc/plan/stage_runner.h"

namespace vc::planner {
namespace {

using internal::BuildClasses;
using internal::Classes;
using internal::CoverModel;
using internal::ReducedModel;
using internal::ScanArc;
using internal::TargetVoxels;
using internal::WarmStart;
using Clock = std::chrono::steady_clock;

// The selection stage's progress fraction at the end of greedy (with consolidation), of the size
// probe, the voxel classes, the model reduction and the scan graph; CBC's time limit fills the rest.
constexpr double kGreedyShare = 0.3, kProbeEnd = 0.33, kClassesEnd = 0.4, kReductionEnd = 0.47, kArcsEnd = 0.5;

double SecondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Completes `m` once the reduction is done: resolves chains of stand-ins to a column or a forced
// candidate, numbers the candidates still active as columns and merges the classes still to
// cover by their (now smaller) sets of columns.
void AssembleColumns(const Classes& cl, const std::vector<char>& active_class, const std::vector<char>& active,
                     ReducedModel& m) {
  const int n_candidates = static_cast<int>(active.size());
  const int n_classes = static_cast<int>(active_class.size());
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
}

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
  // Rounds run until nothing changes: each advances through what the rounds before it left, so the
  // fraction never falls although the number of rounds is not known.
  internal::ProgressPacer pacer;
  int round = 0;
  double done_before = 0;
  auto report = [&](uint64_t checked, uint64_t total) {
    if (!ctx.progress || !pacer.Due()) return;
    std::string note =
        "exact: model reduction round " + std::to_string(round) + " (" + std::to_string(m.dominated) + " dominated)";
    if (const std::string left = pacer.TimeLeft(checked, total); !left.empty()) note += ", " + left + " in this round";
    const double fraction = done_before + (1.0 - done_before) * (total ? double(checked) / double(total) : 0.0);
    ctx.progress(ProgressEvent{Stage::kSelection, fraction, std::move(note), checked, total, "candidates"});
  };
  bool changed = true;
  while (changed) {
    changed = false;
    ++round;
    pacer.Restart();
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
      if (i % 256 == 0) {
        VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (model reduction)"));
        report(i, order.size());
      }
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
    done_before += (1.0 - done_before) / 2;  // a full round done, another may follow
  }
  AssembleColumns(cl, active_class, active, m);
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

// What one pass over the candidates' voxels tells before any class is built: per voxel, how many
// candidates see it and a hash of which. Voxels of one class hash alike (a collision only merges two
// classes), so the distinct (hash, views) pairs count the classes and their non-zeros from below.
// Voxels a fixed station sees are left out (`skip_fixed`: they are forced and leave the model).
struct SizeProbe {
  std::vector<uint32_t> views;  // per voxel: candidates that see it (0: outside the model)
  uint64_t classes = 0;         // voxel classes of the model before the reduction, at least
  uint64_t nonzeros = 0;        // their (class, candidate) pairs, at least
  uint64_t voxels = 0;          // coverable voxels outside the fixed stations' sets
  int first_column = 0;         // candidates before it are fixed stations outside the model
};

Result<SizeProbe> ProbeSize(const std::vector<VoxelSet>& sets, int fixed, bool skip_fixed, const JobContext& ctx) {
  SizeProbe probe;
  const size_t n_voxels = sets.empty() ? 0 : sets[0].size();
  probe.first_column = skip_fixed ? fixed : 0;
  probe.views.assign(n_voxels, 0);
  std::vector<uint64_t> hash(n_voxels, 0);
  std::vector<char> fixed_sees(skip_fixed ? n_voxels : 0, 0);
  for (int c = 0; c < probe.first_column; ++c) sets[c].ForEach([&](size_t v) { fixed_sees[v] = 1; });
  uint64_t key = 0x9e3779b97f4a7c15ull;
  internal::ProgressPacer pacer;
  for (size_t c = probe.first_column; c < sets.size(); ++c) {
    if (c % 64 == 0) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (model size)"));
      if (pacer.Due()) {
        std::string note = "exact: model size";
        if (const std::string left = pacer.TimeLeft(c, sets.size()); !left.empty()) note += ", " + left;
        ctx.ReportCount(Stage::kSelection, c, sets.size(), "candidates", std::move(note));
      }
    }
    key = key * 6364136223846793005ull + 1442695040888963407ull;  // one odd key per candidate
    const uint64_t k = key | 1;
    sets[c].ForEach([&](size_t v) {
      ++probe.views[v];
      hash[v] += k;
    });
  }
  std::vector<std::pair<uint64_t, uint32_t>> signatures;
  for (size_t v = 0; v < n_voxels; ++v) {
    if (!fixed_sees.empty() && fixed_sees[v]) probe.views[v] = 0;
    if (probe.views[v] > 0) signatures.emplace_back(hash[v], probe.views[v]);
  }
  probe.voxels = signatures.size();
  std::sort(signatures.begin(), signatures.end());
  for (size_t i = 0; i < signatures.size(); ++i) {
    if (i > 0 && signatures[i] == signatures[i - 1]) continue;
    ++probe.classes;
    probe.nonzeros += signatures[i].second;
  }
  return probe;
}

// A relaxation of the station problem small enough to bound in about a second: the voxels seen by
// the fewest candidates (ascending views, then index) up to max_pairs (voxel, candidate) pairs,
// grouped into classes, with every other voxel of the model counted as covered for free (need
// shrinks by their number). Every plan of the full problem is a plan of this one, so a lower
// bound of this one holds for it. Columns are the candidates from probe.first_column on.
Result<CoverProblem> RareVoxelProblem(const std::vector<VoxelSet>& sets, const SizeProbe& probe, uint64_t need,
                                      uint64_t max_pairs, const JobContext& ctx) {
  CoverProblem p;
  p.columns = static_cast<int>(sets.size()) - probe.first_column;
  std::vector<uint32_t> order;
  for (size_t v = 0; v < probe.views.size(); ++v) {
    if (probe.views[v] > 0) order.push_back(static_cast<uint32_t>(v));
  }
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return probe.views[a] != probe.views[b] ? probe.views[a] < probe.views[b] : a < b;
  });
  std::vector<int32_t> slot(probe.views.size(), -1);
  uint64_t pairs = 0;
  size_t kept = 0;
  for (; kept < order.size() && pairs + probe.views[order[kept]] <= max_pairs; ++kept) {
    pairs += probe.views[order[kept]];
    slot[order[kept]] = static_cast<int32_t>(kept);
  }
  const uint64_t free_voxels = probe.voxels - kept;
  if (need <= free_voxels) return p;  // nothing left to need: no bound beyond 0
  p.need = need - free_voxels;
  std::vector<std::vector<int>> lists(kept);
  for (size_t c = probe.first_column; c < sets.size(); ++c) {
    if (c % 64 == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (bound)"));
    const int column = static_cast<int>(c) - probe.first_column;
    sets[c].ForEach([&](size_t v) {
      if (slot[v] >= 0) lists[slot[v]].push_back(column);
    });
  }
  std::map<std::vector<int>, int> index;
  for (std::vector<int>& cols : lists) {
    auto [it, inserted] = index.emplace(std::move(cols), static_cast<int>(p.weight.size()));
    if (inserted) {
      p.weight.push_back(1);
      p.seen_by.push_back(it->first);
    } else {
      ++p.weight[it->second];
    }
  }
  return p;
}

// The Lagrangian bound's options in a plan: at most kBoundPairVisits pairs visited (about a second;
// on geb079 the first two cores, docs/PLANNING.md "The Lagrangian bound over cores").
constexpr uint64_t kBoundPairVisits = uint64_t{3} << 27;
// ... and its plans (the Lagrangian heuristic) at most kPlanPairVisits, a third of that: hub:4, 5, 7,
// 8 and 9 take 23-37 plans, 9-50 M visits, to reach their optimum; on geb079, whose best plan (49)
// stays above its bound (46), the budget's 20 plans cost about 1.5 s (3 << 27: 59 plans, 2.4 s).
constexpr uint64_t kPlanPairVisits = uint64_t{1} << 27;
constexpr uint64_t kRareVoxelPairs = uint64_t{1} << 20;
// Auto's swap search before the integer program may use this share of the time limit.
constexpr double kSwapShare = 0.25;
// ... and the search that raises the bound on a model of at most kSearchColumns columns the next.
constexpr double kSearchShare = 0.25;
constexpr size_t kSearchColumns = 64;

// The Lagrangian bound on the columns over the reduced model's classes, and the best plan its
// multipliers gave (the Lagrangian heuristic, lagrangian_bound.h; its columns, ascending).
Result<LagrangianBound> ModelLagrangianBound(const ReducedModel& m, uint64_t need, int upper_bound,
                                             const JobContext& ctx) {
  const CoverProblem p{m.weight, m.seen_by, static_cast<int>(m.columns.size()), need};
  return ComputeLagrangianBound(p,
                                {.upper_bound = upper_bound,
                                 .max_pair_visits = kBoundPairVisits,
                                 .primal_plans = true,
                                 .max_plan_pair_visits = kPlanPairVisits},
                                ctx);
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
// Stops when none applies or at the deadline. Once at most `enough` picks are left (a proven
// bound; 0: none) only the 1-for-1 exchanges go on, for coverage.
Result<std::vector<int>> SwapLocalSearch(const Classes& cl, std::vector<int> picks, int fixed, int n_candidates,
                                         uint64_t target, bool max_mode, Clock::time_point deadline,
                                         const JobContext& ctx, size_t enough = 0) {
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
    const bool fewer = picks.size() > enough;  // fewer picks may still be possible
    // Drop a pick the others cover well enough.
    for (size_t i = 0; fewer && i < picks.size() && !improved; ++i) {
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
    for (size_t i = 0; fewer && i < picks.size() && !improved && Clock::now() < deadline; ++i) {
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

// Whether `size` columns of the reduced model cover at least `need` voxels: a depth-first search
// over the columns in order of decreasing weight that prunes a node when its covered weight plus
// the largest marginal gains still to be picked (an upper bound: coverage is submodular, so a
// gain only shrinks as picks are added) falls short. Exhaustive, hence a proof either way, unless
// the deadline stops it (kUnknown).
class FixedSizeSearch {
 public:
  enum class Outcome { kNo, kYes, kUnknown };

  FixedSizeSearch(const ReducedModel& m, uint64_t need, Clock::time_point deadline, const JobContext& ctx)
      : m_(m), need_(need), deadline_(deadline), ctx_(ctx), sees_(m.columns.size()), count_(m.weight.size(), 0) {
    std::vector<uint64_t> width(m.columns.size(), 0);
    for (size_t k = 0; k < m.weight.size(); ++k) {
      for (int j : m.seen_by[k]) {
        sees_[j].push_back(static_cast<int>(k));
        width[j] += m.weight[k];
      }
    }
    order_.resize(m.columns.size());
    for (size_t j = 0; j < order_.size(); ++j) order_[j] = static_cast<int>(j);
    std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return width[a] > width[b]; });
  }

  Result<Outcome> Run(int size) {
    covered_ = 0;
    picks_.clear();
    std::fill(count_.begin(), count_.end(), 0);
    stopped_ = false;
    VC_ASSIGN_OR_RETURN(bool yes, Visit(0, size));
    return yes ? Outcome::kYes : stopped_ ? Outcome::kUnknown : Outcome::kNo;
  }

 private:
  void Add(int j, int delta) {
    for (int k : sees_[j]) {
      if (delta > 0 ? count_[k]++ == 0 : --count_[k] == 0) {
        covered_ = delta > 0 ? covered_ + m_.weight[k] : covered_ - m_.weight[k];
      }
    }
  }

  // Picks `left` more columns among order_[from..]; true once the picks cover need_.
  Result<bool> Visit(size_t from, int left) {
    if (covered_ >= need_) return true;
    if (left == 0 || from >= order_.size()) return false;
    if ((++nodes_ & 255) == 0) {
      VC_RETURN_IF_ERROR(ctx_.CheckCancelled("exact selection"));
      if (Clock::now() > deadline_) stopped_ = true;
    }
    if (stopped_) return false;
    // Marginal gains of the columns still open, and the best `left` of them per suffix start.
    const size_t n = order_.size() - from;
    std::vector<uint64_t> gain(n);
    for (size_t i = 0; i < n; ++i) {
      for (int k : sees_[order_[from + i]]) gain[i] += count_[k] == 0 ? m_.weight[k] : 0;
    }
    std::vector<uint64_t> sorted = gain;
    std::sort(sorted.begin(), sorted.end(), std::greater<>());
    uint64_t best = 0;
    for (int r = 0; r < left && r < static_cast<int>(n); ++r) best += sorted[r];
    if (covered_ + best < need_) return false;
    for (size_t i = 0; i < n; ++i) {
      // The child's bound: its own gain plus the left - 1 largest gains after it (the parent's
      // gains bound the child's).
      std::vector<uint64_t> after(gain.begin() + static_cast<std::ptrdiff_t>(i) + 1, gain.end());
      const size_t take = std::min<size_t>(after.size(), static_cast<size_t>(left - 1));
      std::partial_sort(after.begin(), after.begin() + static_cast<std::ptrdiff_t>(take), after.end(),
                        std::greater<>());
      uint64_t bound = covered_ + gain[i];
      for (size_t r = 0; r < take; ++r) bound += after[r];
      if (bound < need_) continue;
      const int j = order_[from + i];
      Add(j, 1);
      picks_.push_back(j);
      VC_ASSIGN_OR_RETURN(bool yes, Visit(from + i + 1, left - 1));
      if (yes) return true;
      picks_.pop_back();
      Add(j, -1);
      if (stopped_) return false;
    }
    return false;
  }

  const ReducedModel& m_;
  const uint64_t need_;
  const Clock::time_point deadline_;
  const JobContext& ctx_;
  std::vector<std::vector<int>> sees_;  // per column: its classes
  std::vector<int> order_;              // columns by decreasing weight
  std::vector<int> count_;              // per class: picks that see it
  std::vector<int> picks_;
  uint64_t covered_ = 0;
  uint64_t nodes_ = 0;
  bool stopped_ = false;
};

// The directed arcs of the columns' scan graph: both directions of each edge, in order of the
// edge's lower column, then its higher one.
Result<std::vector<ScanArc>> ScanGraphArcs(const std::vector<VoxelSet>& sets, const std::vector<int>& columns,
                                           double min_overlap, const JobContext& ctx) {
  std::vector<ScanArc> arcs;
  const int n_cols = static_cast<int>(columns.size());
  const uint64_t pairs = uint64_t(n_cols) * uint64_t(std::max(n_cols - 1, 0)) / 2;
  uint64_t checked = 0;  // pairs before row a
  internal::ProgressPacer pacer;
  for (int a = 0; a < n_cols; checked += uint64_t(n_cols - 1 - a), ++a) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (scan graph)"));
    if (pacer.Due()) {
      std::string note = "exact: scan graph";
      if (const std::string left = pacer.TimeLeft(checked, pairs); !left.empty()) note += ", " + left;
      ctx.ReportCount(Stage::kSelection, checked, pairs, "pairs of columns", std::move(note));
    }
    for (int b = a + 1; b < n_cols; ++b) {
      if (IsEdge(Overlap(sets[columns[a]], sets[columns[b]]), min_overlap)) {
        arcs.push_back({a, b});
        arcs.push_back({b, a});
      }
    }
  }
  return arcs;
}

// What a CBC solve leaves behind (no CBC object outlives the solve).
struct CbcOutcome {
  bool root_lp_stopped = false;       // the time limit cut off the root LP; nothing below is set
  bool lp_stopped = false;            // an LP in the search was cut off at the deadline
  double root_bound = -COIN_DBL_MAX;  // the root LP's optimum, or -COIN_DBL_MAX when not proven
  bool warm_connected = true;         // the warm start's stations are connected (always without connectivity)
  bool proven_optimal = false;
  bool proven_infeasible = false;
  int status = 0;            // CbcModel::status()
  int secondary_status = 0;  // CbcModel::secondaryStatus()
  int node_count = 0;
  double best_possible = 0;     // CBC's bound on the objective
  bool has_solution = false;    // CBC holds a solution (its own or the warm start)
  std::vector<int> candidates;  // the candidates of the x columns at 1 in that solution
};

// Adds CBC's cut generators (CbcModel keeps its own copies).
void AddCutGenerators(CbcModel& cbc) {
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
  cbc.addCutGenerator(&probing, -1, "Probing");
  cbc.addCutGenerator(&gomory, -1, "Gomory");
  cbc.addCutGenerator(&knapsack, -1, "Knapsack");
  cbc.addCutGenerator(&clique, -1, "Clique");
  cbc.addCutGenerator(&mir, -1, "MIR2");
  cbc.addCutGenerator(&zero_half, -1, "ZeroHalf");
}

// Solves `model` with CBC until start + time_limit_s: the root LP first (primal simplex), then
// branch and bound warm-started from `warm_picks` (candidate indices < n_candidates) where that
// plan is feasible. CANCELLED / DEADLINE_EXCEEDED from ctx.
Result<CbcOutcome> SolveWithCbc(const CoverModel& model, const std::vector<int>& warm_picks, int n_candidates,
                                Clock::time_point start, double time_limit_s, const JobContext& ctx) {
  const ReducedModel& m = model.reduced();
  const bool max_mode = model.options().max_mode;
  SolveWatch watch;
  watch.ctx = &ctx;
  watch.start = start;
  watch.time_limit_s = time_limit_s;
  watch.max_mode = max_mode;
  watch.offset = max_mode ? double(m.forced_covered) : double(m.forced.size());
  watch.last_report = start - std::chrono::seconds(1);
  LpWatchHandler lp_handler(&watch);
  OsiClpSolverInterface solver;
  solver.messageHandler()->setLogLevel(0);
  solver.getModelPtr()->passInEventHandler(&lp_handler);
  model.LoadInto(solver);
  // Primal simplex: on geb079 (49,706 classes) the root LP takes 11 s with it and over 2 min with
  // the dual; with it in the resolves too, CBC proves 69 stations optimal in 67 s.
  solver.setHintParam(OsiDoDualInInitial, false, OsiHintDo);
  solver.setHintParam(OsiDoDualInResolve, false, OsiHintDo);
  // The root LP first, under the deadline (CbcModel copies the solved basis).
  solver.initialSolve();
  VC_RETURN_IF_ERROR(watch.cancelled);
  CbcOutcome out;
  if (watch.lp_stopped) {
    out.root_lp_stopped = true;
    return out;
  }
  // The LP relaxation's optimum bounds the stations (min mode) from below.
  out.root_bound = solver.isProvenOptimal() ? solver.getObjValue() : -COIN_DBL_MAX;
  CbcModel cbc(solver);
  cbc.setLogLevel(0);
  cbc.messageHandler()->setLogLevel(0);
  cbc.setUseElapsedTime(true);
  cbc.setMaximumSeconds(std::max(0.01, time_limit_s - SecondsSince(start)));
  if (!max_mode) cbc.setCutoffIncrement(1.0 - 1e-6);  // the objective is a station count
  AddCutGenerators(cbc);
  CbcRounding rounding(cbc);
  cbc.addHeuristic(&rounding);
  CbcHeuristicLocal local(cbc);
  cbc.addHeuristic(&local);
  CbcHeuristicFPump pump(cbc);
  cbc.addHeuristic(&pump);
  // The warm start: greedy's plan where it satisfies the model (none when it is not connected).
  const WarmStart warm = model.WarmStartFrom(warm_picks, n_candidates);
  out.warm_connected = warm.connected;
  if (warm.feasible) cbc.setBestSolution(warm.values.data(), model.n_columns(), warm.objective, true);
  WatchHandler handler(&watch);
  cbc.passInEventHandler(&handler);
  cbc.branchAndBound();
  VC_RETURN_IF_ERROR(watch.cancelled);
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection"));
  out.lp_stopped = watch.lp_stopped;
  out.proven_optimal = cbc.isProvenOptimal();
  out.proven_infeasible = cbc.isProvenInfeasible();
  out.status = cbc.status();
  out.secondary_status = cbc.secondaryStatus();
  out.node_count = cbc.getNodeCount();
  out.best_possible = cbc.getBestPossibleObjValue();
  const double* best = cbc.bestSolution();
  out.has_solution = best != nullptr;
  for (int j = 0; best != nullptr && j < model.station_cols().count; ++j) {
    if (best[model.station_cols()[j]] > 0.5) out.candidates.push_back(m.columns[j]);
  }
  return out;
}

// One ExactSelector::Select call after the greedy plan: builds the reduced model and the integer
// program, solves it (or takes a fallback) and reads the plan, filling in the Selection.
class ExactRun {
 public:
  ExactRun(const ExactSelectorOptions& options, const std::vector<VoxelSet>& sets, int fixed, const JobContext& ctx,
           Clock::time_point start, Selection greedy);
  Result<Selection> Select();

 private:
  Selection FinishForced(const ReducedModel& m, uint64_t need);
  Result<Selection> SelectOverBudget(const Classes* cl, const ReducedModel* m, uint64_t need, uint64_t estimate);
  Result<Selection> Read(const CoverModel& model, const CbcOutcome& outcome);
  void SetCoveredBound(const CoverModel& model, const CbcOutcome& outcome, bool proven, const std::vector<int>& picks);
  void SetStationBound(const CoverModel& model, const CbcOutcome& outcome, bool proven, size_t stations);
  Status SetRelaxedBound(const ReducedModel* m, uint64_t need, bool model_fits);
  Result<int> ModelBound(const ReducedModel& m, uint64_t need);
  const std::vector<int>& WarmPicks() const;
  Result<std::optional<Selection>> TryTheBoundFirst(const Classes& cl, const ReducedModel& m, uint64_t need);
  Result<int> RareVoxelBound();
  bool AtLeastAsGoodAsGreedy(const std::vector<int>& picks) const;
  bool StrictlyBetterThanGreedy(const std::vector<int>& picks) const;
  Selection Finish(std::vector<int> picks);
  // The time `share` of the time limit after the selection started.
  Clock::time_point Deadline(double share) const {
    return start_ +
           std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.time_limit_s * share));
  }

  const ExactSelectorOptions& options_;
  const std::vector<VoxelSet>& sets_;
  const int fixed_;
  const JobContext& ctx_;
  const Clock::time_point start_;
  const bool max_mode_;
  const bool connect_;
  // Voxels to cover: TargetVoxels, or what greedy covered when the gain rule stopped it, if less.
  const uint64_t target_;
  // Greedy's plan: its picks, the voxels they cover, its first pass's covered count and stop reason.
  const std::vector<int> greedy_picks_;
  const uint64_t greedy_covered_;
  const uint64_t greedy_pass_covered_;
  const StopReason greedy_stop_;
  bool greedy_connected_ = true;      // set once the flow model has checked greedy's plan
  std::optional<SizeProbe> probe_;    // the model's size before the reduction, once probed
  std::optional<int> model_bound_;    // ModelBound, once computed
  std::vector<int> lagrangian_plan_;  // with it: the Lagrangian heuristic's plan (candidates, the forced ones first)
  Selection out_;
};

ExactRun::ExactRun(const ExactSelectorOptions& options, const std::vector<VoxelSet>& sets, int fixed,
                   const JobContext& ctx, Clock::time_point start, Selection greedy)
    : options_(options),
      sets_(sets),
      fixed_(fixed),
      ctx_(ctx),
      start_(start),
      max_mode_(options.greedy.max_stations > 0),
      connect_(options.greedy.min_overlap > 0),
      target_(greedy.stop == StopReason::kGainRule
                  ? std::min(greedy.covered, TargetVoxels(options.greedy.target_coverage, greedy.coverable))
                  : TargetVoxels(options.greedy.target_coverage, greedy.coverable)),
      greedy_picks_(greedy.picks),
      greedy_covered_(Covered(sets, greedy.picks)),
      greedy_pass_covered_(greedy.covered),
      greedy_stop_(greedy.stop),
      out_(std::move(greedy)) {
  const uint64_t coverable = out_.coverable;
  out_.optimality.solver = "exact";
  out_.optimality.before = {static_cast<int>(sets.size()), static_cast<int>(coverable),
                            static_cast<int>(coverable) + (target_ < coverable ? 1 : 0)};
}

Result<Selection> ExactRun::Select() {
  const int n = static_cast<int>(sets_.size());
  Optimality& opt = out_.optimality;
  const bool full = !max_mode_ && target_ == out_.coverable;
  if (!full) {
    // Below target coverage nothing but domination shrinks the model: its size before the reduction,
    // from one pass over the sets, decides whether the classes are worth building at all.
    VC_ASSIGN_OR_RETURN(probe_, ProbeSize(sets_, fixed_, !connect_, ProgressRange(ctx_, kGreedyShare, kProbeEnd)));
    const uint64_t classes = probe_->classes;
    const uint64_t at_least = CoverModel::EstimatedBytes(probe_->nonzeros + 2 * classes, classes + 1, classes);
    const uint64_t fixed_cover = out_.coverable - probe_->voxels;
    if (at_least > options_.memory_budget_bytes && target_ > fixed_cover) {
      opt.model = {n - probe_->first_column, static_cast<int>(classes), static_cast<int>(classes) + 1};
      return SelectOverBudget(nullptr, nullptr, target_ - fixed_cover, at_least);
    }
  }
  VC_ASSIGN_OR_RETURN(Classes cl, BuildClasses(sets_, ProgressRange(ctx_, kProbeEnd, kClassesEnd)));
  VC_ASSIGN_OR_RETURN(ReducedModel m, Reduce(cl, n, fixed_, full && !connect_, connect_,
                                             ProgressRange(ctx_, kClassesEnd, kReductionEnd)));
  opt.forced = m.forced_sole_view;
  opt.dominated = m.dominated;
  const uint64_t need = target_ - std::min(target_, m.forced_covered);  // voxels the columns must add
  std::vector<ScanArc> arcs;
  if (connect_) {
    VC_ASSIGN_OR_RETURN(arcs, ScanGraphArcs(sets_, m.columns, options_.greedy.min_overlap,
                                            ProgressRange(ctx_, kReductionEnd, kArcsEnd)));
  }
  const CoverModel model(m, std::move(arcs),
                         {.max_mode = max_mode_,
                          .cover_rows = full,
                          .connect = connect_,
                          .max_stations = options_.greedy.max_stations,
                          .fixed = fixed_,
                          .need = need});
  opt.model = {model.station_cols().count, model.class_rows().count, model.n_rows()};
  // Nothing left to decide: the forced candidates reach the target (or there are no columns).
  if (model.station_cols().count == 0 || (!max_mode_ && need == 0)) return FinishForced(m, need);
  const uint64_t estimate = model.EstimatedBytes();
  if (estimate > options_.memory_budget_bytes) return SelectOverBudget(&cl, &m, need, estimate);
  if (options_.prefer_greedy && !max_mode_ && !connect_) {
    VC_ASSIGN_OR_RETURN(std::optional<Selection> proven, TryTheBoundFirst(cl, m, need));
    if (proven) return std::move(*proven);
  }
  VC_ASSIGN_OR_RETURN(CbcOutcome outcome, SolveWithCbc(model, WarmPicks(), n, start_, options_.time_limit_s,
                                                       ProgressRange(ctx_, kArcsEnd, 1.0)));
  return Read(model, outcome);
}

Selection ExactRun::FinishForced(const ReducedModel& m, uint64_t need) {
  Optimality& opt = out_.optimality;
  opt.status = OptimalityStatus::kOptimal;
  std::vector<int> picks = m.forced;
  if (!max_mode_ && need > 0) picks = greedy_picks_;  // unreachable: columns would remain
  opt.lower_bound = static_cast<double>(picks.size());
  opt.covered_bound = max_mode_ ? std::min(Covered(sets_, picks), target_) : 0;
  return Finish(std::move(picks));
}

// Over the budget no integer program is built: greedy's plan, or greedy plus the swap local search.
// Without `m` the model was refused before the reduction (`cl` is built here when the swaps need it).
Result<Selection> ExactRun::SelectOverBudget(const Classes* cl, const ReducedModel* m, uint64_t need,
                                             uint64_t estimate) {
  Optimality& opt = out_.optimality;
  const std::string too_large = "the integer program (" + std::string(m == nullptr ? "at least " : "") + "about " +
                                std::to_string(estimate >> 20) + " MiB) exceeds the memory budget (" +
                                std::to_string(options_.memory_budget_bytes >> 20) + " MiB); ";
  const std::string bound_note = max_mode_ ? "" : ", with the Lagrangian bound";
  if (!options_.swap_search) {
    opt.solver = "greedy";
    opt.status = OptimalityStatus::kHeuristic;
    opt.note = too_large + "greedy plan" + bound_note;
    VC_RETURN_IF_ERROR(SetRelaxedBound(m, need, false));
    return Finish(greedy_picks_);
  }
  std::optional<Classes> built;
  if (cl == nullptr) {
    VC_ASSIGN_OR_RETURN(built, BuildClasses(sets_, ProgressRange(ctx_, kProbeEnd, kClassesEnd)));
    cl = &*built;
  }
  const Clock::time_point deadline = Deadline(1.0);
  VC_ASSIGN_OR_RETURN(
      std::vector<int> picks,
      SwapLocalSearch(*cl, greedy_picks_, fixed_, static_cast<int>(sets_.size()), target_, max_mode_, deadline, ctx_));
  opt.solver = "greedy+swap";
  opt.status = OptimalityStatus::kHeuristic;
  opt.note = too_large + "greedy plus swap local search instead" + bound_note;
  VC_RETURN_IF_ERROR(SetRelaxedBound(m, need, false));
  return Finish(std::move(picks));
}

// Where no LP bound is at hand (over the budget, or the LP cut off), the best of the counting bound
// (the forced candidates plus what the widest candidate would need; over the reduced model, when
// built) and the Lagrangian bound: over the reduced classes when the model fits, else over the
// rarest voxels (RareVoxelProblem). Nothing with max_stations (the objective is coverage).
Status ExactRun::SetRelaxedBound(const ReducedModel* m, uint64_t need, bool model_fits) {
  if (max_mode_) return Status::Ok();
  Optimality& opt = out_.optimality;
  int bound = 0;
  if (m != nullptr) {
    const int forced = static_cast<int>(m->forced.size());
    bound = forced + static_cast<int>(CountingBound(*m, need));
    if (model_fits) {
      VC_ASSIGN_OR_RETURN(int model_bound, ModelBound(*m, need));
      bound = std::max(bound, model_bound);
    }
  }
  if (m == nullptr || !model_fits) {
    VC_ASSIGN_OR_RETURN(int rare, RareVoxelBound());
    bound = std::max(bound, rare);
  }
  opt.lower_bound = bound;
  if (opt.lower_bound > 0) opt.status = OptimalityStatus::kFeasible;
  return Status::Ok();
}

// The forced candidates plus the best of the counting and the Lagrangian bound over the reduced
// model's classes (computed once).
Result<int> ExactRun::ModelBound(const ReducedModel& m, uint64_t need) {
  if (!model_bound_) {
    const int forced = static_cast<int>(m.forced.size());
    const int upper_bound = static_cast<int>(greedy_picks_.size());
    VC_ASSIGN_OR_RETURN(LagrangianBound b, ModelLagrangianBound(m, need, std::max(1, upper_bound - forced), ctx_));
    model_bound_ = forced + std::max(static_cast<int>(CountingBound(m, need)), b.bound);
    lagrangian_plan_ = m.forced;
    for (int j : b.plan) lagrangian_plan_.push_back(m.columns[j]);
  }
  return *model_bound_;
}

// CBC's warm start: greedy's plan, or the Lagrangian heuristic's (computed with the bound first) where
// it has fewer stations and reaches the target over the candidates' own sets (issue 36: on geb079
// 49 stations against greedy's 51, which CBC did not improve on within its time). Without
// connection only: the heuristic knows no scan graph.
const std::vector<int>& ExactRun::WarmPicks() const {
  if (connect_ || max_mode_ || lagrangian_plan_.empty() || lagrangian_plan_.size() >= greedy_picks_.size()) {
    return greedy_picks_;
  }
  return Covered(sets_, lagrangian_plan_) >= target_ ? lagrangian_plan_ : greedy_picks_;
}

// Auto's way past the integer program where a cheap bound settles it (issue 36: on atrium:2 the
// root LP alone outlasts the 20 s limit, while the Lagrangian bound, a fraction of a second, is
// already the optimum). Greedy's plan at the bound is optimal as it is; above it, the swap local
// search from greedy's plan (kSwapShare of the time limit) that reaches the bound is optimal too,
// and where the swaps stall, the Lagrangian heuristic's plan at the bound (its 1-for-1 exchanges that
// cover more within the next kSearchShare). Otherwise nothing: CBC runs as before, warm-started
// from greedy, and reuses the bound if its root LP is cut off.
Result<std::optional<Selection>> ExactRun::TryTheBoundFirst(const Classes& cl, const ReducedModel& m, uint64_t need) {
  VC_ASSIGN_OR_RETURN(int bound, ModelBound(m, need));
  Optimality& opt = out_.optimality;
  std::string how = "the Lagrangian or counting bound proves it";
  const auto proven = [&](std::vector<int> picks) {
    opt.status = OptimalityStatus::kOptimal;
    opt.lower_bound = bound;
    opt.note = how + "; no integer program solved";
    return std::optional<Selection>(Finish(std::move(picks)));
  };
  if (static_cast<int>(greedy_picks_.size()) <= bound) return proven(greedy_picks_);
  const Clock::time_point deadline = Deadline(kSwapShare);
  VC_ASSIGN_OR_RETURN(std::vector<int> picks,
                      SwapLocalSearch(cl, greedy_picks_, fixed_, static_cast<int>(sets_.size()), target_, false,
                                      deadline, ctx_, static_cast<size_t>(bound)));
  if (static_cast<int>(picks.size()) <= bound && Covered(sets_, picks) >= target_) return proven(std::move(picks));
  // The Lagrangian heuristic's plan (issue 36: on hub:K the swaps from greedy's 2K + 1 stations
  // find no 2K, the multipliers do), checked over the candidates' own sets.
  if (!lagrangian_plan_.empty() && static_cast<int>(lagrangian_plan_.size()) <= bound &&
      Covered(sets_, lagrangian_plan_) >= target_) {
    how = "the Lagrangian or counting bound proves the Lagrangian heuristic's plan";
    const Clock::time_point swap_deadline = Deadline(kSwapShare + kSearchShare);
    VC_ASSIGN_OR_RETURN(std::vector<int> thicker,
                        SwapLocalSearch(cl, lagrangian_plan_, fixed_, static_cast<int>(sets_.size()), target_, false,
                                        swap_deadline, ctx_, static_cast<size_t>(bound)));
    return proven(std::move(thicker));
  }
  // A small model: raise the bound by proving, size by size, that no plan of `bound` stations
  // reaches the target (FixedSizeSearch). A plan found at some size only stops the search: CBC
  // finds one too, so the plan stays what CBC returns (and the same as before this step).
  if (m.columns.size() <= kSearchColumns) {
    const Clock::time_point search_deadline = Deadline(kSwapShare + kSearchShare);
    FixedSizeSearch search(m, need, search_deadline, ctx_);
    const int forced = static_cast<int>(m.forced.size());
    while (bound < static_cast<int>(picks.size())) {
      VC_ASSIGN_OR_RETURN(FixedSizeSearch::Outcome o, search.Run(bound - forced));
      if (o != FixedSizeSearch::Outcome::kNo) break;
      ++bound;  // no plan of `bound` stations: every plan has more
      how = "a search over every plan of " + std::to_string(bound - 1) + " stations proves it";
    }
    model_bound_ = bound;
    if (static_cast<int>(picks.size()) <= bound) return proven(std::move(picks));
  }
  return std::optional<Selection>();
}

// The fixed stations outside the model plus the Lagrangian bound of RareVoxelProblem.
Result<int> ExactRun::RareVoxelBound() {
  if (!probe_) {  // after the model was built: the counts move, the fraction stays
    VC_ASSIGN_OR_RETURN(probe_, ProbeSize(sets_, fixed_, !connect_, ProgressRange(ctx_, kArcsEnd, kArcsEnd)));
  }
  const uint64_t fixed_cover = out_.coverable - probe_->voxels;
  const uint64_t need = target_ - std::min(target_, fixed_cover);
  VC_ASSIGN_OR_RETURN(CoverProblem p, RareVoxelProblem(sets_, *probe_, need, kRareVoxelPairs, ctx_));
  const int upper_bound = std::max(1, static_cast<int>(greedy_picks_.size()) - probe_->first_column);
  VC_ASSIGN_OR_RETURN(
      LagrangianBound b,
      ComputeLagrangianBound(p, {.upper_bound = upper_bound, .max_pair_visits = kBoundPairVisits}, ctx_));
  return probe_->first_column + b.bound;
}

Result<Selection> ExactRun::Read(const CoverModel& model, const CbcOutcome& outcome) {
  const ReducedModel& m = model.reduced();
  const uint64_t need = model.options().need;
  Optimality& opt = out_.optimality;
  if (outcome.root_lp_stopped) {
    opt.status = OptimalityStatus::kFeasible;
    VC_RETURN_IF_ERROR(SetRelaxedBound(&m, need, true));
    opt.note = "the time limit cut off the LP relaxation; the bound is the Lagrangian or counting bound";
    return Finish(WarmPicks());
  }
  greedy_connected_ = outcome.warm_connected;
  if (connect_ && !outcome.lp_stopped && outcome.proven_infeasible) {
    opt.solver = "greedy";
    opt.status = OptimalityStatus::kHeuristic;
    opt.note = "no connected plan over these candidates reaches the target at min_overlap " +
               std::to_string(options_.greedy.min_overlap) + "; greedy plan";
    return Finish(greedy_picks_);
  }
  if (!outcome.lp_stopped && (outcome.status == 2 || outcome.proven_infeasible)) {
    return InternalError("exact selection: CBC could not solve the station problem (status " +
                         std::to_string(outcome.status) + "/" + std::to_string(outcome.secondary_status) + ")");
  }
  // An LP cut off at the deadline proves nothing.
  const bool proven = outcome.proven_optimal && !outcome.lp_stopped;
  std::vector<int> picks = m.forced;
  picks.insert(picks.end(), outcome.candidates.begin(), outcome.candidates.end());
  if (!outcome.has_solution || !AtLeastAsGoodAsGreedy(picks)) picks = greedy_picks_;
  opt.status = proven ? OptimalityStatus::kOptimal : OptimalityStatus::kFeasible;
  if (max_mode_) {
    SetCoveredBound(model, outcome, proven, picks);
  } else {
    SetStationBound(model, outcome, proven, picks.size());
    // A bound that meets the plan proves it, though the time limit stopped CBC's search (hub:6:
    // 12 stations, root bound 12, at 20 s).
    if (opt.lower_bound >= static_cast<double>(picks.size())) opt.status = OptimalityStatus::kOptimal;
  }
  return Finish(std::move(picks));
}

// CBC's bound is only kept when no LP was cut off or a node was solved (its bound stays valid).
void ExactRun::SetCoveredBound(const CoverModel& model, const CbcOutcome& outcome, bool proven,
                               const std::vector<int>& picks) {
  const bool cbc_bound = !outcome.lp_stopped || outcome.node_count > 0;
  const double b = std::max(cbc_bound ? outcome.best_possible : -COIN_DBL_MAX, outcome.root_bound);
  const double bound_covered =
      b <= -1e30 ? double(model.options().need) : std::floor(-b + model.eps() * options_.greedy.max_stations + 1e-6);
  Optimality& opt = out_.optimality;
  opt.covered_bound =
      std::min<uint64_t>(target_, model.reduced().forced_covered + static_cast<uint64_t>(std::max(0.0, bound_covered)));
  if (proven) opt.covered_bound = std::min(Covered(sets_, picks), target_);
}

void ExactRun::SetStationBound(const CoverModel& model, const CbcOutcome& outcome, bool proven, size_t stations) {
  const bool cbc_bound = !outcome.lp_stopped || outcome.node_count > 0;
  const double counting = CountingBound(model.reduced(), model.options().need);
  const double ilp =
      std::max(0.0, std::ceil(std::max(cbc_bound ? outcome.best_possible : 0.0, outcome.root_bound) - 1e-6));
  Optimality& opt = out_.optimality;
  opt.lower_bound = static_cast<double>(model.reduced().forced.size()) + std::max(counting, ilp);
  if (proven) opt.lower_bound = static_cast<double>(stations);
  if (outcome.lp_stopped)
    opt.note = "the time limit cut off an LP in the search; the bound is the root LP's or CBC's last";
}

// Never worse than greedy: (reaches the target, no more stations) or (more covered, no more stations),
// or greedy's plan is not connected where it must be.
bool ExactRun::AtLeastAsGoodAsGreedy(const std::vector<int>& picks) const {
  const uint64_t covered = Covered(sets_, picks);
  if (max_mode_) {
    return !greedy_connected_ ||
           std::make_pair(std::min(covered, target_), -static_cast<int64_t>(picks.size())) >=
               std::make_pair(std::min(greedy_covered_, target_), -static_cast<int64_t>(greedy_picks_.size()));
  }
  return covered >= target_ &&
         (greedy_covered_ < target_ || picks.size() <= greedy_picks_.size() || !greedy_connected_);
}

// Whether `picks` is strictly better than greedy's plan: greedy's is not connected where it must
// be (the integer program's plans are), or (reaches the target with fewer stations, or greedy's
// does not reach it) or, with max_stations, (more covered, capped at the target; or as much with
// fewer stations).
bool ExactRun::StrictlyBetterThanGreedy(const std::vector<int>& picks) const {
  if (!greedy_connected_) return true;
  const uint64_t covered = Covered(sets_, picks);
  if (max_mode_) {
    return std::make_pair(std::min(covered, target_), -static_cast<int64_t>(picks.size())) >
           std::make_pair(std::min(greedy_covered_, target_), -static_cast<int64_t>(greedy_picks_.size()));
  }
  return covered >= target_ && (greedy_covered_ < target_ || picks.size() < greedy_picks_.size());
}

// The Selection with `picks`: in greedy order among themselves (or greedy's plan as it was, with
// prefer_greedy), the stop reason and the gap.
Selection ExactRun::Finish(std::vector<int> picks) {
  Optimality& opt = out_.optimality;
  if (options_.prefer_greedy && !StrictlyBetterThanGreedy(picks)) picks = greedy_picks_;
  if (options_.prefer_greedy && SameSet(picks, greedy_picks_)) {
    // Greedy's plan as GreedySelector returned it: its order, its covered count and stop reason.
    out_.picks = greedy_picks_;
    out_.covered = greedy_pass_covered_;
    out_.stop = greedy_stop_;
  } else {
    const bool greedys = SameSet(picks, greedy_picks_);
    out_.picks = SortByMarginalGain(sets_, std::move(picks), fixed_);
    out_.covered = Covered(sets_, out_.picks);
    // The gain rule set the target: reaching it is the gain rule's stop.
    const StopReason reached =
        greedy_stop_ == StopReason::kGainRule ? StopReason::kGainRule : StopReason::kTargetReached;
    out_.stop = greedys                          ? greedy_stop_  // e.g. kMinGain, which no recount can tell
                : out_.covered >= out_.coverable ? StopReason::kExhausted
                : out_.covered >= target_        ? reached
                                                 : StopReason::kMaxStations;
  }
  opt.stations = static_cast<int>(out_.picks.size());
  if (max_mode_) {
    opt.lower_bound = opt.stations;
    const uint64_t capped = std::min(out_.covered, target_);
    opt.gap = opt.covered_bound > 0
                  ? double(opt.covered_bound - std::min(capped, opt.covered_bound)) / opt.covered_bound
                  : 0.0;
    if (opt.status == OptimalityStatus::kHeuristic) opt.gap = 1;
  } else {
    opt.lower_bound = std::min<double>(opt.lower_bound, opt.stations);
    opt.gap = opt.stations > 0 ? (opt.stations - opt.lower_bound) / opt.stations : 0.0;
  }
  opt.seconds = SecondsSince(start_);
  return std::move(out_);
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
  VC_ASSIGN_OR_RETURN(Selection greedy,
                      GreedySelector(options_.greedy).Select(sets, fixed, ProgressRange(ctx, 0.0, kGreedyShare)));
  return ExactRun(options_, sets, fixed, ctx, start, std::move(greedy)).Select();
}

}  // namespace vc::planner
