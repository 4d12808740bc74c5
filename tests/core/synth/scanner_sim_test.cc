#include "vc/synth/scanner_sim.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace vc {
namespace {

constexpr double kPi = std::numbers::pi;

double Radians(double deg) { return deg * kPi / 180.0; }

// A scanner that casts exactly one beam, straight along +x.
SimulatedScanner OneBeamAlongX() {
  SimulatedScanner s;
  s.hfov_deg = 0.5;
  s.horizontal_step_deg = 1.0;
  s.vfov_min_deg = 0.0;
  s.vfov_max_deg = 0.5;
  s.vertical_step_deg = 1.0;
  return s;
}

AnalyticScene WallAt(double x_m, double half_side_m) {
  AnalyticScene scene;
  scene.primitives.push_back(Rectangle({x_m, 0, 0}, {0, half_side_m, 0}, {0, 0, half_side_m}));
  return scene;
}

SimulatedScan Scan(const AnalyticScene& scene, const SimulatedScanner& scanner) {
  Result<SimulatedScan> scan = SimulateScan(scene, scanner);
  EXPECT_TRUE(scan.ok()) << scan.status().ToString();
  return scan.ok() ? *std::move(scan) : SimulatedScan{};
}

TEST(ScannerSimTest, OneBeamPatternCastsOneBeam) {
  EXPECT_EQ(OneBeamAlongX().BeamCount(), 1u);
  SimulatedScanner full;
  EXPECT_EQ(full.BeamCount(), 360u * 181u);
  full.horizontal_step_deg = full.vertical_step_deg = 0.1;
  EXPECT_EQ(full.BeamCount(), 3600u * 1801u);  // the cost quoted in the header
}

TEST(ScannerSimTest, BeamStraightAtAWallReturnsAPointAtItsDistance) {
  for (double d : {0.7, 3.0, 41.25}) {
    const SimulatedScan scan = Scan(WallAt(d, 1.0), OneBeamAlongX());
    ASSERT_EQ(scan.points_m.size(), 1u) << d;
    EXPECT_NEAR(scan.points_m[0].x(), d, 1e-5);
    EXPECT_NEAR(scan.points_m[0].y(), 0.0, 1e-6);
    EXPECT_NEAR(scan.points_m[0].z(), 0.0, 1e-6);
    EXPECT_EQ(scan.primitive[0], 0);
  }
}

TEST(ScannerSimTest, BeamAtABoxAndAColumnStopsAtTheirNearSide) {
  AnalyticScene box;
  box.primitives.push_back(BoxAboutZ({3, 0, 0}, {0.5, 0.5, 0.5}, Radians(45)));
  SimulatedScan scan = Scan(box, OneBeamAlongX());
  ASSERT_EQ(scan.points_m.size(), 1u);
  EXPECT_NEAR(scan.points_m[0].x(), 3.0 - 0.5 * std::sqrt(2.0), 1e-5);

  AnalyticScene column;
  column.primitives.push_back(SceneCylinder{{2, 0, -1}, {2, 0, 1}, 0.01});
  scan = Scan(column, OneBeamAlongX());
  ASSERT_EQ(scan.points_m.size(), 1u);
  EXPECT_NEAR(scan.points_m[0].x(), 1.99, 1e-5);
}

TEST(ScannerSimTest, ThinRailHitDistancesMatchTheCircle) {
  AnalyticScene rail;
  rail.primitives.push_back(SceneCylinder{{2, 0, -1}, {2, 0, 1}, 0.01});
  for (double alpha_deg : {0.0, 0.1, -0.2, 0.28}) {
    const double a = Radians(alpha_deg);
    const std::optional<SceneHit> hit = IntersectScene(rail, {0, 0, 0}, {std::cos(a), std::sin(a), 0}, 0.0, 100.0);
    ASSERT_TRUE(hit.has_value()) << alpha_deg;
    const double lateral = 2.0 * std::sin(a);
    EXPECT_NEAR(hit->distance_m, 2.0 * std::cos(a) - std::sqrt(0.01 * 0.01 - lateral * lateral), 1e-9);
  }
  EXPECT_FALSE(IntersectScene(rail, {0, 0, 0}, {std::cos(Radians(0.3)), std::sin(Radians(0.3)), 0}, 0.0, 100.0));
  // Along the axis, a beam meets the cap.
  const std::optional<SceneHit> cap = IntersectScene(rail, {2, 0, -3}, {0, 0, 1}, 0.0, 100.0);
  ASSERT_TRUE(cap.has_value());
  EXPECT_NEAR(cap->distance_m, 2.0, 1e-12);
}

TEST(ScannerSimTest, ArbitraryAxisCylinderIsHitOnItsSurface) {
  AnalyticScene scene;
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 1, 1).normalized();
  const SceneCylinder rail{WorldPoint(3, 0, 0) - 2 * axis, WorldPoint(3, 0, 0) + 2 * axis, 0.05};
  scene.primitives.push_back(rail);
  // The beam along +x crosses the axis at (3, 0, 0), at angle acos(axis.x) to it.
  const std::optional<SceneHit> hit = IntersectScene(scene, {0, 0, 0}, {1, 0, 0}, 0.0, 100.0);
  ASSERT_TRUE(hit.has_value());
  const double sin_angle = std::sqrt(1.0 - axis.x() * axis.x());
  EXPECT_NEAR(hit->distance_m, 3.0 - 0.05 / sin_angle, 1e-9);
  EXPECT_NEAR(DistanceToSurfaceM(rail, {hit->distance_m, 0, 0}), 0.0, 1e-9);
}

