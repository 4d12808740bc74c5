#include "vc/plan/greedy.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <numeric>
#include <optional>
#include <queue>
#include <string>
#include <unordered_map>

#include "vc/plan/scan_graph.h"

namespace vc::planner {

uint64_t CountAnd(const VoxelSet& a, const VoxelSet& b) { return a.CountAnd(b); }

uint64_t CountBits(const VoxelSet& a) { return a.count(); }

void UnionInto(VoxelSet& a, const VoxelSet& b) { a.Union(b); }

namespace {

// uncovered &= ~s.
void SubtractFrom(VoxelSet& uncovered, const VoxelSet& s) { uncovered.Subtract(s); }

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

// Overlaps between candidates (scan_graph.h), computed on demand; the ones among few nodes (the
// picks) are cached, so that consolidation's repeated component counts cost one intersection per
// pair.
class Overlaps {
 public:
  explicit Overlaps(const std::vector<VoxelSet>& sets) : sets_(sets), sizes_(sets.size()) {
    for (size_t i = 0; i < sets.size(); ++i) sizes_[i] = CountBits(sets[i]);
  }
  // Whether candidates a and b have an edge at min_overlap.
  bool Edge(int a, int b, double min_overlap) const {
    return IsEdge(Overlap(CountAnd(sets_[a], sets_[b]), sizes_[a], sizes_[b]), min_overlap);
  }
  // Edge, cached.
  bool CachedEdge(int a, int b, double min_overlap) {
    if (a > b) std::swap(a, b);
    const uint64_t key = uint64_t(a) * sets_.size() + uint64_t(b);
    auto it = cache_.find(key);
    if (it == cache_.end()) it = cache_.emplace(key, Edge(a, b, min_overlap)).first;
    return it->second;
  }
  // Number of components of the scan graph of `nodes` (candidate indices).
  int Components(const std::vector<int>& nodes, double min_overlap) {
    std::vector<int> parent(nodes.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    int count = static_cast<int>(nodes.size());
    for (size_t a = 0; a < nodes.size(); ++a) {
      for (size_t b = a + 1; b < nodes.size(); ++b) {
        const int ra = find(static_cast<int>(a)), rb = find(static_cast<int>(b));
        if (ra == rb || !CachedEdge(nodes[a], nodes[b], min_overlap)) continue;
        parent[rb] = ra;
        --count;
      }
    }
    return count;
  }
  // The components of `nodes`, as lists of candidate indices in the order of `nodes`.
  std::vector<std::vector<int>> Groups(const std::vector<int>& nodes, double min_overlap) {
    std::vector<int> group(nodes.size(), -1);
    std::vector<std::vector<int>> groups;
    for (size_t a = 0; a < nodes.size(); ++a) {
      if (group[a] >= 0) continue;
      group[a] = static_cast<int>(groups.size());
      groups.push_back({nodes[a]});
      for (size_t k = 0; k < groups.back().size(); ++k) {  // breadth-first over the group
        for (size_t b = 0; b < nodes.size(); ++b) {
          if (group[b] < 0 && CachedEdge(groups.back()[k], nodes[b], min_overlap)) {
            group[b] = group[a];
            groups.back().push_back(nodes[b]);
          }
        }
      }
    }
    return groups;
  }

 private:
  const std::vector<VoxelSet>& sets_;
  std::vector<uint64_t> sizes_;
  std::unordered_map<uint64_t, bool> cache_;
};

// The shortest chain (fewest candidates, breadth-first over edges at min_overlap) from any of
// `sources` to a candidate for which score() is >= 0: the candidates after the source, ending
// with the highest-scoring target at the first depth that has one (lowest index on ties). Empty
// when no chain exists.
template <typename Score>
Result<std::vector<int>> ShortestChain(const Overlaps& overlaps, size_t candidates, const std::vector<int>& sources,
                                       double min_overlap, const JobContext& ctx, Score score) {
  constexpr int kUnseen = -2, kSource = -1;
  std::vector<int> prev(candidates, kUnseen);
  for (int s : sources) prev[s] = kSource;
  std::vector<int> frontier = sources;
  while (!frontier.empty()) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("linking the scan graph"));
    std::vector<int> next;
    int best = -1;
    int64_t best_score = -1;
    for (int u : frontier) {
      for (size_t c = 0; c < candidates; ++c) {
        if (prev[c] != kUnseen || !overlaps.Edge(u, static_cast<int>(c), min_overlap)) continue;
        prev[c] = u;
        next.push_back(static_cast<int>(c));
      }
    }
    for (int c : next) {
      const int64_t sc = score(c);
      if (sc > best_score || (sc == best_score && sc >= 0 && c < best)) {
        best_score = sc;
        best = c;
      }
    }
    if (best_score >= 0) {
      std::vector<int> chain;
      for (int c = best; c != kSource; c = prev[c]) chain.push_back(c);
      chain.pop_back();  // the source
      std::reverse(chain.begin(), chain.end());
      return chain;
    }
    frontier = std::move(next);
  }
  return std::vector<int>{};
}

// "87.3 %".
std::string FormatPercent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * fraction);
  return text;
}

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
  if (!(options.min_overlap >= 0.0 && options.min_overlap <= 1.0)) {
    return InvalidArgumentError("min_overlap must be in [0, 1]");
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
  const uint64_t min_gain = std::max<uint64_t>(options.min_marginal_gain_voxels, 1);
  const size_t fixed = static_cast<size_t>(options.fixed);
  const double min_overlap = options.min_overlap;
  const bool registration = min_overlap > 0;
  std::optional<Overlaps> overlaps;
  if (registration) overlaps.emplace(sets);

  // Registration: which candidates have an edge to a pick; before the first pick, all compete.
  std::vector<char> picked(sets.size(), 0), linked(sets.size(), 0);
  std::vector<int> picked_list;
  auto constrained = [&] { return registration && !picked_list.empty(); };
  auto eligible = [&](int c) { return !constrained() || linked[c]; };
  std::priority_queue<Entry, std::vector<Entry>, EntryLess> heap;
  std::vector<Entry> parked;  // lazy: popped while not linked; back in the heap once linked
  // Stations picked so far (the total is not known in advance) and the coverage reached.
  auto report_selection = [&] {
    if (!ctx.progress) return;
    const double fraction = coverable > 0 ? std::min(1.0, double(result.covered) / coverable) : 1.0;
    ctx.progress(ProgressEvent{Stage::kSelection, fraction, "coverage " + FormatPercent(fraction), result.picks.size(),
                               0, "stations"});
  };
  auto pick = [&](int c, uint64_t gain, bool connector) {
    SubtractFrom(uncovered, sets[c]);
    result.covered += gain;
    result.picks.push_back({c, gain, result.covered, connector});
    result.connectors += connector;
    picked[c] = 1;
    picked_list.push_back(c);
    if (!registration) return;
    for (size_t i = fixed; i < sets.size(); ++i) {
      if (!linked[i] && !picked[i] && overlaps->Edge(c, static_cast<int>(i), min_overlap)) linked[i] = 1;
    }
    for (size_t k = 0; k < parked.size();) {
      if (linked[parked[k].index]) {
        heap.push(parked[k]);
        parked[k] = parked.back();
        parked.pop_back();
      } else {
        ++k;
      }
    }
  };
  // The fixed stations first, whatever they add.
  for (size_t i = 0; i < fixed; ++i) pick(static_cast<int>(i), CountAnd(sets[i], uncovered), false);

  if (options.lazy) {
    // Only the fixed stations cover anything yet, so these are exact gains for round 0.
    for (size_t i = fixed; i < sets.size(); ++i) {
      heap.push({fixed ? CountAnd(sets[i], uncovered) : CountBits(sets[i]), static_cast<int>(i), 0});
      ++result.gain_evaluations;
    }
  }
  auto at_max = [&](size_t more) {
    return options.max_stations > 0 && picked_list.size() - fixed + more > static_cast<size_t>(options.max_stations);
  };

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
    if (at_max(1)) {
      result.stop = StopReason::kMaxStations;
      break;
    }
    int best = -1;
    uint64_t best_gain = 0;
    if (options.lazy) {
      while (!heap.empty()) {
        Entry top = heap.top();
        heap.pop();
        if (picked[top.index]) continue;  // picked as a link of a chain
        if (!eligible(top.index)) {
          parked.push_back(top);
          continue;
        }
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
        if (picked[i] || !eligible(static_cast<int>(i))) continue;
        const uint64_t g = CountAnd(sets[i], uncovered);
        ++result.gain_evaluations;
        if (g > best_gain) {  // strict: ties keep the lowest index
          best_gain = g;
          best = static_cast<int>(i);
        }
      }
    }
    if ((best < 0 || best_gain < min_gain) && constrained()) {
      // Nothing linked gains enough: a chain to the nearest candidates that do, or a new group.
      std::vector<uint64_t> gains(sets.size(), 0);
      int unlinked_best = -1;
      for (size_t i = fixed; i < sets.size(); ++i) {
        if (picked[i] || linked[i]) continue;
        gains[i] = CountAnd(sets[i], uncovered);
        ++result.gain_evaluations;
        if (gains[i] >= min_gain && (unlinked_best < 0 || gains[i] > gains[unlinked_best])) {
          unlinked_best = static_cast<int>(i);
        }
      }
      if (unlinked_best >= 0) {
        VC_ASSIGN_OR_RETURN(std::vector<int> chain,
                            ShortestChain(*overlaps, sets.size(), picked_list, min_overlap, ctx, [&](int c) -> int64_t {
                              return !picked[c] && !linked[c] && gains[c] >= min_gain ? int64_t(gains[c]) : -1;
                            }));
        if (chain.empty()) {
          ++result.new_groups;
          chain = {unlinked_best};
        }
        if (at_max(chain.size())) {
          result.stop = StopReason::kMaxStations;
          break;
        }
        for (size_t k = 0; k < chain.size(); ++k) {
          pick(chain[k], CountAnd(sets[chain[k]], uncovered), k + 1 < chain.size());
        }
        ++round;
        report_selection();
        continue;
      }
    }
    if (best < 0 || best_gain < min_gain) {
      result.stop = StopReason::kMinGain;
      break;
    }
    pick(best, best_gain, false);
    ++round;
    report_selection();
  }
  // Groups the fixed stations left apart: joined by the shortest chains that exist.
  if (registration && result.stop != StopReason::kMaxStations) {
    while (true) {
      const std::vector<std::vector<int>> groups = overlaps->Groups(picked_list, min_overlap);
      if (groups.size() <= 1) break;
      std::vector<char> other(sets.size(), 0);
      for (size_t g = 1; g < groups.size(); ++g) {
        for (int c : groups[g]) other[c] = 1;
      }
      VC_ASSIGN_OR_RETURN(std::vector<int> chain, ShortestChain(*overlaps, sets.size(), groups[0], min_overlap, ctx,
                                                                [&](int c) -> int64_t { return other[c] ? 0 : -1; }));
      if (chain.size() < 2) break;  // none, or (impossible) a direct edge between two groups
      chain.pop_back();             // the station of another group it reaches
      for (int c : chain) pick(c, CountAnd(sets[c], uncovered), true);
    }
  }
  return result;
}

