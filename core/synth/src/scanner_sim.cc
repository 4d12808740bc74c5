// The scanner simulator (see scanner_sim.h for the model).
//
// Intersection. The scene is first prepared once per scan (each polygon's plane and its vertices
// projected on the plane's two dominant axes; each cylinder's unit axis and length), then every
// beam tests every primitive: polygons by their plane and a crossing-number point-in-polygon test,
// boxes by the slab method in the box's own frame, cylinders by the lateral quadric (the numerically
// stable root pair) and the two cap discs. The nearest hit with min < t <= max wins.
//
// Randomness. Each beam draws from its own SplitMix64 stream (Steele et al. 2014) seeded by the
// scanner's seed and the beam's index, and the Gaussian by Box-Muller, so the points do not depend on
// the standard library's distributions or on the order the beams are cast in.
#include "vc/synth/scanner_sim.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

namespace vc {
namespace {

constexpr double kPlanarityToleranceM = 1e-6;
constexpr double kOrthonormalTolerance = 1e-6;
constexpr double kMinBeamDistanceM = 1e-9;  // a station exactly on a surface does not hit it
constexpr double kAngleSlack = 1e-9;        // fov / step ratios this close to an integer count as one

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

std::string Vec(const Eigen::Vector3d& v) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "(%g, %g, %g)", v.x(), v.y(), v.z());
  return buffer;
}

double Radians(double deg) { return deg * std::numbers::pi / 180.0; }

struct PreparedPolygon {
  Eigen::Vector3d normal;  // unit
  double offset = 0.0;     // normal . x = offset on the plane
  int axis_u = 0, axis_v = 1;
  std::vector<Eigen::Vector2d> vertices_uv;
};

struct PreparedCylinder {
  Eigen::Vector3d base;
  Eigen::Vector3d axis;  // unit
  double length = 0.0;
  double radius = 0.0;
};

// Newell's normal of a polygon (not normalised; zero for collinear vertices).
Eigen::Vector3d NewellNormal(const std::vector<WorldPoint>& v) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < v.size(); ++i) n += v[i].cross(v[(i + 1) % v.size()]);
  return n;
}

PreparedPolygon Prepare(const ScenePolygon& polygon) {
  PreparedPolygon p;
  p.normal = NewellNormal(polygon.vertices_m).normalized();
  p.offset = p.normal.dot(polygon.vertices_m[0]);
  int drop = 0;
  p.normal.cwiseAbs().maxCoeff(&drop);
  p.axis_u = (drop + 1) % 3;
  p.axis_v = (drop + 2) % 3;
  for (const WorldPoint& v : polygon.vertices_m) p.vertices_uv.emplace_back(v[p.axis_u], v[p.axis_v]);
  return p;
}

PreparedCylinder Prepare(const SceneCylinder& cylinder) {
  const Eigen::Vector3d span = cylinder.top_m - cylinder.base_m;
  return {cylinder.base_m, span.normalized(), span.norm(), cylinder.radius_m};
}

// Crossing-number test (even-odd rule) of q against a polygon in its plane's (u, v) coordinates.
bool InsidePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
  bool inside = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > q.y()) != (b.y() > q.y()) && q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

// The smallest of t1, t2 in (t_min, t_max], if any.
std::optional<double> FirstWithin(double t1, double t2, double t_min, double t_max) {
  if (t1 > t2) std::swap(t1, t2);
  if (t1 > t_min && t1 <= t_max) return t1;
  if (t2 > t_min && t2 <= t_max) return t2;
  return std::nullopt;
}

std::optional<double> Intersect(const PreparedPolygon& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                double t_min, double t_max) {
  const double denominator = p.normal.dot(d);
  if (denominator == 0.0) return std::nullopt;
  const double t = (p.offset - p.normal.dot(o)) / denominator;
  if (!(t > t_min && t <= t_max)) return std::nullopt;
  const Eigen::Vector3d hit = o + t * d;
  if (!InsidePolygon(p.vertices_uv, {hit[p.axis_u], hit[p.axis_v]})) return std::nullopt;
  return t;
}

