#include "vc/visibility/scanner_limits.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace vc {

ScannerLimits::ScannerLimits(const ScannerModel& s, double r, const Eigen::Vector3d& uo,
                             std::optional<double> heading_deg)
    : uo_(uo) {
  min2_ = (s.min_range_m / r) * (s.min_range_m / r);
  max2_ = (s.max_range_m / r) * (s.max_range_m / r);
  // elevation >= vfov_min  <=>  dz >= tan(vfov_min) h, and likewise for the maximum (h the
  // horizontal distance): no atan2 per face.
  vfov_lo_ = s.vfov_min_deg > -90.0;
  vfov_hi_ = s.vfov_max_deg < 90.0;
  tan_lo_ = vfov_lo_ ? std::tan(s.vfov_min_deg * std::numbers::pi / 180.0) : 0.0;
  tan_hi_ = vfov_hi_ ? std::tan(s.vfov_max_deg * std::numbers::pi / 180.0) : 0.0;
  incidence_ = s.HasIncidenceLimit();
  const double c = std::cos(s.max_incidence_deg * std::numbers::pi / 180.0);
  cos2_max_ = c * c;
  spacing_ = s.HasSpacingLimit();
  spacing_k_ = spacing_ ? r * (s.angular_step_deg * std::numbers::pi / 180.0) / s.max_spacing_m : 0.0;
  azimuth_ = heading_deg.has_value() && s.hfov_deg < 360.0;
  if (azimuth_) {
    const double heading_rad = *heading_deg * std::numbers::pi / 180.0;
    const double half_rad = s.hfov_deg / 2 * std::numbers::pi / 180.0;
    right_edge_ = {std::cos(heading_rad - half_rad), std::sin(heading_rad - half_rad)};
    left_edge_ = {std::cos(heading_rad + half_rad), std::sin(heading_rad + half_rad)};
    wide_ = s.hfov_deg > 180.0;
  }
  active_ = true;  // the range always is; BoxVerdict says where it matters
}

bool ScannerLimits::InAzimuth(double dx, double dy) const {
  // Left of (counter-clockwise from) the right edge, and right of the left edge.
  const bool after_right = right_edge_.x() * dy - right_edge_.y() * dx >= 0;
  const bool before_left = dx * left_edge_.y() - dy * left_edge_.x() >= 0;
  return wide_ ? (after_right || before_left) : (after_right && before_left);
}

