// Grouped surface visibility (core/visibility/src/surface_groups.cc): the same sets as the per-voxel test on
// structured synthetic scenes, cluttered planes and a real scan, plus the certificates' parts
// (FreeCone, solid occluder boxes) on hand-made cases.
#include "vc/visibility/surface_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>

#include "testing/scenes.h"
#include "testing/test_paths.h"
#include "vc/plan/candidates.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"
#include "vc/synth/synth.h"
#include "vc/visibility/visibility.h"

namespace vc {
namespace {

using Eigen::Vector3d;
using internal::FreeBox;
using internal::FreeCone;
using internal::GrowFreeBox;
using internal::GrowSolidBox;
using internal::PassesThroughInterior;
using internal::Segment;
using internal::SolidBox;

VoxelScene MakeScene(const std::vector<VoxelIndex>& voxels, double r = 0.1) {
  return testing::SceneOfVoxels(voxels, r);
}

// Grouped and per-voxel sets must be identical, voxel by voxel. Returns the number visible.
size_t ExpectSameSets(const VoxelScene& s, const std::vector<WorldPoint>& vps, const std::string& what,
                      const std::optional<ScannerModel>& scanner = std::nullopt) {
  VisibilitySetsOptions grouped;
  grouped.threads = 2;
  grouped.scanner = scanner;
  VisibilitySetsOptions per_voxel = grouped;
  per_voxel.per_voxel = true;
  auto a = ComputeVisibilitySets(s, vps, grouped);
  auto b = ComputeVisibilitySets(s, vps, per_voxel);
  EXPECT_TRUE(a.ok() && b.ok());
  if (!a.ok() || !b.ok()) return 0;
  size_t visible = 0, mismatches = 0;
  for (size_t k = 0; k < vps.size(); ++k) {
    for (size_t i = 0; i < s.occupied.size(); ++i) {
      mismatches += (*a)[k].test(i) != (*b)[k].test(i);
      visible += (*b)[k].test(i);
    }
  }
  EXPECT_EQ(mismatches, 0u) << what;
  return visible;
}

// Exact evaluation with corners decided by face groups must give every face the same V as with
// one ray per corner.
void ExpectSameEvaluation(const VoxelScene& s, const std::vector<WorldPoint>& vps, const std::string& what) {
  EvaluateOptions grouped;
  grouped.threads = 2;
  grouped.keep_per_viewpoint_values = true;
  EvaluateOptions per_corner = grouped;
  per_corner.per_corner = true;
  auto a = Evaluate(s, vps, grouped);
  auto b = Evaluate(s, vps, per_corner);
  ASSERT_TRUE(a.ok() && b.ok()) << what;
  size_t mismatches = 0, seen = 0;
  for (size_t k = 0; k < vps.size(); ++k) {
    for (size_t i = 0; i < a->per_viewpoint_face_values[k].size(); ++i) {
      mismatches += a->per_viewpoint_face_values[k][i] != b->per_viewpoint_face_values[k][i];
      seen += b->per_viewpoint_face_values[k][i] > 0;
    }
  }
  EXPECT_EQ(mismatches, 0u) << what;
  EXPECT_GT(seen, 0u) << what;
  EXPECT_EQ(a->overall.global_visibility, b->overall.global_visibility) << what;
}

std::vector<WorldPoint> Candidates(const VoxelScene& s, size_t every) {
  auto grid = planner::GenerateCandidates(s, {});
  EXPECT_TRUE(grid.ok());
  std::vector<WorldPoint> out;
  if (!grid.ok()) return out;
  for (size_t k = 0; k < grid->positions.size(); k += every) out.push_back(grid->positions[k]);
  return out;
}

VoxelScene SyntheticScene(const std::string& spec) {
  SynthOptions so;
  so.spacing_m = 0.05;
  SceneInput in;
  in.points = *GenerateScene(spec, so);
  VoxelizeOptions vo;
  vo.resolution_m = 0.1;
  return *Voxelize(in, vo);
}

TEST(GroupedSurfaceVisibilityTest, SameSetsAsPerVoxelOnSyntheticScenes) {
  for (const char* spec : {"hall", "rooms:3", "twofloor", "comb:3", "lroom"}) {
    const VoxelScene s = SyntheticScene(spec);
    std::vector<WorldPoint> vps = Candidates(s, 97);
    // Viewpoints close to surfaces, where one brick holds voxels on both sides of o.
    const WorldPoint lo = s.BoundsMin(), hi = s.BoundsMax();
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 4; ++i) {
      vps.push_back(lo + (hi - lo).cwiseProduct(Vector3d(u(rng), u(rng), u(rng))));
    }
    EXPECT_GT(ExpectSameSets(s, vps, spec), 0u) << spec;
  }
}

// Every limit of the scanner model on, at values that cut through the scenes (range, blind cone,
// incidence, spacing), so that bricks are decided whole by the range, face by face, and not at all.
ScannerModel EveryLimit() {
  ScannerModel sc;
  sc.min_range_m = 0.8;
  sc.max_range_m = 4.5;
  sc.vfov_min_deg = -55;
  sc.vfov_max_deg = 60;
  sc.max_incidence_deg = 70;
  sc.angular_step_deg = 0.05;
  sc.max_spacing_m = 0.006;
  return sc;
}

TEST(GroupedSurfaceVisibilityTest, SameSetsAsPerVoxelOnClutteredPlanes) {
  // Large planes (where groups are decided whole) with holes, posts and loose voxels in front of
  // them (where groups split and certificates fail), seen from random points, some outside the
  // scene's box and some a fraction of a voxel from a plane; without limits and with every limit
  // of the scanner model on.
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<VoxelIndex> v;
    std::uniform_int_distribution<int> c(0, 47), hole(0, 9);
    for (int x = 0; x < 48; ++x)
      for (int y = 0; y < 48; ++y) {
        v.push_back({x, y, 0});                       // floor
        if (hole(rng) != 0) v.push_back({x, 47, y});  // wall with holes
        if (x % 12 == 5 && y % 12 == 5)               // posts
          for (int z = 1; z < 20; ++z) v.push_back({x, y, z});
      }
    for (int i = 0; i < 200; ++i) v.push_back({c(rng), c(rng), c(rng) / 2});  // clutter
    const VoxelScene s = MakeScene(v);
    std::vector<WorldPoint> vps;
    std::uniform_real_distribution<double> p(-8, 56);
    for (int i = 0; i < 6; ++i) {
      WorldPoint o(p(rng) * 0.1, p(rng) * 0.1, std::abs(p(rng)) * 0.05);
      if (i == 0) o.z() = 1.0 + 1e-9;  // just above the floor's top plane (z = 1 voxel)
      vps.push_back(o);
    }
    const size_t unlimited = ExpectSameSets(s, vps, "trial " + std::to_string(trial));
    const size_t limited = ExpectSameSets(s, vps, "limits, trial " + std::to_string(trial), EveryLimit());
    EXPECT_GT(limited, 0u);
    EXPECT_LT(limited, unlimited);  // the limits bite
  }
}