TEST(ScannerSimTest, NonConvexPolygonIsHitOnlyInside) {
  // An L in the plane x = 2: the square [-1, 1]^2 less its quadrant y > 0, z > 0.
  AnalyticScene scene;
  scene.primitives.push_back(ScenePolygon{{{2, -1, -1}, {2, 1, -1}, {2, 1, 0}, {2, 0, 0}, {2, 0, 1}, {2, -1, 1}}});
  auto hits_towards = [&](double y, double z) {
    return IntersectScene(scene, {0, 0, 0}, Eigen::Vector3d(2, y, z).normalized(), 0.0, 100.0).has_value();
  };
  EXPECT_TRUE(hits_towards(-0.5, 0.5));
  EXPECT_TRUE(hits_towards(0.5, -0.5));
  EXPECT_TRUE(hits_towards(-0.5, -0.5));
  EXPECT_FALSE(hits_towards(0.5, 0.5));
  EXPECT_FALSE(hits_towards(1.5, 0.0));
}

TEST(ScannerSimTest, StairTreadsAreAtTheirHeights) {
  const StairOptions options{.foot_m = {1, 0, 0}, .heading_rad = Radians(90), .step_count = 5};
  AnalyticScene scene;
  for (const SceneBox& step : StairFlight(options)) scene.primitives.push_back(step);
  ASSERT_EQ(scene.primitives.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    const WorldPoint above(1.0, (i + 0.5) * options.run_m, 10.0);
    const std::optional<SceneHit> hit = IntersectScene(scene, above, {0, 0, -1}, 0.0, 100.0);
    ASSERT_TRUE(hit.has_value()) << i;
    EXPECT_EQ(hit->primitive, i);
    EXPECT_NEAR(10.0 - hit->distance_m, (i + 1) * options.rise_m, 1e-9);
  }
  EXPECT_FALSE(IntersectScene(scene, {1.0 + options.width_m, 0.1, 10.0}, {0, 0, -1}, 0.0, 100.0));
}

TEST(ScannerSimTest, EveryCapturedPointLiesOnTheSurfaceItHit) {
  const AnalyticScene scene = RoomWithClutterScene();
  ASSERT_TRUE(ValidateScene(scene).ok());
  SimulatedScanner scanner;
  scanner.position_m = kRoomWithClutterStationM;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.25;
  const SimulatedScan exact = Scan(scene, scanner);
  ASSERT_FALSE(exact.points_m.empty());
  std::vector<int> hits_per_primitive(scene.primitives.size(), 0);
  for (size_t i = 0; i < exact.points_m.size(); ++i) {
    const ScenePrimitive& hit = scene.primitives[exact.primitive[i]];
    ASSERT_LT(DistanceToSurfaceM(hit, exact.points_m[i].cast<double>()), 1e-5) << i;
    ++hits_per_primitive[exact.primitive[i]];
  }
  for (size_t p = 0; p < scene.primitives.size(); ++p) EXPECT_GT(hits_per_primitive[p], 0) << "primitive " << p;

  scanner.range_noise_sigma_m = 0.01;
  const SimulatedScan noisy = Scan(scene, scanner);
  ASSERT_EQ(noisy.points_m.size(), exact.points_m.size());
  double sum_sq = 0.0;
  for (size_t i = 0; i < noisy.points_m.size(); ++i) {
    const double d = DistanceToSurfaceM(scene.primitives[noisy.primitive[i]], noisy.points_m[i].cast<double>());
    ASSERT_LT(d, 6 * 0.01) << i;
    sum_sq += d * d;
  }
  // Distances to the surface are |noise| x (at most 1), so their RMS is at most sigma, and near it.
  const double rms = std::sqrt(sum_sq / static_cast<double>(noisy.points_m.size()));
  EXPECT_GT(rms, 0.004);
  EXPECT_LT(rms, 0.0105);
}

