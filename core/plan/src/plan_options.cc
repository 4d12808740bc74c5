#include "vc/plan/plan_options.h"

#include <cmath>
#include <string>

#include "format.h"

namespace vc {

using planner::Coordinate;
using planner::Num;

Status PlanOptions::Validate(const FieldNamer& namer) const {
  const auto name = [&namer](std::string_view path) { return NameOf(namer, path); };
  const auto nth = [&name](std::string_view list, size_t i) {
    return name(std::string(list) + "[" + std::to_string(i) + "]");
  };
#define VC_CHECK_ROW(type, row, ...) \
  VC_RETURN_IF_ERROR(CheckNamedParameter(VC_PARAMETER_INFO(type, row, __VA_ARGS__), row, namer));
  VC_PLAN_PARAMETERS(VC_CHECK_ROW)
#undef VC_CHECK_ROW
  if (min_gain_voxels_per_minute > 0 && min_gain_m2_per_minute > 0) {
    return InvalidArgumentError(name("min_gain_voxels_per_minute") + " (" + Num(min_gain_voxels_per_minute) + ") and " +
                                name("min_gain_m2_per_minute") + " (" + Num(min_gain_m2_per_minute) +
                                ") are both set: the gain rule counts voxels or square metres, give one (the other 0)");
  }
  VC_RETURN_IF_ERROR(scanner.Validate(namer));
  if (scanner.HasHorizontalFieldOfView()) {
    return InvalidArgumentError(name("scanner.hfov_deg") + " is " + Num(scanner.hfov_deg) +
                                " deg, but the planner's stations have no heading (it does not choose one), so it "
                                "plans only with the full circle; leave hfov_deg at 360");
  }
  for (size_t i = 0; i < tripod_heights_m.size(); ++i) {
    const double h = tripod_heights_m[i];
    const std::string height = nth("tripod_heights_m", i);
    if (!std::isfinite(h)) return InvalidArgumentError(height + " is not finite");
    if (h <= clearance_m) {
      return InvalidArgumentError(height + " (" + Num(h) + " m) must be larger than " + name("clearance_m") + " (" +
                                  Num(clearance_m) + " m): the scanner would touch the floor");
    }
    for (size_t j = 0; j < i; ++j) {
      if (tripod_heights_m[j] == h) {
        return InvalidArgumentError(height + " (" + Num(h) + " m) repeats " + nth("tripod_heights_m", j));
      }
    }
  }
  if (tripod_heights_m.empty() && clearance_m >= tripod_height_m) {
    return InvalidArgumentError(name("clearance_m") + " (" + Num(clearance_m) + " m) must be smaller than " +
                                name("tripod_height_m") + " (" + Num(tripod_height_m) +
                                " m): the scanner would touch the floor");
  }
  if (refine && refine_step_m > refine_radius_m) {
    return InvalidArgumentError(name("refine_step_m") + " (" + Num(refine_step_m) + " m) must not exceed " +
                                name("refine_radius_m") + " (" + Num(refine_radius_m) + " m)");
  }
  if (local_candidates && local_candidates_step_m > local_candidates_radius_m) {
    return InvalidArgumentError(name("local_candidates_step_m") + " (" + Num(local_candidates_step_m) +
                                " m) must not exceed " + name("local_candidates_radius_m") + " (" +
                                Num(local_candidates_radius_m) + " m)");
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (!candidates[i].allFinite()) return InvalidArgumentError(nth("candidates", i) + " is not finite");
  }
  for (size_t i = 0; i < keep_out.size(); ++i) {
    VC_RETURN_IF_ERROR(ValidateKeepOutZone(keep_out[i], nth("keep_out", i)));
  }
  for (size_t i = 0; i < fixed_stations.size(); ++i) {
    const WorldPoint& p = fixed_stations[i];
    const std::string station = nth("fixed_stations", i);
    if (!p.allFinite()) return InvalidArgumentError(station + " is not finite");
    if (const int z = KeepOutZoneContaining(keep_out, p); z >= 0) {
      return InvalidArgumentError(nth("keep_out", size_t(z)) + ": " + station + " (" + Coordinate(p.x()) + ", " +
                                  Coordinate(p.y()) + ", " + Coordinate(p.z()) + ") lies inside this zone");
    }
  }
  if (route_start &&
      (!std::isfinite(route_start->x()) || !std::isfinite(route_start->y()) || std::isinf(route_start->z()))) {
    return InvalidArgumentError(name("route_start") +
                                " needs finite x and y (and a finite z, or NaN for the lowest floor)");
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

std::optional<GainRule> GainRuleOf(const PlanOptions& options, double resolution_m) {
  if (options.min_gain_voxels_per_minute > 0) {
    return GainRule{"min_gain_voxels_per_minute", options.min_gain_voxels_per_minute,
                    options.min_gain_voxels_per_minute};
  }
  if (options.min_gain_m2_per_minute > 0 && resolution_m > 0) {
    return GainRule{"min_gain_m2_per_minute", options.min_gain_m2_per_minute,
                    options.min_gain_m2_per_minute / (resolution_m * resolution_m)};
  }
  return std::nullopt;
}

std::vector<double> PlanOptions::TripodHeights() const {
  if (!tripod_heights_m.empty()) return tripod_heights_m;
  return {tripod_height_m};
}

}  // namespace vc
