// The walking route between planned stations: in which order a crew carries the scanner from one
// station to the next, along which path, and how far it walks (beyond the paper).
//
// Walk graph. The scene's columns are grouped into square walk cells of k x k voxel columns
// (k = round(cell_m / resolution), 1 by default), each represented by its centre column. A cell
// has one walk node per standing surface of that column (several in a multi-storey scene): the top
// voxel of an occupied run with at least headroom_m of free voxels above it (the same column scan
// as the candidates' standing surfaces), and whose walking person fits: the voxel columns whose
// square footprint comes closer than clearance_m to the cell column's centre (as HasClearance
// measures) are free from max_step_m above the surface up to headroom_m above it (a cylinder, so a
// threshold, a skirting board or a stair's next step lower than max_step_m does not block, a wall
// or a desk does); with max_blocked_fraction > 0, up to that fraction of the cylinder's columns
// may hold something (scan noise, chair legs, a door leaf): the planner passes 0.35, as geb079's
// cluttered offices leave almost no fully free cylinder. Each node links to the
// node of each of its 8 neighbour cells whose surface differs from its own by at most max_step_m
// (in whole voxels, at least one when max_step_m > 0: with voxels coarser than the step, as
// fr_campus at 0.4 m, a walkable slope still rises a voxel at a time)
// (the closest in height, the higher on a tie; a voxel more where either node is bridged, below);
// a diagonal link needs both side cells to have such a node, so paths never cut a wall's corner.
// A link costs the 3D distance between the two surface points. Stairs and ramps in the scan thus link storeys; without
// them each storey is its own component. k is limited to 2 * clearance_m / resolution (at least 1): with coarser cells
// a thin wall could pass between two neighbouring cells' cylinders unseen.
//
// Holes. Scans leave the floor unseen in places (shadows under furniture; rooms seen only through
// their doors, like geb079's offices). Let zb be the lowest real surface within max_gap_m of a
// cell (a square window of cells; a sliding minimum over rows, then columns). A cell whose column
// has no standing surface at or below zb + max_step_m gets a bridged node at zb if its column is
// free from zb up to headroom_m (nothing there at all: a wall, a desk or a step is never bridged)
// and the cylinder test above passes. "No surface at or below" keeps bridging off the air beside
// a stair or a platform, whose floor below was seen; the price is that an unseen patch of an upper
// storey over a seen lower one is not bridged, nor unseen floor near a lower surface (a sunken
// area) at its own height, and that unseen ground just outside a scan's edge is walkable. Since zb
// is a minimum, it lies up to a voxel below the floor around it where that is uneven or noisy
// (geb079's corridor floor spans three voxel levels), so a link or a snap to a bridged node may
// span a voxel more than max_step_m.
//
// Gaps. A straight link spans a gap of 1 or 2 voxels (kMaxGapVoxels; cells of one voxel) whose
// cells have no node within a step of either end, whose columns are free from just above the lower
// end up to the higher end's headroom, and were seen below that: a drain, a duct or the joint
// between two slabs, seen to its bottom, is stepped over, costing the straight distance; a wall, a
// sill higher than max_step_m or a wider trench is not.
//
// Stations. A station's floor is floor_z_m (or, when NaN, the top of the highest occupied run
// below the optical centre). It snaps to a walk node whose surface is within max(max_step_m, 2
// voxels) of that floor: within the tripod's footprint (clearance_m, at least a cell) the one of
// the largest region (nodes linked by walks), so a station among clutter joins the floor a crew
// walks in on rather than a box top beside it; else the nearest horizontally within 1 m (then the
// 3D-nearest, then the lowest node number); a station without one is reported in `warnings` and
// forms a part of its own. The start snaps the same way to the highest walk surface within 1 m horizontally that is at
// most max_step_m above start.z (a floor point or a person's eye), else the nearest in height.
//
// Order. Shortest walking distances between stations (Dijkstra, with the connectors from each
// station's floor point to its node) define the parts: groups of stations linked by walkable
// paths. A station's Dijkstra targets only the stations of its weak component (nodes linked in
// either direction), so it never searches a component for a station it cannot reach. Up to
// kExhaustiveOrderMax (150) stations every pair is exact (one Dijkstra per station, stopped once
// the later stations are settled). Above, each station's Dijkstra stops at its 16 nearest
// stations (exact), 16 landmark stations per component (the first station, then farthest-point
// by straight distance) give exact distances to all, and every other pair gets the walk via its
// best landmark (an upper bound; landmarks as in Goldberg & Harrelson 2005): 294 stations on
// fr_campus at 0.2 m, 789k walk nodes: 81 s -> 10 s, the route 2.2 % longer (docs/BENCHMARKS.md).
// The start's part is walked first, then the others from the lowest floor up (ties: lowest
// station number). Within a part the order is an open path (no return): OrderOpenPath (below;
// Croes 1958; Or 1976). Ties are broken by index, so the route is deterministic. Leg lengths and
// polylines are always exact (one Dijkstra per leg, stopped at its end).
//
// Cost: the window minimum is 2 (2 max_gap_m / cell + 1) cells per cell (geb079 at 0.08 m with
// max_gap_m 1.5: about 0.25 s for the whole route of 15 stations). Memory: one 4-byte offset per
// cell and about 92 bytes per walk node (surface, neighbours, Dijkstra state), and 16 bytes per
// pair of stations (the distances and a part's copy); RESOURCE_EXHAUSTED when either exceeds
// memory_budget_bytes (geb079 at 0.08 m: see docs/PLANNING.md). Progress (Stage::kRoute) is
// reported per station and landmark; ctx is honoured in every long loop. Stateless; safe to call
// from several threads.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/voxel_scene.h"

