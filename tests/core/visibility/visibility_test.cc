#include "vc/visibility/visibility.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "testing/scenes.h"
#include "vc/raycast/occluders.h"
#include "vc/raycast/ray_traversal.h"

namespace vc {
namespace {

using Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

// A scene at resolution 1 m from voxel indices (index = world metres, so hand computation is easy).
VoxelScene MakeScene(const std::vector<VoxelIndex>& voxels, double r = 1.0) {
  return testing::SceneOfVoxels(voxels, r);
}

// ---- Hand-computed cases ----

TEST(PerceiveFaceTest, LoneVoxelIsTransparentSoEveryFaceIsFull) {
  // A single voxel seen from straight above: with the voxel itself transparent (paper s.2.1),
  // every corner ray ends in one of the 8 voxels around its corner, so all 6 faces are full.
  const VoxelScene s = MakeScene({{0, 0, 0}});
  const WorldPoint o(0.5, 0.5, 5.5);
  for (int f = 0; f < 6; ++f) EXPECT_EQ(PerceiveFace(s.grid, o, {0, 0, 0}, Face(f)), Perception::kFull) << f;
}

TEST(PerceiveFaceTest, FaceBehindAWallIsNotVisible) {
  std::vector<VoxelIndex> v = {{0, 0, 0}};
  for (int x = -5; x <= 5; ++x)
    for (int y = -5; y <= 5; ++y) v.push_back({x, y, 2});  // a plate at z in [2,3)
  const VoxelScene s = MakeScene(v);
  const WorldPoint o(0.5, 0.5, 5.5);
  EXPECT_EQ(PerceiveFace(s.grid, o, {0, 0, 0}, Face::kPosZ), Perception::kNone);
  EXPECT_EQ(FaceVisibility(s.grid, o, {0, 0, 0}, Face::kPosZ, {}), 0.0);
  EXPECT_FALSE(IsCompatible(s.grid, o, {0, 0, 0}));
  EXPECT_FALSE(IsSurfaceVisible(s.grid, o, {0, 0, 0}));
}

TEST(PerceiveFaceTest, HalfHiddenFaceIsPartial) {
  // Viewpoint (2.5, 0.5, 8.5). In the layer z in [2,3), the rays to the top corners with x = 0
  // run at x = (z - 1) / 3, in column 0; those to the corners with x = 1 run at
  // x = 1 + (z - 1) / 5, in column 1. A bar of voxels (0, -1..1, 2) hides exactly the two x = 0
  // corners: 2 of 4 visible -> partial, V = 0.3.
  std::vector<VoxelIndex> v = {{0, 0, 0}};
  for (int y = -1; y <= 1; ++y) v.push_back({0, y, 2});
  const VoxelScene s = MakeScene(v);
  const WorldPoint o(2.5, 0.5, 8.5);
  EXPECT_EQ(PerceiveFace(s.grid, o, {0, 0, 0}, Face::kPosZ), Perception::kPartial);
  EXPECT_DOUBLE_EQ(FaceVisibility(s.grid, o, {0, 0, 0}, Face::kPosZ, {}), 0.3);
  // Without the bar the same face is full.
  const VoxelScene bare = MakeScene({{0, 0, 0}});
  EXPECT_EQ(PerceiveFace(bare.grid, o, {0, 0, 0}, Face::kPosZ), Perception::kFull);
}

TEST(VisibilityValueTest, HandValues) {
  const ScannerModel s;  // [0.5, 75] m
  // d = 10.5 m, theta = 60 deg: D = 10/74.5, A = 1/3.
  EXPECT_NEAR(VisibilityValue(Perception::kFull, 10.5, kPi / 3, s), 0.5 + 0.3 * (1 - 10.0 / 74.5) + 0.2 / 3, 1e-12);
  // Head-on from either side (theta = 0 or pi) gives A = 1; grazing (pi/2) gives A = 0.
  EXPECT_NEAR(VisibilityValue(Perception::kFull, 0.5, 0.0, s), 1.0, 1e-12);
  EXPECT_NEAR(VisibilityValue(Perception::kFull, 0.5, kPi, s), 1.0, 1e-12);
  EXPECT_NEAR(VisibilityValue(Perception::kFull, 0.5, kPi / 2, s), 0.8, 1e-12);
  // At Rmax, D = 1: only the class constant and the angle term remain.
  EXPECT_NEAR(VisibilityValue(Perception::kFull, 75.0, 0.0, s), 0.7, 1e-12);
  EXPECT_DOUBLE_EQ(VisibilityValue(Perception::kPartial, 20.0, 1.0, s), 0.3);
  EXPECT_DOUBLE_EQ(VisibilityValue(Perception::kNone, 20.0, 0.0, s), 0.0);
  // Outside [Rmin, Rmax]: not visible, whatever the class.
  EXPECT_DOUBLE_EQ(VisibilityValue(Perception::kFull, 0.49, 0.0, s), 0.0);
  EXPECT_DOUBLE_EQ(VisibilityValue(Perception::kFull, 75.01, 0.0, s), 0.0);
  EXPECT_DOUBLE_EQ(VisibilityValue(Perception::kPartial, 80, 0.0, s), 0.0);
}

TEST(FaceVisibilityTest, DistanceAndAngleMeasuredToFaceCentre) {
  const VoxelScene s = MakeScene({{0, 0, 0}});
  // Top face centre (0.5, 0.5, 1); viewpoint 4 m straight above: d = 4, head-on.
  EXPECT_NEAR(FaceVisibility(s.grid, WorldPoint(0.5, 0.5, 5.0), {0, 0, 0}, Face::kPosZ, {}),
              0.5 + 0.3 * (1 - 3.5 / 74.5) + 0.2, 1e-12);
  // +x face centre (1, 0.5, 0.5) from (4, 0.5, 3.5): ray (-3, 0, -3), 45 deg off the normal.
  EXPECT_NEAR(FaceVisibility(s.grid, WorldPoint(4, 0.5, 3.5), {0, 0, 0}, Face::kPosX, {}),
              0.5 + 0.3 * (1 - (std::sqrt(18.0) - 0.5) / 74.5) + 0.2 * 0.5, 1e-12);
}

TEST(ScannerModelTest, RejectsBadRanges) {
  EXPECT_TRUE(ScannerModel{}.Validate().ok());
  EXPECT_FALSE((ScannerModel{2.0, 1.0}).Validate().ok());
  EXPECT_FALSE((ScannerModel{std::nan(""), 1.0}).Validate().ok());
  EXPECT_FALSE((ScannerModel{-1.0, 10.0}).Validate().ok());
}

TEST(SelectionTestsTest, CompatibilityHasThe45DegreeConeSurfaceVisibilityDoesNot) {
  // A floor plate one voxel thick; viewpoint 1.5 m above voxel (0,0,0)'s centre.
  std::vector<VoxelIndex> v;
  for (int x = -45; x <= 45; ++x)
    for (int y = -5; y <= 5; ++y) v.push_back({x, y, 0});
  const VoxelScene s = MakeScene(v, 0.1);
  const WorldPoint o(0.05, 0.05, 1.6);
  EXPECT_TRUE(IsCompatible(s.grid, o, {0, 0, 0}));
  EXPECT_TRUE(IsSurfaceVisible(s.grid, o, {0, 0, 0}));
  // 0.9 m off (about 30 deg from the normal): still inside the cone.
  EXPECT_TRUE(IsCompatible(s.grid, o, {9, 0, 0}));
  // 4 m off (about 69 deg): the ray to the centre enters the layer through a neighbour.
  EXPECT_FALSE(IsCompatible(s.grid, o, {-40, 0, 0}));
  EXPECT_TRUE(IsSurfaceVisible(s.grid, o, {-40, 0, 0}));
  // A viewpoint inside an occupied voxel sees nothing.
  EXPECT_FALSE(IsSurfaceVisible(s.grid, WorldPoint(0.05, 0.05, 0.05), {1, 0, 0}));
  EXPECT_FALSE(IsCompatible(s.grid, WorldPoint(0.05, 0.05, 0.05), {1, 0, 0}));
}

// ---- Oracles written plainly from the definitions ----

std::optional<VoxelIndex> PlainFirstHit(const OccupancyGrid& g, const Vector3d& a, const Vector3d& b,
                                        const VoxelIndex* transparent) {
  for (const VoxelIndex& v : RayTraversal(a, b)) {
    if (transparent && v == *transparent) continue;
    if (g.Occupied(v)) return v;
  }
  return std::nullopt;
}

bool PlainCompatible(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& v) {
  if (g.Occupied(int(std::floor(uo.x())), int(std::floor(uo.y())), int(std::floor(uo.z())))) return false;
  auto h = PlainFirstHit(g, uo, Vector3d(v.x + 0.5, v.y + 0.5, v.z + 0.5), nullptr);
  return h && *h == v;
}

bool PlainSurfaceVisible(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& v) {
  if (g.Occupied(int(std::floor(uo.x())), int(std::floor(uo.y())), int(std::floor(uo.z())))) return false;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const double plane = (axis == 0 ? v.x : axis == 1 ? v.y : v.z) + side;
      const bool facing = side ? uo[axis] > plane : uo[axis] < plane;
      if (!facing) continue;
      VoxelIndex n = v;
      (axis == 0 ? n.x : axis == 1 ? n.y : n.z) += side ? 1 : -1;
      if (g.Occupied(n)) continue;
      Vector3d c(v.x + 0.5, v.y + 0.5, v.z + 0.5);
      c[axis] = plane;
      if (!PlainFirstHit(g, uo, c, &v)) return true;
    }
  }
  return false;
}

