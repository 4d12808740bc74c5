#include "vc/plan/greedy.h"

#include <algorithm>
#include <queue>
#include <string>

namespace vc::planner {

uint64_t CountAnd(const VoxelSet& a, const VoxelSet& b) { return a.CountAnd(b); }

uint64_t CountBits(const VoxelSet& a) { return a.count(); }

void UnionInto(VoxelSet& a, const VoxelSet& b) {
  auto& wa = a.words();
  const auto& wb = b.words();
  for (size_t i = 0; i < wa.size(); ++i) wa[i] |= wb[i];
}

namespace {

// uncovered &= ~s.
void SubtractFrom(VoxelSet& uncovered, const VoxelSet& s) {
  auto& wu = uncovered.words();
  const auto& ws = s.words();
  for (size_t i = 0; i < wu.size(); ++i) wu[i] &= ~ws[i];
}

// Heap entry: a gain that is exact when `round` is the current round, an upper bound otherwise.
struct Entry {
  uint64_t gain;
  int index;
  int round;
};
// Max-heap order: larger gain first, then lower index.
struct EntryLess {
  bool operator()(const Entry& a, const Entry& b) const {
    if (a.gain != b.gain) return a.gain < b.gain;
    return a.index > b.index;
  }
};

}  // namespace

Result<GreedyResult> SelectGreedy(const std::vector<VoxelSet>& sets, const GreedyOptions& options,
                                  const JobContext& ctx) {
  if (options.max_stations < 0) return InvalidArgumentError("max_stations must be >= 0");
  if (options.fixed < 0 || static_cast<size_t>(options.fixed) > sets.size()) {
    return InvalidArgumentError("fixed must be in [0, " + std::to_string(sets.size()) + "]");
  }
  if (!(options.target_coverage > 0.0 && options.target_coverage <= 1.0)) {
    return InvalidArgumentError("target_coverage must be in (0, 1]");
  }
  GreedyResult result;
  if (sets.empty()) return result;
  const size_t n = sets[0].size();
  for (size_t i = 1; i < sets.size(); ++i) {
    if (sets[i].size() != n) {
      return InvalidArgumentError("visibility set " + std::to_string(i) + " has " + std::to_string(sets[i].size()) +
                                  " voxels, expected " + std::to_string(n));
    }
  }
  VoxelSet uncovered(n);
  for (const VoxelSet& s : sets) UnionInto(uncovered, s);
  result.coverable = CountBits(uncovered);
  const double coverable = static_cast<double>(result.coverable);
  const uint64_t min_gain = std::max<uint64_t>(options.min_marginal_gain, 1);
  const size_t fixed = static_cast<size_t>(options.fixed);
  // The fixed stations first, whatever they add.
  for (size_t i = 0; i < fixed; ++i) {
    const uint64_t gain = CountAnd(sets[i], uncovered);
    SubtractFrom(uncovered, sets[i]);
    result.covered += gain;
    result.picks.push_back({static_cast<int>(i), gain, result.covered});
  }

  std::priority_queue<Entry, std::vector<Entry>, EntryLess> heap;
  if (options.lazy) {
    // Only the fixed stations cover anything yet, so these are exact gains for round 0.
    for (size_t i = fixed; i < sets.size(); ++i) {
      heap.push({fixed ? CountAnd(sets[i], uncovered) : CountBits(sets[i]), static_cast<int>(i), 0});
      ++result.gain_evaluations;
    }
  }

  int round = 0;
  while (true) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("greedy selection"));
    if (result.covered >= result.coverable) {
      result.stop = StopReason::kExhausted;
      break;
    }
    if (static_cast<double>(result.covered) >= options.target_coverage * coverable) {
      result.stop = StopReason::kTargetReached;
      break;
    }
    if (options.max_stations > 0 && static_cast<int>(result.picks.size() - fixed) >= options.max_stations) {
      result.stop = StopReason::kMaxStations;
      break;
    }
    int best = -1;
    uint64_t best_gain = 0;
    if (options.lazy) {
      while (!heap.empty()) {
        Entry top = heap.top();
        heap.pop();
        if (top.round == round) {  // exact, and no other bound beats it: the plain argmax
          best = top.index;
          best_gain = top.gain;
          break;
        }
        top.gain = CountAnd(sets[top.index], uncovered);
        top.round = round;
        ++result.gain_evaluations;
        heap.push(top);
      }
    } else {
      for (size_t i = fixed; i < sets.size(); ++i) {
        const uint64_t g = CountAnd(sets[i], uncovered);
        ++result.gain_evaluations;
        if (g > best_gain) {  // strict: ties keep the lowest index
          best_gain = g;
          best = static_cast<int>(i);
        }
      }
    }
    if (best < 0 || best_gain < min_gain) {
      result.stop = StopReason::kMinGain;
      break;
    }
    SubtractFrom(uncovered, sets[best]);
    result.covered += best_gain;
    result.picks.push_back({best, best_gain, result.covered});
    ++round;
    ctx.Report(Stage::kSelection, coverable > 0 ? std::min(1.0, result.covered / coverable) : 1.0);
  }
  return result;
}

