#include "vc/plan/greedy.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <queue>
#include <string>
#include <unordered_map>

#include "progress_pacer.h"
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

// The gain rule in voxels per minute: min_gain_voxels_per_minute when > 0, else
// min_gain_m2_per_minute x surface_voxels_per_m2 (0 = off).
double GainRuleVoxelsPerMinute(const GreedyOptions& options) {
  if (options.min_gain_voxels_per_minute > 0) return options.min_gain_voxels_per_minute;
  return options.min_gain_m2_per_minute * options.surface_voxels_per_m2;
}

// INVALID_ARGUMENT for options out of range or `fixed` beyond the `candidates` sets.
Status CheckOptions(const GreedyOptions& options, size_t candidates) {
  if (options.max_stations < 0) return InvalidArgumentError("max_stations must be >= 0");
  if (options.fixed < 0 || static_cast<size_t>(options.fixed) > candidates) {
    return InvalidArgumentError("fixed must be in [0, " + std::to_string(candidates) + "]");
  }
  if (!(options.target_coverage > 0.0 && options.target_coverage <= 1.0)) {
    return InvalidArgumentError("target_coverage must be in (0, 1]");
  }
  if (!(options.min_gain_voxels_per_minute >= 0.0 && std::isfinite(options.min_gain_voxels_per_minute))) {
    return InvalidArgumentError("min_gain_voxels_per_minute must be finite and >= 0");
  }
  if (!(options.min_gain_m2_per_minute >= 0.0 && std::isfinite(options.min_gain_m2_per_minute))) {
    return InvalidArgumentError("min_gain_m2_per_minute must be finite and >= 0");
  }
  if (!(options.surface_voxels_per_m2 >= 0.0 && std::isfinite(options.surface_voxels_per_m2))) {
    return InvalidArgumentError("surface_voxels_per_m2 must be finite and >= 0");
  }
  if (!(options.station_seconds >= 0.0 && std::isfinite(options.station_seconds))) {
    return InvalidArgumentError("station_seconds must be finite and >= 0");
  }
  if (!(options.min_overlap >= 0.0 && options.min_overlap <= 1.0)) {
    return InvalidArgumentError("min_overlap must be in [0, 1]");
  }
  return Status::Ok();
}

// INVALID_ARGUMENT naming the first set whose size differs from the first's.
Status CheckSameSizes(const std::vector<VoxelSet>& sets) {
  const size_t n = sets[0].size();
  for (size_t i = 1; i < sets.size(); ++i) {
    if (sets[i].size() != n) {
      return InvalidArgumentError("visibility set " + std::to_string(i) + " has " + std::to_string(sets[i].size()) +
                                  " voxels, expected " + std::to_string(n));
    }
  }
  return Status::Ok();
}

// One SelectGreedy over checked sets and options: the voxels still uncovered, the picks so far and,
// with registration, which candidates have an edge to a pick (before the first pick all compete).
class GreedyRun {
 public:
  GreedyRun(const std::vector<VoxelSet>& sets, const GreedyOptions& options, const JobContext& ctx)
      : sets_(sets),
        options_(options),
        ctx_(ctx),
        fixed_(static_cast<size_t>(options.fixed)),
        min_gain_(std::max<uint64_t>(options.min_marginal_gain_voxels, 1)),
        gain_rule_voxels_(GainRuleVoxelsPerMinute(options) * options.station_seconds / 60.0),
        registration_(options.min_overlap > 0),
        uncovered_(sets[0].size()),
        picked_(sets.size(), 0),
        linked_(sets.size(), 0) {
    for (const VoxelSet& s : sets) UnionInto(uncovered_, s);
    result_.coverable = CountBits(uncovered_);
    coverable_ = static_cast<double>(result_.coverable);
    if (registration_) overlaps_.emplace(sets);
  }

  // The fixed stations, the rounds until a stopping rule holds, then (registration) the groups
  // the fixed stations left apart joined where a chain exists.
  Result<GreedyResult> Run() {
    for (size_t i = 0; i < fixed_; ++i) Pick(static_cast<int>(i), Gain(static_cast<int>(i)), false);
    if (options_.lazy) SeedHeap();
    while (true) {
      VC_RETURN_IF_ERROR(ctx_.CheckCancelled("greedy selection"));
      if (const std::optional<StopReason> stop = StopBeforeRound()) {
        result_.stop = *stop;
        break;
      }
      const Best best = options_.lazy ? BestLazy() : BestPlain();
      const bool gains_enough = best.candidate >= 0 && best.gain >= min_gain_;
      if (!gains_enough && Constrained()) {
        VC_ASSIGN_OR_RETURN(const ChainOutcome chain, PickChainToAGain());
        if (chain == ChainOutcome::kMaxStations) {
          result_.stop = StopReason::kMaxStations;
          break;
        }
        if (chain == ChainOutcome::kPicked) {
          EndRound();
          continue;
        }
      }
      if (!gains_enough) {
        result_.stop = StopReason::kMinGain;
        break;
      }
      if (!picked_list_.empty() && static_cast<double>(best.gain) < gain_rule_voxels_) {
        result_.stop = StopReason::kGainRule;
        break;
      }
      Pick(best.candidate, best.gain, false);
      EndRound();
    }
    if (registration_ && result_.stop != StopReason::kMaxStations) VC_RETURN_IF_ERROR(JoinGroups());
    return std::move(result_);
  }