std::optional<double> Intersect(const SceneBox& box, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                                double t_max) {
  const Eigen::Vector3d local_o = box.rotation.transpose() * (o - box.centre_m);
  const Eigen::Vector3d local_d = box.rotation.transpose() * d;
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double h = box.half_extent_m[a];
    if (local_d[a] == 0.0) {
      if (std::abs(local_o[a]) > h) return std::nullopt;
      continue;
    }
    const double t1 = (-h - local_o[a]) / local_d[a];
    const double t2 = (h - local_o[a]) / local_d[a];
    t_near = std::max(t_near, std::min(t1, t2));
    t_far = std::min(t_far, std::max(t1, t2));
  }
  if (t_near > t_far) return std::nullopt;
  return FirstWithin(t_near, t_far, t_min, t_max);
}

std::optional<double> Intersect(const PreparedCylinder& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                double t_min, double t_max) {
  const Eigen::Vector3d oc = o - c.base;
  const double oc_axial = oc.dot(c.axis);
  const double d_axial = d.dot(c.axis);
  const Eigen::Vector3d oc_lateral = oc - oc_axial * c.axis;
  const Eigen::Vector3d d_lateral = d - d_axial * c.axis;
  std::optional<double> best;
  auto consider = [&](double t) {
    if (t > t_min && t <= t_max && (!best || t < *best)) best = t;
  };
  const double qa = d_lateral.squaredNorm();
  const double qb = 2.0 * oc_lateral.dot(d_lateral);
  const double qc = oc_lateral.squaredNorm() - c.radius * c.radius;
  const double discriminant = qb * qb - 4.0 * qa * qc;
  if (qa > 0.0 && discriminant >= 0.0) {
    const double q = -0.5 * (qb + std::copysign(std::sqrt(discriminant), qb));
    for (double t : {q / qa, q != 0.0 ? qc / q : q / qa}) {
      const double h = oc_axial + t * d_axial;
      if (h >= 0.0 && h <= c.length) consider(t);
    }
  }
  if (d_axial != 0.0) {
    for (double cap : {0.0, c.length}) {
      const double t = (cap - oc_axial) / d_axial;
      if ((oc_lateral + t * d_lateral).squaredNorm() <= c.radius * c.radius) consider(t);
    }
  }
  return best;
}

// A scene with its per-primitive precomputation, for casting many beams.
class PreparedScene {
 public:
  explicit PreparedScene(const AnalyticScene& scene) {
    for (const ScenePrimitive& primitive : scene.primitives) {
      if (const auto* polygon = std::get_if<ScenePolygon>(&primitive)) {
        primitives_.emplace_back(Prepare(*polygon));
      } else if (const auto* box = std::get_if<SceneBox>(&primitive)) {
        primitives_.emplace_back(*box);
      } else {
        primitives_.emplace_back(Prepare(std::get<SceneCylinder>(primitive)));
      }
    }
  }

  std::optional<SceneHit> Nearest(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                                  double t_max) const {
    std::optional<SceneHit> best;
    for (size_t i = 0; i < primitives_.size(); ++i) {
      const double limit = best ? best->distance_m : t_max;
      const std::optional<double> t =
          std::visit([&](const auto& p) { return Intersect(p, o, d, t_min, limit); }, primitives_[i]);
      if (t && (!best || *t < best->distance_m)) best = SceneHit{*t, static_cast<int>(i)};
    }
    return best;
  }

 private:
  std::vector<std::variant<PreparedPolygon, SceneBox, PreparedCylinder>> primitives_;
};

Status ValidatePolygon(const ScenePolygon& polygon, const std::string& where) {
  if (polygon.vertices_m.size() < 3) {
    return InvalidArgumentError(where + ".vertices_m needs at least 3 vertices, got " +
                                std::to_string(polygon.vertices_m.size()));
  }
  for (const WorldPoint& v : polygon.vertices_m) {
    if (!v.allFinite()) return InvalidArgumentError(where + ".vertices_m must be finite, got " + Vec(v));
  }
  const Eigen::Vector3d n = NewellNormal(polygon.vertices_m);
  if (n.norm() < 1e-12) return InvalidArgumentError(where + ".vertices_m are collinear (the polygon has no area)");
  const Eigen::Vector3d unit = n.normalized();
  for (const WorldPoint& v : polygon.vertices_m) {
    const double off = std::abs(unit.dot(v - polygon.vertices_m[0]));
    if (off > kPlanarityToleranceM) {
      return InvalidArgumentError(where + ".vertices_m are not coplanar: " + Vec(v) + " lies " + Num(off) +
                                  " m off the polygon's plane");
    }
  }
  return Status::Ok();
}