Result<ConsolidateResult> ConsolidatePicks(const std::vector<VoxelSet>& sets, std::vector<int> picks,
                                           const JobContext& ctx, int fixed) {
  ConsolidateResult out;
  if (sets.empty() || picks.empty()) {
    out.picks = std::move(picks);
    return out;
  }
  const size_t words = sets[0].words().size();
  std::vector<int> order;
  for (size_t i = static_cast<size_t>(std::max(fixed, 0)); i < sets.size(); ++i) order.push_back(static_cast<int>(i));
  auto is_fixed = [&](int candidate) { return candidate < fixed; };
  std::vector<uint64_t> sizes(sets.size());
  for (size_t i = 0; i < sets.size(); ++i) sizes[i] = CountBits(sets[i]);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return sizes[a] > sizes[b]; });

  std::vector<uint64_t> c1(words), c2(words), c3(words), rest(words);
  std::vector<size_t> nonzero;
  bool changed = true;
  while (changed) {
    changed = false;
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("consolidation"));
    // Voxels covered at least once, twice, three times.
    std::fill(c1.begin(), c1.end(), 0);
    std::fill(c2.begin(), c2.end(), 0);
    std::fill(c3.begin(), c3.end(), 0);
    for (int p : picks) {
      const auto& w = sets[p].words();
      for (size_t k = 0; k < words; ++k) {
        c3[k] |= c2[k] & w[k];
        c2[k] |= c1[k] & w[k];
        c1[k] |= w[k];
      }
    }
    // A pick nobody needs: all its voxels are covered twice. The latest such pick goes first.
    for (size_t i = picks.size(); i-- > 0 && picks.size() > 1;) {
      if (is_fixed(picks[i])) continue;
      const auto& w = sets[picks[i]].words();
      bool needed = false;
      for (size_t k = 0; k < words && !needed; ++k) needed = (w[k] & ~c2[k]) != 0;
      if (!needed) {
        picks.erase(picks.begin() + static_cast<std::ptrdiff_t>(i));
        ++out.dropped;
        changed = true;
        break;
      }
    }
    if (changed) continue;
    // Two picks one candidate can stand in for.
    for (size_t a = 0; a < picks.size() && !changed; ++a) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("consolidation"));
      if (is_fixed(picks[a])) continue;
      const auto& wa = sets[picks[a]].words();
      for (size_t b = a + 1; b < picks.size() && !changed; ++b) {
        if (is_fixed(picks[b])) continue;
        const auto& wb = sets[picks[b]].words();
        // Voxels only a or b cover: in both and covered exactly twice, or in one and covered once.
        nonzero.clear();
        for (size_t k = 0; k < words; ++k) {
          rest[k] = (wa[k] & wb[k] & ~c3[k]) | ((wa[k] ^ wb[k]) & ~c2[k]);
          if (rest[k]) nonzero.push_back(k);
        }
        for (int c : order) {
          const auto& wc = sets[c].words();
          bool covers = true;
          for (size_t k : nonzero) {
            if (rest[k] & ~wc[k]) {
              covers = false;
              break;
            }
          }
          if (!covers) continue;
          picks[a] = c;
          picks.erase(picks.begin() + static_cast<std::ptrdiff_t>(b));
          ++out.merged;
          changed = true;
          break;
        }
      }
    }
  }
  out.picks = std::move(picks);
  return out;
}

}  // namespace vc::planner
