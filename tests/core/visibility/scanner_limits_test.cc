// The scanner model's limits (vc/visibility/scanner_limits.h) against hand-checkable answers: an
// open floor seen from above, where the range keeps a ring, the blind cone under the tripod
// removes a disc, and the incidence and spacing limits keep a disc. The expected sets are computed
// here in world coordinates with their own formulas, not with ScannerLimits.
#include "vc/visibility/scanner_limits.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>

#include "testing/scenes.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/visibility/visibility.h"

namespace vc {
namespace {

constexpr double kR = 0.1;  // resolution (m)
constexpr int kSide = 80;   // the floor is kSide x kSide voxels: 8 m x 8 m, its top at z = 0.1 m
const WorldPoint kStation(4.03, 3.97, 1.6);

VoxelScene Floor() {
  std::vector<VoxelIndex> v;
  for (int x = 0; x < kSide; ++x)
    for (int y = 0; y < kSide; ++y) v.push_back({x, y, 0});
  return testing::SceneOfVoxels(v, kR);
}

double Deg(double rad) { return rad * 180.0 / std::numbers::pi; }

// What the station sees of the floor, by the selection test `test`, with `scanner`, against
// `want(aim)`: the expected answer from the aim point (the top face's centre, or the voxel's
// centre under compatibility, both judged on the top face). Returns how many are seen.
size_t ExpectFloorSeen(const ScannerModel& scanner, SelectionTest test,
                       const std::function<bool(const WorldPoint& aim)>& want, const std::string& what) {
  const VoxelScene s = Floor();
  VisibilitySetsOptions o;
  o.test = test;
  o.scanner = scanner;
  o.threads = 2;
  VisibilitySetsOptions per_voxel = o;
  per_voxel.per_voxel = true;
  auto sets = ComputeVisibilitySets(s, {kStation}, o);
  auto plain = ComputeVisibilitySets(s, {kStation}, per_voxel);
  EXPECT_TRUE(sets.ok() && plain.ok()) << what;
  if (!sets.ok() || !plain.ok()) return 0;
  size_t seen = 0, wrong = 0;
  for (size_t id = 0; id < s.occupied.size(); ++id) {
    const VoxelIndex v = KeyToIndex(s.occupied[id]);
    const WorldPoint aim((v.x + 0.5) * kR, (v.y + 0.5) * kR,
                         test == SelectionTest::kSurfaceVisibility ? (v.z + 1) * kR : (v.z + 0.5) * kR);
    // Under compatibility, rays that graze the floor meet a neighbour first: only the line of
    // sight decides those, so the expectation is the line-of-sight answer and the limits.
    const bool los = test == SelectionTest::kSurfaceVisibility ? true : IsCompatible(s.grid, kStation, v);
    const bool expected = los && want(aim);
    wrong += (*sets)[0].test(id) != expected;
    wrong += (*plain)[0].test(id) != expected;
    const bool single = test == SelectionTest::kSurfaceVisibility ? IsSurfaceVisible(s.grid, kStation, v, scanner)
                                                                  : IsCompatible(s.grid, kStation, v, scanner);
    wrong += single != expected;
    seen += expected;
  }
  EXPECT_EQ(wrong, 0u) << what;
  return seen;
}

double Distance(const WorldPoint& aim) { return (aim - kStation).norm(); }
double Horizontal(const WorldPoint& aim) { return std::hypot(aim.x() - kStation.x(), aim.y() - kStation.y()); }
double Elevation(const WorldPoint& aim) { return Deg(std::atan2(aim.z() - kStation.z(), Horizontal(aim))); }
// The angle between the top face's normal (+z) and the direction to the station.
double Incidence(const WorldPoint& aim) { return Deg(std::acos((kStation.z() - aim.z()) / Distance(aim))); }

TEST(ScannerLimitsTest, TheRangeKeepsARingOfTheFloor) {
  for (SelectionTest test : {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility}) {
    ScannerModel sc;
    sc.min_range_m = 2.0;
    sc.max_range_m = 3.2;
    const size_t seen = ExpectFloorSeen(
        sc, test, [&](const WorldPoint& a) { return Distance(a) >= 2.0 && Distance(a) <= 3.2; }, "range");
    // The ring's area over a voxel's: pi (R^2 - r^2) / 0.01 with R, r its radii on the floor.
    const double h = kStation.z() - 0.1;
    const double ring = std::numbers::pi * ((3.2 * 3.2 - h * h) - (2.0 * 2.0 - h * h)) / (kR * kR);
    // Under compatibility the floor's grazing rays meet a neighbour first: fewer, but some.
    if (test == SelectionTest::kSurfaceVisibility) {
      EXPECT_NEAR(double(seen), ring, 0.03 * ring);
    } else {
      EXPECT_GT(seen, 100u);
    }
  }
}

TEST(ScannerLimitsTest, TheBlindConeUnderTheTripodRemovesADisc) {
  ScannerModel sc;
  sc.vfov_min_deg = -60;  // a 30 degree blind cone straight down
  const size_t seen = ExpectFloorSeen(
      sc, SelectionTest::kSurfaceVisibility, [&](const WorldPoint& a) { return Elevation(a) >= -60; }, "vfov");
  // The disc removed has radius h tan(30 deg).
  const double h = kStation.z() - 0.1, radius = h * std::tan(std::numbers::pi / 6);
  const double disc = std::numbers::pi * radius * radius / (kR * kR);
  EXPECT_NEAR(double(kSide * kSide - seen), disc, 0.05 * disc);
  // A field of view that ends below the horizon sees the floor and nothing above it; one that
  // starts above the horizon sees no floor at all.
  sc.vfov_min_deg = 5;
  EXPECT_EQ(ExpectFloorSeen(
                sc, SelectionTest::kSurfaceVisibility, [](const WorldPoint&) { return false; }, "up"),
            0u);
}

TEST(ScannerLimitsTest, TheIncidenceLimitKeepsADisc) {
  for (SelectionTest test : {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility}) {
    ScannerModel sc;
    sc.max_incidence_deg = 45;
    const size_t seen = ExpectFloorSeen(
        sc, test, [&](const WorldPoint& a) { return Incidence(a) <= 45; }, "incidence");
    if (test == SelectionTest::kSurfaceVisibility) {
      const double h = kStation.z() - 0.1;  // the disc's radius: h tan(45 deg) = h
      EXPECT_NEAR(double(seen), std::numbers::pi * h * h / (kR * kR), 0.03 * std::numbers::pi * h * h / (kR * kR));
    } else {
      EXPECT_GT(seen, 0u);
    }
  }
}

TEST(ScannerLimitsTest, ThePointSpacingRequirementKeepsADisc) {
  ScannerModel sc;
  sc.angular_step_deg = 0.036;  // about 6 mm at 10 m
  sc.max_spacing_m = 0.002;
  const double step = sc.angular_step_deg * std::numbers::pi / 180;
  const size_t seen = ExpectFloorSeen(
      sc, SelectionTest::kSurfaceVisibility,
      [&](const WorldPoint& a) {
        const double cos_inc = (kStation.z() - a.z()) / Distance(a);
        return Distance(a) * step / cos_inc <= 0.002;
      },
      "spacing");
  EXPECT_GT(seen, 100u);
  EXPECT_LT(seen, size_t(kSide * kSide / 2));
}

TEST(ScannerLimitsTest, EveryLimitAtOnceIsTheirConjunction) {
  ScannerModel sc;
  sc.min_range_m = 1.7;
  sc.max_range_m = 3.5;
  sc.vfov_min_deg = -70;
  sc.vfov_max_deg = 80;
  sc.max_incidence_deg = 60;
  sc.angular_step_deg = 0.05;
  sc.max_spacing_m = 0.004;
  const double step = sc.angular_step_deg * std::numbers::pi / 180;
  for (SelectionTest test : {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility}) {
    EXPECT_GT(ExpectFloorSeen(
                  sc, test,
                  [&](const WorldPoint& a) {
                    const double d = Distance(a), cos_inc = (kStation.z() - a.z()) / d;
                    return d >= 1.7 && d <= 3.5 && Elevation(a) >= -70 && Elevation(a) <= 80 && Incidence(a) <= 60 &&
                           d * step / cos_inc <= 0.004;
                  },
                  "all"),
              0u)
        << SelectionTestName(test);
  }
}

// Ties are inclusive: with r = 1 m every quantity below is exact, and an aim point exactly at a
// limit passes.
TEST(ScannerLimitsTest, AnAimPointExactlyOnALimitPasses) {
  const VoxelScene s = testing::SceneOfVoxels({{0, 0, 0}}, 1.0);
  const WorldPoint above(0.5, 0.5, 4.0);  // 3 m above the top face's centre
  ScannerModel sc;
  sc.max_range_m = 3.0;
  EXPECT_TRUE(IsSurfaceVisible(s.grid, above, {0, 0, 0}, sc));
  sc.max_range_m = 2.999;
  EXPECT_FALSE(IsSurfaceVisible(s.grid, above, {0, 0, 0}, sc));
  sc = ScannerModel();
  sc.min_range_m = 3.0;
  sc.max_range_m = 10;
  EXPECT_TRUE(IsSurfaceVisible(s.grid, above, {0, 0, 0}, sc));
  sc.min_range_m = 3.001;
  EXPECT_FALSE(IsSurfaceVisible(s.grid, above, {0, 0, 0}, sc));
  // Straight down is elevation -90, which vfov_min_deg = -90 keeps and -89.9 does not.
  sc = ScannerModel();
  sc.vfov_min_deg = -90;
  sc.vfov_max_deg = 0;
  EXPECT_TRUE(IsSurfaceVisible(s.grid, above, {0, 0, 0}, sc));
  sc.vfov_min_deg = -89.9;
  EXPECT_FALSE(IsSurfaceVisible(s.grid, above, {0, 0, 0}, sc));
  // From (3.5, 0.5, 4): the top face's centre is 3 m across and 3 m down, incidence 45 degrees.
  // cos(45 deg)^2 rounds, so 45 itself is within rounding; 45.001 passes and 44.999 does not.
  const WorldPoint diagonal(3.5, 0.5, 4.0);
  sc = ScannerModel();
  sc.max_incidence_deg = 45.001;
  EXPECT_TRUE(IsSurfaceVisible(s.grid, diagonal, {0, 0, 0}, sc));
  sc.max_incidence_deg = 44.999;
  EXPECT_FALSE(IsSurfaceVisible(s.grid, diagonal, {0, 0, 0}, sc));
  // Without a scanner there is no limit at all, not even the default range.
  EXPECT_TRUE(IsSurfaceVisible(s.grid, WorldPoint(0.5, 0.5, 1.2), {0, 0, 0}));
  EXPECT_FALSE(IsSurfaceVisible(s.grid, WorldPoint(0.5, 0.5, 1.2), {0, 0, 0}, ScannerModel()));
}

TEST(ScannerLimitsTest, EntryFaceIsTheLastSlabEnteredAndTheLowestAxisOnATie) {
  const ScannerLimits l(ScannerModel(), 1.0, Eigen::Vector3d(0.5, 0.5, 10.5));
  int axis, sign;
  l.EntryFace({0, 0, 0}, &axis, &sign);  // straight down: the top face
  EXPECT_EQ(axis, 2);
  EXPECT_EQ(sign, 1);
  const ScannerLimits side(ScannerModel(), 1.0, Eigen::Vector3d(10.5, 0.5, 1.5));
  side.EntryFace({0, 0, 0}, &axis, &sign);  // from +x, slightly above: enters through +x
  EXPECT_EQ(axis, 0);
  EXPECT_EQ(sign, 1);
  const ScannerLimits diagonal(ScannerModel(), 1.0, Eigen::Vector3d(-4.5, 5.5, 0.5));
  diagonal.EntryFace({0, 0, 0}, &axis, &sign);  // through the edge of -x and +y: x, the lowest axis
  EXPECT_EQ(axis, 0);
  EXPECT_EQ(sign, -1);
}

// BoxVerdict may only decide a box whole when every point of it would get that answer from
// Passes: random boxes around random stations, with the range and the vertical field of view on,
// and points sampled in each box (corners included).
TEST(ScannerLimitsTest, ABoxDecidedWholeHoldsOnlyPointsWithThatAnswer) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  size_t all = 0, none = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    ScannerModel sc;
    sc.min_range_m = 2 * u(rng);
    sc.max_range_m = sc.min_range_m + 0.5 + 20 * u(rng);
    sc.vfov_min_deg = trial % 3 == 0 ? -90 : -89 + 100 * u(rng);
    sc.vfov_max_deg = trial % 3 == 1 ? 90 : std::max(sc.vfov_min_deg + 1, -60 + 150 * u(rng));
    if (sc.vfov_max_deg > 90) sc.vfov_max_deg = 90;
    const double r = 0.1;
    const Eigen::Vector3d uo(40 * u(rng), 40 * u(rng), 40 * u(rng));
    const ScannerLimits l(sc, r, uo);
    const Eigen::Vector3d lo(40 * u(rng) + 20 * u(rng) - 10, 40 * u(rng), 40 * u(rng) - 10);
    const Eigen::Vector3d hi = lo + Eigen::Vector3d(8, 8, 8) * u(rng);
    const auto verdict = l.BoxVerdict(lo, hi);
    if (verdict == ScannerLimits::Verdict::kSome) continue;
    (verdict == ScannerLimits::Verdict::kAll ? all : none) += 1;
    for (int k = 0; k < 64; ++k) {
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a) p[a] = k < 8 ? ((k >> a) & 1 ? hi[a] : lo[a]) : lo[a] + (hi[a] - lo[a]) * u(rng);
      ASSERT_EQ(l.Passes(p, 0, 1), verdict == ScannerLimits::Verdict::kAll) << trial << " point " << k;
    }
  }
  EXPECT_GT(all, 100u);
  EXPECT_GT(none, 100u);
}