TEST(GroupedSurfaceVisibilityTest, SameSetsAsPerVoxelOnGeb079) {
  Result<SceneInput> in = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  VoxelizeOptions vo;
  vo.resolution_m = 0.1;
  Result<VoxelScene> s = Voxelize(*in, vo);
  ASSERT_TRUE(s.ok());
  EXPECT_GT(ExpectSameSets(*s, Candidates(*s, 13), "geb079"), 0u);
  ScannerModel sc = EveryLimit();
  sc.max_range_m = 20;
  EXPECT_GT(ExpectSameSets(*s, Candidates(*s, 29), "geb079 with every limit", sc), 0u);
}

TEST(GroupedSurfaceVisibilityTest, SameSetsAsPerVoxelWithEveryScannerLimitOn) {
  for (const char* spec : {"rooms:3", "twofloor", "lroom"}) {
    const VoxelScene s = SyntheticScene(spec);
    EXPECT_GT(ExpectSameSets(s, Candidates(s, 37), spec, EveryLimit()), 0u) << spec;
  }
}

TEST(GroupedCornersTest, SameFaceValuesAsPerCornerOnSyntheticScenes) {
  for (const char* spec : {"hall", "rooms:3", "twofloor"}) {
    const VoxelScene s = SyntheticScene(spec);
    ExpectSameEvaluation(s, Candidates(s, 211), spec);
  }
}