double PlainFaceValue(const OccupancyGrid& g, const WorldPoint& o, const VoxelIndex& v, int face,
                      double max_range = 75) {
  const Vector3d uo = o / g.resolution_m();
  const int axis = face / 2, side = face % 2;
  int visible = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      Vector3d c(v.x, v.y, v.z);
      c[axis] += side;
      c[(axis + 1) % 3] += a;
      c[(axis + 2) % 3] += b;
      auto h = PlainFirstHit(g, uo, c, &v);
      const bool near =
          h && std::abs(h->x + 0.5 - c.x()) < 1 && std::abs(h->y + 0.5 - c.y()) < 1 && std::abs(h->z + 0.5 - c.z()) < 1;
      visible += (!h || near);
    }
  if (visible == 0) return 0;
  Vector3d center(v.x + 0.5, v.y + 0.5, v.z + 0.5);
  center[axis] += side ? 0.5 : -0.5;
  center *= g.resolution_m();
  const double d = (center - o).norm();
  if (d < 0.5 || d > max_range) return 0;
  if (visible < 4) return 0.3;
  Vector3d n = Vector3d::Zero();
  n[axis] = side ? 1 : -1;
  const double theta = std::acos(std::clamp((center - o).dot(n) / d, -1.0, 1.0));
  return 0.5 + 0.3 * (1 - (d - 0.5) / (max_range - 0.5)) + 0.2 * std::abs(theta - kPi / 2) / (kPi / 2);
}

VoxelScene RandomScene(std::mt19937_64& rng, int count, int extent, double r) {
  std::uniform_int_distribution<int> c(0, extent - 1);
  std::vector<VoxelIndex> v;
  for (int i = 0; i < count; ++i) v.push_back({c(rng), c(rng), c(rng)});
  // A floor, so some voxels are enclosed or half-hidden.
  for (int x = 0; x < extent; ++x)
    for (int y = 0; y < extent; ++y) v.push_back({x, y, 0});
  return MakeScene(v, r);
}