Status ValidateBox(const SceneBox& box, const std::string& where) {
  if (!box.centre_m.allFinite())
    return InvalidArgumentError(where + ".centre_m must be finite, got " + Vec(box.centre_m));
  if (!box.half_extent_m.allFinite() || box.half_extent_m.minCoeff() <= 0.0) {
    return InvalidArgumentError(where + ".half_extent_m must be finite and > 0 on every axis, got " +
                                Vec(box.half_extent_m));
  }
  if (!box.rotation.allFinite() ||
      (box.rotation.transpose() * box.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
          kOrthonormalTolerance) {
    return InvalidArgumentError(where + ".rotation must be orthonormal (its columns are the box's axes)");
  }
  return Status::Ok();
}

Status ValidateCylinder(const SceneCylinder& cylinder, const std::string& where) {
  if (!cylinder.base_m.allFinite() || !cylinder.top_m.allFinite()) {
    return InvalidArgumentError(where + ".base_m and .top_m must be finite, got " + Vec(cylinder.base_m) + " and " +
                                Vec(cylinder.top_m));
  }
  if ((cylinder.top_m - cylinder.base_m).norm() <= 0.0) {
    return InvalidArgumentError(where + ".top_m must differ from .base_m, both are " + Vec(cylinder.base_m));
  }
  if (!std::isfinite(cylinder.radius_m) || cylinder.radius_m <= 0.0) {
    return InvalidArgumentError(where + ".radius_m must be finite and > 0, got " + Num(cylinder.radius_m));
  }
  return Status::Ok();
}

// Number of beams across an angular span: every step once around for a full 360 deg circle, else
// both ends of the span included. Counted in double and saturated just past kMaxSimulatedBeams, so
// a tiny step is refused by the limit instead of overflowing the cast (or the product of two counts).
uint64_t BeamsAcross(double span_deg, double step_deg, bool full_circle) {
  const double steps = std::floor(span_deg / step_deg + kAngleSlack);
  const double beams = full_circle ? std::max(1.0, steps) : steps + 1;
  if (!(beams <= static_cast<double>(kMaxSimulatedBeams))) return kMaxSimulatedBeams + 1;
  return static_cast<uint64_t>(beams);
}

bool IsFullCircle(const SimulatedScanner& s) { return s.hfov_deg >= 360.0 - kAngleSlack; }

uint64_t SplitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The random numbers of one beam: a stream that depends only on the seed and the beam's index.
class BeamRandom {
 public:
  BeamRandom(uint64_t seed, uint64_t beam) : state_(seed) {
    state_ ^= SplitMix64(beam);
    SplitMix64(state_);
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(SplitMix64(state_) >> 11) * 0x1.0p-53; }
  // Standard normal (Box-Muller).
  double Gaussian() {
    const double u1 = 1.0 - Uniform();  // in (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  uint64_t state_;
};

// One beam's outcome, given the nearest surface it meets.
void RecordBeam(const SimulatedScanner& s, uint64_t beam, const Eigen::Vector3d& direction,
                const std::optional<SceneHit>& hit, SimulatedScan& scan) {
  if (!hit) return;
  BeamRandom random(s.seed, beam);
  const bool dropped = random.Uniform() < s.dropout_probability;
  const double range_m =
      s.range_noise_sigma_m > 0.0 ? hit->distance_m + s.range_noise_sigma_m * random.Gaussian() : hit->distance_m;
  if (range_m < s.min_range_m || range_m > s.max_range_m) return;
  ++scan.beams_in_range;
  if (dropped) {
    ++scan.beams_dropped;
    return;
  }
  scan.points_m.push_back((s.position_m + range_m * direction).cast<float>());
  scan.primitive.push_back(hit->primitive);
}

}  // namespace

ScenePolygon Rectangle(const WorldPoint& centre_m, const Eigen::Vector3d& half_u_m, const Eigen::Vector3d& half_v_m) {
  return {{centre_m - half_u_m - half_v_m, centre_m + half_u_m - half_v_m, centre_m + half_u_m + half_v_m,
           centre_m - half_u_m + half_v_m}};
}

SceneBox AxisAlignedBox(const WorldPoint& min_m, const WorldPoint& max_m) {
  return {0.5 * (min_m + max_m), 0.5 * (max_m - min_m), Eigen::Matrix3d::Identity()};
}

SceneBox BoxAboutZ(const WorldPoint& centre_m, const Eigen::Vector3d& half_extent_m, double yaw_rad) {
  return {centre_m, half_extent_m, Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix()};
}

std::vector<SceneBox> StairFlight(const StairOptions& options) {
  std::vector<SceneBox> steps;
  const Eigen::Vector3d ahead(std::cos(options.heading_rad), std::sin(options.heading_rad), 0.0);
  for (int i = 0; i < options.step_count; ++i) {
    const double top_m = (i + 1) * options.rise_m;
    const WorldPoint centre = options.foot_m + (i + 0.5) * options.run_m * ahead + Eigen::Vector3d(0, 0, 0.5 * top_m);
    steps.push_back(BoxAboutZ(centre, {0.5 * options.run_m, 0.5 * options.width_m, 0.5 * top_m}, options.heading_rad));
  }
  return steps;
}

Status ValidateScene(const AnalyticScene& scene) {
  for (size_t i = 0; i < scene.primitives.size(); ++i) {
    const std::string where = "scene.primitives[" + std::to_string(i) + "]";
    const ScenePrimitive& p = scene.primitives[i];
    if (const auto* polygon = std::get_if<ScenePolygon>(&p)) {
      VC_RETURN_IF_ERROR(ValidatePolygon(*polygon, where + " (polygon)"));
    } else if (const auto* box = std::get_if<SceneBox>(&p)) {
      VC_RETURN_IF_ERROR(ValidateBox(*box, where + " (box)"));
    } else {
      VC_RETURN_IF_ERROR(ValidateCylinder(std::get<SceneCylinder>(p), where + " (cylinder)"));
    }
  }
  return Status::Ok();
}

std::optional<SceneHit> IntersectScene(const AnalyticScene& scene, const WorldPoint& origin_m,
                                       const Eigen::Vector3d& direction, double min_distance_m, double max_distance_m) {
  return PreparedScene(scene).Nearest(origin_m, direction, min_distance_m, max_distance_m);
}

double DistanceToSurfaceM(const ScenePrimitive& primitive, const WorldPoint& point_m) {
  if (const auto* polygon = std::get_if<ScenePolygon>(&primitive)) {
    const PreparedPolygon p = Prepare(*polygon);
    const double to_plane = p.normal.dot(point_m) - p.offset;
    if (InsidePolygon(p.vertices_uv, {point_m[p.axis_u], point_m[p.axis_v]})) return std::abs(to_plane);
    double best = std::numeric_limits<double>::infinity();
    const auto& v = polygon->vertices_m;
    for (size_t i = 0; i < v.size(); ++i) {
      const Eigen::Vector3d a = v[i], edge = v[(i + 1) % v.size()] - a;
      const double s = std::clamp((point_m - a).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (point_m - (a + s * edge)).norm());
    }
    return best;
  }
  if (const auto* box = std::get_if<SceneBox>(&primitive)) {
    const Eigen::Vector3d q = (box->rotation.transpose() * (point_m - box->centre_m)).cwiseAbs() - box->half_extent_m;
    const double outside = q.cwiseMax(0.0).norm();
    const double inside = std::min(q.maxCoeff(), 0.0);
    return std::abs(outside + inside);
  }
  const PreparedCylinder c = Prepare(std::get<SceneCylinder>(primitive));
  const Eigen::Vector3d rel = point_m - c.base;
  const double h = rel.dot(c.axis);
  const Eigen::Vector2d q((rel - h * c.axis).norm() - c.radius, std::abs(h - 0.5 * c.length) - 0.5 * c.length);
  return std::abs(q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0));
}

