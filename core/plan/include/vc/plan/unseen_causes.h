// Why no candidate sees an occupied voxel (docs/PLANNING.md, "What no candidate can see"): the
// breakdown behind the headline's "no candidate sees at all", so that a user knows whether a finer
// grid, another height, another floor's candidates or a ladder would help. Each voxel outside the
// coverable set gets the first cause that applies, in the order of UnseenCauses' members.
// Thread-compatible: a pure function.
#pragma once

#include <cstdint>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/keep_out.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"
#include "vc/visibility/voxel_set.h"

namespace vc {

// Counts of occupied voxels no candidate sees, by cause. Geometry is judged at voxel centres.
struct UnseenCauses {
  // All six face neighbours are occupied: inside solid matter (a thick wall, a closed slab), seen
  // from nowhere at this resolution.
  uint64_t interior = 0;
  // The centre lies in a keep-out zone (no station may stand there, and none outside sees it).
  uint64_t in_keep_out = 0;
  // Above the lowest floor level, on a storey (between one floor level and the next) where no
  // candidate stands: that floor needs candidates (0 without floor levels, i.e. with user candidates).
  uint64_t no_candidate_on_floor = 0;
  // Every candidate is nearer than the scanner's min_range_m or farther than its max_range_m.
  uint64_t out_of_range = 0;
  // Every candidate in range sees it above vfov_max_deg or below vfov_min_deg: another tripod
  // height, or a scanner with a wider vertical field, would help.
  uint64_t outside_field_of_view = 0;
  // Every face it has toward empty space faces away from every candidate in range and view: the
  // underside of a floor slab, the outside of an outer wall, the back of a cupboard against a wall.
  // Only a station on that side (another storey, outdoors) would see it.
  uint64_t faces_away = 0;
  // Some open face faces a candidate in range and view, but other surfaces hide it from every such
  // candidate (behind furniture, around a corner), or it is too oblique or too sparsely sampled for
  // the scanner's incidence and spacing limits: more or other candidates would help.
  uint64_t hidden = 0;

  // The voxels counted (occupied voxels outside the coverable set).
  [[nodiscard]] uint64_t total() const {
    return interior + in_keep_out + no_candidate_on_floor + out_of_range + outside_field_of_view + faces_away + hidden;
  }
};

struct UnseenCausesInput {
  const VoxelScene& scene;
  const VoxelSet& coverable;  // over the scene's voxels: what some candidate sees
  // Every position whose visibility set went into `coverable` (candidates, fixed stations, refined
  // positions), local frame (m).
  const std::vector<WorldPoint>& candidates;
  const std::vector<double>& floor_levels_m;  // the candidates' floor levels, ascending; empty: no floor cause
  const std::vector<KeepOutZone>& keep_out;   // local frame
  const ScannerModel& scanner;
};

// The causes of every occupied voxel outside in.coverable, on `threads` workers (0 = all).
// CANCELLED / DEADLINE_EXCEEDED from ctx.
[[nodiscard]] Result<UnseenCauses> CountUnseenCauses(const UnseenCausesInput& in, int threads,
                                                     const JobContext& ctx = {});

}  // namespace vc
