#include "vc/plan/lagrangian_bound.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace vc::planner {
namespace {

// One evaluation of L(u): its value, the rounding-error allowance and the columns chosen.
struct Evaluation {
  long double value = 0;
  long double tolerance = 0;
  std::vector<int> chosen;  // the columns of reduced cost < 0, ascending
};

// A class in the knapsack: u_k / w_k, then the class (the order's tie-break).
struct Priced {
  double ratio;
  int k;
};

class Subgradient {
 public:
  Subgradient(const CoverProblem& p, const LagrangianOptions& o) : p_(p), o_(o) {
    std::vector<uint64_t> width(p.columns, 0);
    for (size_t k = 0; k < p.weight.size(); ++k) {
      for (int j : p.seen_by[k]) width[j] += p.weight[k];
      if (!p.seen_by[k].empty()) coverable_ += p.weight[k];
      most_seers_ = std::max(most_seers_, p.seen_by[k].size());
    }
    for (uint64_t w : width) widest_ = std::max(widest_, w);
    if (o.primal_plans) width_ = std::move(width);
    u_.assign(p.weight.size(), 0.0);
    y_.assign(p.weight.size(), 0.0);
    g_.assign(p.weight.size(), 0.0);
    covered_.assign(p.weight.size(), 0);
  }

  int CountingBound() const { return static_cast<int>((p_.need + widest_ - 1) / widest_); }

  // The cores, each twice the last's seer limit, until one holds every class (or the budget ends).
  Result<LagrangianBound> Run(const JobContext& ctx) {
    LagrangianBound out;
    out.counting_bound = CountingBound();
    out.bound = out.counting_bound;
    out.relaxation = static_cast<double>(p_.need) / static_cast<double>(widest_);
    const double ub = o_.upper_bound > 0 ? o_.upper_bound : std::max(1, p_.columns);
    bool first = true;
    for (uint64_t limit = std::max(1, o_.first_core_seers);; limit *= 2) {
      const bool whole = limit >= most_seers_;
      SetCore(whole ? most_seers_ : limit, first);
      first = false;
      VC_ASSIGN_OR_RETURN(const bool budget_left, Phase(ctx, ub, out));
      if (!budget_left || whole || Done(out, ub)) break;
    }
    // No step ran (the counting bound met UB at once): a plan from the start's multipliers.
    if (o_.primal_plans && out.plan.empty()) {
      Evaluate();
      MakePlan(out);
    }
    out.bound = std::max(0, std::min(out.bound, p_.columns));
    return out;
  }

 private:
  // The core: the classes some column sees and at most `limit` columns see. The other classes keep
  // u_k = 0: free in the knapsack and in no column's price, so L(u) is the same over the core and
  // over every class, and each core's multipliers start the next. The first core starts at
  // Beasley's u_k = w_k / (the widest core column that sees k): every reduced cost is then >= 0.
  void SetCore(uint64_t limit, bool beasley_start) {
    sees_.assign(p_.columns, {});
    core_.clear();
    pairs_ = 0;
    for (size_t k = 0; k < p_.weight.size(); ++k) {
      const size_t n = p_.seen_by[k].size();
      if (n == 0 || n > limit) continue;
      core_.push_back(static_cast<int>(k));
      for (int j : p_.seen_by[k]) sees_[j].push_back(static_cast<int>(k));
      pairs_ += n;
    }
    if (!beasley_start) return;
    std::vector<uint64_t> width(p_.columns, 0);
    for (int j = 0; j < p_.columns; ++j) {
      for (int k : sees_[j]) width[j] += p_.weight[k];
    }
    for (int k : core_) {
      uint64_t seer = 1;
      for (int j : p_.seen_by[k]) seer = std::max(seer, width[j]);
      u_[k] = static_cast<double>(p_.weight[k]) / static_cast<double>(seer);
    }
  }

  // Whether the bound reached UB or the best plan's size (nothing better is left to prove).
  static bool Done(const LagrangianBound& out, double ub) {
    return out.bound >= ub || (!out.plan.empty() && out.bound >= static_cast<int>(out.plan.size()));
  }