 private:
  // The round's best candidate (-1: none eligible) and its gain.
  struct Best {
    int candidate = -1;
    uint64_t gain = 0;
  };
  enum class ChainOutcome : uint8_t { kNoGain, kPicked, kMaxStations };

  // Voxels candidate c would newly cover.
  uint64_t Gain(int c) const { return CountAnd(sets_[c], uncovered_); }
  // Registration after the first pick: only linked candidates compete.
  bool Constrained() const { return registration_ && !picked_list_.empty(); }
  bool Eligible(int c) const { return !Constrained() || linked_[c]; }
  // Whether `more` picks would exceed max_stations (the fixed stations not counted).
  bool AtMax(size_t more) const {
    return options_.max_stations > 0 &&
           picked_list_.size() - fixed_ + more > static_cast<size_t>(options_.max_stations);
  }

  // The stopping rule that holds before a round, if any, in the order exhausted, target, max.
  std::optional<StopReason> StopBeforeRound() const {
    if (result_.covered >= result_.coverable) return StopReason::kExhausted;
    if (static_cast<double>(result_.covered) >= options_.target_coverage * coverable_) {
      return StopReason::kTargetReached;
    }
    if (AtMax(1)) return StopReason::kMaxStations;
    return std::nullopt;
  }

  // Only the fixed stations cover anything yet, so these are exact gains for round 0.
  void SeedHeap() {
    for (size_t i = fixed_; i < sets_.size(); ++i) {
      heap_.push({fixed_ ? Gain(static_cast<int>(i)) : CountBits(sets_[i]), static_cast<int>(i), 0});
      ++result_.gain_evaluations;
    }
  }

  // CELF: stale gains are recounted until the top of the heap is exact for this round.
  Best BestLazy() {
    while (!heap_.empty()) {
      Entry top = heap_.top();
      heap_.pop();
      if (picked_[top.index]) continue;  // picked as a link of a chain
      if (!Eligible(top.index)) {
        parked_.push_back(top);
        continue;
      }
      if (top.round == round_) return {top.index, top.gain};  // exact, and no other bound beats it
      top.gain = Gain(top.index);
      top.round = round_;
      ++result_.gain_evaluations;
      heap_.push(top);
    }
    return {};
  }

  // Every eligible candidate recounted; ties keep the lowest index.
  Best BestPlain() {
    Best best;
    for (size_t i = fixed_; i < sets_.size(); ++i) {
      if (picked_[i] || !Eligible(static_cast<int>(i))) continue;
      const uint64_t g = Gain(static_cast<int>(i));
      ++result_.gain_evaluations;
      if (g > best.gain) best = {static_cast<int>(i), g};
    }
    return best;
  }

  // Nothing linked gains enough: the shortest chain to the nearest unlinked candidates that do, or
  // the best of them as a new group; kNoGain when none of them gains enough.
  Result<ChainOutcome> PickChainToAGain() {
    std::vector<uint64_t> gains(sets_.size(), 0);
    int unlinked_best = -1;
    for (size_t i = fixed_; i < sets_.size(); ++i) {
      if (picked_[i] || linked_[i]) continue;
      gains[i] = Gain(static_cast<int>(i));
      ++result_.gain_evaluations;
      if (gains[i] >= min_gain_ && (unlinked_best < 0 || gains[i] > gains[unlinked_best])) {
        unlinked_best = static_cast<int>(i);
      }
    }
    if (unlinked_best < 0) return ChainOutcome::kNoGain;
    // The unlinked candidates that gain enough, scored by their gain; the others -1.
    auto score = [&](int c) -> int64_t {
      return !picked_[c] && !linked_[c] && gains[c] >= min_gain_ ? int64_t(gains[c]) : -1;
    };
    VC_ASSIGN_OR_RETURN(std::vector<int> chain,
                        ShortestChain(*overlaps_, sets_.size(), picked_list_, options_.min_overlap, ctx_, score));
    if (chain.empty()) {
      ++result_.new_groups;
      chain = {unlinked_best};
    }
    if (AtMax(chain.size())) return ChainOutcome::kMaxStations;
    for (size_t k = 0; k < chain.size(); ++k) Pick(chain[k], Gain(chain[k]), k + 1 < chain.size());
    return ChainOutcome::kPicked;
  }