TEST(GroupedCornersTest, SameFaceValuesAsPerCornerOnClutteredPlanesAndGeb079) {
  std::mt19937_64 rng(9);
  std::vector<VoxelIndex> v;
  std::uniform_int_distribution<int> c(0, 39);
  for (int x = 0; x < 40; ++x)
    for (int y = 0; y < 40; ++y) {
      v.push_back({x, y, 0});
      v.push_back({x, y, 25});                       // ceiling
      if ((x + y) % 7) v.push_back({0, x, y % 25});  // wall with slots
    }
  for (int i = 0; i < 150; ++i) v.push_back({c(rng), c(rng), 1 + c(rng) / 2});
  const VoxelScene s = MakeScene(v);
  ExpectSameEvaluation(s, {WorldPoint(2.05, 1.55, 1.5), WorldPoint(0.35, 3.3, 0.2), WorldPoint(3.95, 3.95, 2.45)},
                       "cluttered");

  Result<SceneInput> in = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  Result<VoxelScene> g = Voxelize(*in, VoxelizeOptions{});
  ASSERT_TRUE(g.ok());
  ExpectSameEvaluation(*g, Candidates(*g, 31), "geb079");
}

// The layer z = 0 over [0, n) x [0, n): a floor whose top faces lie on the plane z = 1.
std::vector<VoxelIndex> Floor(int n) {
  std::vector<VoxelIndex> v;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y) v.push_back({x, y, 0});
  return v;
}

TEST(FreeConeTest, EmptySpaceIsFreeAndAnyVoxelInTheConeIsNot) {
  // Viewer at height 20 above a floor (z = 0 layer, top plane z = 1); faces in [10, 13] x [10, 13].
  const std::vector<VoxelIndex> floor = Floor(32);
  const Vector3d o(2.5, 3.5, 20.25);
  const Vector3d q0(10.5, 10.5, 1), q1(13.5, 13.5, 1);
  {
    const VoxelScene s = MakeScene(floor);
    // The floor layer itself is on the far side of the plane: it does not count.
    EXPECT_TRUE(FreeCone(s.grid, o, 2, true, 1, q0, q1));
  }
  {
    std::vector<VoxelIndex> v = floor;
    v.push_back({6, 7, 10});  // on the segment from o to the rectangle's middle
    const VoxelScene s = MakeScene(v);
    EXPECT_FALSE(FreeCone(s.grid, o, 2, true, 1, q0, q1));
  }
  {
    std::vector<VoxelIndex> v = floor;
    v.push_back({13, 13, 1});  // resting on the floor, under the rectangle's corner
    const VoxelScene s = MakeScene(v);
    EXPECT_FALSE(FreeCone(s.grid, o, 2, true, 1, q0, q1));
  }
  {
    std::vector<VoxelIndex> v = floor;
    v.push_back({25, 3, 10});  // well away from the cone
    const VoxelScene s = MakeScene(v);
    EXPECT_TRUE(FreeCone(s.grid, o, 2, true, 1, q0, q1));
  }
  {
    // Viewer below a ceiling (layer z = 30, bottom plane z = 30).
    std::vector<VoxelIndex> v;
    for (int x = 0; x < 32; ++x)
      for (int y = 0; y < 32; ++y) v.push_back({x, y, 30});
    const VoxelScene s = MakeScene(v);
    const Vector3d c0(10.5, 10.5, 30), c1(13.5, 13.5, 30);
    EXPECT_TRUE(FreeCone(s.grid, o, 2, false, 30, c0, c1));
    v.push_back({11, 11, 29});
    const VoxelScene s2 = MakeScene(v);
    EXPECT_FALSE(FreeCone(s2.grid, o, 2, false, 30, c0, c1));
  }
}