TEST(ScannerSimTest, NothingIsCapturedOutsideTheRangeOrTheHorizontalFieldOfView) {
  SimulatedScanner scanner;
  scanner.position_m = kRoomWithClutterStationM;
  scanner.heading_rad = 0.7;
  scanner.hfov_deg = 90.0;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.5;
  scanner.min_range_m = 2.0;
  scanner.max_range_m = 4.0;
  scanner.range_noise_sigma_m = 0.02;
  const SimulatedScan scan = Scan(RoomWithClutterScene(), scanner);
  ASSERT_GT(scan.points_m.size(), 1000u);
  for (const Eigen::Vector3f& p : scan.points_m) {
    const Eigen::Vector3d v = p.cast<double>() - scanner.position_m;
    ASSERT_GE(v.norm(), 2.0 - 1e-5);
    ASSERT_LE(v.norm(), 4.0 + 1e-5);
    const double off_heading = std::remainder(std::atan2(v.y(), v.x()) - scanner.heading_rad, 2 * kPi);
    ASSERT_LE(std::abs(off_heading), Radians(45.0) + 1e-5);
  }
}

TEST(ScannerSimTest, VerticalFieldOfViewLimitsElevations) {
  SimulatedScanner scanner;
  scanner.position_m = kRoomWithClutterStationM;
  scanner.vfov_min_deg = -20.0;
  scanner.vfov_max_deg = 35.0;
  const SimulatedScan scan = Scan(RoomWithClutterScene(), scanner);
  ASSERT_FALSE(scan.points_m.empty());
  for (const Eigen::Vector3f& p : scan.points_m) {
    const Eigen::Vector3d v = p.cast<double>() - scanner.position_m;
    const double elevation = std::atan2(v.z(), v.head<2>().norm());
    ASSERT_GE(elevation, Radians(-20.0) - 1e-5);
    ASSERT_LE(elevation, Radians(35.0) + 1e-5);
  }
}

TEST(ScannerSimTest, PointsBehindAWallAreNeverCaptured) {
  AnalyticScene scene = WallAt(3.0, 2.0);  // the square [-2, 2]^2 in the plane x = 3
  scene.primitives.push_back(Rectangle({6, 0, 0}, {0, 10, 0}, {0, 0, 10}));
  SimulatedScanner scanner;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.5;
  const SimulatedScan scan = Scan(scene, scanner);
  int behind = 0;
  for (size_t i = 0; i < scan.points_m.size(); ++i) {
    if (scan.primitive[i] != 1) continue;
    ++behind;
    // Where the line of sight to the point crosses x = 3: outside the front wall.
    const Eigen::Vector3d p = scan.points_m[i].cast<double>();
    const Eigen::Vector3d crossing = p * (3.0 / p.x());
    ASSERT_TRUE(std::abs(crossing.y()) > 2.0 - 1e-4 || std::abs(crossing.z()) > 2.0 - 1e-4) << i;
  }
  EXPECT_GT(behind, 100);
}

TEST(ScannerSimTest, ASurfaceInsideTheMinimumRangeBlocksItsBeams) {
  AnalyticScene scene = WallAt(3.0, 2.0);
  scene.primitives.push_back(AxisAlignedBox({0.2, -0.05, -0.05}, {0.3, 0.05, 0.05}));
  SimulatedScanner scanner;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 1.0;
  ASSERT_GT(scanner.min_range_m, 0.3);
  const SimulatedScan scan = Scan(scene, scanner);
  ASSERT_GT(scan.points_m.size(), 1000u);
  for (size_t i = 0; i < scan.points_m.size(); ++i) {
    ASSERT_EQ(scan.primitive[i], 0);
    // The box's shadow is the cone through its front face (x = 0.2, |y|, |z| <= 0.05).
    const Eigen::Vector3d at_box = scan.points_m[i].cast<double>() * (0.2 / scan.points_m[i].x());
    ASSERT_TRUE(std::abs(at_box.y()) > 0.05 - 1e-6 || std::abs(at_box.z()) > 0.05 - 1e-6) << i;
  }
  // The shadow holds about (2 atan(0.25) / 1 deg)^2 = 784 beams.
  EXPECT_LT(scan.points_m.size() + 700, Scan(WallAt(3.0, 2.0), scanner).points_m.size());
}