std::vector<WorldPoint> RandomViewpoints(std::mt19937_64& rng, int count, int extent, double r) {
  std::uniform_real_distribution<double> u(0.2, extent - 0.2);
  std::vector<WorldPoint> out;
  for (int i = 0; i < count; ++i) out.emplace_back(u(rng) * r, u(rng) * r, u(rng) * r);
  return out;
}

// The sets of `opt` against the plain oracles, voxel by voxel; returns how many are in a set.
size_t ExpectSetsMatchOracle(const VoxelScene& s, const std::vector<WorldPoint>& vps, const VisibilitySetsOptions& opt,
                             const std::string& what) {
  auto sets = ComputeVisibilitySets(s, vps, opt);
  EXPECT_TRUE(sets.ok()) << what;
  if (!sets.ok()) return 0;
  size_t positives = 0;
  for (size_t k = 0; k < vps.size(); ++k) {
    EXPECT_EQ((*sets)[k].size(), s.occupied.size()) << what << " vp " << k;
    if ((*sets)[k].size() != s.occupied.size()) return positives;
    const Vector3d uo = vps[k] / s.resolution_m;
    for (size_t id = 0; id < s.occupied.size(); ++id) {
      const VoxelIndex v = KeyToIndex(s.occupied[id]);
      const bool want = opt.test == SelectionTest::kCompatibility ? PlainCompatible(s.grid, uo, v)
                                                                  : PlainSurfaceVisible(s.grid, uo, v);
      EXPECT_EQ((*sets)[k].test(id), want) << what << " vp " << k << " voxel " << id;
      if ((*sets)[k].test(id) != want) return positives;
      positives += want;
    }
  }
  return positives;
}

TEST(ComputeVisibilitySetsTest, EqualsBruteForceOracleForBothTests) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 6; ++trial) {
    const VoxelScene s = RandomScene(rng, 120, 12, 0.1);
    const auto vps = RandomViewpoints(rng, 5, 12, 0.1);
    for (SelectionTest test : {SelectionTest::kCompatibility, SelectionTest::kSurfaceVisibility}) {
      VisibilitySetsOptions opt;
      opt.test = test;
      opt.threads = 2;
      EXPECT_GT(ExpectSetsMatchOracle(
                    s, vps, opt, "trial " + std::to_string(trial) + " test " + std::string(SelectionTestName(test))),
                0u);
    }
  }
}

// With 8 or more viewpoints per thread a task owns its viewpoint and sizes its set itself; every
// viewpoint, far (no shortcuts) or inside an occupied voxel (empty set) included, still gets a
// full-size set with the oracle's answers.
TEST(ComputeVisibilitySetsTest, TaskPerViewpointSetsMatchTheOracle) {
  std::mt19937_64 rng(31);
  const VoxelScene s = RandomScene(rng, 80, 10, 1.0);
  std::vector<WorldPoint> vps = RandomViewpoints(rng, 18, 10, 1.0);
  vps.push_back(WorldPoint(20000.5, 4.25, 6.5));  // far: walked plainly after the grouped pass
  const VoxelIndex inside = KeyToIndex(s.occupied[3]);
  vps.push_back(WorldPoint(inside.x + 0.5, inside.y + 0.5, inside.z + 0.5));
  for (bool per_voxel : {false, true}) {
    VisibilitySetsOptions opt;
    opt.per_voxel = per_voxel;
    opt.threads = 2;
    EXPECT_GT(ExpectSetsMatchOracle(s, vps, opt, per_voxel ? "per voxel" : "grouped"), 0u);
  }
  auto sets = ComputeVisibilitySets(s, vps, {});
  ASSERT_TRUE(sets.ok());
  EXPECT_EQ(sets->back().count(), 0u);  // the viewpoint inside an occupied voxel sees nothing
}

TEST(CheckSetBytesTest, SetsOverTheLimitAreRefusedNamingWhatToChange) {
  const uint64_t limit = uint64_t{4} << 20;
  EXPECT_TRUE(CheckSetBytes(uint64_t{1} << 40, 3, 1000, 0).ok()) << "0 = no limit";
  EXPECT_TRUE(CheckSetBytes(limit, 3, 1000, limit).ok()) << "at the limit";
  EXPECT_EQ(
      CheckSetBytes(limit + 1, 3, 1000, limit),
      ResourceExhaustedError("the visibility sets of 3 positions x 1000 occupied voxels need more than 4 MiB even "
                             "where kept sparse; raise grid_spacing_m or resolution_m, lower max_range_m, or "
                             "raise the memory budget"));
}

TEST(VoxelSetTest, ResizeKeepsBitsBelowTheSizeAndClearsTheRest) {
  VoxelSet s(130);
  for (size_t i : {0, 63, 64, 100, 129}) s.set(i);
  s.Resize(101);
  EXPECT_EQ(s.size(), 101u);
  EXPECT_EQ(s.count(), 4u);  // 129 dropped
  s.Resize(200);
  EXPECT_EQ(s.count(), 4u);  // nothing above 100 comes back
  EXPECT_TRUE(s.test(0) && s.test(63) && s.test(64) && s.test(100));
  EXPECT_FALSE(s.test(129));
  VoxelSet r;
  r.words().reserve(100);
  const uint64_t* where = r.words().data();
  r.Resize(64 * 100);
  EXPECT_EQ(r.words().data(), where);  // in the reserved capacity
  EXPECT_EQ(r.count(), 0u);
}