  // Groups the fixed stations left apart, joined by the shortest chains that exist.
  Status JoinGroups() {
    while (true) {
      const std::vector<std::vector<int>> groups = overlaps_->Groups(picked_list_, options_.min_overlap);
      if (groups.size() <= 1) return Status::Ok();
      std::vector<char> other(sets_.size(), 0);
      for (size_t g = 1; g < groups.size(); ++g) {
        for (int c : groups[g]) other[c] = 1;
      }
      VC_ASSIGN_OR_RETURN(std::vector<int> chain,
                          ShortestChain(*overlaps_, sets_.size(), groups[0], options_.min_overlap, ctx_,
                                        [&](int c) -> int64_t { return other[c] ? 0 : -1; }));
      if (chain.size() < 2) return Status::Ok();  // none, or (impossible) a direct edge between two groups
      chain.pop_back();                           // the station of another group it reaches
      for (int c : chain) Pick(c, Gain(c), true);
    }
  }

  // Candidate c picked: its voxels covered, its pick recorded, and (registration) its neighbours linked.
  void Pick(int c, uint64_t gain, bool connector) {
    SubtractFrom(uncovered_, sets_[c]);
    result_.covered += gain;
    result_.picks.push_back({c, gain, result_.covered, connector});
    result_.connectors += connector;
    picked_[c] = 1;
    picked_list_.push_back(c);
    if (registration_) LinkTo(c);
  }

  // Candidates with an edge to pick c become linked; parked heap entries of those go back.
  void LinkTo(int c) {
    for (size_t i = fixed_; i < sets_.size(); ++i) {
      if (!linked_[i] && !picked_[i] && overlaps_->Edge(c, static_cast<int>(i), options_.min_overlap)) linked_[i] = 1;
    }
    for (size_t k = 0; k < parked_.size();) {
      if (linked_[parked_[k].index]) {
        heap_.push(parked_[k]);
        parked_[k] = parked_.back();
        parked_.pop_back();
      } else {
        ++k;
      }
    }
  }

  // Stations picked so far (the total is not known in advance) and the coverage reached.
  void EndRound() {
    ++round_;
    if (!ctx_.progress) return;
    const double fraction = coverable_ > 0 ? std::min(1.0, double(result_.covered) / coverable_) : 1.0;
    ctx_.progress(ProgressEvent{Stage::kSelection, fraction, "coverage " + FormatPercent(fraction),
                                result_.picks.size(), 0, "stations"});
  }

  const std::vector<VoxelSet>& sets_;
  const GreedyOptions& options_;
  const JobContext& ctx_;
  const size_t fixed_;
  const uint64_t min_gain_;  // min_marginal_gain_voxels, at least 1: a 0 gain always stops
  // The gain rule's threshold: GainRuleVoxelsPerMinute x station_seconds / 60 (0 = off); it stops
  // no plan before its first station.
  const double gain_rule_voxels_;
  const bool registration_;
  VoxelSet uncovered_;
  double coverable_ = 0;  // result_.coverable
  GreedyResult result_;
  std::optional<Overlaps> overlaps_;  // with registration
  std::vector<char> picked_, linked_;
  std::vector<int> picked_list_;
  std::priority_queue<Entry, std::vector<Entry>, EntryLess> heap_;  // lazy
  std::vector<Entry> parked_;  // lazy: popped while not linked; back in the heap once linked
  int round_ = 0;
};

// A value per pick (its candidate index), computed on first use and kept: picks are few.
template <typename Value>
class PerPick {
 public:
  template <typename Compute>
  const Value& Get(int pick, Compute compute) {
    auto it = values_.find(pick);
    if (it == values_.end()) it = values_.emplace(pick, compute()).first;
    return it->second;
  }

 private:
  std::unordered_map<int, Value> values_;  // node-based: references stay valid as it grows
};

