// Sub-voxel surfaces (issue 34; docs/VISIBILITY.md "Sub-voxel surfaces"): per occupied voxel, what
// the input points inside it say about the surface there: their centroid, the normal of the plane
// that fits them best (the covariance's eigenvector of the least eigenvalue), how far the points lie
// from that plane, and whether the voxel is flat enough for its plane to stand for it.
//
// Built from points only: an octree carries no points, so a scene read from an octree has no
// patches, and the selection tests that use them fall back to today's behaviour (visibility.h).
// SurfacePatchBuilder accumulates per voxel the count, the sum and the sum of outer products of
// the points' offsets from the voxel's centre (in double) and their bounding box (in float), 104
// bytes per voxel while it builds, then keeps 40 bytes per voxel (SurfacePatch). Points are added in any order and in
// any number of passes (one per scan), each with VoxelScene::IdOf, so the cost is O(points x log voxels). A voxel whose
// own points do not determine a plane (a sliver of a surface at its edge, one or two points, a noisy strip) takes a
// flat neighbour's plane when its points lie on it (borrowed). A builder is not thread-safe; the patches it returns are
// immutable.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "vc/scene/voxel_scene.h"

namespace vc {

// A patch is flat (SurfacePatch::flat) when it has at least kFlatMinPoints points, their RMS
// distance to the fitted plane is at most kFlatMaxThickness voxel edges, and they spread across
// the plane (RMS along the middle principal axis) at least kFlatMinSpreadPerThickness times that
// distance and at least kFlatMinSpread voxel edges, so that the plane is well determined: a line
// of points (a rail, a cable, a noisy sliver of a surface) is not taken for a plane, while a
// noise-free sliver (two rows of points on one plane) is.
inline constexpr int kFlatMinPoints = 3;
inline constexpr double kFlatMaxThickness = 0.15;
inline constexpr double kFlatMinSpreadPerThickness = 2.0;
inline constexpr double kFlatMinSpread = 0.001;

// Steps of SurfacePatch's box per voxel edge.
inline constexpr int kPatchBoxSteps = 255;

// What the points inside one occupied voxel say about its surface. 40 bytes.
struct SurfacePatch {
  // Mean of the voxel's points (m, the scene's local frame), inside the voxel's cube.
  Eigen::Vector3f centroid_m = Eigen::Vector3f::Zero();
  // Unit normal of the best-fitting plane through the centroid (sign arbitrary); +z with fewer
  // than 3 points.
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  // RMS distance of the points to that plane (m): the flatness measure, 0 for a perfect plane.
  float thickness_m = 0;
  // Points inside the voxel, saturating at 65535.
  uint16_t points = 0;
  // By the rule above, or borrowed (below).
  bool flat = false;
  // The voxel's own points do not give a flat plane, but they lie on a flat 26-neighbour's plane
  // (RMS distance at most kFlatMaxThickness voxel edges; the nearest such plane): its normal is
  // that neighbour's, through this voxel's own centroid, and thickness_m that RMS distance.
  bool borrowed = false;
  // The axis-aligned box the points span, per axis in steps of 1 / kPatchBoxSteps edges from the
  // cube's low corner, rounded outwards (lo down, hi up); the whole cube (0 .. kPatchBoxSteps) for a
  // voxel no point fell in.
  uint8_t box_lo[3] = {0, 0, 0};
  uint8_t box_hi[3] = {kPatchBoxSteps, kPatchBoxSteps, kPatchBoxSteps};
  // Which of the six face-neighbours of the voxel are occupied: bit 2i for the one at -1 along
  // axis i, bit 2i + 1 for +1 (a surface that goes on across that face).
  uint8_t occupied_neighbours = 0;
};
static_assert(sizeof(SurfacePatch) == 40, "SurfacePatch is documented as 40 bytes");

// Accumulates points into the voxels of `scene` (which must outlive the builder).
class SurfacePatchBuilder {
 public:
  explicit SurfacePatchBuilder(const VoxelScene& scene);
  // Adds a point (m, the scene's local frame); a non-finite point, or one in no occupied voxel of
  // the scene, is ignored and counted.
  void Add(const Eigen::Vector3f& point_m);
  // Points ignored by Add.
  uint64_t ignored() const { return ignored_; }
  // One patch per voxel id of the scene. A voxel no point fell in gets a patch with 0 points, its
  // centroid the voxel's centre and flat false.
  std::vector<SurfacePatch> Finish() const;

 private:
  struct Sums {
    double n = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
    // The points' bounding box (offsets from the centre, m).
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
    Eigen::Vector3f hi = Eigen::Vector3f::Constant(-std::numeric_limits<float>::infinity());
  };
  static Eigen::Matrix3d Outer(const Sums& s);
  // Gives `patch` (voxel id's, not flat) the plane of a flat neighbour in `own` (the patches from
  // each voxel's own points) when its points lie on it, as SurfacePatch::borrowed says.
  void BorrowPlane(size_t id, const std::vector<SurfacePatch>& own, SurfacePatch& patch) const;
  const VoxelScene& scene_;
  std::vector<Sums> sums_;
  uint64_t ignored_ = 0;
};

// The patches of `scene` from `points_m` (one pass of SurfacePatchBuilder).
std::vector<SurfacePatch> ComputeSurfacePatches(const VoxelScene& scene, const std::vector<Eigen::Vector3f>& points_m);

}  // namespace vc