namespace vc::planner {

struct RouteOptions {
  double headroom_m = 1.7;   // free height above a surface to walk on it (m); the planner passes tripod + clearance
  double clearance_m = 0.2;  // free horizontal radius around a walking person (m)
  double max_step_m = 0.25;  // largest rise between neighbouring walk cells: stairs, sills, ramps (m)
  double cell_m = 0;         // walk cell edge (m), rounded to whole voxels; 0 = the scene resolution
  double max_gap_m = 0.5;    // unseen floor within this of a seen one (same height) is walked on (m); 0 = none
  // Fraction of the walking cylinder's columns that may hold clutter or scan noise (0 = all free).
  double max_blocked_fraction = 0;
  double snap_radius_m = 1.0;       // how far (horizontally, m) a station or the start may be from its walk node
  std::optional<WorldPoint> start;  // where the walk starts (world, m), if anywhere
  int threads = 0;                  // workers for the distances between stations (0 = all cores)
  int first_station_number = 0;     // warnings number the stations from this (the planner: 1)
  // When set: whether a point (world, m) is known to be free, i.e. observed empty by the scanner's
  // rays (an OctoMap's free leaves). Unseen floor under space not observed free at 0.5, 1.2 or
  // 1.6 m (perhaps a wall the scan never saw) is then walked at unknown_cost_factor times its
  // length: paths prefer space the scan saw, and cross unknown space only where nothing else links.
  // Unset (point clouds carry no such knowledge): occupancy alone.
  std::function<bool(const WorldPoint&)> known_free;
  double unknown_cost_factor = 3;                    // see known_free; legs_m stay true lengths
  uint64_t memory_budget_bytes = uint64_t{1} << 30;  // bound on the walk graph's memory (bytes)
};

// Seconds each phase of PlanRoute took (wall clock; docs/BENCHMARKS.md, "The walking route at campus scale").
struct RouteSeconds {
  double walk_graph_s = 0;  // walk cells, standing surfaces, bridging, the person's cylinder, links, regions
  double bridging_s = 0;    // of walk_graph_s: the window minimum and the bridged candidates (file comment, "Holes")
  double distances_s = 0;   // snapping, walking distances between stations and from the start
  double parts_s = 0;       // parts, their order, and each split's warning (where and why)
  double order_s = 0;       // the order within each part (OrderOpenPath)
  double legs_s = 0;        // each leg's path (one bounded Dijkstra per leg)
};

struct Route {
  // Every station index exactly once, in visiting order.
  std::vector<int> order;
  // legs_m[k]: walking length (m) of the leg arriving at order[k]; legs_m[0] from the start (0
  // without a start); NaN where no walkable path links it to the previous station (a new part).
  std::vector<double> legs_m;
  // Per leg, the path over standing surfaces (world, m; z = the surface's top): first point the
  // previous station's floor point (or the start's walk point), last this station's floor point.
  // Empty where legs_m is NaN, and for k = 0 without a start. Every segment lies over walk nodes
  // or spans a gap of at most 2 voxels (file comment, "Gaps").
  std::vector<std::vector<WorldPoint>> polylines;
  double length_m = 0;  // sum of the finite legs (m)
  int parts = 0;        // groups of stations no walkable path links (1 = one walk; 0 without stations)
  // One per part after the first (its stations, where its walkable floor comes nearest to the
  // others' within 3 m and what lies between: another storey, a rise, a wall, a sill or clutter),
  // and one per station or start with no walk node near it (that station's part is not repeated).
  std::vector<std::string> warnings;
  uint64_t walk_cells = 0;     // cells of the walk grid
  uint64_t walk_nodes = 0;     // walk nodes (bridged ones included)
  uint64_t bridged_nodes = 0;  // of those, the ones bridging floor gaps
  double cell_m = 0;           // the walk cell edge used (m)
  RouteSeconds seconds;        // where the time went
};

// The route through `stations` (optical centres, world, m). floor_z_m: per station the top of the
// floor under it (m), NaN when unknown; empty = all unknown. INVALID_ARGUMENT for non-finite
// stations or options, a floor_z_m of the wrong size, or a cell coarser than the clearance allows;
// RESOURCE_EXHAUSTED when the walk graph or the distances between stations exceed the budget; CANCELLED /
// DEADLINE_EXCEEDED from ctx. No stations: an empty route.
Result<Route> PlanRoute(const VoxelScene& scene, const std::vector<WorldPoint>& stations,
                        const std::vector<double>& floor_z_m, const RouteOptions& options, const JobContext& ctx = {});

// The top (m, the grid's frame) of the highest standing surface at or below `p` in p's voxel column
// (the floor under an optical centre), or NaN when the column holds none below it.
double FloorBelow(const OccupancyGrid& grid, const WorldPoint& p);

// An open-path ordering problem: n points, symmetric distances, an optional fixed start.
struct OpenPathProblem {
  int n = 0;
  std::vector<double> distance_m;    // n x n, row-major, symmetric, finite (m)
  std::vector<double> from_start_m;  // n distances from the start (m), or empty: the path starts anywhere
};

// Length (m) of visiting `order` (a permutation of 0..n-1), from the start if there is one.
double OpenPathLength(const OpenPathProblem& problem, const std::vector<int>& order);
// Nearest neighbour from `first` (or from the start, when there is one and first < 0); ties to the lower index.
std::vector<int> NearestNeighbourPath(const OpenPathProblem& problem, int first);
// `order` improved by 2-opt and Or-opt moves until none shortens it.
std::vector<int> ImprovePath(const OpenPathProblem& problem, std::vector<int> order);
// Up to this many points OrderOpenPath restarts from every point and improves with every move;
// above it, from kLargeOrderRestarts spread points with moves among kOrderNeighbours nearest points.
inline constexpr int kExhaustiveOrderMax = 150;
inline constexpr int kLargeOrderRestarts = 8;
inline constexpr int kOrderNeighbours = 12;
// `order` improved by 2-opt and Or-opt moves that link a point to one of its `neighbours` nearest
// (neighbour lists; Johnson & McGeoch 1997), or put a segment at either end, until none shortens
// it. CANCELLED / DEADLINE_EXCEEDED from ctx (checked every pass).
Result<std::vector<int>> ImprovePathNear(const OpenPathProblem& problem, std::vector<int> order, int neighbours,
                                         const JobContext& ctx = {});
// The heuristic PlanRoute uses. Up to kExhaustiveOrderMax points: nearest neighbour (from the
// start, else from every point), ImprovePath, the shortest kept. Above: nearest neighbour from the
// start, else from kLargeOrderRestarts points spread by farthest-point (point 0 first), each
// ImprovePathNear with kOrderNeighbours, the shortest kept. CANCELLED / DEADLINE_EXCEEDED from ctx.
Result<std::vector<int>> OrderOpenPath(const OpenPathProblem& problem, const JobContext& ctx = {});

}  // namespace vc::planner
