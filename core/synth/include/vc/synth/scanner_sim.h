// A scanner simulator: casts an instrument's beams from a station into an analytic scene and returns
// the points it captures, so that tests can measure a visibility prediction against a "captured" set
// on scenes whose geometry is known exactly (issue 34, docs/VISIBILITY.md "A scanner simulator for
// measuring the test against captured points").
//
// Why the API is split: the scene is plain data (a list of primitives with exact ray intersection,
// in the world frame, metres) that tests build and inspect; IntersectScene and DistanceToSurfaceM
// are the two exact queries on it (the first for the simulator, the second for tests that check a
// captured point lies on a surface); SimulateScan is the instrument on top of IntersectScene.
//
// Model: each beam is an exact ray (no divergence, so no mixed pixels at edges), the first surface it
// meets returns one point at the measured range (true range + Gaussian noise along the beam), no
// intensity, no multiple returns, every surface is opaque and returns (no reflectance, no incidence
// limit). A surface nearer than min_range_m blocks the beam and returns nothing, as in a real
// instrument. Beams are laid on a regular azimuth x elevation grid (at +-90 deg elevation every
// azimuth's beam points the same way, as a real scanner's do near its poles); the noise and the
// dropout of a beam depend only on the seed and the beam's index, so the same options give the same
// points.
//
// Cost: beams x primitives ray tests, a linear scan on one thread (no acceleration structure), which
// is fine for tens of primitives: a 0.1 deg step over 360 x 180 deg is 3600 x 1801 = 6.5e6 beams,
// about 3 s of CPU on RoomWithClutterScene's 21 primitives, and 16 bytes of output per point; tests
// use 0.25-1 deg steps. More than kMaxSimulatedBeams is refused. For hundreds of primitives, add a
// BVH or a uniform grid in front of IntersectScene.
//
// Thread-safety: all functions are pure and may be called concurrently.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"

namespace vc {

// SimulateScan refuses a beam pattern with more beams than this (0.05 deg over 360 x 180 deg fits).
inline constexpr uint64_t kMaxSimulatedBeams = 30'000'000;

// A finite planar polygon (world, m), two-sided: simple (not self-intersecting), >= 3 coplanar vertices
// in order around its boundary; convex or not.
struct ScenePolygon {
  std::vector<WorldPoint> vertices_m;
};

// A solid box (world, m), possibly rotated: the points centre_m + rotation * q with |q_i| <= half_extent_m_i.
struct SceneBox {
  WorldPoint centre_m{0, 0, 0};
  // Half the box's size along each of its own axes (m), each > 0.
  Eigen::Vector3d half_extent_m{0, 0, 0};
  // The box's axes in the world frame (columns), orthonormal.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

// A solid finite cylinder with flat caps (world, m) around the segment from base_m to top_m.
struct SceneCylinder {
  WorldPoint base_m{0, 0, 0};
  WorldPoint top_m{0, 0, 1};
  // Radius (m), > 0 (a thin rail: 0.01).
  double radius_m = 0.1;
};

// One surface of an analytic scene.
using ScenePrimitive = std::variant<ScenePolygon, SceneBox, SceneCylinder>;

// A scene: the union of its primitives' surfaces (world, m). A point index in SimulatedScan refers to
// the position of its primitive in `primitives`.
struct AnalyticScene {
  std::vector<ScenePrimitive> primitives;
};

// The rectangle with corners centre_m +- half_u_m +- half_v_m (half_u_m and half_v_m perpendicular).
ScenePolygon Rectangle(const WorldPoint& centre_m, const Eigen::Vector3d& half_u_m, const Eigen::Vector3d& half_v_m);

// The axis-aligned box [min_m, max_m] (world, m).
SceneBox AxisAlignedBox(const WorldPoint& min_m, const WorldPoint& max_m);

// A box of half extents half_extent_m centred at centre_m, turned by yaw_rad about +z.
SceneBox BoxAboutZ(const WorldPoint& centre_m, const Eigen::Vector3d& half_extent_m, double yaw_rad);

// A straight flight of steps, each a solid block from the foot's height to its tread.
struct StairOptions {
  // Middle of the first step's front edge at floor level (world, m).
  WorldPoint foot_m{0, 0, 0};
  // Direction of ascent, about +z from +x (rad).
  double heading_rad = 0.0;
  int step_count = 8;
  double rise_m = 0.18;
  double run_m = 0.28;
  double width_m = 1.0;
};

// The steps of a flight, lowest first (step_count boxes; none if step_count <= 0).
std::vector<SceneBox> StairFlight(const StairOptions& options);

// INVALID_ARGUMENT naming the primitive and field for a primitive whose fields are not finite or
// break its rules above (a polygon with < 3 vertices, collinear or not coplanar within 1e-6 m; a box
// with a half extent <= 0 or a rotation that is not orthonormal; a cylinder with radius_m <= 0 or
// base_m == top_m).
Status ValidateScene(const AnalyticScene& scene);

// The nearest hit of a ray on the scene's surfaces.
struct SceneHit {
  // Distance from the origin along the (unit) direction (m).
  double distance_m = 0.0;
  // Index of the primitive hit in scene.primitives.
  int primitive = -1;
};

// The nearest surface point origin_m + t * direction on the scene with min_distance_m < t <=
// max_distance_m; direction must be unit length; the scene must be valid (ValidateScene). Nullopt if none.
// Prepares the scene on each call (O(primitives)); SimulateScan prepares it once per scan.
std::optional<SceneHit> IntersectScene(const AnalyticScene& scene, const WorldPoint& origin_m,
                                       const Eigen::Vector3d& direction, double min_distance_m, double max_distance_m);

// Distance (m) from point_m to the surface of `primitive` (0 on it; for a solid, inside or outside).
double DistanceToSurfaceM(const ScenePrimitive& primitive, const WorldPoint& point_m);

// The instrument and its station. Beams: azimuths heading_rad + k * horizontal_step_deg across the
// horizontal field of view (centred on the heading; 360 deg: every step once around), elevations
// vfov_min_deg + j * vertical_step_deg up to vfov_max_deg.
struct SimulatedScanner {
  // Station (world, m): the beams' origin.
  WorldPoint position_m{0, 0, 0};
  // Direction the horizontal field of view is centred on, about +z from +x (rad).
  double heading_rad = 0.0;
  // Horizontal field of view (deg), in (0, 360].
  double hfov_deg = 360.0;
  // Lowest and highest beam elevation (deg), -90 <= vfov_min_deg < vfov_max_deg <= 90.
  double vfov_min_deg = -90.0;
  double vfov_max_deg = 90.0;
  // Angle between neighbouring beams in azimuth and in elevation (deg), in (0, 90].
  double horizontal_step_deg = 1.0;
  double vertical_step_deg = 1.0;
  // Measured ranges outside [min_range_m, max_range_m] give no point (m); 0 <= min < max.
  double min_range_m = 0.5;
  double max_range_m = 75.0;
  // Standard deviation of the Gaussian range noise along the beam (m), >= 0.
  double range_noise_sigma_m = 0.0;
  // Probability that a beam returns nothing, in [0, 1].
  double dropout_probability = 0.0;
  // Seed of the noise and the dropouts; same options -> same points.
  uint64_t seed = 1;

