#include "vc/scene/surface_patches.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace vc {

SurfacePatchBuilder::SurfacePatchBuilder(const VoxelScene& scene) : scene_(scene), sums_(scene.occupied.size()) {}

void SurfacePatchBuilder::Add(const Eigen::Vector3f& point_m) {
  const Eigen::Vector3d p = point_m.cast<double>();
  VoxelKey key;
  if (!p.allFinite() || !CoordToKey(scene_.resolution_m, p, &key)) {
    ++ignored_;
    return;
  }
  const int64_t id = scene_.IdOf(key);
  if (id < 0) {
    ++ignored_;
    return;
  }
  Sums& s = sums_[size_t(id)];
  const Eigen::Vector3d d = p - scene_.Center(size_t(id));
  s.n += 1;
  s.sum += d;
  s.xx += d.x() * d.x();
  s.xy += d.x() * d.y();
  s.xz += d.x() * d.z();
  s.yy += d.y() * d.y();
  s.yz += d.y() * d.z();
  s.zz += d.z() * d.z();
  s.lo = s.lo.cwiseMin(d.cast<float>());
  s.hi = s.hi.cwiseMax(d.cast<float>());
}

namespace {

// The patch of one voxel from its sums and box (offsets from `center`, m) at edge `r` (m).
SurfacePatch PatchOf(double n, const Eigen::Vector3d& sum, const Eigen::Matrix3d& outer, const Eigen::Vector3f& lo,
                     const Eigen::Vector3f& hi, const WorldPoint& center, double r) {
  SurfacePatch patch;
  patch.points = uint16_t(std::min(n, 65535.0));
  if (n == 0) {
    patch.centroid_m = center.cast<float>();
    return patch;
  }
  const double step = r / kPatchBoxSteps;
  for (int i = 0; i < 3; ++i) {
    patch.box_lo[i] = uint8_t(std::clamp(std::floor((double(lo[i]) + 0.5 * r) / step), 0.0, double(kPatchBoxSteps)));
    patch.box_hi[i] = uint8_t(std::clamp(std::ceil((double(hi[i]) + 0.5 * r) / step), 0.0, double(kPatchBoxSteps)));
  }
  const Eigen::Vector3d mean = sum / n;
  // Keep the centroid strictly inside the cube after rounding to float.
  const Eigen::Vector3d inside =
      mean.cwiseMax(Eigen::Vector3d::Constant(-0.4999 * r)).cwiseMin(Eigen::Vector3d::Constant(0.4999 * r));
  patch.centroid_m = (center + inside).cast<float>();
  if (n < kFlatMinPoints) return patch;
  const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);  // ascending
  patch.normal = eig.eigenvectors().col(0).normalized().cast<float>();
  patch.thickness_m = float(std::sqrt(lambda[0]));
  const double thickness = std::sqrt(lambda[0]), spread = std::sqrt(lambda[1]);
  patch.flat = thickness <= kFlatMaxThickness * r && spread >= kFlatMinSpreadPerThickness * thickness &&
               spread >= kFlatMinSpread * r;
  return patch;
}

}  // namespace

Eigen::Matrix3d SurfacePatchBuilder::Outer(const Sums& s) {
  Eigen::Matrix3d outer;
  outer << s.xx, s.xy, s.xz, s.xy, s.yy, s.yz, s.xz, s.yz, s.zz;
  return outer;
}

void SurfacePatchBuilder::BorrowPlane(size_t id, const std::vector<SurfacePatch>& own, SurfacePatch& patch) const {
  const Sums& s = sums_[id];
  const double r = scene_.resolution_m;
  const WorldPoint center = scene_.Center(id);
  const VoxelIndex v = KeyToIndex(scene_.occupied[id]);
  double best = kFlatMaxThickness * r;
  int64_t from = -1;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int64_t w = (dx | dy | dz) == 0 ? -1 : scene_.IdOf(IndexToKey({v.x + dx, v.y + dy, v.z + dz}));
        if (w < 0 || !own[size_t(w)].flat) continue;
        // RMS distance of this voxel's points to w's plane, from the sums: n'Sn / count with S the
        // sum of outer products of the offsets from w's centroid.
        const Eigen::Vector3d n = own[size_t(w)].normal.cast<double>();
        const double offset = n.dot(center - own[size_t(w)].centroid_m.cast<double>());
        const double mean_sq = (n.dot(Outer(s) * n) + 2 * offset * n.dot(s.sum)) / s.n + offset * offset;
        const double rms = std::sqrt(std::max(mean_sq, 0.0));
        if (rms <= best) best = rms, from = w;
      }
    }
  }
  if (from < 0) return;
  patch.normal = own[size_t(from)].normal;
  patch.thickness_m = float(best);
  patch.flat = true;
  patch.borrowed = true;
}

std::vector<SurfacePatch> SurfacePatchBuilder::Finish() const {
  std::vector<SurfacePatch> patches(sums_.size());
  for (size_t id = 0; id < sums_.size(); ++id) {
    const Sums& s = sums_[id];
    patches[id] = PatchOf(s.n, s.sum, Outer(s), s.lo, s.hi, scene_.Center(id), scene_.resolution_m);
  }
  for (size_t id = 0; id < sums_.size(); ++id) {
    const VoxelIndex v = KeyToIndex(scene_.occupied[id]);
    for (int bit = 0; bit < 6; ++bit) {
      VoxelIndex n = v;
      (bit / 2 == 0 ? n.x : bit / 2 == 1 ? n.y : n.z) += bit % 2 ? 1 : -1;
      if (scene_.IdOf(IndexToKey(n)) >= 0) patches[id].occupied_neighbours |= uint8_t(1u << bit);
    }
  }
  const std::vector<SurfacePatch> own = patches;  // planes fitted to each voxel's own points
  for (size_t id = 0; id < sums_.size(); ++id) {
    if (!own[id].flat && sums_[id].n > 0) BorrowPlane(id, own, patches[id]);
  }
  return patches;
}

std::vector<SurfacePatch> ComputeSurfacePatches(const VoxelScene& scene, const std::vector<Eigen::Vector3f>& points_m) {
  SurfacePatchBuilder builder(scene);
  for (const auto& p : points_m) builder.Add(p);
  return builder.Finish();
}

}  // namespace vc