Status SimulatedScanner::Validate() const {
  auto bad = [](const char* field, const std::string& rule, double got) {
    return InvalidArgumentError(std::string("scanner.") + field + " must be " + rule + ", got " + Num(got));
  };
  if (!position_m.allFinite()) return InvalidArgumentError("scanner.position_m must be finite, got " + Vec(position_m));
  if (!std::isfinite(heading_rad)) return bad("heading_rad", "finite", heading_rad);
  if (!(hfov_deg > 0.0 && hfov_deg <= 360.0)) return bad("hfov_deg", "in (0, 360]", hfov_deg);
  if (!(vfov_min_deg >= -90.0 && vfov_min_deg <= 90.0)) return bad("vfov_min_deg", "in [-90, 90]", vfov_min_deg);
  if (!(vfov_max_deg >= -90.0 && vfov_max_deg <= 90.0)) return bad("vfov_max_deg", "in [-90, 90]", vfov_max_deg);
  if (!(vfov_min_deg < vfov_max_deg)) {
    return bad("vfov_min_deg", "< scanner.vfov_max_deg (" + Num(vfov_max_deg) + ")", vfov_min_deg);
  }
  if (!(horizontal_step_deg > 0.0 && horizontal_step_deg <= 90.0)) {
    return bad("horizontal_step_deg", "in (0, 90]", horizontal_step_deg);
  }
  if (!(vertical_step_deg > 0.0 && vertical_step_deg <= 90.0)) {
    return bad("vertical_step_deg", "in (0, 90]", vertical_step_deg);
  }
  if (!(min_range_m >= 0.0 && std::isfinite(min_range_m))) return bad("min_range_m", "finite and >= 0", min_range_m);
  if (!(max_range_m > min_range_m && std::isfinite(max_range_m))) {
    return bad("max_range_m", "finite and > scanner.min_range_m (" + Num(min_range_m) + ")", max_range_m);
  }
  if (!(range_noise_sigma_m >= 0.0 && std::isfinite(range_noise_sigma_m))) {
    return bad("range_noise_sigma_m", "finite and >= 0", range_noise_sigma_m);
  }
  if (!(dropout_probability >= 0.0 && dropout_probability <= 1.0)) {
    return bad("dropout_probability", "in [0, 1]", dropout_probability);
  }
  return Status::Ok();
}