TEST(ComputeVisibilitySetsTest, FarViewpointsAreWalkedPlainlyAndMatchTheOracle) {
  // Beyond kMaxShortcutLength voxels the shortcuts' margins are not argued; such viewpoints must
  // still get the plain walk's answers (grouped default and per-voxel alike).
  std::mt19937_64 rng(23);
  const VoxelScene s = RandomScene(rng, 60, 10, 1.0);
  const std::vector<WorldPoint> vps = {WorldPoint(20000.5, 4.25, 6.5), WorldPoint(4.5, -17000.25, 30.5),
                                       WorldPoint(5.25, 5.5, 8.75)};
  EXPECT_FALSE(internal::ShortcutsHold(s.grid, vps[0] / 1.0));
  EXPECT_TRUE(internal::ShortcutsHold(s.grid, vps[2] / 1.0));
  for (bool per_voxel : {false, true}) {
    VisibilitySetsOptions opt;
    opt.per_voxel = per_voxel;
    opt.threads = 2;
    EXPECT_GT(ExpectSetsMatchOracle(s, vps, opt, per_voxel ? "per voxel" : "grouped"), 0u);
  }
}

// Evaluation::sole_viewer as it must be, from every viewpoint's face values.
std::vector<int32_t> SoleViewers(const Evaluation& ev, size_t voxels) {
  std::vector<int32_t> sole(voxels, kNoViewer);
  for (size_t k = 0; k < ev.per_viewpoint_face_values.size(); ++k)
    for (size_t id = 0; id < voxels; ++id) {
      bool seen = false;
      for (int f = 0; f < 6; ++f) seen |= ev.per_viewpoint_face_values[k][id * 6 + f] > 0;
      if (seen) sole[id] = sole[id] == kNoViewer ? int32_t(k) : kSeveralViewers;
    }
  return sole;
}

TEST(EvaluateTest, ProgressCountsTheStationsAndTheSampledFaces) {
  std::mt19937_64 rng(5);
  const VoxelScene s = RandomScene(rng, 60, 9, 1.0);
  const auto vps = RandomViewpoints(rng, 4, 9, 1.0);
  for (const uint64_t sample : {uint64_t{0}, uint64_t{100}}) {
    std::mutex mu;
    ProgressEvent last;
    JobContext ctx;
    ctx.progress = [&](const ProgressEvent& e) {
      std::lock_guard<std::mutex> lock(mu);
      if (e.done >= last.done) last = e;
    };
    EvaluateOptions opt;
    opt.sample_faces = sample;
    ASSERT_TRUE(Evaluate(s, vps, opt, ctx).ok());
    EXPECT_EQ(last.stage, Stage::kEvaluation);
    EXPECT_EQ(last.unit, sample == 0 ? "stations" : "faces");
    EXPECT_EQ(last.total, sample == 0 ? vps.size() : sample);
    EXPECT_EQ(last.done, last.total);
    EXPECT_EQ(last.fraction, 1.0);
  }
}

TEST(EvaluateTest, GlobalVisibilityEqualsBruteForce) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    const VoxelScene s = RandomScene(rng, 60, 9, 1.0);
    const auto vps = RandomViewpoints(rng, 3, 9, 1.0);
    EvaluateOptions opt;
    opt.keep_face_values = true;
    opt.keep_per_viewpoint_values = true;
    auto ev = Evaluate(s, vps, opt);
    ASSERT_TRUE(ev.ok()) << ev.status().ToString();
    const size_t n = s.occupied.size();
    ASSERT_EQ(ev->faces_total, 6 * n);
    double sum_best = 0;
    std::vector<double> sum_vp(vps.size(), 0);
    for (size_t id = 0; id < n; ++id) {
      const VoxelIndex v = KeyToIndex(s.occupied[id]);
      for (int f = 0; f < 6; ++f) {
        double best = 0;
        for (size_t k = 0; k < vps.size(); ++k) {
          const double val = PlainFaceValue(s.grid, vps[k], v, f);
          ASSERT_NEAR(ev->per_viewpoint_face_values[k][id * 6 + f], val, 1e-6);
          sum_vp[k] += val;
          best = std::max(best, val);
        }
        ASSERT_NEAR(ev->best_face_values[id][f], best, 1e-6);
        sum_best += best;
      }
    }
    EXPECT_NEAR(ev->overall.global_visibility, sum_best / double(6 * n), 1e-9);
    EXPECT_GT(ev->overall.global_visibility, 0.0);
    EXPECT_EQ(ev->sole_viewer, SoleViewers(*ev, n));
    for (size_t k = 0; k < vps.size(); ++k)
      EXPECT_NEAR(ev->per_viewpoint[k].global_visibility, sum_vp[k] / double(6 * n), 1e-9);
  }
}

