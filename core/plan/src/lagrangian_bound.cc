#include "vc/plan/lagrangian_bound.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace vc::planner {
namespace {

// One evaluation of L(u): its value, the rounding-error allowance and the subproblems' solutions.
struct Evaluation {
  long double value = 0;
  long double tolerance = 0;
  std::vector<char> x;    // per column: chosen (reduced cost < 0)
  std::vector<double> y;  // per class: covered share in the knapsack
};

class Subgradient {
 public:
  Subgradient(const CoverProblem& p, const LagrangianOptions& o) : p_(p), o_(o) {
    sees_.resize(p.columns);
    for (size_t k = 0; k < p.weight.size(); ++k) {
      for (int j : p.seen_by[k]) sees_[j].push_back(static_cast<int>(k));
      if (!p.seen_by[k].empty()) {
        coverable_ += p.weight[k];
        pairs_ += p.seen_by[k].size();
      }
    }
    uint64_t widest = 1;
    for (const std::vector<int>& s : sees_) {
      uint64_t w = 0;
      for (int k : s) w += p.weight[k];
      widest = std::max(widest, w);
    }
    widest_ = widest;
    u_.assign(p.weight.size(), 0.0);
    for (size_t k = 0; k < p.weight.size(); ++k) {
      if (!p.seen_by[k].empty()) u_[k] = static_cast<double>(p.weight[k]) / static_cast<double>(widest);
    }
  }

  int CountingBound() const { return static_cast<int>((p_.need + widest_ - 1) / widest_); }

  Result<LagrangianBound> Run(const JobContext& ctx) {
    LagrangianBound out;
    out.counting_bound = CountingBound();
    out.bound = out.counting_bound;
    out.relaxation = static_cast<double>(p_.need) / static_cast<double>(widest_);
    const double ub = o_.upper_bound > 0 ? o_.upper_bound : std::max(1, p_.columns);
    double scale = 2.0;
    int since_better = 0;
    std::vector<double> g(p_.weight.size(), 0.0);
    for (int it = 0; it < o_.max_iterations && out.bound < ub; ++it) {
      if (out.pair_visits + 2 * pairs_ > o_.max_pair_visits && it > 0) break;
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("Lagrangian bound"));
      const Evaluation e = Evaluate();
      out.pair_visits += 2 * pairs_;
      out.iterations = it + 1;
      const double value = static_cast<double>(e.value);
      if (value > out.relaxation) {
        out.relaxation = value;
        out.bound = std::max(out.bound, static_cast<int>(std::ceil(e.value - e.tolerance)));
        since_better = 0;
      } else if (++since_better >= o_.patience) {
        scale /= 2;
        since_better = 0;
        if (scale < o_.min_step_scale) break;
      }
      // The subgradient g_k = y_k - (columns chosen that see k); no step into u_k < 0 at u_k = 0.
      double norm2 = 0;
      for (size_t k = 0; k < g.size(); ++k) {
        if (p_.seen_by[k].empty()) continue;
        int covered = 0;
        for (int j : p_.seen_by[k]) covered += e.x[j];
        g[k] = e.y[k] - covered;
        if (u_[k] <= 0 && g[k] < 0) g[k] = 0;
        norm2 += static_cast<double>(p_.weight[k]) * g[k] * g[k];
      }
      if (norm2 <= 0) break;  // x, y satisfy the relaxed rows with complementary slackness: u is optimal
      // The step in the metric scaled by the class weights (a voxel's price moves, not a class's).
      const double step = scale * std::max(ub - value, 1e-3) / norm2;
      for (size_t k = 0; k < g.size(); ++k) {
        u_[k] = std::max(0.0, u_[k] + step * static_cast<double>(p_.weight[k]) * g[k]);
      }
    }
    out.bound = std::max(0, std::min(out.bound, p_.columns));
    return out;
  }

 private:
  // L(u) at the current multipliers; each sum in long double, with its terms' magnitudes.
  Evaluation Evaluate() const {
    Evaluation e;
    e.x.assign(p_.columns, 0);
    e.y.assign(p_.weight.size(), 0.0);
    long double magnitude = 0;
    for (int j = 0; j < p_.columns; ++j) {
      long double s = 0;
      for (int k : sees_[j]) s += u_[k];
      const long double reduced = 1.0L - s;
      magnitude += 1.0L + s;
      if (reduced < 0) {
        e.x[j] = 1;
        e.value += reduced;
      }
    }
    e.value += Knapsack(e.y, magnitude);
    e.tolerance = 1e-9L * (1.0L + magnitude);
    return e;
  }

  // min sum_k u_k y_k s.t. sum_k w_k y_k >= need, y in [0, 1], over the classes some column sees:
  // the free classes (u_k = 0) first, then by u_k / w_k ascending (ties: the lower class), the last split.
  long double Knapsack(std::vector<double>& y, long double& magnitude) const {
    uint64_t taken = 0;
    std::vector<int> priced;
    for (size_t k = 0; k < p_.weight.size(); ++k) {
      if (p_.seen_by[k].empty()) continue;
      if (u_[k] <= 0) {
        y[k] = 1;
        taken += p_.weight[k];
      } else {
        priced.push_back(static_cast<int>(k));
      }
    }
    long double cost = 0;
    if (taken >= p_.need) return cost;
    if (p_.need < coverable_) OrderCheapestFirst(priced, p_.need - taken);
    for (int k : priced) {
      const uint64_t rest = p_.need - taken;
      const uint64_t w = p_.weight[k];
      const double share = w <= rest ? 1.0 : static_cast<double>(rest) / static_cast<double>(w);
      y[k] = share;
      cost += static_cast<long double>(u_[k]) * share;
      magnitude += static_cast<long double>(u_[k]);
      taken += std::min(w, rest);
      if (taken >= p_.need) break;
    }
    return cost;
  }

  // Moves the classes the knapsack takes to the front of `priced` (by u_k / w_k ascending, ties:
  // the lower class), the last of them, which may be split, last: a weighted quickselect for the
  // class where the weight reaches `need`, then a sort of the few around it.
  void OrderCheapestFirst(std::vector<int>& priced, uint64_t need) const {
    const auto cheaper = [&](int a, int b) {
      const double ra = u_[a] / static_cast<double>(p_.weight[a]);
      const double rb = u_[b] / static_cast<double>(p_.weight[b]);
      return ra != rb ? ra < rb : a < b;
    };
    auto first = priced.begin(), last = priced.end();
    while (last - first > 32) {
      auto mid = first + (last - first) / 2;
      std::nth_element(first, mid, last, cheaper);
      uint64_t below = 0;
      for (auto it = first; it != mid; ++it) below += p_.weight[*it];
      if (below >= need) {
        last = mid;
      } else {
        need -= below + std::min(need - below, p_.weight[*mid]);
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
  std::vector<std::vector<int>> sees_;  // per column: the classes it sees, ascending
  std::vector<double> u_;               // per class: the multiplier of y_k <= sum x_j
  uint64_t coverable_ = 0;              // weight of the classes some column sees
  uint64_t widest_ = 1;                 // the widest column's weight (at least 1)
  uint64_t pairs_ = 0;                  // (class, column) pairs
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