  // Subgradient steps over the current core: at most max_iterations, until lambda falls below
  // min_step_scale or the bound reaches UB (or the best plan). False when the pair-visit budget ran
  // out. With primal_plans, a plan at every step whose L(u) is the core's best so far.
  Result<bool> Phase(const JobContext& ctx, double ub, LagrangianBound& out) {
    double scale = 2.0;
    double best = -1;  // this core's best L(u)
    int since_better = 0;
    uint64_t chosen_pairs = 0;  // the last subgradient's pair visits
    for (int it = 0; it < o_.max_iterations && !Done(out, ub); ++it) {
      if (out.pair_visits + pairs_ + chosen_pairs > o_.max_pair_visits && out.iterations > 0) return false;
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("Lagrangian bound"));
      const Evaluation e = Evaluate();
      ++out.iterations;
      const double value = static_cast<double>(e.value);
      if (value > out.relaxation) {
        out.relaxation = value;
        out.bound = std::max(out.bound, static_cast<int>(std::ceil(e.value - e.tolerance)));
      }
      if (value > best) {
        best = value;
        since_better = 0;
        if (o_.primal_plans && out.plan_pair_visits < o_.max_plan_pair_visits) MakePlan(out);
      } else if (++since_better >= o_.patience) {
        scale /= 2;
        since_better = 0;
        if (scale < o_.min_step_scale) break;
      }
      // The subgradient g_k = y_k - (columns chosen that see k) over the core; no step into u_k < 0
      // at u_k = 0. Only the chosen columns' pairs are visited (few have a reduced cost below 0).
      chosen_pairs = 0;
      for (int j : e.chosen) {
        for (int k : sees_[j]) ++covered_[k];
        chosen_pairs += sees_[j].size();
      }
      out.pair_visits += pairs_ + chosen_pairs;
      double norm2 = 0;
      for (int k : core_) {
        g_[k] = y_[k] - covered_[k];
        covered_[k] = 0;
        if (u_[k] <= 0 && g_[k] < 0) g_[k] = 0;
        norm2 += static_cast<double>(p_.weight[k]) * g_[k] * g_[k];
      }
      if (norm2 <= 0) break;  // x, y satisfy the relaxed rows with complementary slackness: u is optimal
      // The step in the metric scaled by the class weights (a voxel's price moves, not a class's).
      const double step = scale * std::max(ub - value, 1e-3) / norm2;
      for (int k : core_) u_[k] = std::max(0.0, u_[k] + step * static_cast<double>(p_.weight[k]) * g_[k]);
    }
    return true;
  }

  // sum_{k in sees} u_k in double (four partial sums; the bound's hot loop).
  double PriceOf(const std::vector<int>& sees) const {
    double a = 0, b = 0, c = 0, d = 0;
    size_t i = 0;
    for (; i + 4 <= sees.size(); i += 4) {
      a += u_[sees[i]];
      b += u_[sees[i + 1]];
      c += u_[sees[i + 2]];
      d += u_[sees[i + 3]];
    }
    for (; i < sees.size(); ++i) a += u_[sees[i]];
    return (a + b) + (c + d);
  }

  // L(u) at the current multipliers, the knapsack's y in y_. A column's price is a double sum of
  // n terms >= 0, off by at most n 2^-53 of itself; the sums over columns and classes are in long
  // double, with their terms' magnitudes. The tolerance covers both.
  Evaluation Evaluate() {
    Evaluation e;
    long double magnitude = 0;
    long double price_error = 0;
    reduced_.resize(p_.columns);
    for (int j = 0; j < p_.columns; ++j) {
      const double s = PriceOf(sees_[j]);
      const long double reduced = 1.0L - s;
      reduced_[j] = 1.0 - s;
      magnitude += 1.0L + s;
      price_error += static_cast<long double>(sees_[j].size() + 1) * 0x1p-52L * s;
      if (reduced < 0) {
        e.chosen.push_back(j);
        e.value += reduced;
      }
    }
    e.value += Knapsack(magnitude);
    e.tolerance = 1e-9L * (1.0L + magnitude) + price_error;
    return e;
  }