TEST(ScannerSimTest, DropoutRemovesBeamsAtItsRate) {
  SimulatedScanner scanner;
  scanner.position_m = kRoomWithClutterStationM;
  scanner.min_range_m = 0.0;
  const AnalyticScene room = RoomWithClutterScene();

  const SimulatedScan kept = Scan(room, scanner);
  // The room is closed, so every beam returns.
  EXPECT_EQ(kept.beams, scanner.BeamCount());
  EXPECT_EQ(kept.beams_in_range, kept.beams);
  EXPECT_EQ(kept.points_m.size(), kept.beams);
  EXPECT_EQ(kept.beams_dropped, 0u);

  scanner.dropout_probability = 1.0;
  const SimulatedScan none = Scan(room, scanner);
  EXPECT_TRUE(none.points_m.empty());
  EXPECT_EQ(none.beams_dropped, kept.beams);

  scanner.dropout_probability = 0.3;
  const SimulatedScan some = Scan(room, scanner);
  const double kept_fraction = static_cast<double>(some.points_m.size()) / static_cast<double>(kept.beams);
  EXPECT_NEAR(kept_fraction, 0.7, 0.01);
  EXPECT_EQ(some.points_m.size() + some.beams_dropped, kept.beams);
}

// Beams of a step_deg grid that meet a side x side square at distance d seen head-on, from the
// solid angle: for azimuth a the square spans elevations |tan e| <= (side / 2d) cos a, so the count
// is the integral over a of 2 atan((side / 2d) cos a), divided by step^2 (radians).
double ExpectedHeadOnCount(double side_m, double distance_m, double step_deg) {
  const double half = 0.5 * side_m / distance_m;
  const double a_max = std::atan(half);
  const int n = 2000;
  double integral = 0.0;
  for (int i = 0; i < n; ++i) {
    const double a = -a_max + (i + 0.5) * (2 * a_max / n);
    integral += 2.0 * std::atan(half * std::cos(a)) * (2 * a_max / n);
  }
  return integral / (Radians(step_deg) * Radians(step_deg));
}

TEST(ScannerSimTest, AngularDensityMatchesTheStep) {
  for (double step_deg : {0.25, 0.5}) {
    Result<AnalyticScene> plane = TiltedPlaneScene(0.0, 3.0, 4.0);
    ASSERT_TRUE(plane.ok());
    SimulatedScanner scanner;
    scanner.horizontal_step_deg = scanner.vertical_step_deg = step_deg;
    const SimulatedScan scan = Scan(*plane, scanner);
    const double expected = ExpectedHeadOnCount(4.0, 3.0, step_deg);
    EXPECT_NEAR(static_cast<double>(scan.points_m.size()) / expected, 1.0, 0.01) << step_deg;
  }
}

// Beams of a step_deg grid that meet TiltedPlaneScene(tilt_deg, distance_m, side_m), from a surface
// integral: a patch dA at p subtends dOmega = cos(incidence) dA / |p|^2, and the grid holds
// dOmega / (cos(elevation) step^2) beams per patch.
double ExpectedTiltedCount(double tilt_deg, double distance_m, double side_m, double step_deg) {
  const Eigen::Vector3d normal(std::cos(Radians(tilt_deg)), std::sin(Radians(tilt_deg)), 0.0);
  const Eigen::Vector3d across(-normal.y(), normal.x(), 0.0);
  const int n = 400;
  const double cell = side_m / n;
  double beams = 0.0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d p = Eigen::Vector3d(distance_m, 0, 0) + (-0.5 * side_m + (i + 0.5) * cell) * across +
                                Eigen::Vector3d(0, 0, -0.5 * side_m + (j + 0.5) * cell);
      const double r = p.norm();
      const double cos_incidence = std::abs(normal.dot(p)) / r;
      const double cos_elevation = p.head<2>().norm() / r;
      beams += cos_incidence * cell * cell / (r * r * cos_elevation);
    }
  }
  return beams / (Radians(step_deg) * Radians(step_deg));
}

