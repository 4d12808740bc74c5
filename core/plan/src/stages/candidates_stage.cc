#include <cmath>
#include <string>
#include <utility>

#include "format.h"
#include "vc/plan/candidates.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/stages.h"

namespace vc::planner {
namespace {

// A local position as the user gave it: in the input's frame (VoxelScene::frame_origin_m added).
std::string InputFrame(const VoxelScene& scene, const WorldPoint& local) {
  const WorldPoint p = scene.frame_origin_m.isZero() ? local : WorldPoint(local + scene.frame_origin_m);
  return Coordinate(p.x()) + ", " + Coordinate(p.y()) + ", " + Coordinate(p.z());
}

// The box [lo, hi] (local) in the input's frame.
std::string Bounds(const VoxelScene& scene, const WorldPoint& local_lo, const WorldPoint& local_hi) {
  const bool zero = scene.frame_origin_m.isZero();
  const WorldPoint lo = zero ? local_lo : WorldPoint(local_lo + scene.frame_origin_m);
  const WorldPoint hi = zero ? local_hi : WorldPoint(local_hi + scene.frame_origin_m);
  return "x " + Coordinate(lo.x()) + ".." + Coordinate(hi.x()) + ", y " + Coordinate(lo.y()) + ".." +
         Coordinate(hi.y()) + ", z " + Coordinate(lo.z()) + ".." + Coordinate(hi.z()) + " m";
}

// INVALID_ARGUMENT naming `what`[i] when a user position is out of range or inside an occupied
// voxel (naming the voxel's bounds).
Status CheckUserPositions(const VoxelScene& scene, const std::vector<WorldPoint>& user, const char* what) {
  for (size_t i = 0; i < user.size(); ++i) {
    const WorldPoint& p = user[i];
    const std::string name = std::string(what) + "[" + std::to_string(i) + "] (" + InputFrame(scene, p) + ")";
    if (!ViewpointInRange(p, scene.resolution_m)) {
      return InvalidArgumentError(name + " is more than " + Num(kMaxViewpointIndex * scene.resolution_m) +
                                  " m from the origin along an axis; use coordinates in the scene's frame");
    }
    const VoxelIndex v = scene.grid.WorldToIndex(p);
    if (scene.grid.Occupied(v)) {
      const double r = scene.resolution_m;
      const WorldPoint lo(v.x * r, v.y * r, v.z * r);
      return InvalidArgumentError(name + " lies inside an occupied voxel (" +
                                  Bounds(scene, lo, lo + WorldPoint::Constant(r)) +
                                  "): a wall, the floor or furniture; is its height the floor's rather than the "
                                  "scanner's?");
    }
  }
  return Status::Ok();
}

// How far outside the occupied voxels' bounding box a fixed station may lie (m): a tripod over a
// scanned floor with nothing scanned above it.
constexpr double kFixedStationBoundsMargin_m = 2.0;
// A fixed station whose nearest occupied voxel straight below is farther than this (m) gets a warning.
constexpr double kFixedStationFloorWithin_m = 3.0;

// Distance (m) from p down to the top of the nearest occupied voxel straight below it; NaN if none.
double DistanceToFloorBelow(const VoxelScene& scene, const WorldPoint& p) {
  const VoxelIndex v = scene.grid.WorldToIndex(p);
  for (int z = v.z; z >= scene.grid.min_index().z; --z) {
    if (scene.grid.Occupied(v.x, v.y, z)) return p.z() - (z + 1) * scene.resolution_m;
  }
  return std::nan("");
}

// INVALID_ARGUMENT naming fixed_stations[i] (the i+1-th station of the user's file) and the scene's
// bounds when one lies outside them (widened by kFixedStationBoundsMargin_m); a warning for each one
// without an occupied voxel within kFixedStationFloorWithin_m straight below.
Result<std::vector<std::string>> CheckFixedStations(const VoxelScene& scene, const std::vector<WorldPoint>& fixed) {
  std::vector<std::string> warnings;
  if (fixed.empty()) return warnings;
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(kFixedStationBoundsMargin_m);
  const WorldPoint lo = scene.BoundsMin(), hi = scene.BoundsMax();
  for (size_t i = 0; i < fixed.size(); ++i) {
    const WorldPoint& p = fixed[i];
    const std::string name = "fixed_stations[" + std::to_string(i) + "] (station " + std::to_string(i + 1) +
                             " of the file, at " + InputFrame(scene, p) + ")";
    if ((p.array() < (lo - margin).array()).any() || (p.array() > (hi + margin).array()).any()) {
      return InvalidArgumentError(name + " lies outside the scene's bounds (" + Bounds(scene, lo, hi) +
                                  ", widened by " + Num(kFixedStationBoundsMargin_m) +
                                  " m); is it in another frame or unit than the scene?");
    }
    const double below_m = DistanceToFloorBelow(scene, p);
    if (std::isnan(below_m)) {
      warnings.push_back(name +
                         " has no floor below it: no occupied voxel lies straight below, down to the scene's "
                         "bottom at z = " +
                         Coordinate(lo.z() + scene.frame_origin_m.z()) + " m, " + Num(p.z() - lo.z()) + " m below it");
    } else if (below_m > kFixedStationFloorWithin_m) {
      warnings.push_back(name + " has no floor within " + Num(kFixedStationFloorWithin_m) +
                         " m below it: the nearest occupied voxel straight below is " + Num(below_m) + " m down");
    }
  }
  return warnings;
}

// The user's candidates, checked: in range, and not inside an occupied voxel; those in a keep-out
// zone are dropped (with a warning). FAILED_PRECONDITION when none is left.
Result<CandidatesOutput> UserCandidates(const VoxelScene& scene, const PlanOptions& options) {
  VC_RETURN_IF_ERROR(CheckUserPositions(scene, options.candidates, "candidates"));
  CandidatesOutput out;
  for (const WorldPoint& p : options.candidates) {
    if (KeepOutZoneContaining(options.keep_out, p) >= 0) {
      ++out.in_keep_out;
      continue;
    }
    out.positions.push_back(p);
  }
  if (out.positions.empty()) {
    return FailedPreconditionError("all " + std::to_string(options.candidates.size()) +
                                   " candidates lie in keep-out zones; pass candidates outside them");
  }
  if (out.in_keep_out > 0) {
    out.warnings.push_back(std::to_string(out.in_keep_out) + " of " + std::to_string(options.candidates.size()) +
                           " candidates lie in keep-out zones and were dropped");
  }
  out.floor_z_m.assign(out.positions.size(), std::nan(""));
  return out;
}

// The generated grid; FAILED_PRECONDITION when no floor is found or no candidate survives.
Result<CandidatesOutput> GridCandidates(const VoxelScene& scene, const PlanOptions& options, const JobContext& ctx) {
  VC_ASSIGN_OR_RETURN(CandidateGrid grid, GenerateCandidates(scene, CandidateOptionsFor(options), ctx));
  CandidatesOutput out;
  if (!options.keep_out.empty()) {
    size_t kept = 0;
    for (size_t i = 0; i < grid.positions.size(); ++i) {
      if (KeepOutZoneContaining(options.keep_out, grid.positions[i]) >= 0) {
        ++out.in_keep_out;
        continue;
      }
      grid.positions[kept] = grid.positions[i];
      grid.floor_z_m[kept] = grid.floor_z_m[i];
      ++kept;
    }
    grid.positions.resize(kept);
    grid.floor_z_m.resize(kept);
  }
  for (const FloorLevel& l : grid.levels) out.floor_levels_m.push_back(l.z_m);
  out.ground = grid.ground;
  out.grid_cells = grid.cells;
  out.cells_without_floor = grid.rejected_no_floor;
  out.cells_failing_clearance = grid.rejected_clearance;
  if (grid.positions.empty()) {
    const bool terrain = grid.ground.model == GroundModel::kTerrain;
    if (terrain ? grid.ground_columns == 0 : grid.levels.empty()) {
      return FailedPreconditionError("no floor found: no occupied voxel has tripod_height_m + clearance_m = " +
                                     Num(options.tripod_height_m + options.clearance_m) +
                                     " m of free space above it; lower them or pass candidates");
    }
    std::string levels;
    for (double z : out.floor_levels_m) levels += (levels.empty() ? "" : ", ") + Num(z);
    const std::string ground = terrain ? "terrain ground, " + std::to_string(grid.ground_columns) + " voxel columns"
                                       : "floor levels at z = " + levels + " m";
    return FailedPreconditionError(
        "no candidate survived: of " + std::to_string(grid.cells) + " grid cells, " +
        std::to_string(grid.rejected_no_floor) + " had no floor below (" + ground + ") and " +
        std::to_string(grid.rejected_clearance) +
        " had occupied voxels within clearance_m = " + Num(options.clearance_m) + " m" +
        (out.in_keep_out ? ", and " + std::to_string(out.in_keep_out) + " candidates lay in keep-out zones"
                         : std::string()) +
        "; lower clearance_m or grid_spacing_m, or pass candidates");
  }
  if (grid.positions.size() < 5) {
    out.warnings.push_back("only " + std::to_string(grid.positions.size()) +
                           " candidates survived the clearance filter (" + std::to_string(grid.rejected_clearance) +
                           " cells with floor failed clearance_m = " + Num(options.clearance_m) + " m, " +
                           std::to_string(grid.rejected_no_floor) +
                           " had no floor below) — lower clearance_m or grid_spacing_m, or check the floor estimate");
  }
  out.positions = std::move(grid.positions);
  out.floor_z_m = std::move(grid.floor_z_m);
  return out;
}

}  // namespace

CandidateOptions CandidateOptionsFor(const PlanOptions& options) {
  return {.grid_spacing_m = options.grid_spacing_m,
          .tripod_height_m = options.tripod_height_m,
          .clearance_m = options.clearance_m,
          .tripod_heights_m = options.tripod_heights_m,
          .doorway_candidates = options.doorway_candidates,
          .ground = options.ground,
          .walk_max_step_m = options.walk_max_step_m};
}

PlanOptions CoarseToFineOptions(const PlanOptions& options) {
  PlanOptions out = options;
  out.local_candidates = true;
  out.local_candidates_radius_m = options.grid_spacing_m;
  out.local_candidates_step_m = options.grid_spacing_m;
  out.local_candidates_rounds = 1;
  return out;
}

std::string CoarseToFineNote(const CandidatesOutput& candidates, int32_t threshold) {
  if (!candidates.coarse) return "";
  const CandidatesOutput::CoarseGrid& coarse = *candidates.coarse;
  const size_t coarse_candidates = candidates.positions.size();
  return "coarse then fine: the " + Num(coarse.fine_spacing_m) + " m grid gives " +
         std::to_string(coarse.fine_candidates) +
         " candidates, more than coarse_above_candidates = " + std::to_string(threshold) +
         ", so the plan selected over the " + Num(coarse.coarse_spacing_m) + " m grid's " +
         std::to_string(coarse_candidates) + ", then again with the " + Num(coarse.fine_spacing_m) +
         " m positions around its picks, their sets whole (coarse_above_candidates = 0 plans on the full grid)";
}

Result<CandidatesOutput> RunCandidatesStage(const CandidatesInput& in, const PlanOptions& options,
                                            const JobContext& ctx) {
  VC_RETURN_IF_ERROR(CheckUserPositions(in.scene, options.fixed_stations, "fixed_stations"));
  VC_ASSIGN_OR_RETURN(std::vector<std::string> fixed_warnings, CheckFixedStations(in.scene, options.fixed_stations));
  Result<CandidatesOutput> out =
      options.candidates.empty() ? GridCandidates(in.scene, options, ctx) : UserCandidates(in.scene, options);
  const bool may_go_coarse =
      options.candidates.empty() && options.coarse_above_candidates > 0 && !options.local_candidates;
  if (out.ok() && may_go_coarse && out->positions.size() > static_cast<size_t>(options.coarse_above_candidates)) {
    PlanOptions coarse_options = options;
    coarse_options.grid_spacing_m = options.grid_spacing_m * kCoarseGridFactor;
    Result<CandidatesOutput> coarse = GridCandidates(in.scene, coarse_options, ctx);
    // No candidate on the coarse grid (FAILED_PRECONDITION): the full grid stays; anything else
    // (cancelled, out of time or memory) ends the stage as it would have on the full grid.
    if (!coarse.ok() && coarse.status().code() != StatusCode::kFailedPrecondition) return coarse.status();
    if (coarse.ok()) {
      coarse->coarse =
          CandidatesOutput::CoarseGrid{options.grid_spacing_m, coarse_options.grid_spacing_m, out->positions.size()};
      ctx.Report(Stage::kCandidates, 1.0,
                 "coarse then fine: " + std::to_string(out->positions.size()) + " candidates on the " +
                     Num(options.grid_spacing_m) +
                     " m grid > coarse_above_candidates = " + std::to_string(options.coarse_above_candidates) +
                     "; selecting over the " + Num(coarse_options.grid_spacing_m) + " m grid's " +
                     std::to_string(coarse->positions.size()) + " first");
      out = std::move(coarse);
    }
  }
  if (out.ok()) out->warnings.insert(out->warnings.begin(), fixed_warnings.begin(), fixed_warnings.end());
  return out;
}

}  // namespace vc::planner