ScannerLimits::Verdict ScannerLimits::AzimuthVerdict(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const {
  // Both sides are linear in (dx, dy), so over the rectangle their extremes are at its corners.
  double right_min = std::numeric_limits<double>::infinity(), right_max = -right_min;
  double left_min = right_min, left_max = right_max, far = 0;
  for (int k = 0; k < 4; ++k) {
    const double dx = ((k & 1) ? hi.x() : lo.x()) - uo_.x(), dy = ((k & 2) ? hi.y() : lo.y()) - uo_.y();
    const double after_right = right_edge_.x() * dy - right_edge_.y() * dx;
    const double before_left = dx * left_edge_.y() - dy * left_edge_.x();
    right_min = std::min(right_min, after_right), right_max = std::max(right_max, after_right);
    left_min = std::min(left_min, before_left), left_max = std::max(left_max, before_left);
    far = std::max(far, std::abs(dx) + std::abs(dy));
  }
  const double margin = 1e-9 * (far + 1);
  const bool all_right = right_min >= margin, all_left = left_min >= margin;
  const bool none_right = right_max <= -margin, none_left = left_max <= -margin;
  if (wide_) {
    if (none_right && none_left) return Verdict::kNone;
    return all_right || all_left ? Verdict::kAll : Verdict::kSome;
  }
  if (none_right || none_left) return Verdict::kNone;
  return all_right && all_left ? Verdict::kAll : Verdict::kSome;
}

bool ScannerLimits::Passes(const Eigen::Vector3d& aim, int axis, int sign) const {
  if (!active_) return true;
  const Eigen::Vector3d d = uo_ - aim;  // from the aim point to the station
  const double d2 = d.squaredNorm();
  if (!(d2 >= min2_ && d2 <= max2_)) return false;
  if (vfov_lo_ || vfov_hi_) {
    // The aim point's elevation seen from the station, compared through its tangent dz / h with
    // dz = aim.z - station.z = -d.z and h the horizontal distance, squared to spare the root.
    const double dz = -d.z(), dz2 = dz * dz, h2 = d.x() * d.x() + d.y() * d.y();
    if (vfov_lo_) {  // dz >= tan_lo h
      const bool above =
          tan_lo_ <= 0 ? (dz >= 0 || dz2 <= tan_lo_ * tan_lo_ * h2) : (dz >= 0 && dz2 >= tan_lo_ * tan_lo_ * h2);
      if (!above) return false;
    }
    if (vfov_hi_) {  // dz <= tan_hi h
      const bool below =
          tan_hi_ >= 0 ? (dz <= 0 || dz2 <= tan_hi_ * tan_hi_ * h2) : (dz <= 0 && dz2 >= tan_hi_ * tan_hi_ * h2);
      if (!below) return false;
    }
  }
  if (azimuth_ && !InAzimuth(-d.x(), -d.y())) return false;
  // s = |d| cos(incidence): the component of d along the face's outward normal.
  const double s = sign > 0 ? d[axis] : -d[axis];
  if (incidence_ && !(s >= 0 && s * s >= cos2_max_ * d2)) return false;
  // spacing = |d| r step / cos(incidence) = d2 r step / s <= max_spacing  <=>  d2 k <= s.
  if (spacing_ && !(s > 0 && d2 * spacing_k_ <= s)) return false;
  return true;
}

ScannerLimits::Verdict ScannerLimits::BoxVerdict(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const {
  if (!active_) return Verdict::kAll;
  double near[3], far[3];
  for (int a = 0; a < 3; ++a) {
    near[a] = std::max({lo[a] - uo_[a], uo_[a] - hi[a], 0.0});
    far[a] = std::max(std::abs(lo[a] - uo_[a]), std::abs(hi[a] - uo_[a]));
  }
  const double near2 = near[0] * near[0] + near[1] * near[1] + near[2] * near[2];
  const double far2 = far[0] * far[0] + far[1] * far[1] + far[2] * far[2];
  // A margin for the rounding of these sums against Passes' own: a box within it of a limit is
  // decided point by point.
  const double slack = 1e-9 * (far2 + 1);
  if (near2 > max2_ + slack || far2 < min2_ - slack) return Verdict::kNone;
  const Verdict azimuth = azimuth_ ? AzimuthVerdict(lo, hi) : Verdict::kAll;
  if (azimuth == Verdict::kNone) return Verdict::kNone;
  if (!(near2 >= min2_ + slack && far2 <= max2_ - slack) || incidence_ || spacing_) return Verdict::kSome;
  if (vfov_lo_ || vfov_hi_) {
    // Every point must have dz >= tan_lo h (and dz <= tan_hi h), dz = z - station.z over
    // [lo.z, hi.z] - station.z and h the horizontal distance over [h_near, h_far]; each condition
    // is linear in dz and in h, so its worst case is at an end of each range.
    const double h_near = std::sqrt(near[0] * near[0] + near[1] * near[1]);
    const double h_far = std::sqrt(far[0] * far[0] + far[1] * far[1]);
    const double margin = 1e-9 * (std::sqrt(far2) + 1);
    if (vfov_lo_ && !(lo[2] - uo_[2] - tan_lo_ * (tan_lo_ <= 0 ? h_near : h_far) >= margin)) return Verdict::kSome;
    if (vfov_hi_ && !(tan_hi_ * (tan_hi_ >= 0 ? h_near : h_far) - (hi[2] - uo_[2]) >= margin)) return Verdict::kSome;
  }
  return azimuth;
}

void ScannerLimits::EntryFace(const VoxelIndex& v, int* axis, int* sign) const {
  const double lo[3] = {double(v.x), double(v.y), double(v.z)};
  double best = -1;
  *axis = 0;
  *sign = 1;
  for (int a = 0; a < 3; ++a) {
    const double centre = lo[a] + 0.5;
    double t;
    int s;
    if (uo_[a] < lo[a]) {
      t = (lo[a] - uo_[a]) / (centre - uo_[a]);
      s = -1;
    } else if (uo_[a] > lo[a] + 1) {
      t = (lo[a] + 1 - uo_[a]) / (centre - uo_[a]);
      s = 1;
    } else {
      continue;  // the station is within v's slab along a: the segment does not enter it there
    }
    if (t > best) best = t, *axis = a, *sign = s;
  }
}

}  // namespace vc