// A short range: Evaluate skips the blocks of corners and voxels (and the bricks of face groups)
// that lie out of it; every face must still get the oracle's V, and the sparse values must list
// exactly the faces with V > 0, on one thread and on several (a task per viewpoint, and shared).
TEST(EvaluateTest, AShortRangeGivesTheOraclesValuesAndSparseValuesListThem) {
  std::mt19937_64 rng(17);
  const double r = 0.1, range = 2.5;
  const VoxelScene s = RandomScene(rng, 1500, 100, r);  // 10 m across
  const auto vps = RandomViewpoints(rng, 8, 100, r);    // 2 threads: a task per viewpoint; 3: shared
  size_t seen = 0, beyond = 0;
  for (int threads : {1, 2, 3}) {
    EvaluateOptions opt;
    opt.threads = threads;
    opt.scanner.max_range_m = range;
    opt.keep_per_viewpoint_values = true;
    opt.keep_sparse_per_viewpoint_values = true;
    auto ev = Evaluate(s, vps, opt);
    ASSERT_TRUE(ev.ok()) << ev.status().ToString();
    ASSERT_EQ(ev->per_viewpoint_sparse_values.size(), vps.size());
    for (size_t k = 0; k < vps.size(); ++k) {
      const std::vector<float>& dense = ev->per_viewpoint_face_values[k];
      const SparseFaceValues& sparse = ev->per_viewpoint_sparse_values[k];
      ASSERT_EQ(sparse.faces.size(), sparse.values.size());
      size_t next = 0;
      for (size_t slot = 0; slot < dense.size(); ++slot) {
        const VoxelIndex v = KeyToIndex(s.occupied[slot / 6]);
        if (threads == 1) {
          ASSERT_NEAR(dense[slot], PlainFaceValue(s.grid, vps[k], v, int(slot % 6), range), 1e-6)
              << "viewpoint " << k << " voxel " << slot / 6 << " face " << slot % 6;
          seen += dense[slot] > 0;
          beyond += (Vector3d(v.x + 0.5, v.y + 0.5, v.z + 0.5) * r - vps[k]).norm() > range + r;
        }
        if (dense[slot] > 0) {
          ASSERT_LT(next, sparse.size());
          EXPECT_EQ(sparse.faces[next], slot);
          EXPECT_EQ(sparse.values[next], dense[slot]);
          ++next;
        }
      }
      EXPECT_EQ(next, sparse.size());
    }
  }
  EXPECT_GT(seen, 500u);
  EXPECT_GT(beyond, 10000u);  // most of the scene lies out of range
}

// The corner rays' occluder cache holds the solid box grown from an occluder met more than 8
// voxels before its corner (evaluate.cc): behind thick blocks and a wall standing on two layers of
// ground, seen from tripod heights where rays graze the ground, every face still gets the plain
// oracle's V (a box grown one voxel too far, into free space, fails this).
TEST(EvaluateTest, GrownOccluderBoxesGiveTheOraclesValuesBehindSolidBlocks) {
  std::mt19937_64 rng(43);
  const double r = 0.1;
  const int extent = 56;
  std::vector<VoxelIndex> v;
  for (int x = 0; x < extent; ++x)
    for (int y = 0; y < extent; ++y) v.push_back({x, y, 0}), v.push_back({x, y, 1});
  std::uniform_int_distribution<int> at(4, extent - 12), side(3, 8), height(4, 12);
  for (int b = 0; b < 7; ++b) {
    const int x0 = at(rng), y0 = at(rng), sx = side(rng), sy = side(rng), h = height(rng);
    for (int x = x0; x < x0 + sx; ++x)
      for (int y = y0; y < y0 + sy; ++y)
        for (int z = 2; z < 2 + h; ++z) v.push_back({x, y, z});
  }
  for (int x = 30; x < 32; ++x)
    for (int y = 8; y < 48; ++y)
      for (int z = 2; z < 15; ++z) v.push_back({x, y, z});
  const VoxelScene s = MakeScene(v, r);
  std::uniform_real_distribution<double> u(0.3, extent - 0.3), z(2.3, 16.0);
  std::vector<WorldPoint> vps;
  while (vps.size() < 5) {
    const Vector3d p(u(rng), u(rng), z(rng));
    if (!s.grid.Occupied(int(std::floor(p.x())), int(std::floor(p.y())), int(std::floor(p.z())))) vps.push_back(p * r);
  }
  EvaluateOptions opt;
  opt.keep_per_viewpoint_values = true;
  auto ev = Evaluate(s, vps, opt);
  ASSERT_TRUE(ev.ok()) << ev.status().ToString();
  size_t seen = 0, hidden = 0;
  for (size_t k = 0; k < vps.size(); ++k) {
    for (size_t slot = 0; slot < ev->per_viewpoint_face_values[k].size(); ++slot) {
      const VoxelIndex voxel = KeyToIndex(s.occupied[slot / 6]);
      const double want = PlainFaceValue(s.grid, vps[k], voxel, int(slot % 6));
      ASSERT_NEAR(ev->per_viewpoint_face_values[k][slot], want, 1e-6)
          << "viewpoint " << k << " voxel " << slot / 6 << " face " << slot % 6;
      (want > 0 ? seen : hidden) += 1;
    }
  }
  EXPECT_GT(seen, 3000u);
  EXPECT_GT(hidden, 10000u);
}

// With enough viewpoints per thread each thread evaluates whole viewpoints and the threads' best
// values are merged; with fewer, each viewpoint runs on all threads. Both must give the same
// figures, bit for bit, as one thread; on the small scene also the brute-force values. The large
// one has several chunks of bricks, corners and voxels, so that with 3 threads the work within a
// viewpoint is shared (and the group pass sets its bits atomically).
TEST(EvaluateTest, TaskPerViewpointGivesTheSameFiguresAsOneThread) {
  std::mt19937_64 rng(31);
  for (const int extent : {14, 150}) {
    const VoxelScene s = RandomScene(rng, extent == 14 ? 300 : 3000, extent, 0.1);
    const auto vps = RandomViewpoints(rng, 11, extent, 0.1);  // 2 threads: a task per viewpoint; 3: not
    const std::string scene = "extent " + std::to_string(extent);
    auto run = [&](int threads) {
      EvaluateOptions opt;
      opt.threads = threads;
      opt.keep_face_values = true;
      opt.keep_per_viewpoint_values = true;
      auto ev = Evaluate(s, vps, opt);
      EXPECT_TRUE(ev.ok()) << ev.status().ToString();
      return *ev;
    };
    const Evaluation one = run(1);
    EXPECT_GT(one.overall.global_visibility, 0.0) << scene;
    EXPECT_EQ(one.sole_viewer, SoleViewers(one, s.occupied.size())) << scene;
    const size_t n = s.occupied.size();
    for (size_t id = 0; extent == 14 && id < n; ++id) {
      const VoxelIndex v = KeyToIndex(s.occupied[id]);
      for (int f = 0; f < 6; ++f) {
        double best = 0;
        for (size_t k = 0; k < vps.size(); ++k) best = std::max(best, PlainFaceValue(s.grid, vps[k], v, f));
        ASSERT_NEAR(one.best_face_values[id][f], best, 1e-6) << "voxel " << id << " face " << f;
      }
    }
    for (int threads : {2, 3}) {
      const Evaluation other = run(threads);
      const std::string what = scene + ", " + std::to_string(threads) + " threads";
      EXPECT_EQ(other.overall.global_visibility, one.overall.global_visibility) << what;
      EXPECT_EQ(other.overall.fully_visible_fraction, one.overall.fully_visible_fraction) << what;
      EXPECT_EQ(other.overall.mean_full_visibility, one.overall.mean_full_visibility) << what;
      EXPECT_EQ(other.overall.partially_visible_fraction, one.overall.partially_visible_fraction) << what;
      ASSERT_EQ(other.per_viewpoint.size(), vps.size());
      for (size_t k = 0; k < vps.size(); ++k) {
        EXPECT_EQ(other.per_viewpoint[k].global_visibility, one.per_viewpoint[k].global_visibility)
            << what << ", " << k;
        EXPECT_EQ(other.per_viewpoint[k].fully_visible_fraction, one.per_viewpoint[k].fully_visible_fraction) << what;
        EXPECT_EQ(other.per_viewpoint_face_values[k], one.per_viewpoint_face_values[k]) << what << ", viewpoint " << k;
      }
      EXPECT_EQ(other.best_face_values, one.best_face_values) << what;
      EXPECT_EQ(other.sole_viewer, one.sole_viewer) << what;
    }
  }
}