// One ConsolidatePicks over non-empty sets and picks: each pass drops one pick or merges one pair,
// until a pass changes nothing.
//
// How often the picks cover each voxel is counted once and then updated by each change on the
// voxels of the picks it removed or added. Whether a pick is needed (covers a voxel alone) and,
// without registration, whether a pair can merge depend only on the picks involved and on those
// counts at their voxels, so both are remembered (needed_, failed_) until a change adds or removes
// a pick that shares a voxel with them: a pass rechecks only what a change touched. The first
// droppable pick and the first mergeable pair are the same as if everything were rechecked, and so
// are the picks.
class Consolidation {
 public:
  Consolidation(const std::vector<VoxelSet>& sets, std::vector<int> picks, const GreedyOptions& options,
                const JobContext& ctx)
      : sets_(sets),
        ctx_(ctx),
        fixed_(options.fixed),
        min_overlap_(options.min_overlap),
        words_((sets[0].size() + 63) / 64),
        candidate_words_((sets.size() + 63) / 64),
        picks_(std::move(picks)),
        slots_(picks_.size()),
        c1_(words_),
        c2_(words_),
        c3_(words_),
        rest_(words_),
        block_words_((((words_ + kWordsPerBlock - 1) / kWordsPerBlock) + 63) / 64),
        budget_s_(options.consolidate_budget_s),
        start_(std::chrono::steady_clock::now()) {
    for (size_t i = static_cast<size_t>(std::max(fixed_, 0)); i < sets.size(); ++i) {
      order_.push_back(static_cast<int>(i));
    }
    std::vector<uint64_t> sizes(sets.size());
    for (size_t i = 0; i < sets.size(); ++i) sizes[i] = CountBits(sets[i]);
    std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return sizes[a] > sizes[b]; });
    rank_.assign(sets.size(), -1);
    for (size_t r = 0; r < order_.size(); ++r) rank_[order_[r]] = static_cast<int>(r);
    if (min_overlap_ > 0) overlaps_.emplace(sets);
    groups_ = overlaps_ ? overlaps_->Components(picks_, min_overlap_) : 1;
    std::iota(slots_.begin(), slots_.end(), 0);
    slot_count_ = picks_.size();
    needed_.assign(slot_count_, -1);
    if (!overlaps_) failed_.assign((slot_count_ * slot_count_ + 63) / 64, 0);
  }

  Result<ConsolidateResult> Run() {
    while (true) {
      VC_RETURN_IF_ERROR(ctx_.CheckCancelled("consolidation"));
      ++pass_;
      pairs_ = picks_.size() * (picks_.size() - 1) / 2;
      pacer_.Restart();
      (void)pacer_.Due();  // this report counts as the interval's
      ReportPass(0);
      if (pass_ == 1) CountCoverage();
      VC_ASSIGN_OR_RETURN(const bool dropped, DropOne());
      if (dropped) {
        EndPass(0);
        continue;
      }
      if (out_.budget_reached) break;
      VC_ASSIGN_OR_RETURN(const bool merged, MergeOne());
      if (!merged) break;
    }
    out_.seconds = Elapsed();
    ctx_.Report(Stage::kSelection, 1.0,
                PassNote() + (out_.budget_reached
                                  ? ", stopped at its time budget of " + std::to_string(std::lround(budget_s_)) + " s"
                                  : ", done"));
    out_.picks = std::move(picks_);
    return std::move(out_);
  }

 private:
  bool IsFixed(int candidate) const { return candidate < fixed_; }
  double Elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  // Whether the time budget is spent (then noted in out_): the search for a change stops, and the
  // picks are those of the changes made so far (each keeps the coverage).
  bool OverBudget() {
    if (budget_s_ <= 0 || out_.budget_reached) return out_.budget_reached;
    out_.budget_reached = Elapsed() > budget_s_;
    return out_.budget_reached;
  }

  // "consolidation pass 2 (1 dropped, 0 merged)".
  std::string PassNote() const {
    return "consolidation pass " + std::to_string(pass_) + " (" + std::to_string(out_.dropped) + " dropped, " +
           std::to_string(out_.merged) + " merged)";
  }
  // The fraction after `checked` of this pass's pairs: each pass advances through what the passes
  // before it left, so the fraction never falls although the number of passes is not known.
  double Fraction(uint64_t checked) const {
    return pairs_ == 0 ? done_before_ : done_before_ + (1.0 - done_before_) * double(checked) / double(pairs_);
  }
  // `checked` of this pass's pairs of picks, and the time left in this pass at the rate so far.
  void ReportPass(uint64_t checked) const {
    if (!ctx_.progress) return;
    std::string note = PassNote();
    if (const std::string left = pacer_.TimeLeft(checked, pairs_); !left.empty()) note += ", " + left + " in this pass";
    ctx_.progress(
        ProgressEvent{Stage::kSelection, Fraction(checked), std::move(note), checked, pairs_, "pairs of picks"});
  }
  // A pass that changed the picks after `checked` pairs: the next one starts where it stopped.
  void EndPass(uint64_t checked) { done_before_ = Fraction(checked); }

  // A pick's words (a sparse pick is made dense once).
  const std::vector<uint64_t>& Words(int pick) {
    if (!sets_[pick].sparse()) return sets_[pick].words();
    const VoxelSet& dense = dense_copies_.Get(pick, [&] {
      VoxelSet copy = sets_[pick];
      copy.Densify();
      return copy;
    });
    return dense.words();
  }

  // A pick's nonzero words: on a large site a station sees a small share of it, so a pair's rest_
  // is computed on these, not on every word of the scene.
  const std::vector<size_t>& NonzeroWords(int pick) {
    return nonzero_words_.Get(pick, [&] {
      std::vector<size_t> nonzero;
      const std::vector<uint64_t>& w = Words(pick);
      for (size_t k = 0; k < w.size(); ++k) {
        if (w[k]) nonzero.push_back(k);
      }
      return nonzero;
    });
  }

  // The candidates that see any voxel of a pick, as bits: one standing in for picks a and b must
  // see the voxels only they cover, so it is a neighbour of a (of b) when some of those lie in a
  // (in b). Far-apart picks have no common neighbour and are passed over at once. A dense
  // candidate is tested on the pick's nonzero words only: on a large site that is a small share of
  // the scene, and this was most of consolidation's time (every pick against every candidate).
  // Candidates that share no block with the pick (Blocks) are ruled out first, on a few words each.
  const std::vector<uint64_t>& Neighbours(int pick) {
    return neighbours_.Get(pick, [&] {
      const std::vector<uint64_t>& words = Words(pick);
      const std::vector<size_t>& nonzero = NonzeroWords(pick);
      std::vector<uint64_t> bits(candidate_words_, 0);
      for (size_t c = 0; c < sets_.size(); ++c) {
        if (!ShareABlock(static_cast<int>(c), pick)) continue;
        bool meets = false;
        if (sets_[c].sparse()) {
          meets = sets_[c].Intersects(sets_[pick]);
        } else {
          const std::vector<uint64_t>& other = sets_[c].words();
          for (size_t i = 0; i < nonzero.size() && !meets; ++i) meets = (other[nonzero[i]] & words[nonzero[i]]) != 0;
        }
        if (meets) bits[c >> 6] |= uint64_t{1} << (c & 63);
      }
      return bits;
    });
  }

  // The blocks of kWordsPerBlock words (512 voxels) in which each candidate has a voxel, as bits,
  // computed for every candidate on first use: two candidates that share no block share no voxel.
  // On a campus a station sees a small part of the scene, so most pairs of candidates are told apart
  // here in a few words instead of on the pick's nonzero words.
  const uint64_t* Blocks(int c) {
    if (blocks_.empty()) {
      blocks_.assign(sets_.size() * block_words_, 0);
      for (size_t i = 0; i < sets_.size(); ++i) {
        uint64_t* b = &blocks_[i * block_words_];
        if (sets_[i].sparse()) {
          sets_[i].ForEach([&](size_t id) {
            const size_t block = id / (64 * kWordsPerBlock);
            b[block >> 6] |= uint64_t{1} << (block & 63);
          });
          continue;
        }
        const std::vector<uint64_t>& w = sets_[i].words();
        for (size_t k = 0; k < w.size(); ++k) {
          if (w[k]) b[(k / kWordsPerBlock) >> 6] |= uint64_t{1} << ((k / kWordsPerBlock) & 63);
        }
      }
    }
    return &blocks_[static_cast<size_t>(c) * block_words_];
  }
  bool ShareABlock(int x, int y) {
    const uint64_t* bx = Blocks(x);
    const uint64_t* by = Blocks(y);
    for (size_t k = 0; k < block_words_; ++k) {
      if (bx[k] & by[k]) return true;
    }
    return false;
  }

  // The candidates that see one voxel only `pick` covers (the first such voxel), as bits; kept while
  // that voxel stays covered by `pick` alone. For a needed pick only (Needed).
  const std::vector<uint64_t>& Seers(int pick) {
    auto it = seers_.find(pick);
    if (it != seers_.end() && counts_[it->second.first] == 1) return it->second.second;
    const std::vector<uint64_t>& w = Words(pick);
    size_t probe = 0;
    for (size_t k : NonzeroWords(pick)) {
      if (const uint64_t sole = w[k] & ~c2_[k]; sole != 0) {
        probe = k * 64 + static_cast<size_t>(std::countr_zero(sole));
        break;
      }
    }
    std::vector<uint64_t> bits(candidate_words_, 0);
    for (size_t c = 0; c < sets_.size(); ++c) {
      if (sets_[c].test(probe)) bits[c >> 6] |= uint64_t{1} << (c & 63);
    }
    auto& entry = seers_[pick];
    entry = {probe, std::move(bits)};
    return entry.second;
  }

  // Whether candidate c is among `bits` (nullptr: no constraint).
  static bool Has(const std::vector<uint64_t>* bits, int c) { return !bits || (((*bits)[c >> 6] >> (c & 63)) & 1); }

  // Registration: `after` must not split the picks' scan graph into more groups.
  bool KeepsLinked(const std::vector<int>& after) {
    if (!overlaps_) return true;
    const int n = overlaps_->Components(after, min_overlap_);
    if (n > groups_) return false;
    groups_ = n;
    return true;
  }

  // How often the picks cover each voxel (counts_), and as bits the voxels covered at least once
  // (c1_), twice (c2_), three times (c3_). Counted once; each change then recounts its picks only.
  void CountCoverage() {
    counts_.assign(sets_[0].size(), 0);
    for (int p : picks_) Recount(p, +1);
  }
  // Adds (delta +1) or removes (-1) one pick's voxels from the counts and their bits.
  void Recount(int pick, int delta) {
    const std::vector<uint64_t>& w = Words(pick);
    for (size_t k : NonzeroWords(pick)) {
      for (uint64_t bits = w[k]; bits != 0; bits &= bits - 1) {
        const int j = std::countr_zero(bits);
        uint32_t& n = counts_[k * 64 + static_cast<size_t>(j)];
        n = delta > 0 ? n + 1 : n - 1;
        const uint64_t bit = uint64_t{1} << j;
        c1_[k] = n >= 1 ? c1_[k] | bit : c1_[k] & ~bit;
        c2_[k] = n >= 2 ? c2_[k] | bit : c2_[k] & ~bit;
        c3_[k] = n >= 3 ? c3_[k] | bit : c3_[k] & ~bit;
      }
    }
  }
  // Whether the pick at position i covers a voxel no other pick covers; kept per slot until a
  // change touches the pick.
  bool Needed(size_t i) {
    int8_t& known = needed_[static_cast<size_t>(slots_[i])];
    if (known >= 0) return known;
    const std::vector<uint64_t>& w = Words(picks_[i]);
    bool needed = false;
    for (size_t k : NonzeroWords(picks_[i])) {
      if ((needed = (w[k] & ~c2_[k]) != 0)) break;
    }
    known = needed;
    return needed;
  }

  // Drops a pick nobody needs (all its voxels covered twice), the latest such pick first.
  // Notes which picks cover a voxel alone (sole_) on the way. Checks cancellation after every pick
  // and reports the picks checked at most once per pacer interval (registration makes each slow).
  Result<bool> DropOne() {
    sole_.assign(picks_.size(), 0);
    if (picks_.size() <= 1) return false;
    for (size_t i = picks_.size(); i-- > 0;) {
      VC_RETURN_IF_ERROR(ctx_.CheckCancelled("consolidation"));
      if (OverBudget()) return false;
      if (pacer_.Due() && ctx_.progress) {
        const uint64_t checked = picks_.size() - 1 - i;
        ctx_.progress(ProgressEvent{Stage::kSelection, Fraction(0), PassNote() + ", looking for a pick to drop",
                                    checked, picks_.size(), "picks checked"});
      }
      if (IsFixed(picks_[i])) continue;
      const bool needed = Needed(i);
      sole_[i] = needed;
      if (needed) continue;
      std::vector<int> after = picks_;
      after.erase(after.begin() + static_cast<std::ptrdiff_t>(i));
      if (!KeepsLinked(after)) continue;
      const int dropped = picks_[i];
      picks_ = std::move(after);
      slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(i));
      AfterChange({dropped}, -1, -1);
      ++out_.dropped;
      return true;
    }
    return false;
  }

  // Replaces the first pair of picks (in pick order) one candidate can stand in for.
  // Checks cancellation after every pair and reports at most once per pacer interval.
  Result<bool> MergeOne() {
    uint64_t checked = 0;
    for (size_t a = 0; a < picks_.size(); ++a) {
      for (size_t b = a + 1; b < picks_.size(); ++b, ++checked) {
        VC_RETURN_IF_ERROR(ctx_.CheckCancelled("consolidation"));
        if (OverBudget()) return false;
        if (pacer_.Due()) ReportPass(checked);
        if (IsFixed(picks_[a]) || IsFixed(picks_[b]) || Failed(a, b)) continue;
        if (!MergePair(a, b)) {
          NoteFailed(a, b);
          continue;
        }
        EndPass(checked + 1);
        return true;
      }
    }
    return false;
  }

  // Fills rest_ (on the words listed in nonzero_) with the voxels only picks a and b cover: in both
  // and covered exactly twice, or in one and covered once (only in words where a or b has a voxel).
  // Returns whether any of them lies in a and in b.
  std::pair<bool, bool> FindRest(int a, int b) {
    const std::vector<uint64_t>& wa = Words(a);
    const std::vector<uint64_t>& wb = Words(b);
    const std::vector<size_t>& za = NonzeroWords(a);
    const std::vector<size_t>& zb = NonzeroWords(b);
    nonzero_.clear();
    bool in_a = false, in_b = false;
    for (size_t i = 0, j = 0; i < za.size() || j < zb.size();) {
      const size_t k = j == zb.size() || (i < za.size() && za[i] < zb[j]) ? za[i] : zb[j];
      i += i < za.size() && za[i] == k;
      j += j < zb.size() && zb[j] == k;
      rest_[k] = (wa[k] & wb[k] & ~c3_[k]) | ((wa[k] ^ wb[k]) & ~c2_[k]);
      if (!rest_[k]) continue;
      nonzero_.push_back(k);
      in_a |= (rest_[k] & wa[k]) != 0;
      in_b |= (rest_[k] & wb[k]) != 0;
    }
    return {in_a, in_b};
  }

  // Whether `candidate` sees every voxel of rest_.
  bool CoversRest(const VoxelSet& candidate) const {
    for (size_t k : nonzero_) {
      if (!candidate.sparse()) {
        if (rest_[k] & ~candidate.words()[k]) return false;
      } else {
        for (uint64_t bits = rest_[k]; bits != 0; bits &= bits - 1) {
          if (!candidate.test(k * 64 + static_cast<size_t>(std::countr_zero(bits)))) return false;
        }
      }
    }
    return true;
  }

  // Replaces picks a < b by the first candidate (in order_) that covers what only they cover and
  // keeps the scan graph's groups.
  //
  // Picks that each cover a voxel alone (sole_) need a stand-in among the neighbours of both: where
  // there is none, the pair is passed over before rest_ is computed (most pairs on a large site);
  // otherwise only the common neighbours are tried, in order_.
  bool MergePair(size_t a, size_t b) {
    if (sole_[a] && sole_[b]) {
      // A stand-in must see a voxel only a covers and one only b covers: the candidates that see
      // both are few, and most pairs on a large site have none.
      const std::vector<uint64_t>& seers_a = Seers(picks_[a]);
      const std::vector<uint64_t>& seers_b = Seers(picks_[b]);
      if (!Meet(seers_a, seers_b)) return false;
      FindRest(picks_[a], picks_[b]);
      CommonNeighboursInOrder(seers_a, seers_b);
      for (int c : common_) {
        if (TryStandIn(a, b, c)) return true;
      }
      return false;
    }
    const auto [in_a, in_b] = FindRest(picks_[a], picks_[b]);
    const std::vector<uint64_t>* need_a = in_a ? &Neighbours(picks_[a]) : nullptr;
    const std::vector<uint64_t>* need_b = in_b ? &Neighbours(picks_[b]) : nullptr;
    if (need_a && need_b && !Meet(*need_a, *need_b)) return false;  // no candidate sees into both
    if (need_a && need_b) {
      CommonNeighboursInOrder(*need_a, *need_b);
      for (int c : common_) {
        if (TryStandIn(a, b, c)) return true;
      }
      return false;
    }
    for (int c : order_) {
      if (Has(need_a, c) && Has(need_b, c) && TryStandIn(a, b, c)) return true;
    }
    return false;
  }

  // Whether two candidate bitsets share a candidate.
  bool Meet(const std::vector<uint64_t>& x, const std::vector<uint64_t>& y) const {
    for (size_t k = 0; k < candidate_words_; ++k) {
      if (x[k] & y[k]) return true;
    }
    return false;
  }

  // common_: the non-fixed candidates in both x and y, in order_.
  void CommonNeighboursInOrder(const std::vector<uint64_t>& x, const std::vector<uint64_t>& y) {
    common_.clear();
    for (size_t k = 0; k < candidate_words_; ++k) {
      for (uint64_t bits = x[k] & y[k]; bits != 0; bits &= bits - 1) {
        const size_t c = k * 64 + static_cast<size_t>(std::countr_zero(bits));
        if (rank_[c] >= 0) common_.push_back(static_cast<int>(c));
      }
    }
    std::sort(common_.begin(), common_.end(), [&](int p, int q) { return rank_[p] < rank_[q]; });
  }

  // The bit of failed_ for the pair of slots s and t, in either order.
  size_t SlotPairBit(size_t s, size_t t) const { return std::min(s, t) * slot_count_ + std::max(s, t); }
  // The bit of failed_ for the picks at positions a and b (without registration).
  size_t FailedBit(size_t a, size_t b) const {
    return SlotPairBit(static_cast<size_t>(slots_[a]), static_cast<size_t>(slots_[b]));
  }
  // Whether the picks at positions a and b were found unmergeable since the last change near them.
  bool Failed(size_t a, size_t b) const {
    if (failed_.empty()) return false;
    const size_t bit = FailedBit(a, b);
    return (failed_[bit >> 6] >> (bit & 63)) & 1;
  }
  void NoteFailed(size_t a, size_t b) {
    if (failed_.empty()) return;
    const size_t bit = FailedBit(a, b);
    failed_[bit >> 6] |= uint64_t{1} << (bit & 63);
  }
  // After a change that removed the `removed` picks and added candidate `added` (-1: none) in
  // `new_slot`: the counts are updated, and every pick that shares a voxel with one of them (its
  // voxels' counts changed), and the new pick, loses what was known of it (Needed, failed_).
  void AfterChange(std::vector<int> changed, int added, int new_slot) {
    for (int c : changed) Recount(c, -1);
    if (added >= 0) {
      Recount(added, +1);
      changed.push_back(added);
    }
    for (size_t i = 0; i < picks_.size(); ++i) {
      bool touched = slots_[i] == new_slot;
      for (size_t k = 0; k < changed.size() && !touched; ++k) touched = SeesInto(picks_[i], changed[k]);
      if (!touched) continue;
      needed_[static_cast<size_t>(slots_[i])] = -1;
      if (!failed_.empty()) ForgetSlot(static_cast<size_t>(slots_[i]));
    }
  }
  // Whether candidates x and c share a voxel (tested on c's nonzero words).
  bool SeesInto(int x, int c) {
    if (!ShareABlock(x, c)) return false;
    const std::vector<uint64_t>& wx = Words(x);
    const std::vector<uint64_t>& wc = Words(c);
    for (size_t k : NonzeroWords(c)) {
      if (wx[k] & wc[k]) return true;
    }
    return false;
  }
  // Clears every failed_ bit of slot s.
  void ForgetSlot(size_t s) {
    for (size_t t = 0; t < slot_count_; ++t) {
      const size_t bit = SlotPairBit(s, t);
      failed_[bit >> 6] &= ~(uint64_t{1} << (bit & 63));
    }
  }

  // Replaces picks a < b by candidate c if c sees all of rest_ and the scan graph keeps its groups.
  bool TryStandIn(size_t a, size_t b, int c) {
    // A voxel of rest_ every candidate standing in must see: one test rules most out.
    if (!nonzero_.empty()) {
      const size_t probe = nonzero_[0] * 64 + static_cast<size_t>(std::countr_zero(rest_[nonzero_[0]]));
      if (!sets_[c].test(probe)) return false;
    }
    if (!CoversRest(sets_[c])) return false;
    std::vector<int> after = picks_;
    after[a] = c;
    after.erase(after.begin() + static_cast<std::ptrdiff_t>(b));
    if (!KeepsLinked(after)) return false;
    const int replaced_a = picks_[a], replaced_b = picks_[b];
    picks_ = std::move(after);
    slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(b));
    AfterChange({replaced_a, replaced_b}, c, slots_[a]);
    ++out_.merged;
    return true;
  }

  const std::vector<VoxelSet>& sets_;
  const JobContext& ctx_;
  const int fixed_;
  const double min_overlap_;
  const size_t words_;            // per voxel set
  const size_t candidate_words_;  // per candidate bitset (Neighbours)
  std::vector<int> picks_;
  std::vector<int> slots_;   // per pick: its row and column in failed_ (a stand-in takes the slot of the first pick)
  std::vector<int> order_;   // the non-fixed candidates by decreasing |set|, then index
  std::vector<int> rank_;    // per candidate: its place in order_, -1 for a fixed one
  std::vector<int> common_;  // CommonNeighboursInOrder's output
  std::vector<char> sole_;   // per pick this pass: covers a voxel no other pick covers
  std::optional<Overlaps> overlaps_;  // with registration
  int groups_ = 1;                    // components of the picks' scan graph
  PerPick<VoxelSet> dense_copies_;    // sparse picks, made dense
  PerPick<std::vector<size_t>> nonzero_words_;
  PerPick<std::vector<uint64_t>> neighbours_;
  std::unordered_map<int, std::pair<size_t, std::vector<uint64_t>>> seers_;  // Seers: probe voxel, bits
  size_t slot_count_ = 0;                                                    // the picks consolidation started with
  std::vector<uint64_t> failed_;  // without registration: bit s * slot_count_ + t, s < t, for an unmergeable pair
  std::vector<int8_t> needed_;    // per slot: Needed's answer, -1 when not known
  std::vector<uint32_t> counts_;  // per voxel: how many picks cover it
  std::vector<uint64_t> c1_, c2_, c3_, rest_;
  std::vector<size_t> nonzero_;  // the words where rest_ has a voxel
  static constexpr size_t kWordsPerBlock = 8;
  const size_t block_words_;      // per candidate in blocks_
  std::vector<uint64_t> blocks_;  // Blocks: block_words_ per candidate
  const double budget_s_;         // GreedyOptions::consolidate_budget_s
  const std::chrono::steady_clock::time_point start_;
  ConsolidateResult out_;
  int pass_ = 0;                   // 1-based number of the pass running
  uint64_t pairs_ = 0;             // pairs of picks in this pass
  double done_before_ = 0;         // the progress fraction this pass started at
  internal::ProgressPacer pacer_;  // within a pass
};

}  // namespace

uint64_t SmallestGainPickedVoxels(const GreedyOptions& options) {
  const double gain_rule = std::ceil(GainRuleVoxelsPerMinute(options) * options.station_seconds / 60.0 - 1e-9);
  return std::max<uint64_t>({1, options.min_marginal_gain_voxels, static_cast<uint64_t>(std::max(0.0, gain_rule))});
}

Result<GreedyResult> SelectGreedy(const std::vector<VoxelSet>& sets, const GreedyOptions& options,
                                  const JobContext& ctx) {
  VC_RETURN_IF_ERROR(CheckOptions(options, sets.size()));
  if (sets.empty()) return GreedyResult{};
  VC_RETURN_IF_ERROR(CheckSameSizes(sets));
  return GreedyRun(sets, options, ctx).Run();
}

Result<ConsolidateResult> ConsolidatePicks(const std::vector<VoxelSet>& sets, std::vector<int> picks,
                                           const GreedyOptions& options, const JobContext& ctx) {
  if (sets.empty() || picks.empty()) {
    ConsolidateResult out;
    out.picks = std::move(picks);
    return out;
  }
  return Consolidation(sets, std::move(picks), options, ctx).Run();
}

}  // namespace vc::planner