TEST(FreeConeTest, VoxelsOfTheBoxCoverOutsideThePyramidDoNotCount) {
  // The same floor and viewer. The box cover's last piece reaches from the rectangle back
  // towards o (to x < 10 for any piece longer than 1.2 voxels); a voxel resting on the floor
  // just in front of the rectangle lies in that box but below every line of sight (at z in
  // [1, 2] the pyramid has x > 10.08).
  const std::vector<VoxelIndex> floor = Floor(32);
  const Vector3d o(2.5, 3.5, 20.25);
  const Vector3d q0(10.5, 10.5, 1), q1(13.5, 13.5, 1);
  {
    std::vector<VoxelIndex> v = floor;
    v.push_back({9, 11, 1});
    const VoxelScene s = MakeScene(v);
    EXPECT_TRUE(FreeCone(s.grid, o, 2, true, 1, q0, q1));
    // What the certificate claims: every face centre of the rectangle is reached.
    for (int x = 10; x <= 13; ++x)
      for (int y = 10; y <= 13; ++y) {
        const VoxelIndex face{x, y, 0};
        EXPECT_FALSE(FirstOccupied(s.grid, o, Vector3d(x + 0.5, y + 0.5, 1), &face)) << x << "," << y;
      }
  }
  {
    // A voxel that the segment to the corner (13.5, 13.5, 1) passes through counts.
    std::vector<VoxelIndex> v = floor;
    v.push_back({12, 12, 2});  // crossed by that segment for s in [0.896, 0.948]
    EXPECT_FALSE(FreeCone(MakeScene(v).grid, o, 2, true, 1, q0, q1));
  }
  {
    // One row of faces (q0.y == q1.y): the pyramid is flat, and is widened to stay well defined.
    std::vector<VoxelIndex> v = floor;
    v.push_back({9, 12, 1});
    EXPECT_TRUE(FreeCone(MakeScene(v).grid, o, 2, true, 1, Vector3d(10.5, 12.5, 1), Vector3d(13.5, 12.5, 1)));
    v.push_back({11, 11, 3});  // on the segment to (12.5, 12.5, 1), near s = 0.9
    EXPECT_FALSE(FreeCone(MakeScene(v).grid, o, 2, true, 1, Vector3d(10.5, 12.5, 1), Vector3d(13.5, 12.5, 1)));
  }
}

// Walks 30 segments from o to the rectangle q0..q1 on the plane u[axis] = plane (its 4 corners,
// then random points of it). Returns the first k whose walk meets an occupied voxel on o's side
// of the plane (above: index along axis >= plane; below: < plane), or -1 if none does.
int FirstWalkMeetingTheViewersSide(const OccupancyGrid& grid, const Vector3d& o, int axis, bool above, int plane,
                                   const Vector3d& q0, const Vector3d& q1, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u01(0, 1);
  const int b1 = (axis + 1) % 3, b2 = (axis + 2) % 3;
  for (int k = 0; k < 30; ++k) {
    const double fu = k < 4 ? (k & 1) : u01(rng), fw = k < 4 ? (k >> 1) : u01(rng);
    Vector3d q = q0;
    q[b1] += fu * (q1[b1] - q0[b1]);
    q[b2] += fw * (q1[b2] - q0[b2]);
    const auto hit = FirstOccupied(grid, o, q);
    const int hit_a = hit ? (axis == 0 ? hit->x : axis == 1 ? hit->y : hit->z) : 0;
    if (hit && (above ? hit_a >= plane : hit_a < plane)) return k;
  }
  return -1;
}