  // min sum_k u_k y_k s.t. sum_k w_k y_k >= need, y in [0, 1], over the classes some column sees:
  // the free classes (u_k = 0, every class outside the core among them) first, then by u_k / w_k
  // ascending (ties: the lower class), the last split. y_ is set over the core.
  long double Knapsack(long double& magnitude) {
    uint64_t taken = coverable_;
    priced_.clear();
    for (int k : core_) {
      y_[k] = 0;
      if (u_[k] > 0) {
        priced_.push_back({u_[k] / static_cast<double>(p_.weight[k]), k});
        taken -= p_.weight[k];
      } else {
        y_[k] = 1;
      }
    }
    long double cost = 0;
    if (taken >= p_.need) return cost;
    if (p_.need < coverable_) OrderCheapestFirst(priced_, p_.need - taken);
    for (const Priced& c : priced_) {
      const int k = c.k;
      const uint64_t rest = p_.need - taken;
      const uint64_t w = p_.weight[k];
      const double share = w <= rest ? 1.0 : static_cast<double>(rest) / static_cast<double>(w);
      y_[k] = share;
      cost += static_cast<long double>(u_[k]) * share;
      magnitude += static_cast<long double>(u_[k]);
      taken += std::min(w, rest);
      if (taken >= p_.need) break;
    }
    return cost;
  }

  // A plan from the current multipliers (the header's primal heuristic): greedy by the score of
  // Caprara, Fischetti & Toth until need is covered, then the columns the others make redundant
  // dropped by decreasing reduced cost. Kept in out.plan when it has fewer columns.
  void MakePlan(LagrangianBound& out) {
    if (all_sees_.empty()) {
      all_sees_.assign(p_.columns, {});
      for (size_t k = 0; k < p_.weight.size(); ++k) {
        for (int j : p_.seen_by[k]) all_sees_[j].push_back(static_cast<int>(k));
      }
      plan_count_.assign(p_.weight.size(), 0);
    }
    ++out.plans;
    // Per column: its reduced cost over the classes still uncovered, and their weight.
    std::vector<double> gamma = reduced_;
    std::vector<uint64_t> gain = width_;
    std::vector<int> plan;
    uint64_t covered = 0;
    while (covered < p_.need) {
      const double rest = static_cast<double>(p_.need - covered);
      int best = -1;
      double best_score = 0;
      for (int j = 0; j < p_.columns; ++j) {
        if (gain[j] == 0) continue;  // nothing new (every column in the plan among them)
        const double mu = std::min(static_cast<double>(gain[j]), rest);
        const double score = gamma[j] > 0 ? gamma[j] / mu : gamma[j] * mu;
        if (best < 0 || score < best_score) {
          best = j;
          best_score = score;
        }
      }
      if (best < 0) break;  // unreachable: CheckProblem ensures the columns see need
      plan.push_back(best);
      for (int k : all_sees_[best]) {
        if (plan_count_[k]++ > 0) continue;
        covered += p_.weight[k];
        for (int j : p_.seen_by[k]) {
          gain[j] -= p_.weight[k];
          gamma[j] += u_[k];
        }
        out.plan_pair_visits += p_.seen_by[k].size();
      }
      out.plan_pair_visits += all_sees_[best].size();
    }
    // Redundant columns, the least attractive (highest reduced cost) first.
    std::vector<int> order = plan;
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return reduced_[a] != reduced_[b] ? reduced_[a] > reduced_[b] : a > b; });
    std::vector<int> kept;
    for (int j : order) {
      uint64_t unique = 0;
      for (int k : all_sees_[j]) unique += plan_count_[k] == 1 ? p_.weight[k] : 0;
      out.plan_pair_visits += 2 * all_sees_[j].size();
      if (covered - unique >= p_.need) {
        covered -= unique;
        for (int k : all_sees_[j]) --plan_count_[k];
      } else {
        kept.push_back(j);
      }
    }
    for (int j : kept) {
      for (int k : all_sees_[j]) plan_count_[k] = 0;
    }
    if (out.plan.empty() || kept.size() < out.plan.size()) {
      std::sort(kept.begin(), kept.end());
      out.plan = std::move(kept);
    }
  }

  // Moves the classes the knapsack takes to the front of `priced` (by u_k / w_k ascending, ties:
  // the lower class), the last of them, which may be split, last: a weighted quickselect for the
  // class where the weight reaches `need`, then a sort of the few around it.
  void OrderCheapestFirst(std::vector<Priced>& priced, uint64_t need) const {
    const auto cheaper = [](const Priced& a, const Priced& b) {
      return a.ratio != b.ratio ? a.ratio < b.ratio : a.k < b.k;
    };
    auto first = priced.begin(), last = priced.end();
    while (last - first > 32) {
      auto mid = first + (last - first) / 2;
      std::nth_element(first, mid, last, cheaper);
      uint64_t below = 0;
      for (auto it = first; it != mid; ++it) below += p_.weight[it->k];
      if (below >= need) {
        last = mid;
      } else {
        need -= below + std::min(need - below, p_.weight[mid->k]);
        if (need == 0) {
          last = mid + 1;
          break;
        }
        first = mid + 1;
      }
    }
    std::sort(first, last, cheaper);
  }

  const CoverProblem& p_;
  const LagrangianOptions& o_;
  std::vector<int> core_;                   // the classes of the current core, ascending
  std::vector<std::vector<int>> sees_;      // per column: the core classes it sees, ascending
  std::vector<double> u_;                   // per class: the multiplier of y_k <= sum x_j (0 outside the core)
  std::vector<double> y_;                   // per core class: its share in the last knapsack
  std::vector<double> g_;                   // per core class: the last subgradient
  std::vector<int> covered_;                // per class: chosen columns that see it (0 between iterations)
  std::vector<Priced> priced_;              // the knapsack's classes of u_k > 0 (kept to reuse its memory)
  std::vector<double> reduced_;             // per column: 1 - sum_{k seen} u_k at the last evaluation
  std::vector<uint64_t> width_;             // per column: the weight it sees (with primal_plans)
  std::vector<std::vector<int>> all_sees_;  // per column: every class it sees (built by the first plan)
  std::vector<int> plan_count_;             // per class: plan columns that see it (0 between plans)
  uint64_t coverable_ = 0;                  // weight of the classes some column sees
  uint64_t widest_ = 1;                     // the widest column's weight (at least 1)
  uint64_t pairs_ = 0;                      // (class, column) pairs of the core
  size_t most_seers_ = 0;                   // the most columns that see one class
};