// Evaluations of consecutive groups of viewpoints, joined, are one evaluation of them all, bit for
// bit: the overall and per-viewpoint figures, the best face values, the sole viewers (shifted to
// the joined indices) and the sparse values; for both face sets. The reduction's batches rely on it.
TEST(EvaluateTest, JoinedEvaluationsEqualOneEvaluationOfAll) {
  std::mt19937_64 rng(37);
  const VoxelScene s = RandomScene(rng, 3000, 150, 0.1);
  const auto vps = RandomViewpoints(rng, 11, 150, 0.1);
  for (const FaceSet faces : {FaceSet::kAll, FaceSet::kExposed}) {
    EvaluateOptions opt;
    opt.faces = faces;
    opt.threads = 2;
    opt.scanner.max_range_m = 4.0;  // a short range, so that many voxels have a sole viewer
    opt.keep_face_values = true;
    opt.keep_sparse_per_viewpoint_values = true;
    Result<Evaluation> all = Evaluate(s, vps, opt);
    ASSERT_TRUE(all.ok()) << all.status().ToString();
    opt.keep_join_state = true;
    std::optional<Evaluation> joined;
    for (const auto& [b, e] : std::vector<std::pair<size_t, size_t>>{{0, 4}, {4, 9}, {9, 11}}) {
      Result<Evaluation> part = Evaluate(s, std::vector<WorldPoint>(vps.begin() + b, vps.begin() + e), opt);
      ASSERT_TRUE(part.ok()) << part.status().ToString();
      ASSERT_EQ(part->best_values.size(), s.occupied.size() * kFacesPerVoxel);
      if (!joined) {
        joined = std::move(*part);
        continue;
      }
      Result<Evaluation> j = JoinEvaluations(std::move(*joined), std::move(*part));
      ASSERT_TRUE(j.ok()) << j.status().ToString();
      joined = std::move(*j);
    }
    const std::string what = faces == FaceSet::kAll ? "all faces" : "exposed faces";
    EXPECT_GT(all->overall.global_visibility, 0.0) << what;
    EXPECT_EQ(joined->faces_total, all->faces_total) << what;
    EXPECT_EQ(joined->overall.global_visibility, all->overall.global_visibility) << what;
    EXPECT_EQ(joined->overall.fully_visible_fraction, all->overall.fully_visible_fraction) << what;
    EXPECT_EQ(joined->overall.mean_full_visibility, all->overall.mean_full_visibility) << what;
    EXPECT_EQ(joined->overall.partially_visible_fraction, all->overall.partially_visible_fraction) << what;
    ASSERT_EQ(joined->per_viewpoint.size(), vps.size()) << what;
    ASSERT_EQ(joined->per_viewpoint_sparse_values.size(), vps.size()) << what;
    for (size_t k = 0; k < vps.size(); ++k) {
      EXPECT_EQ(joined->per_viewpoint[k].global_visibility, all->per_viewpoint[k].global_visibility) << what << k;
      EXPECT_EQ(joined->per_viewpoint_sparse_values[k].faces, all->per_viewpoint_sparse_values[k].faces) << what << k;
      EXPECT_EQ(joined->per_viewpoint_sparse_values[k].values, all->per_viewpoint_sparse_values[k].values) << what;
    }
    EXPECT_EQ(joined->best_face_values, all->best_face_values) << what;
    EXPECT_EQ(joined->sole_viewer, all->sole_viewer) << what;
    // Some voxel has a sole viewer after the first group, so the shift is tested.
    EXPECT_TRUE(std::any_of(joined->sole_viewer.begin(), joined->sole_viewer.end(), [](int32_t v) { return v >= 4; }))
        << what;
  }
}

