// Candidate stations on the operating plane (ALGORITHM.md s.7.1; paper s.3.2).
//
// Standing surfaces: in every voxel column, the top voxel of each occupied run with at least
// tripod height + clearance of free space above it. Floor levels: the dominant heights of those
// surfaces over the whole scene (a histogram of columns, smoothed over +-0.15 m (at least 2 voxels); a level needs at
// least a quarter of the strongest level's columns and lies at least tripod height + clearance
// from a stronger one, so desks and shelves under a floor's ceiling do not count). A level whose
// surfaces are mostly roofs — nothing occupied above them, another occupied run below them in the
// same column (the outside of a ceiling) — is dropped; an open room's floor (nothing below) stays. Candidates: for each
// level and each cell of a grid over the occupied footprint, the standing surface within +-0.15 m of that level closest
// to it under the cell centre (in the 3 x 3 voxel columns around it) is the cell's floor (uneven floors and ramps); the
// candidate stands at its top + tripod height, and is kept if the voxels within the clearance radius are all free. So
// every storey of a multi-level scene gets its own candidates, each with floor below it. With several tripod heights
// the levels come from the lowest, and each cell gets one candidate per height (in the order of the heights
// given) that fits under what is above its floor. With doorway_candidates, positions in narrow passages
// (doorways, pinch points; issue 21) follow the grid's and pass the same floor and clearance checks.
//
// Terrain (GroundModel::kTerrain; issue 35): where the ground is not a few flat floors (outdoors,
// ramps, sloping sites) the floor levels above miss most of it. There the ground is a height field:
// a standing surface is walkable where its local slope (its height difference to the surfaces
// kSlopeBaseM away along x and y) is at most kTerrainMaxSlope, two walkable surfaces of 4-adjacent
// columns are linked when their heights differ by at most walk_max_step_m, and the ground is the
// largest linked component, so roofs, car tops and tables (higher than a step above what is around
// them) are not ground. Each cell's candidate stands tripod height above the ground under its
// centre. GroundModel::kAuto finds that ground either way and picks floors when at least
// kFloorShare of its surfaces lie within a floor level's band (or there is none), else terrain.
// Internal to vc_core.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/voxel_scene.h"

namespace vc {

// How the candidates' ground is modelled (PlanOptions::ground; docs/PLANNING.md, "Terrain").
enum class GroundModel : uint8_t {
  kAuto,     // the default: floors when the standing surfaces cluster at a few levels, else terrain
  kFloors,   // discrete floor levels (buildings)
  kTerrain,  // a height field of walkable ground (outdoor sites, ramps, slopes)
};
// "auto", "floors", "terrain".
std::string_view GroundModelName(GroundModel model);

}  // namespace vc

