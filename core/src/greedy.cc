#include "greedy.h"

#include <algorithm>
#include <bit>
#include <queue>
#include <string>

namespace vc::planner {

std::string_view GreedyStopName(GreedyStop stop) {
  switch (stop) {
    case GreedyStop::kExhausted: return "exhausted";
    case GreedyStop::kTargetReached: return "target_reached";
    case GreedyStop::kMaxStations: return "max_stations";
    case GreedyStop::kMinGain: return "min_gain";
  }
  return "unknown";
}

uint64_t CountAnd(const VoxelSet& a, const VoxelSet& b) {
  const auto& wa = a.words();
  const auto& wb = b.words();
  uint64_t n = 0;
  for (size_t i = 0; i < wa.size(); ++i) n += std::popcount(wa[i] & wb[i]);
  return n;
}

uint64_t CountBits(const VoxelSet& a) {
  uint64_t n = 0;
  for (uint64_t w : a.words()) n += std::popcount(w);
  return n;
}

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
  if (!(options.target_coverage > 0.0 && options.target_coverage <= 1.0)) {
    return InvalidArgumentError("target_coverage must be in (0, 1]");
  }
  GreedyResult result;
  if (sets.empty()) return result;
  const size_t n = sets[0].size();
  for (size_t i = 1; i < sets.size(); ++i) {
    if (sets[i].size() != n) {
      return InvalidArgumentError("visibility set " + std::to_string(i) + " has " +
                                  std::to_string(sets[i].size()) + " voxels, expected " +
                                  std::to_string(n));
    }
  }
  VoxelSet uncovered(n);
  for (const VoxelSet& s : sets) UnionInto(uncovered, s);
  result.coverable = CountBits(uncovered);
  const double coverable = static_cast<double>(result.coverable);
  const uint64_t min_gain = std::max<uint64_t>(options.min_marginal_gain, 1);

  std::priority_queue<Entry, std::vector<Entry>, EntryLess> heap;
  if (options.lazy) {
    // Nothing is covered yet, so the initial counts are exact gains for round 0.
    for (size_t i = 0; i < sets.size(); ++i) {
      heap.push({CountBits(sets[i]), static_cast<int>(i), 0});
      ++result.gain_evaluations;
    }
  }

  int round = 0;
  while (true) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("greedy selection"));
    if (result.covered >= result.coverable) {
      result.stop = GreedyStop::kExhausted;
      break;
    }
    if (static_cast<double>(result.covered) >= options.target_coverage * coverable) {
      result.stop = GreedyStop::kTargetReached;
      break;
    }
    if (options.max_stations > 0 && static_cast<int>(result.picks.size()) >= options.max_stations) {
      result.stop = GreedyStop::kMaxStations;
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
      for (size_t i = 0; i < sets.size(); ++i) {
        const uint64_t g = CountAnd(sets[i], uncovered);
        ++result.gain_evaluations;
        if (g > best_gain) {  // strict: ties keep the lowest index
          best_gain = g;
          best = static_cast<int>(i);
        }
      }
    }
    if (best < 0 || best_gain < min_gain) {
      result.stop = GreedyStop::kMinGain;
      break;
    }
    SubtractFrom(uncovered, sets[best]);
    result.covered += best_gain;
    result.picks.push_back({best, best_gain, result.covered});
    ++round;
    ctx.Report("greedy", coverable > 0 ? std::min(1.0, result.covered / coverable) : 1.0);
  }
  return result;
}

}  // namespace vc::planner