TEST(EvaluateTest, JoinRefusesEvaluationsItCannotJoinNamingWhy) {
  std::mt19937_64 rng(41);
  const VoxelScene s = RandomScene(rng, 300, 14, 0.1);
  const VoxelScene other = RandomScene(rng, 200, 14, 0.1);
  const auto vps = RandomViewpoints(rng, 2, 14, 0.1);
  EvaluateOptions opt;
  opt.keep_join_state = true;
  auto eval = [&](const VoxelScene& scene, const EvaluateOptions& o) {
    Result<Evaluation> e = Evaluate(scene, vps, o);
    EXPECT_TRUE(e.ok()) << e.status().ToString();
    return *e;
  };
  auto refused = [&](Evaluation a, Evaluation b, const std::string& why) {
    Result<Evaluation> j = JoinEvaluations(std::move(a), std::move(b));
    ASSERT_FALSE(j.ok()) << why;
    EXPECT_EQ(j.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(j.status().message().find(why), std::string::npos) << j.status().ToString();
  };
  EXPECT_TRUE(JoinEvaluations(eval(s, opt), eval(s, opt)).ok());
  EvaluateOptions plain;
  refused(eval(s, opt), eval(s, plain), "keep_join_state");
  refused(eval(s, opt), eval(other, opt), "different scenes");
  EvaluateOptions with_values = opt;
  with_values.keep_face_values = true;
  refused(eval(s, opt), eval(s, with_values), "keep_face_values");
  EvaluateOptions sampled = opt;
  sampled.sample_faces = 100;
  refused(eval(s, opt), eval(s, sampled), "sampled");
}

// The evaluation built from groups of viewpoints' sparse values with their join state (as replicas
// give them), joined, is one evaluation of them all, bit for bit; for both face sets. The sparse
// values with the join state are the plain ones with each face's double V and perception beside.
TEST(EvaluateTest, EvaluationOfSparseValuesJoinedEqualsOneEvaluationOfAll) {
  std::mt19937_64 rng(43);
  const VoxelScene s = RandomScene(rng, 3000, 150, 0.1);
  const auto vps = RandomViewpoints(rng, 9, 150, 0.1);
  for (const FaceSet faces : {FaceSet::kAll, FaceSet::kExposed}) {
    const std::string what = faces == FaceSet::kAll ? "all faces" : "exposed faces";
    EvaluateOptions opt;
    opt.faces = faces;
    opt.threads = 2;
    opt.scanner.max_range_m = 4.0;  // many voxels with a sole viewer
    opt.keep_face_values = true;
    opt.keep_sparse_per_viewpoint_values = true;
    Result<Evaluation> all = Evaluate(s, vps, opt);
    ASSERT_TRUE(all.ok()) << all.status().ToString();
    EvaluateOptions sparse = opt;
    sparse.keep_face_values = false;
    sparse.keep_sparse_join_state = true;
    std::optional<Evaluation> joined;
    for (const auto& [b, e] : std::vector<std::pair<size_t, size_t>>{{0, 3}, {3, 8}, {8, 9}}) {
      Result<Evaluation> part = Evaluate(s, std::vector<WorldPoint>(vps.begin() + b, vps.begin() + e), sparse);
      ASSERT_TRUE(part.ok()) << part.status().ToString();
      for (size_t k = 0; k < e - b; ++k) {
        const SparseFaceValues& got = part->per_viewpoint_sparse_values[k];
        const SparseFaceValues& plain = all->per_viewpoint_sparse_values[b + k];
        ASSERT_TRUE(got.HasJoinState()) << what << k;
        EXPECT_EQ(got.faces, plain.faces) << what << k;
        EXPECT_EQ(got.values, plain.values) << what << k;
        for (size_t j = 0; j < got.size(); ++j) {
          ASSERT_EQ(float(got.exact_values[j]), got.values[j]) << what << k;
          ASSERT_TRUE(got.perceptions[j] == 1 || got.perceptions[j] == 2) << what << k;
        }
      }
      Result<Evaluation> built =
          EvaluationOfSparseValues(s, faces, part->per_viewpoint, part->per_viewpoint_sparse_values);
      ASSERT_TRUE(built.ok()) << built.status().ToString();
      if (!joined) {
        joined = std::move(*built);
        continue;
      }
      Result<Evaluation> j = JoinEvaluations(std::move(*joined), std::move(*built));
      ASSERT_TRUE(j.ok()) << j.status().ToString();
      joined = std::move(*j);
    }
    EXPECT_GT(all->overall.global_visibility, 0.0) << what;
    EXPECT_EQ(joined->faces_total, all->faces_total) << what;
    EXPECT_EQ(joined->faces_evaluated, all->faces_evaluated) << what;
    EXPECT_EQ(joined->overall.global_visibility, all->overall.global_visibility) << what;
    EXPECT_EQ(joined->overall.fully_visible_fraction, all->overall.fully_visible_fraction) << what;
    EXPECT_EQ(joined->overall.mean_full_visibility, all->overall.mean_full_visibility) << what;
    EXPECT_EQ(joined->overall.partially_visible_fraction, all->overall.partially_visible_fraction) << what;
    ASSERT_EQ(joined->per_viewpoint.size(), vps.size()) << what;
    for (size_t k = 0; k < vps.size(); ++k) {
      EXPECT_EQ(joined->per_viewpoint[k].global_visibility, all->per_viewpoint[k].global_visibility) << what << k;
    }
    EXPECT_EQ(joined->best_face_values, all->best_face_values) << what;
    EXPECT_EQ(joined->sole_viewer, all->sole_viewer) << what;
    EXPECT_TRUE(std::any_of(joined->sole_viewer.begin(), joined->sole_viewer.end(), [](int32_t v) { return v >= 3; }))
        << what;
  }
}

// A value for a face outside F (a face between two occupied voxels, with the exposed faces) is not
// one Evaluate gives: refused, not summed into the figures (a peer's reply is checked by this).
TEST(EvaluateTest, EvaluationOfSparseValuesRefusesAFaceOutsideTheFaceSet) {
  const VoxelScene s = MakeScene({{0, 0, 0}, {1, 0, 0}});
  ASSERT_EQ(s.occupied.size(), 2u);
  const size_t low = KeyToIndex(s.occupied[0]).x < KeyToIndex(s.occupied[1]).x ? 0 : 1;
  SparseFaceValues v;
  v.faces = {uint32_t(low * kFacesPerVoxel + int(Face::kPosX))};  // the face its neighbour covers
  v.values = {0.5f};
  v.exact_values = {0.5};
  v.perceptions = {uint8_t(Perception::kFull)};
  Result<Evaluation> e = EvaluationOfSparseValues(s, FaceSet::kExposed, {VisibilityFigures{}}, {v});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(e.status().message().find("not in the evaluated face set"), std::string::npos) << e.status().ToString();
  e = EvaluationOfSparseValues(s, FaceSet::kAll, {VisibilityFigures{}}, {v});  // in F with all faces
  ASSERT_TRUE(e.ok()) << e.status().ToString();
  EXPECT_EQ(e->faces_total, 12u);
  EXPECT_DOUBLE_EQ(e->overall.global_visibility, 0.5 / 12);
}

TEST(EvaluateTest, EvaluationOfSparseValuesRefusesValuesWithoutJoinState) {
  std::mt19937_64 rng(47);
  const VoxelScene s = RandomScene(rng, 300, 14, 0.1);
  const auto vps = RandomViewpoints(rng, 2, 14, 0.1);
  EvaluateOptions opt;
  opt.keep_sparse_per_viewpoint_values = true;
  Result<Evaluation> plain = Evaluate(s, vps, opt);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  ASSERT_GT(plain->per_viewpoint_sparse_values[0].size() + plain->per_viewpoint_sparse_values[1].size(), 0u);
  Result<Evaluation> e =
      EvaluationOfSparseValues(s, FaceSet::kAll, plain->per_viewpoint, plain->per_viewpoint_sparse_values);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(e.status().message().find("keep_sparse_join_state"), std::string::npos) << e.status().ToString();
  e = EvaluationOfSparseValues(s, FaceSet::kAll, {}, plain->per_viewpoint_sparse_values);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("figures"), std::string::npos) << e.status().ToString();
  opt.keep_sparse_join_state = true;
  Result<Evaluation> with = Evaluate(s, vps, opt);
  ASSERT_TRUE(with.ok());
  std::vector<SparseFaceValues> unsorted = with->per_viewpoint_sparse_values;
  SparseFaceValues& v = unsorted[0].size() > 1 ? unsorted[0] : unsorted[1];
  ASSERT_GT(v.size(), 1u);
  std::swap(v.faces[0], v.faces[1]);
  e = EvaluationOfSparseValues(s, FaceSet::kAll, with->per_viewpoint, unsorted);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("ascending"), std::string::npos) << e.status().ToString();
}