Status CheckProblem(const CoverProblem& p) {
  if (p.seen_by.size() != p.weight.size()) {
    return InvalidArgumentError("Lagrangian bound: " + std::to_string(p.weight.size()) + " class weights but " +
                                std::to_string(p.seen_by.size()) + " column lists");
  }
  uint64_t coverable = 0;
  for (size_t k = 0; k < p.weight.size(); ++k) {
    if (p.weight[k] == 0) return InvalidArgumentError("Lagrangian bound: class " + std::to_string(k) + " weighs 0");
    for (int j : p.seen_by[k]) {
      if (j < 0 || j >= p.columns) {
        return InvalidArgumentError("Lagrangian bound: class " + std::to_string(k) + " names column " +
                                    std::to_string(j) + " of " + std::to_string(p.columns));
      }
    }
    if (!p.seen_by[k].empty()) coverable += p.weight[k];
  }
  if (p.need > coverable) {
    return InvalidArgumentError("Lagrangian bound: need " + std::to_string(p.need) + " voxels but the columns see " +
                                std::to_string(coverable));
  }
  return Status::Ok();
}

}  // namespace

Result<LagrangianBound> ComputeLagrangianBound(const CoverProblem& problem, const LagrangianOptions& options,
                                               const JobContext& ctx) {
  VC_RETURN_IF_ERROR(CheckProblem(problem));
  if (problem.need == 0) return LagrangianBound{};
  return Subgradient(problem, options).Run(ctx);
}

}  // namespace vc::planner