// Soundness on random clutter: whenever FreeCone proves a rectangle free, no walk from o to a
// point of it meets an occupied voxel on o's side of the plane; and the test does prove many.
// Every axis, both sides of the plane, near the origin and 20,000 voxels from it.
TEST(FreeConeTest, WhatItProvesFreeIsFreeOnRandomClutter) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> c(0, 39);
  std::uniform_real_distribution<double> u01(0, 1);
  int proven = 0, refuted = 0, proven_far = 0, proven_grazing = 0, proven_boxed = 0;
  for (int scene = 0; scene < 12; ++scene) {
    const int axis = scene % 3, b1 = (axis + 1) % 3, b2 = (axis + 2) % 3;
    const bool above = (scene / 3) % 2 == 0;  // viewer above a floor, or below a ceiling
    const int off = scene >= 6 ? 20000 : 0;
    // Local coordinates (u along b1, w along b2, h along the axis) to index space.
    auto at = [&](double u, double w, double h) {
      Vector3d g;
      g[b1] = u + off, g[b2] = w + off, g[axis] = h + off;
      return g;
    };
    // The surface layer is h = 0; its faces towards the viewer lie on h = 1 (above) or h = 0.
    const int plane_h = above ? 1 : 0;
    const double toward = above ? 1 : -1;
    std::vector<VoxelIndex> v;
    auto add = [&](int u, int w, int h) {
      const Vector3d g = at(u, w, h);
      v.push_back({int(g.x()), int(g.y()), int(g.z())});
    };
    for (int u = 0; u < 40; ++u)
      for (int w = 0; w < 40; ++w) add(u, w, 0);
    for (int i = 0; i < 100 + 40 * (scene % 6); ++i) add(c(rng), c(rng), above ? 1 + c(rng) % 12 : -1 - c(rng) % 12);
    const VoxelScene s = MakeScene(v);
    for (int trial = 0; trial < 300; ++trial) {
      const int u0 = c(rng) % 36, w0 = c(rng) % 36, du = c(rng) % 5, dw = c(rng) % 5;
      // Face centres on the plane (corner evaluation uses integer corners; both are rectangles).
      const double shift = trial % 7 == 0 ? 0.0 : 0.5;
      // Every 5th rectangle lies one layer beyond the plane, as the back corners' do; only o's
      // side of the plane is tested then too.
      const double q_h = trial % 5 == 3 ? plane_h - toward : plane_h;
      const Vector3d q0 = at(u0 + shift, w0 + shift, q_h), q1 = at(u0 + du + shift, w0 + dw + shift, q_h);
      double ou = 40 * u01(rng), ow = 40 * u01(rng), oh = plane_h + toward * (1 + 30 * u01(rng));
      const bool grazing = trial % 4 == 1, far = trial % 4 == 2;
      if (grazing) {
        // From 0.1 down to 1e-9 off the plane; every other one on the line of an edge, exactly or
        // by an offset below a unit in the last place of the far coordinates.
        oh = plane_h + toward * std::pow(10.0, -1 - trial % 9);
        if (trial % 2) ow = w0 + shift + (trial % 3) * 3e-11;
      } else if (far) {
        // Hundreds to thousands of voxels away, low over the plane.
        ou = u0 + (trial % 8 < 4 ? -1 : 1) * (200 + 2800 * u01(rng));
        oh = plane_h + toward * (0.5 + 20 * u01(rng));
      }
      const Vector3d o = at(ou, ow, oh);
      if (s.grid.Occupied(int(std::floor(o.x())), int(std::floor(o.y())), int(std::floor(o.z())))) continue;
      // Without and with the free box around o, whose part of the cone is then not scanned.
      const FreeBox around = GrowFreeBox(s.grid, o);
      ASSERT_FALSE(around.empty());
      const bool plain = FreeCone(s.grid, o, axis, above, plane_h + off, q0, q1);
      const bool boxed = FreeCone(s.grid, o, axis, above, plane_h + off, q0, q1, around);
      proven_boxed += boxed;
      if (!plain && !boxed) {
        ++refuted;
        continue;
      }
      ++proven;
      proven_far += far;
      proven_grazing += grazing;
      const int k = FirstWalkMeetingTheViewersSide(s.grid, o, axis, above, plane_h + off, q0, q1, rng);
      ASSERT_EQ(k, -1) << "scene " << scene << " trial " << trial << " point " << k;
    }
  }
  EXPECT_GT(proven, 600);
  EXPECT_GT(refuted, 600);
  EXPECT_GT(proven_far, 50);
  EXPECT_GT(proven_grazing, 50);
  EXPECT_GT(proven_boxed, 600);
}