TEST(EvaluateTest, SamplingIsUnbiasedWithinItsConfidenceInterval) {
  std::mt19937_64 rng(99);
  const VoxelScene s = RandomScene(rng, 400, 20, 0.1);
  const auto vps = RandomViewpoints(rng, 3, 20, 0.1);
  auto exact = Evaluate(s, vps, {});
  ASSERT_TRUE(exact.ok());
  EvaluateOptions opt;
  opt.sample_faces = 20000;
  opt.seed = 5;
  auto est = Evaluate(s, vps, opt);
  ASSERT_TRUE(est.ok());
  EXPECT_TRUE(est->sampled);
  EXPECT_GT(est->global_visibility_ci95, 0.0);
  EXPECT_LT(est->global_visibility_ci95, 0.01);
  EXPECT_NEAR(est->overall.global_visibility, exact->overall.global_visibility, 1.5 * est->global_visibility_ci95);
}

TEST(EvaluateTest, ExposedFaceSetExcludesSharedFaces) {
  const VoxelScene s = MakeScene({{0, 0, 0}, {1, 0, 0}});
  EvaluateOptions opt;
  opt.faces = FaceSet::kExposed;
  auto ev = Evaluate(s, {WorldPoint(0.5, 0.5, 5.5)}, opt);
  ASSERT_TRUE(ev.ok());
  EXPECT_EQ(ev->faces_total, 10u);
  opt.faces = FaceSet::kAll;
  EXPECT_EQ(Evaluate(s, {WorldPoint(0.5, 0.5, 5.5)}, opt)->faces_total, 12u);
}

TEST(EvaluateTest, RejectsNonFiniteViewpointAndBadRange) {
  const VoxelScene s = MakeScene({{0, 0, 0}});
  EXPECT_EQ(Evaluate(s, {WorldPoint(std::nan(""), 0, 0)}, {}).status().code(), StatusCode::kInvalidArgument);
  EvaluateOptions opt;
  opt.scanner.max_range_m = 0.1;
  EXPECT_EQ(Evaluate(s, {WorldPoint(0, 0, 3)}, opt).status().code(), StatusCode::kInvalidArgument);
  // Absurdly far (beyond 2^20 voxels): refused by Evaluate, sees nothing in the selection sets.
  const WorldPoint far(0, 0, 1e12);
  const Status st = Evaluate(s, {far}, {}).status();
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(st.message().find("from the origin"), std::string::npos) << st.ToString();
  auto sets = ComputeVisibilitySets(s, {far, WorldPoint(0.5, 0.5, 3)}, {});
  ASSERT_TRUE(sets.ok());
  EXPECT_EQ((*sets)[0].count(), 0u);
  EXPECT_EQ((*sets)[1].count(), 1u);
}

TEST(ComputeVisibilitySetsTest, CancellationStopsTheJob) {
  std::mt19937_64 rng(1);
  const VoxelScene s = RandomScene(rng, 100, 10, 0.1);
  CancelToken token;
  token.Cancel();
  JobContext ctx;
  ctx.cancel = &token;
  auto r = ComputeVisibilitySets(s, RandomViewpoints(rng, 3, 10, 0.1), {}, ctx);
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace vc
