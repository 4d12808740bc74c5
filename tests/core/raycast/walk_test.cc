// The Amanatides & Woo walk state and its jumps (vc/raycast/walk.h), against a reference computed
// without them: the voxels a segment passes through are those of the intervals between its
// boundary crossings, each crossing t = (k - a_i) / d_i computed on its own and sorted. Segments
// with a near-tie (two crossings closer than kNearTie, where rounding decides the order) are left
// out of the oracle comparisons; exact ties are pinned by their own tests.
#include "vc/raycast/walk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <vector>

#include "vc/raycast/ray_traversal.h"
#include "vc/scene/occupancy_grid.h"

namespace vc::internal {
namespace {

using Eigen::Vector3d;

constexpr double kNearTie = 1e-9;

std::tuple<int, int, int> T(const VoxelIndex& v) { return {v.x, v.y, v.z}; }
VoxelIndex Cur(const Walk& w) { return {w.cur[0], w.cur[1], w.cur[2]}; }
VoxelIndex VoxelOf(const Vector3d& p) {
  return {int(std::floor(p.x())), int(std::floor(p.y())), int(std::floor(p.z()))};
}

// The voxels the segment a -> b passes through, in order (see the file comment). `min_gap` gets the
// smallest parameter distance between two crossings.
std::vector<VoxelIndex> CrossedVoxels(const Vector3d& a, const Vector3d& b, double* min_gap) {
  std::vector<double> ts = {0.0, 1.0};
  for (int i = 0; i < 3; ++i) {
    const double d = b[i] - a[i];
    if (d == 0) continue;
    const double lo = std::min(a[i], b[i]), hi = std::max(a[i], b[i]);
    for (double k = std::floor(lo) + 1; k <= hi; ++k) ts.push_back((k - a[i]) / d);
  }
  std::sort(ts.begin(), ts.end());
  *min_gap = 1.0;
  std::vector<VoxelIndex> out;
  for (size_t j = 1; j < ts.size(); ++j) {
    *min_gap = std::min(*min_gap, ts[j] - ts[j - 1]);
    out.push_back(VoxelOf(a + (ts[j - 1] + ts[j]) / 2 * (b - a)));
  }
  return out;
}

// The voxels Walk visits from a to b, stepping with Advance.
std::vector<VoxelIndex> Walked(const Vector3d& a, const Vector3d& b) {
  Walk w(a, b);
  std::vector<VoxelIndex> out = {Cur(w)};
  while (w.remaining > 0) {
    w.Advance();
    out.push_back(Cur(w));
  }
  return out;
}

bool Inside(const VoxelIndex& v, const int lo[3], const int hi[3]) {
  return v.x >= lo[0] && v.x <= hi[0] && v.y >= lo[1] && v.y <= hi[1] && v.z >= lo[2] && v.z <= hi[2];
}

TEST(WalkTest, VisitsExactlyTheVoxelsTheSegmentCrossesInOrder) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-20, 20);
  int compared = 0;
  for (int n = 0; n < 4000; ++n) {
    const Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    double gap = 0;
    const std::vector<VoxelIndex> expect = CrossedVoxels(a, b, &gap);
    if (gap < kNearTie) continue;
    ++compared;
    const std::vector<VoxelIndex> got = Walked(a, b);
    ASSERT_EQ(got.size(), expect.size()) << "segment " << n;
    for (size_t i = 0; i < got.size(); ++i) ASSERT_EQ(T(got[i]), T(expect[i])) << "segment " << n << " voxel " << i;
  }
  EXPECT_GT(compared, 3900);
}

TEST(WalkTest, NeverSkipsAFaceAdjacentVoxelAndTakesEachAxisItsSteps) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-50, 50);
  for (int n = 0; n < 2000; ++n) {
    // Every fourth segment parallel to a plane, every eighth to an axis: axes without steps.
    Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    if (n % 4 == 0) b.z() = a.z();
    if (n % 8 == 0) b.y() = a.y();
    const Walk start(a, b);
    int steps = 0;
    for (int i = 0; i < 3; ++i) {
      const int want = std::abs(int(std::floor(b[i])) - int(std::floor(a[i])));
      ASSERT_EQ(start.left[i], want) << "axis " << i << " of segment " << n;
      ASSERT_EQ(start.step[i], b[i] > a[i] ? 1 : b[i] < a[i] ? -1 : 0) << "axis " << i << " of segment " << n;
      if (want == 0) {
        ASSERT_EQ(start.t_max[i], kInf);
      }
      steps += want;
    }
    ASSERT_EQ(start.remaining, steps);
    const std::vector<VoxelIndex> path = Walked(a, b);
    ASSERT_EQ(T(path.front()), T(VoxelOf(a)));
    ASSERT_EQ(T(path.back()), T(VoxelOf(b)));
    for (size_t i = 1; i < path.size(); ++i) {
      const int d = std::abs(path[i].x - path[i - 1].x) + std::abs(path[i].y - path[i - 1].y) +
                    std::abs(path[i].z - path[i - 1].z);
      ASSERT_EQ(d, 1) << "segment " << n << " step " << i << " is not to a face-adjacent voxel";
    }
  }
}

