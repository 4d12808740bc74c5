// Greedy station selection (ALGORITHM.md s.7.3; paper s.3.2) over precomputed visibility sets.
//
// Each round picks the candidate that sees the most still-uncovered coverable voxels (coverable =
// seen by at least one candidate); ties go to the lowest candidate index. The plain version
// recounts every candidate each round; the lazy version (CELF, Leskovec et al. 2007) keeps stale
// gains as upper bounds in a max-heap, which is exact because gains only shrink as coverage grows,
// and the heap orders (gain desc, index asc) so both versions pick identically. Internal to
// vc::plan; the planner reaches it through GreedySelector (selector.h). Thread-compatible: no
// shared state.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/selector.h"
#include "vc/visibility/visibility.h"

namespace vc::planner {

struct GreedyPick {
  int candidate = -1;          // index into the sets
  uint64_t marginal_gain = 0;  // voxels newly covered by this pick
  uint64_t covered_after = 0;  // covered voxels after this pick
  bool connector = false;      // picked to link the scan graph (min_overlap), not for its gain
};

struct GreedyResult {
  std::vector<GreedyPick> picks;
  uint64_t coverable = 0;  // |union of all sets|
  uint64_t covered = 0;    // |union of the picked sets|
  StopReason stop = StopReason::kExhausted;
  uint64_t gain_evaluations = 0;  // intersections counted (lazy needs far fewer)
  int connectors = 0;             // picks made to link the scan graph (GreedyPick::connector)
  int new_groups = 0;             // times no chain reached a gaining candidate (min_overlap > 0)
};

// Greedy maximum coverage over `sets` (all of the same size), with the options' stopping rules,
// fixed stations and registration (GreedyOptions, selector.h; consolidate is not read here).
// INVALID_ARGUMENT for sets of different sizes or bad options; CANCELLED / DEADLINE_EXCEEDED from
// ctx (checked every round).
Result<GreedyResult> SelectGreedy(const std::vector<VoxelSet>& sets, const GreedyOptions& options,
                                  const JobContext& ctx = {});

// The smallest gain SelectGreedy picks a station for after the first one: min_marginal_gain_voxels
// (at least 1) and the gain rule's voxels per station (GreedyOptions: voxels per minute x
// station_seconds / 60), rounded up; whichever is larger.
uint64_t SmallestGainPickedVoxels(const GreedyOptions& options);

// Consolidation (our extension, after the greedy picks): drops a pick whose voxels the other picks
// all cover, or replaces two picks by one candidate that sees every voxel only those two covered,
// until neither applies. The covered set never shrinks and the count only falls. Greedy is not
// optimal (e.g. comb:5 on a 1 m grid: 7 greedy picks where 5 candidates suffice); this repairs the
// typical case where two early picks each cover half of what one candidate sees. Candidates are
// tried in order of decreasing |set|, then index; picks are examined in greedy order. Picks of the
// first options.fixed sets (fixed stations) are never dropped or replaced, nor used as
// replacements; with options.min_overlap > 0 a change must not add a group to the picks' scan
// graph. The stopping rules and options.consolidate are not read here.
struct ConsolidateResult {
  std::vector<int> picks;  // candidate indices; a replacement takes the place of the earlier pick
  int dropped = 0;         // picks removed as covered by the others
  int merged = 0;          // pairs replaced by one candidate
  // The time budget (GreedyOptions::consolidate_budget_s) ran out: the picks are those of the
  // changes made until then (each keeps the coverage), and a further change may have been possible.
  bool budget_reached = false;
  double seconds = 0;  // consolidation's wall time
};
// CANCELLED / DEADLINE_EXCEEDED from ctx.
Result<ConsolidateResult> ConsolidatePicks(const std::vector<VoxelSet>& sets, std::vector<int> picks,
                                           const GreedyOptions& options = {}, const JobContext& ctx = {});

// |a AND b| over the raw bitset words (equal sizes).
uint64_t CountAnd(const VoxelSet& a, const VoxelSet& b);
// Number of set bits.
uint64_t CountBits(const VoxelSet& a);
// a |= b.
void UnionInto(VoxelSet& a, const VoxelSet& b);

}  // namespace vc::planner
