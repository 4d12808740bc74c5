#include "vc/plan/plan_options.h"

#include <cmath>
#include <string>

#include "format.h"

namespace vc {

using planner::Coordinate;
using planner::Num;

Status PlanOptions::Validate() const {
#define VC_CHECK_ROW(type, name, ...) \
  VC_RETURN_IF_ERROR(CheckParameter(VC_PARAMETER_INFO(type, name, __VA_ARGS__), name));
  VC_PLAN_PARAMETERS(VC_CHECK_ROW)
#undef VC_CHECK_ROW
  VC_RETURN_IF_ERROR(scanner.Validate());
  if (scanner.HasHorizontalFieldOfView()) {
    return InvalidArgumentError("scanner.hfov_deg is " + Num(scanner.hfov_deg) +
                                " deg, but the planner's stations have no heading (it does not choose one), so it "
                                "plans only with the full circle; leave hfov_deg at 360");
  }
  for (size_t i = 0; i < tripod_heights_m.size(); ++i) {
    const double h = tripod_heights_m[i];
    const std::string name = "tripod_heights_m[" + std::to_string(i) + "]";
    if (!std::isfinite(h)) return InvalidArgumentError(name + " is not finite");
    if (h <= clearance_m) {
      return InvalidArgumentError(name + " (" + Num(h) + " m) must be larger than clearance_m (" + Num(clearance_m) +
                                  " m): the scanner would touch the floor");
    }
    for (size_t j = 0; j < i; ++j) {
      if (tripod_heights_m[j] == h) {
        return InvalidArgumentError(name + " (" + Num(h) + " m) repeats tripod_heights_m[" + std::to_string(j) + "]");
      }
    }
  }
  if (tripod_heights_m.empty() && clearance_m >= tripod_height_m) {
    return InvalidArgumentError("clearance_m (" + Num(clearance_m) + " m) must be smaller than tripod_height_m (" +
                                Num(tripod_height_m) + " m): the scanner would touch the floor");
  }
  if (refine && refine_step_m > refine_radius_m) {
    return InvalidArgumentError("refine_step_m (" + Num(refine_step_m) + " m) must not exceed refine_radius_m (" +
                                Num(refine_radius_m) + " m)");
  }
  if (local_candidates && local_candidates_step_m > local_candidates_radius_m) {
    return InvalidArgumentError("local_candidates_step_m (" + Num(local_candidates_step_m) +
                                " m) must not exceed local_candidates_radius_m (" + Num(local_candidates_radius_m) +
                                " m)");
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (!candidates[i].allFinite()) return InvalidArgumentError("candidates[" + std::to_string(i) + "] is not finite");
  }
  for (size_t i = 0; i < keep_out.size(); ++i) {
    VC_RETURN_IF_ERROR(ValidateKeepOutZone(keep_out[i], "keep_out[" + std::to_string(i) + "]"));
  }
  for (size_t i = 0; i < fixed_stations.size(); ++i) {
    const WorldPoint& p = fixed_stations[i];
    const std::string name = "fixed_stations[" + std::to_string(i) + "]";
    if (!p.allFinite()) return InvalidArgumentError(name + " is not finite");
    if (const int z = KeepOutZoneContaining(keep_out, p); z >= 0) {
      return InvalidArgumentError(name + " (" + Coordinate(p.x()) + ", " + Coordinate(p.y()) + ", " +
                                  Coordinate(p.z()) + ") lies inside keep_out[" + std::to_string(z) + "]");
    }
  }
  if (route_start &&
      (!std::isfinite(route_start->x()) || !std::isfinite(route_start->y()) || std::isinf(route_start->z()))) {
    return InvalidArgumentError("route_start needs finite x and y (and a finite z, or NaN for the lowest floor)");
  }
  return Status::Ok();
}

PlanOptions InLocalFrame(PlanOptions options, const WorldPoint& frame_origin_m) {
  if (frame_origin_m.isZero()) return options;
  for (WorldPoint& p : options.candidates) p -= frame_origin_m;
  for (WorldPoint& p : options.fixed_stations) p -= frame_origin_m;
  if (options.route_start) *options.route_start -= frame_origin_m;
  for (KeepOutZone& zone : options.keep_out) {
    zone.min -= frame_origin_m;
    zone.max -= frame_origin_m;
    for (size_t i = 0; i < zone.polygon_xy_m.size(); ++i) zone.polygon_xy_m[i] -= frame_origin_m[i % 2];
  }
  return options;
}

std::vector<double> PlanOptions::TripodHeights() const {
  if (!tripod_heights_m.empty()) return tripod_heights_m;
  return {tripod_height_m};
}

}  // namespace vc