TEST(ScannerSimTest, AngularDensityOnTiltedPlanesMatchesTheStep) {
  for (double tilt_deg : {0.0, 30.0, 60.0}) {
    Result<AnalyticScene> plane = TiltedPlaneScene(tilt_deg, 3.0, 4.0);
    ASSERT_TRUE(plane.ok());
    SimulatedScanner scanner;
    scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.25;
    const SimulatedScan scan = Scan(*plane, scanner);
    const double expected = ExpectedTiltedCount(tilt_deg, 3.0, 4.0, 0.25);
    EXPECT_NEAR(static_cast<double>(scan.points_m.size()) / expected, 1.0, 0.01) << tilt_deg;
  }
  EXPECT_NEAR(ExpectedTiltedCount(0.0, 3.0, 4.0, 0.5) / ExpectedHeadOnCount(4.0, 3.0, 0.5), 1.0, 1e-3);
}

TEST(ScannerSimTest, TiltedPlanePointsLieOnTheTiltedPlane) {
  for (double tilt_deg : {0.0, 30.0, -45.0, 60.0}) {
    Result<AnalyticScene> plane = TiltedPlaneScene(tilt_deg);
    ASSERT_TRUE(plane.ok());
    SimulatedScanner scanner;
    scanner.horizontal_step_deg = scanner.vertical_step_deg = 1.0;
    const SimulatedScan scan = Scan(*plane, scanner);
    ASSERT_GT(scan.points_m.size(), 100u) << tilt_deg;
    const Eigen::Vector3d normal(std::cos(Radians(tilt_deg)), std::sin(Radians(tilt_deg)), 0.0);
    for (const Eigen::Vector3f& p : scan.points_m) {
      ASSERT_NEAR(normal.dot(p.cast<double>() - Eigen::Vector3d(3, 0, 0)), 0.0, 1e-5) << tilt_deg;
      ASSERT_LE(std::abs(p.z()), 2.0 + 1e-5);
    }
  }
  EXPECT_EQ(TiltedPlaneScene(90.0).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(TiltedPlaneScene(10.0, 0.0).status().code(), StatusCode::kInvalidArgument);
}

TEST(ScannerSimTest, SameSeedSamePointsOtherSeedOtherNoise) {
  SimulatedScanner scanner;
  scanner.position_m = kRoomWithClutterStationM;
  scanner.min_range_m = 0.0;
  scanner.range_noise_sigma_m = 0.01;
  scanner.dropout_probability = 0.1;
  const AnalyticScene room = RoomWithClutterScene();
  const SimulatedScan a = Scan(room, scanner);
  const SimulatedScan b = Scan(room, scanner);
  EXPECT_EQ(a.points_m, b.points_m);
  EXPECT_EQ(a.primitive, b.primitive);

  scanner.seed = 2;
  const SimulatedScan c = Scan(room, scanner);
  EXPECT_NE(a.points_m, c.points_m);

  scanner.dropout_probability = 0.0;
  const SimulatedScan d = Scan(room, scanner);
  scanner.seed = 3;
  const SimulatedScan e = Scan(room, scanner);
  ASSERT_EQ(d.points_m.size(), e.points_m.size());
  int differ = 0;
  for (size_t i = 0; i < d.points_m.size(); ++i) differ += d.points_m[i] != e.points_m[i];
  EXPECT_GT(differ, static_cast<int>(d.points_m.size() * 0.99));
}

struct BadOption {
  const char* field;
  void (*spoil)(SimulatedScanner&);
};

TEST(ScannerSimTest, BadOptionsAreNamedErrors) {
  const BadOption cases[] = {
      {"scanner.position_m", [](SimulatedScanner& s) { s.position_m.x() = std::nan(""); }},
      {"scanner.heading_rad", [](SimulatedScanner& s) { s.heading_rad = INFINITY; }},
      {"scanner.hfov_deg", [](SimulatedScanner& s) { s.hfov_deg = 0.0; }},
      {"scanner.hfov_deg", [](SimulatedScanner& s) { s.hfov_deg = 361.0; }},
      {"scanner.vfov_min_deg", [](SimulatedScanner& s) { s.vfov_min_deg = -91.0; }},
      {"scanner.vfov_max_deg", [](SimulatedScanner& s) { s.vfov_max_deg = 90.5; }},
      {"scanner.vfov_min_deg", [](SimulatedScanner& s) { s.vfov_min_deg = s.vfov_max_deg = 10.0; }},
      {"scanner.horizontal_step_deg", [](SimulatedScanner& s) { s.horizontal_step_deg = 0.0; }},
      {"scanner.vertical_step_deg", [](SimulatedScanner& s) { s.vertical_step_deg = -1.0; }},
      {"scanner.vertical_step_deg", [](SimulatedScanner& s) { s.vertical_step_deg = std::nan(""); }},
      {"scanner.min_range_m", [](SimulatedScanner& s) { s.min_range_m = -0.1; }},
      {"scanner.max_range_m", [](SimulatedScanner& s) { s.max_range_m = s.min_range_m; }},
      {"scanner.range_noise_sigma_m", [](SimulatedScanner& s) { s.range_noise_sigma_m = -0.01; }},
      {"scanner.dropout_probability", [](SimulatedScanner& s) { s.dropout_probability = 1.5; }},
  };
  const AnalyticScene scene = WallAt(3.0, 1.0);
  for (const BadOption& c : cases) {
    SimulatedScanner scanner;
    c.spoil(scanner);
    const Result<SimulatedScan> scan = SimulateScan(scene, scanner);
    ASSERT_FALSE(scan.ok()) << c.field;
    EXPECT_EQ(scan.status().code(), StatusCode::kInvalidArgument) << c.field;
    EXPECT_EQ(scan.status().message().rfind(c.field, 0), 0u) << scan.status().message();
  }
}

TEST(ScannerSimTest, TooManyBeamsIsResourceExhausted) {
  SimulatedScanner scanner;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.01;
  const Result<SimulatedScan> scan = SimulateScan(WallAt(3.0, 1.0), scanner);
  ASSERT_FALSE(scan.ok());
  EXPECT_EQ(scan.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(scan.status().message().find("horizontal_step_deg"), std::string::npos);
}

// Steps so small that the beam counts overflow a uint64 (or their product wraps below the limit)
// are refused by the limit too, never cast out of range.
TEST(ScannerSimTest, AVanishingStepIsResourceExhaustedNotAnOverflow) {
  for (const double step : {1e-300, 1e-10, 1e-7}) {
    SimulatedScanner scanner;
    scanner.horizontal_step_deg = scanner.vertical_step_deg = step;
    EXPECT_GT(scanner.BeamCount(), kMaxSimulatedBeams) << step;
    const Result<SimulatedScan> scan = SimulateScan(WallAt(3.0, 1.0), scanner);
    ASSERT_FALSE(scan.ok()) << step;
    EXPECT_EQ(scan.status().code(), StatusCode::kResourceExhausted) << step;
  }
}

struct BadScene {
  const char* message_start;
  ScenePrimitive primitive;
};

TEST(ScannerSimTest, BadPrimitivesAreNamedErrors) {
  Eigen::Matrix3d skew = Eigen::Matrix3d::Identity();
  skew(0, 1) = 0.5;
  const BadScene cases[] = {
      {"scene.primitives[1] (polygon).vertices_m needs at least 3", ScenePolygon{{{0, 0, 0}, {1, 0, 0}}}},
      {"scene.primitives[1] (polygon).vertices_m are collinear", ScenePolygon{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}}},
      {"scene.primitives[1] (polygon).vertices_m are not coplanar",
       ScenePolygon{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.01}}}},
      {"scene.primitives[1] (box).half_extent_m", SceneBox{{0, 0, 0}, {1, 0, 1}}},
      {"scene.primitives[1] (box).rotation", SceneBox{{0, 0, 0}, {1, 1, 1}, skew}},
      {"scene.primitives[1] (cylinder).radius_m", SceneCylinder{{0, 0, 0}, {0, 0, 1}, 0.0}},
      {"scene.primitives[1] (cylinder).top_m", SceneCylinder{{0, 0, 1}, {0, 0, 1}, 0.1}},
  };
  for (const BadScene& c : cases) {
    AnalyticScene scene = WallAt(3.0, 1.0);
    scene.primitives.push_back(c.primitive);
    const Result<SimulatedScan> scan = SimulateScan(scene, SimulatedScanner{});
    ASSERT_FALSE(scan.ok()) << c.message_start;
    EXPECT_EQ(scan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(scan.status().message().rfind(c.message_start, 0), 0u) << scan.status().message();
  }
}

}  // namespace
}  // namespace vc