TEST(WalkTest, ExactTiesStepZThenYThenX) {
  // Through a corner where all three axes cross at once, then one where x and y do.
  const std::vector<VoxelIndex> corner = Walked(Vector3d(0.5, 0.5, 0.5), Vector3d(1.5, 1.5, 1.5));
  const std::vector<std::tuple<int, int, int>> want = {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  ASSERT_EQ(corner.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(T(corner[i]), want[i]) << i;
  const std::vector<VoxelIndex> edge = Walked(Vector3d(1.5, 1.5, 0.5), Vector3d(-0.5, -0.5, 0.5));
  const std::vector<std::tuple<int, int, int>> want_edge = {{1, 1, 0}, {1, 0, 0}, {0, 0, 0}, {0, -1, 0}, {-1, -1, 0}};
  ASSERT_EQ(edge.size(), want_edge.size());
  for (size_t i = 0; i < want_edge.size(); ++i) EXPECT_EQ(T(edge[i]), want_edge[i]) << i;
}

// RayTraversal steps with its own copy of the rule; on lattice segments (ties everywhere) the two
// must still agree voxel for voxel.
TEST(WalkTest, AgreesWithRayTraversalOnSegmentsFullOfTies) {
  std::mt19937_64 rng(13);
  std::uniform_int_distribution<int> c(-6, 6);
  for (int n = 0; n < 3000; ++n) {
    const Vector3d a(c(rng) + 0.5, c(rng) + 0.5, c(rng) + 0.5), b(c(rng) + 0.5, c(rng) + 0.5, c(rng) + 0.5);
    std::vector<VoxelIndex> plain;
    for (const VoxelIndex& v : RayTraversal(a, b)) plain.push_back(v);
    const std::vector<VoxelIndex> walked = Walked(a, b);
    ASSERT_EQ(walked.size(), plain.size()) << "segment " << n;
    for (size_t i = 0; i < walked.size(); ++i) ASSERT_EQ(T(walked[i]), T(plain[i])) << "segment " << n;
  }
}

TEST(WalkTest, ASegmentInsideOneVoxelHasNoStep) {
  const Walk w(Vector3d(2.1, -3.9, 0.2), Vector3d(2.8, -3.2, 0.2));
  EXPECT_EQ(w.remaining, 0);
  EXPECT_EQ(T(Cur(w)), std::make_tuple(2, -4, 0));
}

// A box around the walk's voxel after a random number of steps: the jump lands on the last voxel
// the plain walk visits inside the box, with the plain walk's count of steps left, and walking on
// from there visits the plain walk's remaining voxels. When the walk ends inside the box, the jump
// says so (false).
TEST(JumpAcrossBoxTest, LandsOnTheLastVoxelThePlainWalkVisitsInsideTheBox) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-15, 15);
  std::uniform_int_distribution<int> extent(0, 5);
  int jumped = 0, ended_inside = 0;
  for (int n = 0; n < 6000; ++n) {
    const Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    double gap = 0;
    const std::vector<VoxelIndex> path = CrossedVoxels(a, b, &gap);
    if (gap < kNearTie) continue;
    Walk w(a, b);
    const size_t first = std::uniform_int_distribution<size_t>(0, path.size() - 1)(rng);
    for (size_t s = 0; s < first; ++s) w.Advance();
    const int cur[3] = {w.cur[0], w.cur[1], w.cur[2]};
    int lo[3], hi[3];
    for (int i = 0; i < 3; ++i) lo[i] = cur[i] - extent(rng), hi[i] = cur[i] + extent(rng);
    size_t last = first;
    while (last + 1 < path.size() && Inside(path[last + 1], lo, hi)) ++last;
    const bool left_box = JumpAcrossBox(lo, hi, w);
    if (last + 1 == path.size()) {
      EXPECT_FALSE(left_box) << "segment " << n << " ends inside the box";
      ++ended_inside;
      continue;
    }
    ASSERT_TRUE(left_box) << "segment " << n;
    ++jumped;
    ASSERT_EQ(T(Cur(w)), T(path[last])) << "segment " << n;
    ASSERT_EQ(size_t(w.remaining), path.size() - 1 - last) << "segment " << n;
    for (size_t i = last + 1; i < path.size(); ++i) {
      w.Advance();
      ASSERT_EQ(T(Cur(w)), T(path[i])) << "segment " << n << " voxel " << i << " after the jump";
    }
    EXPECT_EQ(w.remaining, 0);
  }
  EXPECT_GT(jumped, 3000);
  EXPECT_GT(ended_inside, 100);
}