// V (ALGORITHM.md s.5) is 0 for a face that fails a limit and unchanged for one that passes.
TEST(ScannerLimitsTest, EvaluationGivesVZeroOutsideTheLimitsAndTheSameVInside) {
  const VoxelScene s = Floor();
  EvaluateOptions plain;
  plain.threads = 2;
  plain.keep_per_viewpoint_values = true;
  EvaluateOptions limited = plain;
  limited.scanner.max_incidence_deg = 45;
  limited.scanner.vfov_min_deg = -60;
  auto a = Evaluate(s, {kStation}, plain);
  auto b = Evaluate(s, {kStation}, limited);
  ASSERT_TRUE(a.ok() && b.ok());
  size_t kept = 0, zeroed = 0;
  for (size_t id = 0; id < s.occupied.size(); ++id) {
    const VoxelIndex v = KeyToIndex(s.occupied[id]);
    const size_t slot = id * kFacesPerVoxel + size_t(Face::kPosZ);
    const WorldPoint aim((v.x + 0.5) * kR, (v.y + 0.5) * kR, kR);
    const float va = a->per_viewpoint_face_values[0][slot], vb = b->per_viewpoint_face_values[0][slot];
    if (Incidence(aim) <= 45 && Elevation(aim) >= -60) {
      EXPECT_EQ(vb, va) << id;
      kept += va > 0;
    } else {
      EXPECT_EQ(vb, 0.0f) << id;
      zeroed += va > 0;
    }
  }
  EXPECT_GT(kept, 100u);
  EXPECT_GT(zeroed, 100u);
  EXPECT_LT(b->overall.global_visibility, a->overall.global_visibility);
}