// A refuted rectangle reports where its cone test failed; the parts it is split into (as the
// group walk splits them) may start their own cone tests there. Whatever such a test proves free
// is free: no walk from o to a point of the part meets an occupied voxel on o's side. Reporting
// the end of the failing piece instead fails this test (and 5 others). At the time of writing:
// 2,387 rectangles refuted (1,287 past the cone's middle), 1,720 parts proven, 7,828 refuted.
TEST(FreeConeTest, PartsOfARefutedRectangleMayStartWhereItFailed) {
  std::mt19937_64 rng(29);
  std::uniform_int_distribution<int> c(0, 39);
  std::uniform_real_distribution<double> u01(0, 1);
  int refuted = 0, parts_proven = 0, parts_refuted = 0, late_failures = 0;
  for (int scene = 0; scene < 6; ++scene) {
    const int axis = scene % 3;
    const bool above = scene < 3;
    std::vector<VoxelIndex> v;
    auto add = [&](int u, int w, int h) {
      VoxelIndex g;
      (axis == 0 ? g.y : axis == 1 ? g.z : g.x) = u;
      (axis == 0 ? g.z : axis == 1 ? g.x : g.y) = w;
      (axis == 0 ? g.x : axis == 1 ? g.y : g.z) = h;
      v.push_back(g);
    };
    for (int u = 0; u < 40; ++u)
      for (int w = 0; w < 40; ++w) add(u, w, 0);
    // Clutter, most of it low over the plane, where the cones of neighbouring faces part.
    for (int i = 0; i < 150; ++i) add(c(rng), c(rng), (above ? 1 : -1) * (1 + c(rng) % (i % 3 ? 3 : 12)));
    const VoxelScene s = MakeScene(v);
    const int plane = above ? 1 : 0;
    const int b1 = (axis + 1) % 3, b2 = (axis + 2) % 3;
    for (int trial = 0; trial < 400; ++trial) {
      const int u0 = c(rng) % 32, w0 = c(rng) % 32;
      Vector3d q0, q1, o;
      q0[axis] = q1[axis] = plane;
      q0[b1] = u0 + 0.5, q1[b1] = u0 + 7.5;
      q0[b2] = w0 + 0.5, q1[b2] = w0 + 7.5;
      o[b1] = 40 * u01(rng), o[b2] = 40 * u01(rng), o[axis] = plane + (above ? 1 : -1) * (2 + 28 * u01(rng));
      if (s.grid.Occupied(int(std::floor(o.x())), int(std::floor(o.y())), int(std::floor(o.z())))) continue;
      const FreeBox around = trial % 2 ? GrowFreeBox(s.grid, o) : FreeBox();
      double failed_at = -1;
      if (FreeCone(s.grid, o, axis, above, plane, q0, q1, around, 0, &failed_at)) continue;
      ++refuted;
      ASSERT_GE(failed_at, 0);
      ASSERT_LT(failed_at, 1);
      late_failures += failed_at > 0.5;
      for (int part = 0; part < 4; ++part) {
        Vector3d p0 = q0, p1 = q1;
        (part & 1 ? p0 : p1)[b1] = u0 + (part & 1 ? 4.5 : 3.5);
        (part & 2 ? p0 : p1)[b2] = w0 + (part & 2 ? 4.5 : 3.5);
        if (!FreeCone(s.grid, o, axis, above, plane, p0, p1, around, failed_at)) {
          ++parts_refuted;
          continue;
        }
        ++parts_proven;
        const int k = FirstWalkMeetingTheViewersSide(s.grid, o, axis, above, plane, p0, p1, rng);
        ASSERT_EQ(k, -1) << "scene " << scene << " trial " << trial << " part " << part << " point " << k;
      }
    }
  }
  EXPECT_GT(refuted, 800);
  EXPECT_GT(late_failures, 200);
  EXPECT_GT(parts_proven, 400);
  EXPECT_GT(parts_refuted, 800);
}