Result<ConsolidateResult> ConsolidatePicks(const std::vector<VoxelSet>& sets, std::vector<int> picks,
                                           const GreedyOptions& options, const JobContext& ctx) {
  const int fixed = options.fixed;
  const double min_overlap = options.min_overlap;
  ConsolidateResult out;
  if (sets.empty() || picks.empty()) {
    out.picks = std::move(picks);
    return out;
  }
  const size_t words = (sets[0].size() + 63) / 64;
  // The picks' words (a sparse pick is made dense once; picks are few), and any candidate's word k.
  std::unordered_map<int, VoxelSet> dense_copies;
  auto pick_words = [&](int c) -> const std::vector<uint64_t>& {
    if (!sets[c].sparse()) return sets[c].words();
    auto it = dense_copies.find(c);
    if (it == dense_copies.end()) {
      it = dense_copies.emplace(c, sets[c]).first;
      it->second.Densify();
    }
    return it->second.words();
  };
  // A pick's nonzero words: on a large site a station sees a small share of it, so a pair's
  // `rest` below is computed on these, not on every word of the scene.
  std::unordered_map<int, std::vector<size_t>> nonzero_words;
  auto pick_nonzero = [&](int c) -> const std::vector<size_t>& {
    auto it = nonzero_words.find(c);
    if (it == nonzero_words.end()) {
      std::vector<size_t> nz;
      const auto& w = pick_words(c);
      for (size_t k = 0; k < w.size(); ++k) {
        if (w[k]) nz.push_back(k);
      }
      it = nonzero_words.emplace(c, std::move(nz)).first;
    }
    return it->second;
  };
  // The candidates that see any voxel of a pick, as bits: one standing in for picks a and b must
  // see the voxels only they cover, so it is a neighbour of a (of b) when some of those lie in a
  // (in b). Far-apart picks have no common neighbour and are passed over at once.
  const size_t candidate_words = (sets.size() + 63) / 64;
  std::unordered_map<int, std::vector<uint64_t>> neighbour_bits;
  auto neighbours = [&](int p) -> const std::vector<uint64_t>& {
    auto it = neighbour_bits.find(p);
    if (it == neighbour_bits.end()) {
      std::vector<uint64_t> bits(candidate_words, 0);
      for (size_t c = 0; c < sets.size(); ++c) {
        if (sets[c].Intersects(sets[p])) bits[c >> 6] |= uint64_t{1} << (c & 63);
      }
      it = neighbour_bits.emplace(p, std::move(bits)).first;
    }
    return it->second;
  };
  auto has = [](const std::vector<uint64_t>* bits, int c) { return !bits || (((*bits)[c >> 6] >> (c & 63)) & 1); };
  std::vector<int> order;
  for (size_t i = static_cast<size_t>(std::max(fixed, 0)); i < sets.size(); ++i) order.push_back(static_cast<int>(i));
  auto is_fixed = [&](int candidate) { return candidate < fixed; };
  std::vector<uint64_t> sizes(sets.size());
  for (size_t i = 0; i < sets.size(); ++i) sizes[i] = CountBits(sets[i]);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return sizes[a] > sizes[b]; });

  // Registration: a change must not split the picks' scan graph into more groups.
  std::optional<Overlaps> overlaps;
  if (min_overlap > 0) overlaps.emplace(sets);
  int groups = overlaps ? overlaps->Components(picks, min_overlap) : 1;
  auto keeps_linked = [&](const std::vector<int>& after) {
    if (!overlaps) return true;
    const int n = overlaps->Components(after, min_overlap);
    if (n > groups) return false;
    groups = n;
    return true;
  };

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
      const auto& w = pick_words(p);
      for (size_t k = 0; k < words; ++k) {
        c3[k] |= c2[k] & w[k];
        c2[k] |= c1[k] & w[k];
        c1[k] |= w[k];
      }
    }
    // A pick nobody needs: all its voxels are covered twice. The latest such pick goes first.
    for (size_t i = picks.size(); i-- > 0 && picks.size() > 1;) {
      if (is_fixed(picks[i])) continue;
      const auto& w = pick_words(picks[i]);
      bool needed = false;
      for (size_t k = 0; k < words && !needed; ++k) needed = (w[k] & ~c2[k]) != 0;
      if (!needed) {
        std::vector<int> after = picks;
        after.erase(after.begin() + static_cast<std::ptrdiff_t>(i));
        if (!keeps_linked(after)) continue;
        picks = std::move(after);
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
      const auto& wa = pick_words(picks[a]);
      for (size_t b = a + 1; b < picks.size() && !changed; ++b) {
        if (is_fixed(picks[b])) continue;
        const auto& wb = pick_words(picks[b]);
        // Voxels only a or b cover: in both and covered exactly twice, or in one and covered once
        // (only in words where a or b has a voxel).
        nonzero.clear();
        bool in_a = false, in_b = false;
        const std::vector<size_t>& za = pick_nonzero(picks[a]);
        const std::vector<size_t>& zb = pick_nonzero(picks[b]);
        for (size_t i = 0, j = 0; i < za.size() || j < zb.size();) {
          const size_t k = j == zb.size() || (i < za.size() && za[i] < zb[j]) ? za[i] : zb[j];
          i += i < za.size() && za[i] == k;
          j += j < zb.size() && zb[j] == k;
          rest[k] = (wa[k] & wb[k] & ~c3[k]) | ((wa[k] ^ wb[k]) & ~c2[k]);
          if (!rest[k]) continue;
          nonzero.push_back(k);
          in_a |= (rest[k] & wa[k]) != 0;
          in_b |= (rest[k] & wb[k]) != 0;
        }
        const std::vector<uint64_t>* need_a = in_a ? &neighbours(picks[a]) : nullptr;
        const std::vector<uint64_t>* need_b = in_b ? &neighbours(picks[b]) : nullptr;
        if (need_a && need_b) {
          bool any = false;
          for (size_t k = 0; k < candidate_words && !any; ++k) any = ((*need_a)[k] & (*need_b)[k]) != 0;
          if (!any) continue;  // no candidate sees into both
        }
        // A voxel of `rest` every candidate standing in must see: one test rules most out.
        const bool has_probe = !nonzero.empty();
        const size_t probe = has_probe ? nonzero[0] * 64 + static_cast<size_t>(std::countr_zero(rest[nonzero[0]])) : 0;
        for (int c : order) {
          if (!has(need_a, c) || !has(need_b, c)) continue;
          const VoxelSet& sc = sets[c];
          if (has_probe && !sc.test(probe)) continue;
          bool covers = true;
          for (size_t k : nonzero) {
            if (!sc.sparse()) {
              if (rest[k] & ~sc.words()[k]) covers = false;
            } else {
              for (uint64_t bits = rest[k]; bits != 0 && covers; bits &= bits - 1) {
                covers = sc.test(k * 64 + static_cast<size_t>(std::countr_zero(bits)));
              }
            }
            if (!covers) break;
          }
          if (!covers) continue;
          std::vector<int> after = picks;
          after[a] = c;
          after.erase(after.begin() + static_cast<std::ptrdiff_t>(b));
          if (!keeps_linked(after)) continue;
          picks = std::move(after);
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