// --- The horizontal field of view: an aim point's azimuth within heading +- hfov / 2 ---

// The reference's own azimuth test: atan2, in degrees, the difference to the heading wrapped to
// [-180, 180]. `near_edge` is set when the aim point lies within 1e-9 deg of an edge, where the
// engine's rounding may answer either way.
bool InSector(double dx, double dy, double heading_deg, double hfov_deg, bool* near_edge) {
  *near_edge = false;
  if (hfov_deg >= 360 || (dx == 0 && dy == 0)) return true;
  const double off = std::abs(std::remainder(Deg(std::atan2(dy, dx)) - heading_deg, 360.0));
  *near_edge = std::abs(off - hfov_deg / 2) < 1e-9;
  return off <= hfov_deg / 2;
}

// A floor and random blocks in a 24 x 24 x 12 voxel box (0.1 m voxels).
VoxelScene ClutteredScene(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> c(0, 23), h(1, 11);
  std::vector<VoxelIndex> v;
  for (int x = 0; x < 24; ++x)
    for (int y = 0; y < 24; ++y) v.push_back({x, y, 0});
  for (int i = 0; i < 260; ++i) v.push_back({c(rng), c(rng), h(rng)});
  return testing::SceneOfVoxels(v, kR);
}

// Per ray, independently of ScannerLimits: voxel v passes `test` from uo (index space) with only
// the azimuth limit on. Surface: some exposed face facing uo whose centre is in the sector and
// reached with v transparent; compatibility: v's centre is in the sector and the first occupied
// voxel on the way. Counts aim points on an edge in *edges (their answer is not compared).
bool ReferenceInSector(const OccupancyGrid& g, const Eigen::Vector3d& uo, const VoxelIndex& v, SelectionTest test,
                       double heading_deg, double hfov_deg, size_t* edges) {
  if (g.Occupied(int(std::floor(uo.x())), int(std::floor(uo.y())), int(std::floor(uo.z())))) return false;
  bool near_edge = false;
  if (test == SelectionTest::kCompatibility) {
    const Eigen::Vector3d c(v.x + 0.5, v.y + 0.5, v.z + 0.5);
    const bool in = InSector(c.x() - uo.x(), c.y() - uo.y(), heading_deg, hfov_deg, &near_edge);
    *edges += near_edge;
    const auto hit = FirstOccupied(g, uo, c);
    return in && hit && *hit == v;
  }
  bool seen = false;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const double plane = (axis == 0 ? v.x : axis == 1 ? v.y : v.z) + side;
      if (!(side ? uo[axis] > plane : uo[axis] < plane)) continue;
      VoxelIndex n = v;
      (axis == 0 ? n.x : axis == 1 ? n.y : n.z) += side ? 1 : -1;
      if (g.Occupied(n)) continue;
      Eigen::Vector3d c(v.x + 0.5, v.y + 0.5, v.z + 0.5);
      c[axis] = plane;
      const bool in = InSector(c.x() - uo.x(), c.y() - uo.y(), heading_deg, hfov_deg, &near_edge);
      *edges += near_edge;
      if (in && !FirstOccupied(g, uo, c, &v)) seen = true;
    }
  }
  return seen;
}