uint64_t SimulatedScanner::BeamCount() const {
  return BeamsAcross(hfov_deg, horizontal_step_deg, IsFullCircle(*this)) *
         BeamsAcross(vfov_max_deg - vfov_min_deg, vertical_step_deg, false);
}

Result<SimulatedScan> SimulateScan(const AnalyticScene& scene, const SimulatedScanner& scanner) {
  VC_RETURN_IF_ERROR(scanner.Validate());
  VC_RETURN_IF_ERROR(ValidateScene(scene));
  const bool full_circle = IsFullCircle(scanner);
  const uint64_t azimuths = BeamsAcross(scanner.hfov_deg, scanner.horizontal_step_deg, full_circle);
  const uint64_t elevations =
      BeamsAcross(scanner.vfov_max_deg - scanner.vfov_min_deg, scanner.vertical_step_deg, false);
  if (azimuths * elevations > kMaxSimulatedBeams) {
    return ResourceExhaustedError("the beam pattern has " + std::to_string(azimuths * elevations) +
                                  " beams, more than the simulator's limit of " + std::to_string(kMaxSimulatedBeams) +
                                  "; use a larger scanner.horizontal_step_deg or vertical_step_deg, or a narrower "
                                  "field of view");
  }
  const double step_az = Radians(scanner.horizontal_step_deg);
  const double first_az = full_circle ? scanner.heading_rad - std::numbers::pi
                                      : scanner.heading_rad - 0.5 * static_cast<double>(azimuths - 1) * step_az;
  const PreparedScene prepared(scene);
  SimulatedScan scan;
  scan.beams = azimuths * elevations;
  for (uint64_t k = 0; k < azimuths; ++k) {
    const double az = first_az + static_cast<double>(k) * step_az;
    for (uint64_t j = 0; j < elevations; ++j) {
      const double el = Radians(
          std::min(scanner.vfov_min_deg + static_cast<double>(j) * scanner.vertical_step_deg, scanner.vfov_max_deg));
      const Eigen::Vector3d direction(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const std::optional<SceneHit> hit =
          prepared.Nearest(scanner.position_m, direction, kMinBeamDistanceM, std::numeric_limits<double>::infinity());
      RecordBeam(scanner, k * elevations + j, direction, hit, scan);
    }
  }
  return scan;
}

Result<AnalyticScene> TiltedPlaneScene(double tilt_deg, double distance_m, double side_m) {
  if (!(std::abs(tilt_deg) < 90.0)) return InvalidArgumentError("tilt_deg must be in (-90, 90), got " + Num(tilt_deg));
  if (!(distance_m > 0.0 && std::isfinite(distance_m))) {
    return InvalidArgumentError("distance_m must be finite and > 0, got " + Num(distance_m));
  }
  if (!(side_m > 0.0 && std::isfinite(side_m))) {
    return InvalidArgumentError("side_m must be finite and > 0, got " + Num(side_m));
  }
  const double tilt = Radians(tilt_deg);
  const Eigen::Vector3d across(-std::sin(tilt), std::cos(tilt), 0.0);
  AnalyticScene scene;
  scene.primitives.push_back(
      Rectangle({distance_m, 0.0, 0.0}, 0.5 * side_m * across, Eigen::Vector3d(0.0, 0.0, 0.5 * side_m)));
  return scene;
}

AnalyticScene RoomWithClutterScene() {
  AnalyticScene scene;
  auto add = [&scene](ScenePrimitive p) { scene.primitives.push_back(std::move(p)); };
  const Eigen::Vector3d x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  add(Rectangle({4, 3, 0}, 4 * x, 3 * y));      // floor
  add(Rectangle({4, 3, 3}, 4 * x, 3 * y));      // ceiling
  add(Rectangle({0, 3, 1.5}, 3 * y, 1.5 * z));  // walls x = 0, x = 8, y = 0, y = 6
  add(Rectangle({8, 3, 1.5}, 3 * y, 1.5 * z));
  add(Rectangle({4, 0, 1.5}, 4 * x, 1.5 * z));
  add(Rectangle({4, 6, 1.5}, 4 * x, 1.5 * z));
  add(AxisAlignedBox({4.5, 1.0, 0.72}, {6.0, 2.0, 0.76}));  // table top and legs
  for (const double leg_x : {4.55, 5.95}) {
    for (const double leg_y : {1.05, 1.95}) {
      add(AxisAlignedBox({leg_x - 0.025, leg_y - 0.025, 0.0}, {leg_x + 0.025, leg_y + 0.025, 0.72}));
    }
  }
  add(SceneCylinder{{5.5, 4.2, 0.0}, {5.5, 4.2, 3.0}, 0.2});  // column
  const StairOptions stairs{.foot_m = {1.0, 5.5, 0.0}, .step_count = 6, .run_m = 0.3, .width_m = 0.9};
  for (const SceneBox& step : StairFlight(stairs)) add(step);
  const WorldPoint handrail_foot = stairs.foot_m + Eigen::Vector3d(0.0, -0.5 * stairs.width_m, 0.9);
  add(SceneCylinder{handrail_foot,
                    handrail_foot + stairs.step_count * Eigen::Vector3d(stairs.run_m, 0.0, stairs.rise_m), 0.02});
  add(SceneCylinder{{0.5, 1.0, 1.0}, {3.5, 1.0, 1.0}, 0.01});  // thin rail
  const double lean = Radians(30.0);
  add(Rectangle({8.0 - 0.75 * std::sin(lean), 1.5, 0.75 * std::cos(lean)}, 0.5 * y,
                0.75 * Eigen::Vector3d(std::sin(lean), 0.0, std::cos(lean))));  // board leaning on the wall x = 8
  return scene;
}

}  // namespace vc