// The free box around a viewpoint holds no occupied voxel, and none of its sides can move out by
// one layer (each stops at an occupied voxel or one voxel beyond the grid).
TEST(FreeBoxTest, HoldsNoOccupiedVoxelAndNoSideCanGrow) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> c(0, 29);
  std::uniform_real_distribution<double> u01(-8, 38);  // the scenes span about [0, 30): inside and out
  for (int scene = 0; scene < 6; ++scene) {
    std::vector<VoxelIndex> v;
    for (int i = 0; i < 20 + 60 * scene; ++i) v.push_back({c(rng), c(rng), c(rng)});
    const VoxelScene s = MakeScene(v);
    const VoxelIndex& gmin = s.grid.min_index();
    int grown = 0;
    for (int trial = 0; trial < 40; ++trial) {
      const Vector3d o(u01(rng), u01(rng), u01(rng));
      const FreeBox box = GrowFreeBox(s.grid, o);
      if (s.grid.Occupied(int(std::floor(o.x())), int(std::floor(o.y())), int(std::floor(o.z())))) {
        EXPECT_TRUE(box.empty());
        continue;
      }
      ASSERT_FALSE(box.empty());
      EXPECT_TRUE(box.lo.x <= o.x() && o.x() < box.hi.x + 1 && box.lo.y <= o.y() && o.y() < box.hi.y + 1 &&
                  box.lo.z <= o.z() && o.z() < box.hi.z + 1);
      for (int z = box.lo.z; z <= box.hi.z; ++z)
        for (int y = box.lo.y; y <= box.hi.y; ++y)
          for (int x = box.lo.x; x <= box.hi.x; ++x)
            ASSERT_FALSE(s.grid.Occupied(x, y, z)) << x << " " << y << " " << z;
      const int lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
      const int glo[3] = {gmin.x - 1, gmin.y - 1, gmin.z - 1};
      const int ghi[3] = {gmin.x + s.grid.dims()[0], gmin.y + s.grid.dims()[1], gmin.z + s.grid.dims()[2]};
      for (int side = 0; side < 6; ++side) {
        const int a = side / 2;
        const bool up = side % 2;
        if (up ? hi[a] >= ghi[a] : lo[a] <= glo[a]) continue;  // at the limit (or o beyond it)
        int l[3] = {lo[0], lo[1], lo[2]}, h[3] = {hi[0], hi[1], hi[2]};
        l[a] = h[a] = up ? hi[a] + 1 : lo[a] - 1;
        bool any = false;
        for (int z = l[2]; z <= h[2]; ++z)
          for (int y = l[1]; y <= h[1]; ++y)
            for (int x = l[0]; x <= h[0]; ++x) any = any || s.grid.Occupied(x, y, z);
        EXPECT_TRUE(any) << "side " << side << " could grow";
      }
      grown += (box.hi.x - box.lo.x) * (box.hi.y - box.lo.y) * (box.hi.z - box.lo.z) > 0;
    }
    EXPECT_GT(grown, 0);
  }
}

// FreeCone trusts the free box it is given: the part of the cone inside it is not scanned. With a
// box that (wrongly) claims the space around an occluder next to o, a blocked rectangle is
// "proven" free; with the true box, or none, it is not. So the skip is taken, and the box must be
// free (GrowFreeBox's is, FreeBoxTest).
TEST(FreeConeTest, SkipsThePartOfTheConeInsideTheFreeBox) {
  std::vector<VoxelIndex> v;
  for (int x = 0; x < 40; ++x)
    for (int y = 0; y < 40; ++y) v.push_back({x, y, 0});  // a floor, faces up on z = 1
  v.push_back({20, 20, 28});                              // an occluder just below o
  const VoxelScene s = MakeScene(v);
  const Vector3d o(20.5, 20.5, 29.5), q0(18.5, 18.5, 1), q1(22.5, 22.5, 1);
  EXPECT_FALSE(FreeCone(s.grid, o, 2, true, 1, q0, q1));
  const FreeBox around = GrowFreeBox(s.grid, o);
  EXPECT_GT(around.lo.z, 28);  // the true box stops above the occluder
  EXPECT_FALSE(FreeCone(s.grid, o, 2, true, 1, q0, q1, around));
  const FreeBox wrong{{0, 0, 10}, {40, 40, 40}};  // holds the occluder
  EXPECT_TRUE(FreeCone(s.grid, o, 2, true, 1, q0, q1, wrong));
}