// Grouped and per-voxel sets with a heading per viewpoint equal the per-ray reference on cluttered
// scenes, for narrow, half, wider-than-half and nearly full fields of view, with headings on both
// sides of the wrap-around at +-180 deg.
TEST(ScannerLimitsTest, TheSectorEqualsAPerRayReferenceOnClutteredScenes) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.3, 2.1);
  const double hfovs[] = {20, 90, 179.9, 180, 182, 270, 359};
  const double headings[] = {0, 37.3, 90, -120.4, 179.5, -179.5, 180};
  size_t compared = 0, seen = 0, edges = 0;
  for (int trial = 0; trial < 3; ++trial) {
    const VoxelScene s = ClutteredScene(rng);
    std::vector<WorldPoint> vps;
    std::vector<Heading> vp_headings;
    for (size_t k = 0; k < std::size(headings); ++k) {
      vps.emplace_back(u(rng), u(rng), 0.12 + 0.5 * u(rng));
      vp_headings.push_back(headings[(k + size_t(trial)) % std::size(headings)]);
    }
    for (const double hfov : hfovs) {
      ScannerModel sc;
      sc.min_range_m = 0;
      sc.hfov_deg = hfov;
      for (SelectionTest test : {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility}) {
        for (bool per_voxel : {false, true}) {
          VisibilitySetsOptions o;
          o.test = test;
          o.scanner = sc;
          o.headings_deg = vp_headings;
          o.per_voxel = per_voxel;
          o.threads = 2;
          auto sets = ComputeVisibilitySets(s, vps, o);
          ASSERT_TRUE(sets.ok()) << sets.status().ToString();
          for (size_t k = 0; k < vps.size(); ++k) {
            const Eigen::Vector3d uo = s.grid.WorldToIndexSpace(vps[k]);
            for (size_t id = 0; id < s.occupied.size(); ++id) {
              const size_t edges_before = edges;
              const bool want =
                  ReferenceInSector(s.grid, uo, KeyToIndex(s.occupied[id]), test, *vp_headings[k], hfov, &edges);
              if (edges != edges_before) continue;
              ASSERT_EQ((*sets)[k].test(id), want)
                  << "trial " << trial << " hfov " << hfov << " heading " << *vp_headings[k] << " "
                  << SelectionTestName(test) << (per_voxel ? " per voxel" : " grouped") << " voxel " << id;
              ++compared;
              seen += want;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(seen, compared / 10);
  EXPECT_LT(seen, compared);
  EXPECT_LT(edges, compared / 1000);
}

// On the open floor the sector is exactly what an atan2 of each top face's centre says, and a
// heading turned by 360 deg is the same heading.
TEST(ScannerLimitsTest, TheHorizontalFieldOfViewKeepsASectorOfTheFloor) {
  const VoxelScene s = Floor();
  ScannerModel sc;
  sc.hfov_deg = 100;
  size_t counted = 0;
  for (const double heading : {-170.0, 10.0, 190.0}) {
    VisibilitySetsOptions o;
    o.scanner = sc;
    o.headings_deg = {heading};
    o.threads = 2;
    auto sets = ComputeVisibilitySets(s, {kStation}, o);
    ASSERT_TRUE(sets.ok()) << sets.status().ToString();
    size_t seen = 0;
    for (size_t id = 0; id < s.occupied.size(); ++id) {
      const VoxelIndex v = KeyToIndex(s.occupied[id]);
      const WorldPoint aim((v.x + 0.5) * kR, (v.y + 0.5) * kR, kR);
      bool edge = false;
      const bool want = Distance(aim) >= sc.min_range_m &&
                        InSector(aim.x() - kStation.x(), aim.y() - kStation.y(), heading, sc.hfov_deg, &edge);
      ASSERT_FALSE(edge);
      ASSERT_EQ((*sets)[0].test(id), want) << heading << " voxel " << id;
      seen += want;
    }
    if (heading == -170.0) counted = seen;
    if (heading == 190.0) {
      EXPECT_EQ(seen, counted);  // 190 deg is -170 deg
    }
    EXPECT_GT(seen, s.occupied.size() / 5);
    EXPECT_LT(seen, s.occupied.size() / 2);
  }
}

// BoxVerdict with a heading may only decide a box whole when every point of it gets that answer:
// kNone (skipped) never holds a point in the sector, kAll only points in it.
TEST(ScannerLimitsTest, ABoxPartlyInTheSectorIsNeverSkipped) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  size_t all = 0, none = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    ScannerModel sc;
    sc.min_range_m = 0.2 * u(rng);
    sc.max_range_m = 100;
    sc.hfov_deg = trial % 4 == 0 ? 180.0 : 1 + 358 * u(rng);
    const double heading = -540 + 1080 * u(rng);
    const Eigen::Vector3d uo(40 * u(rng), 40 * u(rng), 40 * u(rng));
    const ScannerLimits l(sc, 0.1, uo, heading);
    ASSERT_TRUE(l.LimitsAzimuth());
    const Eigen::Vector3d lo(60 * u(rng) - 10, 60 * u(rng) - 10, 40 * u(rng));
    const Eigen::Vector3d hi = lo + Eigen::Vector3d(12 * u(rng), 12 * u(rng), 4 * u(rng));
    const auto verdict = l.BoxVerdict(lo, hi);
    if (verdict == ScannerLimits::Verdict::kSome) continue;
    (verdict == ScannerLimits::Verdict::kAll ? all : none) += 1;
    for (int k = 0; k < 64; ++k) {
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a) p[a] = k < 8 ? ((k >> a) & 1 ? hi[a] : lo[a]) : lo[a] + (hi[a] - lo[a]) * u(rng);
      ASSERT_EQ(l.Passes(p, 0, 1), verdict == ScannerLimits::Verdict::kAll) << trial << " point " << k;
    }
  }
  EXPECT_GT(all, 500u);
  EXPECT_GT(none, 500u);
  // Without a heading, or with hfov 360, the azimuth limits nothing.
  ScannerModel sc;
  sc.hfov_deg = 90;
  EXPECT_FALSE(ScannerLimits(sc, 0.1, Eigen::Vector3d::Zero()).LimitsAzimuth());
  sc.hfov_deg = 360;
  EXPECT_FALSE(ScannerLimits(sc, 0.1, Eigen::Vector3d::Zero(), 45.0).LimitsAzimuth());
}

// V is 0 for a face whose centre is outside the sector and unchanged inside it.
TEST(ScannerLimitsTest, EvaluationWithAHeadingGivesVZeroOutsideTheSector) {
  const VoxelScene s = Floor();
  EvaluateOptions plain;
  plain.threads = 2;
  plain.keep_per_viewpoint_values = true;
  EvaluateOptions limited = plain;
  limited.scanner.hfov_deg = 182;
  limited.headings_deg = {-100.0};
  auto a = Evaluate(s, {kStation}, plain);
  auto b = Evaluate(s, {kStation}, limited);
  ASSERT_TRUE(a.ok() && b.ok()) << b.status().ToString();
  size_t kept = 0, zeroed = 0;
  for (size_t id = 0; id < s.occupied.size(); ++id) {
    const VoxelIndex v = KeyToIndex(s.occupied[id]);
    const size_t slot = id * kFacesPerVoxel + size_t(Face::kPosZ);
    const WorldPoint aim((v.x + 0.5) * kR, (v.y + 0.5) * kR, kR);
    const float va = a->per_viewpoint_face_values[0][slot], vb = b->per_viewpoint_face_values[0][slot];
    bool edge = false;
    if (InSector(aim.x() - kStation.x(), aim.y() - kStation.y(), -100.0, 182, &edge)) {
      EXPECT_EQ(vb, va) << id;
      kept += va > 0;
    } else {
      EXPECT_EQ(vb, 0.0f) << id;
      zeroed += va > 0;
    }
  }
  EXPECT_GT(kept, 1000u);
  EXPECT_GT(zeroed, 1000u);
}

TEST(ScannerLimitsTest, AFieldOfViewBelow360WithoutAHeadingIsRefusedNamingTheViewpoint) {
  const VoxelScene s = Floor();
  const std::vector<WorldPoint> vps = {kStation, kStation + WorldPoint(1, 0, 0)};
  VisibilitySetsOptions o;
  o.scanner = ScannerModel();
  o.scanner->hfov_deg = 182;
  o.headings_deg = {0.0, std::nullopt};
  auto sets = ComputeVisibilitySets(s, vps, o);
  ASSERT_EQ(sets.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(sets.status().message().find("viewpoint 2 has no heading"), std::string::npos) << sets.status().ToString();
  o.headings_deg.clear();
  EXPECT_NE(ComputeVisibilitySets(s, vps, o).status().message().find("viewpoint 1 has no heading"), std::string::npos);
  o.headings_deg = {0.0};
  EXPECT_NE(ComputeVisibilitySets(s, vps, o).status().message().find("1 headings for 2 viewpoints"), std::string::npos);
  o.headings_deg = {0.0, std::numeric_limits<double>::infinity()};
  EXPECT_NE(ComputeVisibilitySets(s, vps, o).status().message().find("viewpoint 2 has a heading that is not finite"),
            std::string::npos);
  o.headings_deg = {0.0, 90.0};
  EXPECT_TRUE(ComputeVisibilitySets(s, vps, o).ok());
  // With hfov 360 a heading is optional and changes nothing.
  o.scanner->hfov_deg = 360;
  o.headings_deg = {0.0, std::nullopt};
  auto with = ComputeVisibilitySets(s, vps, o);
  o.headings_deg.clear();
  auto without = ComputeVisibilitySets(s, vps, o);
  ASSERT_TRUE(with.ok() && without.ok());
  EXPECT_EQ((*with)[0].count(), (*without)[0].count());
  // Evaluate refuses the same.
  EvaluateOptions e;
  e.scanner.hfov_deg = 90;
  e.headings_deg = {std::nullopt, 0.0};
  auto ev = Evaluate(s, vps, e);
  ASSERT_EQ(ev.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(ev.status().message().find("viewpoint 1 has no heading"), std::string::npos) << ev.status().ToString();
}

TEST(ScannerModelTest, InvalidLimitsNameTheirField) {
  auto message = [](ScannerModel s) { return s.Validate().message(); };
  ScannerModel s;
  EXPECT_TRUE(s.Validate().ok());
  s.vfov_min_deg = 10;
  s.vfov_max_deg = 10;
  EXPECT_NE(message(s).find("scanner.vfov_max_deg"), std::string::npos);
  s = ScannerModel();
  s.vfov_min_deg = std::nan("");
  EXPECT_NE(message(s).find("scanner.vfov_min_deg"), std::string::npos);
  s = ScannerModel();
  s.max_incidence_deg = 0;
  EXPECT_NE(message(s).find("scanner.max_incidence_deg"), std::string::npos);
  s.max_incidence_deg = 90.5;
  EXPECT_NE(message(s).find("scanner.max_incidence_deg"), std::string::npos);
  s = ScannerModel();
  s.max_spacing_m = 0.01;
  EXPECT_NE(message(s).find("scanner.angular_step_deg"), std::string::npos);
  s.angular_step_deg = 0.036;
  EXPECT_TRUE(s.Validate().ok());
  s.max_spacing_m = -1;
  EXPECT_NE(message(s).find("scanner.max_spacing_m"), std::string::npos);
  for (const double bad : {0.0, -10.0, 360.5, std::nan("")}) {
    s = ScannerModel();
    s.hfov_deg = bad;
    EXPECT_NE(message(s).find("scanner.hfov_deg"), std::string::npos) << bad;
  }
  s.hfov_deg = 360;
  EXPECT_TRUE(s.Validate().ok());
  s.hfov_deg = 0.5;
  EXPECT_TRUE(s.Validate().ok());
}

}  // namespace
}  // namespace vc