// Sparse scenes: every empty brick's free box (FreeBrickBox) contains the brick and holds no
// occupied voxel, checked against the list of occupied voxels the grid was built from.
TEST(FreeBrickBoxTest, ContainsItsBrickAndHoldsNoOccupiedVoxel) {
  std::mt19937_64 rng(33);
  std::uniform_int_distribution<int> c(-60, 60);
  std::uniform_int_distribution<int> in_brick(0, OccupancyGrid::kBrick - 1);
  int boxes = 0, wider_than_the_cube = 0;
  for (int scene = 0; scene < 4; ++scene) {
    std::vector<VoxelIndex> occupied;
    for (int k = 0; k < 12; ++k) {
      const VoxelIndex base{c(rng), c(rng), c(rng)};
      for (int d = 0; d < 20; ++d) occupied.push_back({base.x + d % 5, base.y + d / 5, base.z});
    }
    for (int y = -60; y <= 60; ++y) occupied.push_back({c(rng), y, -60});  // a scattered floor row
    Result<OccupancyGrid> grid = OccupancyGrid::Build(0.1, occupied, uint64_t{1} << 26);
    ASSERT_TRUE(grid.ok()) << grid.status().ToString();
    const VoxelIndex& min = grid->min_index();
    const int lo3[3] = {min.x, min.y, min.z};
    const Eigen::Vector3i& bd = grid->brick_dims();
    for (int bz = 0; bz < bd.z(); ++bz) {
      for (int by = 0; by < bd.y(); ++by) {
        for (int bx = 0; bx < bd.x(); ++bx) {
          const uint64_t brick = grid->BrickLinear(bx, by, bz);
          if (grid->BrickSlot(brick) != 0) continue;
          const uint32_t rel[3] = {uint32_t(bx * OccupancyGrid::kBrick + in_brick(rng)),
                                   uint32_t(by * OccupancyGrid::kBrick + in_brick(rng)),
                                   uint32_t(bz * OccupancyGrid::kBrick + in_brick(rng))};
          int lo[3], hi[3];
          FreeBrickBox(*grid, brick, rel, lo3, lo, hi);
          ++boxes;
          const VoxelIndex voxel{lo3[0] + int(rel[0]), lo3[1] + int(rel[1]), lo3[2] + int(rel[2])};
          ASSERT_TRUE(Inside(voxel, lo, hi));
          const int cube = (2 * (grid->BrickDistance(brick) - 1) + 1) * OccupancyGrid::kBrick;
          for (int i = 0; i < 3; ++i) {
            ASSERT_EQ((lo[i] - lo3[i]) % OccupancyGrid::kBrick, 0) << "not brick-aligned";
            ASSERT_EQ((hi[i] + 1 - lo3[i]) % OccupancyGrid::kBrick, 0) << "not brick-aligned";
            ASSERT_GE(hi[i] - lo[i] + 1, cube) << "smaller than the cube of its distance";
            if (hi[i] - lo[i] + 1 > cube) ++wider_than_the_cube;
          }
          for (const VoxelIndex& v : occupied) ASSERT_FALSE(Inside(v, lo, hi)) << "an occupied voxel in a free box";
        }
      }
    }
  }
  EXPECT_GT(boxes, 1000);
  EXPECT_GT(wider_than_the_cube, 0) << "no box was widened by ExtraBricks: the test misses that part";
}

}  // namespace
}  // namespace vc::internal
