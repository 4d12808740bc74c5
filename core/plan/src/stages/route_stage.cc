#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "vc/plan/route.h"
#include "vc/plan/stages.h"
#include "vc/scene/octomap_adapter.h"

namespace vc::planner {

namespace {

// The walking route's settings for real scans (docs/PLANNING.md, "The walking route").
constexpr double kRouteMaxGapM = 1.5;
constexpr double kRouteMaxBlockedFraction = 0.35;

}  // namespace

Result<RouteOutput> RunRouteStage(const RouteInput& in, const PlanOptions& options, const JobContext& ctx) {
  const std::vector<double> heights = options.TripodHeights();
  RouteOptions o;
  o.headroom_m = *std::min_element(heights.begin(), heights.end()) + options.clearance_m;
  o.clearance_m = options.clearance_m;
  o.max_step_m = options.walk_max_step_m;
  o.max_gap_m = kRouteMaxGapM;
  o.max_blocked_fraction = kRouteMaxBlockedFraction;
  o.memory_budget_bytes = options.memory_budget_bytes / 4;
  o.threads = options.threads;
  o.first_station_number = 1;  // as on heatmap.png and in vc-client's table
  if (in.input.octree) {
    const octomap::OcTree* tree = in.input.octree.get();
    o.known_free = [tree](const WorldPoint& p) { return IsKnownFree(*tree, p); };
  }
  if (options.route_start) {
    WorldPoint start = *options.route_start;
    if (std::isnan(start.z())) {
      start.z() = in.floor_levels_m.empty() ? in.scene.BoundsMin().z() : in.floor_levels_m.front();
    }
    o.start = start;
  }
  RouteOutput out;
  Result<Route> route = PlanRoute(in.scene, in.stations, in.floor_z_m, o, ctx);
  if (route.ok()) {
    out.route = std::move(*route);
  } else if (route.status().code() == StatusCode::kResourceExhausted) {
    out.unrouted_reason = route.status().message();
  } else {
    return route.status();
  }
  return out;
}

}  // namespace vc::planner
