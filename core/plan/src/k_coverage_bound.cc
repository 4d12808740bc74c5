#include "vc/plan/k_coverage_bound.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>

namespace vc::planner {
namespace {

using Clock = std::chrono::steady_clock;

bool Expired(const KCoverageOptions& o) { return o.deadline && Clock::now() >= *o.deadline; }

// The sums of the largest 0..max_k of `values`.
template <typename T>
std::vector<T> TopSums(std::vector<T> values, int max_k) {
  const int k = std::min<int>(max_k, static_cast<int>(values.size()));
  std::partial_sort(values.begin(), values.begin() + k, values.end(), std::greater<T>());
  std::vector<T> out(static_cast<size_t>(k) + 1, T{0});
  for (int i = 0; i < k; ++i) out[i + 1] = out[i] + values[i];
  return out;
}

// The model with each column's classes and the running state of the bounds.
struct Run {
  const KCoverageProblem& p;
  const KCoverageOptions& o;
  int max_k = 0;
  std::vector<std::vector<int>> sees;  // per column: the classes it sees
  uint64_t total = 0;                  // sum of the weights
  uint64_t pairs = 0;                  // (class, column) pairs
  std::vector<uint64_t> ub, best;      // per k (index k; 0 unused)
  std::vector<int> ub_prefix;          // per k: greedy's prefix whose multipliers gave ub[k]
  std::vector<int> covered_at;         // per class: the greedy step that covered it (INT_MAX: none)
  uint64_t visits = 0;                 // subgradient pairs visited

  Run(const KCoverageProblem& problem, const KCoverageOptions& options) : p(problem), o(options) {
    max_k = std::min(options.max_k, problem.columns);
    sees.resize(static_cast<size_t>(std::max(0, problem.columns)));
    for (size_t i = 0; i < p.weight.size(); ++i) {
      total += p.weight[i];
      pairs += p.seen_by[i].size();
      for (int j : p.seen_by[i]) sees[j].push_back(static_cast<int>(i));
    }
    ub.assign(static_cast<size_t>(max_k) + 1, total);
    best.assign(static_cast<size_t>(max_k) + 1, 0);
    ub_prefix.assign(static_cast<size_t>(max_k) + 1, 0);
  }

  // Voxels from a bound computed in floating point: rounded down after a tolerance above the
  // rounding error of the sums (each price a sum of at most `classes` terms in [0, w]).
  uint64_t FloorBound(long double x) const {
    if (x <= 0) return 0;
    const long double tolerance = 1e-9L * (static_cast<long double>(total) + 1.0L);
    return static_cast<uint64_t>(std::floor(x + tolerance));
  }

  // Pure maximum-coverage greedy with every column's marginal gain kept up to date (each class,
  // once covered, leaves the gains of its columns once: all steps together visit every pair once):
  // best[k] = greedy's first k picks, ub[k] = min over prefixes P of f(P) + the k largest gains.
  void Greedy() {
    std::vector<uint64_t> gain(sees.size(), 0);
    for (size_t j = 0; j < sees.size(); ++j) {
      for (int i : sees[j]) gain[j] += p.weight[i];
    }
    covered_at.assign(p.weight.size(), INT_MAX);
    uint64_t f = 0;
    for (int m = 0; m <= max_k; ++m) {
      const std::vector<uint64_t> top = TopSums(gain, max_k);
      for (int k = 1; k <= max_k; ++k) {
        if (f + top[k] < ub[k]) ub[k] = f + top[k], ub_prefix[k] = m;
      }
      if (m == max_k) break;
      const int pick = static_cast<int>(std::max_element(gain.begin(), gain.end()) - gain.begin());
      f += gain[pick];
      best[m + 1] = f;
      for (int i : sees[pick]) {
        if (covered_at[i] != INT_MAX) continue;
        covered_at[i] = m + 1;
        for (int j : p.seen_by[i]) gain[j] -= p.weight[i];
      }
    }
    // Greedy's guarantee, for this greedy's own prefix: best[k] >= (1 - (1 - 1/k)^k) OPT_k.
    for (int k = 1; k <= max_k; ++k) {
      const long double ratio = 1.0L - std::pow(1.0L - 1.0L / k, static_cast<long double>(k));
      const long double bound = std::ceil(static_cast<long double>(best[k]) / ratio * (1.0L + 1e-12L));
      if (bound < static_cast<long double>(ub[k])) ub[k] = static_cast<uint64_t>(bound);
    }
  }