// GrowSolidBox, on random dense clutter: the box holds h, lies within the limit, is all
// occupied, and no side can move out by one layer within the limit (each side's next layer holds
// a free voxel or lies beyond the limit).
TEST(SolidBoxTest, AllOccupiedAndNoSideCanGrow) {
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<int> c(0, 23);
  std::uniform_real_distribution<double> u01(0, 1);
  int large = 0, at_limit = 0;
  for (int scene = 0; scene < 4; ++scene) {
    // Slabs and blocks with random holes, so that boxes stop on every side at different rounds.
    std::vector<VoxelIndex> v;
    const double density = 0.9 + 0.025 * scene;
    for (int z = 0; z < 24; ++z)
      for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x)
          if ((scene % 2 == 0 || z % 6 < 3) && u01(rng) < density) v.push_back({x, y, z});
    const VoxelScene s = MakeScene(v);
    auto all_occupied = [&](const int l[3], const int u[3]) {
      for (int z = l[2]; z <= u[2]; ++z)
        for (int y = l[1]; y <= u[1]; ++y)
          for (int x = l[0]; x <= u[0]; ++x)
            if (!s.grid.Occupied(x, y, z)) return false;
      return true;
    };
    for (int trial = 0; trial < 200; ++trial) {
      const VoxelIndex h{c(rng), c(rng), c(rng)};
      if (!s.grid.Occupied(h)) continue;
      for (int limit : {1, 2, 8, 32}) {
        const SolidBox box = GrowSolidBox(s.grid, h, limit);
        const int lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
        const int h3[3] = {h.x, h.y, h.z};
        ASSERT_TRUE(box.Contains(h));
        ASSERT_TRUE(all_occupied(lo, hi)) << "scene " << scene << " trial " << trial;
        for (int side = 0; side < 6; ++side) {
          const int a = side / 2;
          const int layer = side % 2 ? hi[a] + 1 : lo[a] - 1;
          ASSERT_LE(std::abs(layer - h3[a]), limit + 1);
          if (std::abs(layer - h3[a]) > limit) {
            ++at_limit;
            continue;
          }
          int l[3] = {lo[0], lo[1], lo[2]}, u[3] = {hi[0], hi[1], hi[2]};
          l[a] = u[a] = layer;
          ASSERT_FALSE(all_occupied(l, u))
              << "scene " << scene << " trial " << trial << " limit " << limit << " side " << side;
        }
        large += (box.hi.x - box.lo.x) * (box.hi.y - box.lo.y) * (box.hi.z - box.lo.z) >= 8;
      }
    }
  }
  EXPECT_GT(large, 100);
  EXPECT_GT(at_limit, 100);
}

TEST(SolidBoxTest, GrowsAcrossAWallAndBlocksSegmentsThroughItsInterior) {
  // A wall x = 10, y and z in [0, 15], with a hole at (10, 12, 12).
  std::vector<VoxelIndex> v;
  for (int y = 0; y < 16; ++y)
    for (int z = 0; z < 16; ++z)
      if (!(y == 12 && z == 12)) v.push_back({10, y, z});
  const VoxelScene s = MakeScene(v);
  const SolidBox box = GrowSolidBox(s.grid, {10, 5, 5}, 8);
  EXPECT_EQ(box.lo.x, 10);
  EXPECT_EQ(box.hi.x, 10);
  for (int y = box.lo.y; y <= box.hi.y; ++y)
    for (int z = box.lo.z; z <= box.hi.z; ++z) EXPECT_TRUE(s.grid.Occupied(10, y, z));
  EXPECT_LE(box.lo.y, 3);  // it did grow, within the limit of 8
  EXPECT_GE(box.hi.y, 7);
  EXPECT_GE(box.lo.y, -3);
  // Straight through the wall: blocked. Ending on the wall, or passing beside it: not proven.
  EXPECT_TRUE(PassesThroughInterior(Segment({2.5, 5.5, 5.5}, {18.5, 5.5, 5.5}), box));
  EXPECT_FALSE(PassesThroughInterior(Segment({2.5, 5.5, 5.5}, {10.0, 5.5, 5.5}), box));
  EXPECT_FALSE(PassesThroughInterior(Segment({2.5, 5.5, 5.5}, {18.5, 5.5, 40.5}), box));
  // Along the wall's face plane x = 10: touches, never enters the interior.
  EXPECT_FALSE(PassesThroughInterior(Segment({10.0, -3.5, 5.5}, {10.0, 20.5, 5.5}), box));
}

}  // namespace
}  // namespace vc