namespace vc::planner {

// Auto picks floors when at least this share of the walkable ground's surfaces (its largest linked
// component) lies within +-0.15 m (at least 2 voxels) of a floor level.
inline constexpr double kFloorShare = 0.9;
// Terrain: the steepest ground a tripod stands on and a route walks (rise over run: 0.36, 20 deg).
inline constexpr double kTerrainMaxSlope = 0.36;
// Terrain: the horizontal distance over which a surface's slope is measured, each side (m).
inline constexpr double kSlopeBaseM = 0.5;

// The ground model a candidate grid used and why (PlanResult::ground; plan.json `ground`).
struct GroundChoice {
  GroundModel model = GroundModel::kAuto;  // kFloors or kTerrain; kAuto only for user candidates
  double floor_share = 0;                  // share of the ground's surfaces on a floor level, 0..1
  std::string reason;                      // one sentence: forced, or auto's test and its numbers
};

struct CandidateOptions {
  double grid_spacing_m = 1.0;   // grid cell size (m)
  double tripod_height_m = 1.5;  // optical centre above the floor's top (m)
  double clearance_m = 0.2;      // free radius around the optical centre (m)
  // Several optical-centre heights (m): when non-empty, replaces tripod_height_m. Floor levels and
  // standing surfaces use the lowest; a cell gets a candidate at each height whose column above
  // its floor is free for height + clearance_m and that has the clearance.
  std::vector<double> tripod_heights_m;
  // Also candidates in narrow passages (doorways, corridor pinch points): where a free run of the
  // level's obstacle slice at tripod height, along x or y, is narrower than 2 grid_spacing_m
  // (and at least 2 clearance_m), on the passage's centre line every grid_spacing_m / 4, and
  // beyond its ends at grid_spacing_m / 8, then every grid_spacing_m / 4, up to grid_spacing_m / 2.
  // Off here (the bare grid); plans take PlanOptions::doorway_candidates, which is on by default.
  bool doorway_candidates = false;
  // The ground model: auto (by the floor-share test), floors or terrain.
  GroundModel ground = GroundModel::kAuto;
  // Terrain: the largest rise between adjacent ground columns (m), as the walking route's.
  double walk_max_step_m = 0.25;
};

struct FloorLevel {
  double z_m = 0;        // top of the level's dominant floor voxels (m)
  uint64_t columns = 0;  // voxel columns with a standing surface within the level's band
};

struct CandidateGrid {
  std::vector<WorldPoint> positions;  // kept candidates, level by level, then y, then x
  std::vector<double> floor_z_m;      // per candidate: top of the floor under it (m)
  std::vector<int> level;             // per candidate: index into levels; -1 on terrain
  std::vector<double> height_m;       // per candidate: its tripod height above floor_z_m (m)
  std::vector<FloorLevel> levels;     // ascending z; empty on terrain
  GroundChoice ground;                // the model used and why
  uint64_t ground_columns = 0;        // terrain: voxel columns of the ground component
  // Grid cells x levels x heights examined; of those, the ones without a standing surface of the
  // level below, and the ones with floor but occupied voxels within the clearance (or, at a
  // height above the lowest, within height + clearance above the floor).
  uint64_t cells = 0;
  uint64_t rejected_no_floor = 0;
  uint64_t rejected_clearance = 0;
  // Passage candidates (doorway_candidates): kept ones, appended after the grid's, level by level.
  uint64_t passage_candidates = 0;
};

// Generates the candidate grid for `scene`. CANCELLED / DEADLINE_EXCEEDED from ctx.
Result<CandidateGrid> GenerateCandidates(const VoxelScene& scene, const CandidateOptions& options,
                                         const JobContext& ctx = {});

// True if p's voxel is free and no occupied voxel's cube comes closer than clearance_m to p.
bool HasClearance(const OccupancyGrid& grid, const WorldPoint& p, double clearance_m);

// Top (m) of the standing surface closest to `near_z_m`, within +-0.15 m (at least 2 voxels),
// under (x, y) (3 x 3 voxel columns), or nullopt. Used to move a station during refinement.
std::optional<double> FloorTopNear(const OccupancyGrid& grid, double x_m, double y_m, double near_z_m,
                                   const CandidateOptions& options);

// Terrain: top (m) of the ground under (x_m, y_m) reached on foot from the floor whose top is
// `from_floor_z_m` under `from` (x, y): walking the straight line between them column by column,
// in each the standing surface (not a roof, with the headroom of options' lowest height) closest
// to the last one within walk_max_step_m (at least a voxel); up to 2 columns in a row with nothing
// occupied near are a gap in the map and crossed. nullopt where a wall, an object or a drop is in
// the way, where (x_m, y_m) has no such surface, or where the whole rise is more than
// kTerrainMaxSlope times the horizontal distance plus a voxel.
std::optional<double> GroundTopReached(const OccupancyGrid& grid, const WorldPoint& from, double from_floor_z_m,
                                       double x_m, double y_m, const CandidateOptions& options);

// The floor (top, m) of a station moved from `from`, whose floor's top is from_floor_z_m, to
// (x_m, y_m) (refinement, local candidates): GroundTopReached when options.ground is kTerrain (so
// on a slope the station keeps its height over the local ground), else FloorTopNear (the floor
// level's band).
std::optional<double> MovedStationFloor(const OccupancyGrid& grid, const WorldPoint& from, double from_floor_z_m,
                                        double x_m, double y_m, const CandidateOptions& options);

}  // namespace vc::planner