  // v (u_i = w_i v_i) of greedy's prefix m: 0 on the classes it covers, 1 elsewhere.
  std::vector<double> PrefixMultipliers(int m) const {
    std::vector<double> v(p.weight.size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = covered_at[i] <= m ? 0.0 : 1.0;
    return v;
  }

  // UB_k(v), the k dearest columns in `top`; updates best[k] with what those columns cover.
  long double Evaluate(const std::vector<double>& v, int k, std::vector<int>& top, std::vector<int>& count) {
    long double base = 0;
    for (size_t i = 0; i < v.size(); ++i) base += static_cast<long double>(p.weight[i]) * (1.0 - v[i]);
    // In long double: FloorBound's tolerance (1e-9 of the total) must cover the sums' rounding, and
    // k prices of up to |S_j| terms each in double could exceed it on large models.
    std::vector<long double> price(sees.size(), 0.0L);
    for (size_t j = 0; j < sees.size(); ++j) {
      for (int i : sees[j]) price[j] += static_cast<long double>(p.weight[i]) * v[i];
    }
    visits += pairs;
    top.resize(sees.size());
    for (size_t j = 0; j < top.size(); ++j) top[j] = static_cast<int>(j);
    std::nth_element(top.begin(), top.begin() + (k - 1), top.end(),
                     [&](int a, int b) { return price[a] != price[b] ? price[a] > price[b] : a < b; });
    top.resize(static_cast<size_t>(k));
    long double sum = base;
    uint64_t covered = 0;
    std::fill(count.begin(), count.end(), 0);
    for (int j : top) {
      sum += price[j];
      for (int i : sees[j]) {
        if (count[i]++ == 0) covered += p.weight[i];
      }
      visits += sees[j].size();
    }
    best[k] = std::max(best[k], covered);
    return sum;
  }

  // Subgradient steps for k from `v` (left at the best multipliers found) within `budget` pairs.
  void Subgradient(int k, std::vector<double>& v, uint64_t budget) {
    std::vector<int> top, count(p.weight.size(), 0);
    std::vector<double> best_v = v;
    long double best_ub = static_cast<long double>(ub[k]);
    double lambda = 1.0;
    int since_better = 0;
    const uint64_t start = visits;
    for (int it = 0; it < o.max_iterations_per_k && visits - start + pairs <= budget && ub[k] > best[k]; ++it) {
      if (Expired(o)) break;
      const long double value = Evaluate(v, k, top, count);
      if (value < best_ub) {
        best_ub = value, best_v = v, since_better = 0;
        ub[k] = std::min(ub[k], FloorBound(value));
      } else if (++since_better >= o.patience) {
        lambda /= 2, since_better = 0;
      }
      double norm = 0;
      for (size_t i = 0; i < count.size(); ++i) {
        const double g = count[i] - 1.0;
        if ((g < 0 && v[i] < 1.0) || (g > 0 && v[i] > 0.0)) norm += static_cast<double>(p.weight[i]) * g * g;
      }
      if (norm <= 0) break;
      const double step = lambda * static_cast<double>(value - static_cast<long double>(best[k])) / norm;
      for (size_t i = 0; i < v.size(); ++i) v[i] = std::clamp(v[i] - step * (count[i] - 1.0), 0.0, 1.0);
    }
    v = std::move(best_v);
  }

  void Subgradients() {
    std::vector<double> v;
    std::vector<int> top, count(p.weight.size(), 0);
    for (int k = 1; k <= max_k; ++k) {
      if (ub[k] <= best[k] || Expired(o)) continue;
      const uint64_t left = o.max_pair_visits > visits ? o.max_pair_visits - visits : 0;
      const uint64_t share = left / static_cast<uint64_t>(max_k - k + 1);
      if (share < 2 * pairs) continue;
      // Warm start: k - 1's multipliers where they do better at k than greedy's prefix.
      const long double warm = v.empty() ? static_cast<long double>(total) + 1 : Evaluate(v, k, top, count);
      if (warm < static_cast<long double>(ub[k])) {
        ub[k] = std::min(ub[k], FloorBound(warm));
      } else {
        v = PrefixMultipliers(ub_prefix[k]);
      }
      Subgradient(k, v, share);
    }
  }

  // Branch and bound over the columns (largest first) for the most k columns cover.
  struct Search {
    Run& r;
    int k = 0;
    std::vector<int> order;
    std::vector<int> count;
    uint64_t nodes = 0;
    bool aborted = false;

    void Dfs(size_t from, int depth, uint64_t f) {
      if (f > r.best[k]) r.best[k] = f;
      if (depth == k || r.best[k] >= r.ub[k] || aborted) return;
      if (++nodes > r.o.exact_max_nodes || (nodes % 1024 == 0 && Expired(r.o))) {
        aborted = true;
        return;
      }
      std::vector<uint64_t> gain(order.size() - from, 0);
      for (size_t a = from; a < order.size(); ++a) {
        for (int i : r.sees[order[a]]) gain[a - from] += count[i] == 0 ? r.p.weight[i] : 0;
      }
      const std::vector<uint64_t> top = TopSums(gain, k - depth);
      if (f + top.back() <= r.best[k]) return;
      for (size_t a = from; a < order.size() && !aborted; ++a) {
        if (gain[a - from] == 0) continue;
        uint64_t g = 0;
        for (int i : r.sees[order[a]]) g += count[i]++ == 0 ? r.p.weight[i] : 0;
        Dfs(a + 1, depth + 1, f + g);
        for (int i : r.sees[order[a]]) --count[i];
      }
    }
  };

  void Exact() {
    if (p.columns > o.exact_max_columns || pairs > o.exact_max_pairs) return;
    std::vector<int> order(sees.size());
    for (size_t j = 0; j < order.size(); ++j) order[j] = static_cast<int>(j);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return sees[a].size() > sees[b].size(); });
    for (int k = 1; k <= max_k && !Expired(o); ++k) {
      if (best[k] >= ub[k]) continue;
      Search s{*this, k, order, std::vector<int>(p.weight.size(), 0)};
      s.Dfs(0, 0, 0);
      if (!s.aborted) ub[k] = best[k];  // the search saw every k-set it could not prune
    }
  }

  std::vector<KCoverage> Finish() {
    for (int k = 2; k <= max_k; ++k) best[k] = std::max(best[k], best[k - 1]);  // k - 1 columns and any other
    for (int k = max_k - 1; k >= 1; --k) ub[k] = std::min(ub[k], ub[k + 1]);    // OPT_k <= OPT_{k+1}
    std::vector<KCoverage> out;
    for (int k = 1; k <= max_k; ++k) out.push_back({ub[k], best[k], best[k] >= ub[k]});
    return out;
  }
};

}  // namespace

std::vector<KCoverage> KCoverageBounds(const KCoverageProblem& problem, const KCoverageOptions& options) {
  if (options.max_k < 1 || problem.columns < 1) return {};
  Run run(problem, options);
  run.Greedy();
  run.Subgradients();
  run.Exact();
  return run.Finish();
}

}  // namespace vc::planner
