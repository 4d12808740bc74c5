// The scanner model's hard limits for one station (docs/PLANNING.md "The scanner model").
//
// Per (station, aim point, face): the aim point is the face centre under surface visibility and
// the voxel centre under compatibility; the face is the one judged (under compatibility, the face
// the ray enters through). The limits, all inclusive:
// - range:     d in [min_range_m, max_range_m], d the distance from the station to the aim point;
// - vertical field of view: the aim point's elevation atan2(dz, horizontal distance), in degrees,
//              in [vfov_min_deg, vfov_max_deg];
// - incidence: the angle between the face's outward normal and the direction from the aim point
//              to the station is at most max_incidence_deg;
// - spacing:   d * step_rad / cos(incidence) <= max_spacing_m.
// - horizontal field of view (hfov_deg < 360 and the station has a heading): the aim point's
//              azimuth seen from the station (counter-clockwise from +x) within
//              heading_deg +- hfov_deg / 2, both ends included. It is judged without angles, on the
//              side of the sector's two edge directions the horizontal offset (dx, dy) lies:
//              cross(right edge, d) >= 0 and (hfov <= 180) / or (hfov > 180) cross(d, left edge)
//              >= 0; so an aim point straight above or below the station (dx = dy = 0) is in view
//              whatever the heading.
//
// Every test is computed here, once, in index space (voxel units): the grouped engine, the per-ray
// reference and the evaluation all call Passes, so they agree on every tie. Squared lengths are
// compared, so an aim point exactly on a limit passes up to the rounding of (limit / resolution)^2;
// that rounding is the same in every path.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "vc/scene/occupancy_grid.h"
#include "vc/visibility/visibility.h"

namespace vc {

class ScannerLimits {
 public:
  ScannerLimits() = default;  // no limit at all
  // uo: the station in index space (OccupancyGrid::WorldToIndexSpace). heading_deg: the azimuth of
  // the centre of the horizontal field of view (degrees, counter-clockwise from +x); without one,
  // or with hfov_deg 360, no azimuth limit (callers refuse hfov < 360 without a heading).
  ScannerLimits(const ScannerModel& scanner, double resolution_m, const Eigen::Vector3d& uo,
                std::optional<double> heading_deg = std::nullopt);

  // Whether any limit can fail (with the defaults on a scene within 75 m: only near the station).
  bool active() const { return active_; }
  // Whether Passes depends on the face it is judged on (an incidence or spacing limit is on).
  bool JudgesFace() const { return incidence_ || spacing_; }

  // True if the aim point (index space) passes every limit, judged on the face whose outward
  // normal is +axis (sign > 0) or -axis (sign < 0).
  bool Passes(const Eigen::Vector3d& aim, int axis, int sign) const;

  // Whether the horizontal field of view limits this station.
  bool LimitsAzimuth() const { return azimuth_; }

  // What the limits say for every aim point in the box [lo, hi] (index space): kNone when no point
  // of the box is in range, or none is in the horizontal field of view; kAll when every point is
  // in range and in both fields of view, and no incidence or spacing limit is on (those depend on
  // the face); kSome otherwise (decide point by point). Conservative: a margin far above rounding
  // separates a decided box from the limits, so a box partly in view is never kNone.
  enum class Verdict { kNone, kSome, kAll };
  Verdict BoxVerdict(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const;

  // The face a segment from the station to the centre of voxel v enters v through: the axis whose
  // slab the segment enters last (at an exact tie the lowest axis, which the walk's tie rule - z,
  // then y, then x - steps last), with the sign of that face's outward normal. The station must
  // lie outside v.
  void EntryFace(const VoxelIndex& v, int* axis, int* sign) const;

 private:
  Eigen::Vector3d uo_ = Eigen::Vector3d::Zero();
  bool active_ = false;
  double min2_ = 0, max2_ = 0;              // squared range, voxel units
  bool vfov_lo_ = false, vfov_hi_ = false;  // a lower / upper elevation limit is on
  double tan_lo_ = 0, tan_hi_ = 0;          // their tangents
  bool incidence_ = false;
  double cos2_max_ = 0;  // cos^2(max_incidence)
  bool spacing_ = false;
  double spacing_k_ = 0;  // resolution * step_rad / max_spacing: d^2 * k <= s passes
  bool azimuth_ = false;  // a horizontal field of view below 360 deg with a heading
  bool wide_ = false;     // that field of view is wider than 180 deg: either edge's side passes
  Eigen::Vector2d right_edge_ = Eigen::Vector2d::Zero();  // direction of heading - hfov / 2
  Eigen::Vector2d left_edge_ = Eigen::Vector2d::Zero();   // direction of heading + hfov / 2

  // The horizontal offset (x, y) from the station to p passes the azimuth limit.
  bool InAzimuth(double dx, double dy) const;
  // The azimuth limit's verdict on the box's horizontal rectangle (kNone, kSome or kAll).
  Verdict AzimuthVerdict(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const;
};

}  // namespace vc