  // INVALID_ARGUMENT naming the field ("scanner.horizontal_step_deg must be > 0, got 0") for a value
  // that is not finite or outside its range above, or min_range_m >= max_range_m.
  Status Validate() const;
  // Number of beams the pattern casts.
  uint64_t BeamCount() const;
};

// What a simulated scan captured.
struct SimulatedScan {
  // Captured points (world, m), in beam order: azimuth by azimuth, elevations upward within each.
  std::vector<Eigen::Vector3f> points_m;
  // For each point, the index of the primitive its beam hit.
  std::vector<int> primitive;
  // Beams cast.
  uint64_t beams = 0;
  // Beams whose first surface lay within [min_range_m, max_range_m] after noise, dropped or not.
  uint64_t beams_in_range = 0;
  // Of those, beams lost to dropout.
  uint64_t beams_dropped = 0;
};

// Casts every beam of `scanner` into `scene`. INVALID_ARGUMENT for bad options or a bad scene (see
// Validate, ValidateScene); RESOURCE_EXHAUSTED for more than kMaxSimulatedBeams beams.
Result<SimulatedScan> SimulateScan(const AnalyticScene& scene, const SimulatedScanner& scanner);

// A side_m x side_m square plane centred at (distance_m, 0, 0), facing a station at the origin
// (normal -x) when tilt_deg = 0 and turned by tilt_deg about the vertical axis through its centre.
// INVALID_ARGUMENT unless |tilt_deg| < 90, distance_m > 0 and side_m > 0.
Result<AnalyticScene> TiltedPlaneScene(double tilt_deg, double distance_m = 3.0, double side_m = 4.0);

// A station inside RoomWithClutterScene, clear of every object (world, m).
inline const WorldPoint kRoomWithClutterStationM{2.0, 3.0, 1.5};

// A closed 8 x 6 x 3 m room ([0, 8] x [0, 6] x [0, 3], inward surfaces as polygons) holding a table,
// a column (radius 0.2 m), a flight of 6 steps along the wall y = 6 with a handrail (radius 0.02 m),
// a thin horizontal rail (radius 0.01 m) and a board leaning at 30 deg against the wall x = 8.
AnalyticScene RoomWithClutterScene();

}  // namespace vc
