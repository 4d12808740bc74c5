#include "vc/core/voxel_scene.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vc/core/octomap_adapter.h"

namespace vc {
namespace {

// Packs a key into 48 bits in VoxelKey's order (z, then y, then x), so sorting packed values
// sorts keys.
uint64_t Pack(const VoxelKey& k) { return (uint64_t(k.z) << 32) | (uint64_t(k.y) << 16) | uint64_t(k.x); }
VoxelKey Unpack(uint64_t p) { return {uint16_t(p & 0xffff), uint16_t((p >> 16) & 0xffff), uint16_t(p >> 32)}; }

Status CheckResolution(double r) {
  if (!std::isfinite(r) || r <= 0) {
    return InvalidArgumentError("resolution must be a positive, finite number of metres; got " + std::to_string(r));
  }
  if (r < 0.001 || r > 100) {
    return InvalidArgumentError("resolution " + std::to_string(r) + " m is outside the supported range 0.001-100 m");
  }
  return Status::Ok();
}

// Refuses a box of voxel indices [lo, hi] that cannot be represented or would not fit.
Status CheckExtent(const Eigen::Vector3d& lo_m, const Eigen::Vector3d& hi_m, double r, uint64_t budget) {
  const Eigen::Vector3d lo = (lo_m / r).array().floor(), hi = (hi_m / r).array().floor();
  std::ostringstream ext;
  ext.precision(4);
  ext << (hi_m - lo_m).x() << " x " << (hi_m - lo_m).y() << " x " << (hi_m - lo_m).z() << " m";
  if ((lo.array() < -kKeyOffset).any() || (hi.array() >= kKeyOffset).any()) {
    const double needed = std::max(lo_m.cwiseAbs().maxCoeff(), hi_m.cwiseAbs().maxCoeff()) / (kKeyOffset - 1);
    std::ostringstream os;
    os << "the scene (extent " << ext.str() << ", bounding box " << lo_m.transpose() << " .. " << hi_m.transpose()
       << " m) does not fit OctoMap's 65536-voxel key range at resolution " << r
       << " m; coordinates must lie within +-" << kKeyOffset * r << " m of the origin. Use a resolution of at least "
       << std::ceil(needed * 1000) / 1000 << " m or move the scene near the origin";
    return InvalidArgumentError(os.str());
  }
  const VoxelIndex a{int(lo.x()), int(lo.y()), int(lo.z())}, b{int(hi.x()), int(hi.y()), int(hi.z())};
  const uint64_t need = OccupancyGrid::BytesNeeded(a, b, 0);
  if (need > budget) {
    const double factor = std::cbrt(double(need) / double(budget) * 1.25);
    std::ostringstream os;
    os << "the scene spans " << ext.str() << "; at resolution " << r << " m its traversal grid alone needs "
       << double(need) / double(1 << 20) << " MiB, over the memory budget of " << double(budget) / double(1 << 20)
       << " MiB; use a resolution of at least " << std::ceil(r * factor * 1000) / 1000
       << " m, raise the budget, or crop the scene";
    return ResourceExhaustedError(os.str());
  }
  return Status::Ok();
}

}  // namespace

int64_t VoxelScene::IdOf(const VoxelKey& key) const {
  auto it = std::lower_bound(occupied.begin(), occupied.end(), key);
  if (it == occupied.end() || *it != key) return -1;
  return it - occupied.begin();
}

WorldPoint VoxelScene::BoundsMin() const {
  WorldPoint m = WorldPoint::Constant(std::numeric_limits<double>::infinity());
  for (const VoxelKey& k : occupied) m = m.cwiseMin(KeyToCoord(resolution_m, k));
  return m - WorldPoint::Constant(resolution_m / 2);
}

WorldPoint VoxelScene::BoundsMax() const {
  WorldPoint m = WorldPoint::Constant(-std::numeric_limits<double>::infinity());
  for (const VoxelKey& k : occupied) m = m.cwiseMax(KeyToCoord(resolution_m, k));
  return m + WorldPoint::Constant(resolution_m / 2);
}

double WorkingResolution(const SceneInput& input, const VoxelizeOptions& options) {
  if (options.resolution_m != 0) return options.resolution_m;
  if (input.octree) return OctreeResolution(*input.octree);
  return kDefaultResolutionM;
}

Result<std::vector<VoxelKey>> OccupiedKeys(const SceneInput& input, double r, uint64_t budget, const JobContext& ctx) {
  VC_RETURN_IF_ERROR(CheckResolution(r));
  std::vector<uint64_t> packed;
  if (input.octree) {
    const octomap::OcTree& tree = *input.octree;
    WorldPoint lo, hi;
    OccupiedBoundingBox(tree, &lo, &hi);
    if (!(lo.array() <= hi.array()).all()) return InvalidArgumentError("the octree has no occupied voxels");
    VC_RETURN_IF_ERROR(CheckExtent(lo, hi, r, budget));
    // Count first: a coarse leaf at a fine resolution expands to many voxels.
    const double eps = 1e-9;
    uint64_t total = 0;
    auto range = [&](const WorldPoint& m, double s, int axis, int* a, int* b) {
      *a = int(std::floor(m[axis] / r + eps));
      *b = int(std::ceil((m[axis] + s) / r - eps)) - 1;
    };
    ForEachOccupiedLeaf(tree, [&](const WorldPoint& m, double s) {
      uint64_t n = 1;
      for (int i = 0; i < 3; ++i) {
        int a, b;
        range(m, s, i, &a, &b);
        n *= uint64_t(std::max(0, b - a + 1));
      }
      total += n;
    });
    if (total * sizeof(uint64_t) > budget) {
      return ResourceExhaustedError("resampling the octree at " + std::to_string(r) + " m gives " + std::to_string(total) +
                                    " occupied voxels, over the memory budget; use a coarser resolution (the tree's own is " +
                                    std::to_string(tree.getResolution()) + " m)");
    }
    packed.reserve(total);
    ForEachOccupiedLeaf(tree, [&](const WorldPoint& m, double s) {
      int a[3], b[3];
      for (int i = 0; i < 3; ++i) range(m, s, i, &a[i], &b[i]);
      for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
          for (int x = a[0]; x <= b[0]; ++x) packed.push_back(Pack(IndexToKey({x, y, z})));
    });
  } else {
    if (input.points.empty()) return InvalidArgumentError("the point cloud is empty");
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Eigen::Vector3f& p : input.points) {
      lo = lo.cwiseMin(p.cast<double>());
      hi = hi.cwiseMax(p.cast<double>());
    }
    if (!lo.allFinite() || !hi.allFinite()) return InvalidArgumentError("the point cloud has non-finite coordinates");
    VC_RETURN_IF_ERROR(CheckExtent(lo, hi, r, budget));
    if (input.points.size() * sizeof(uint64_t) > budget) {
      return ResourceExhaustedError("voxelising " + std::to_string(input.points.size()) +
                                    " points needs more than the memory budget; raise it or thin the cloud");
    }
    packed.reserve(input.points.size());
    const double f = 1.0 / r;
    for (size_t i = 0; i < input.points.size(); ++i) {
      if ((i & 0xfffff) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("voxelisation"));
      const Eigen::Vector3f& p = input.points[i];
      const VoxelKey k{uint16_t(int(std::floor(f * double(p.x()))) + kKeyOffset),
                       uint16_t(int(std::floor(f * double(p.y()))) + kKeyOffset),
                       uint16_t(int(std::floor(f * double(p.z()))) + kKeyOffset)};
      packed.push_back(Pack(k));
    }
  }
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("voxelisation"));
  std::sort(packed.begin(), packed.end());
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  std::vector<VoxelKey> keys(packed.size());
  for (size_t i = 0; i < packed.size(); ++i) keys[i] = Unpack(packed[i]);
  return keys;
}

Result<VoxelScene> Voxelize(const SceneInput& input, const VoxelizeOptions& options, const JobContext& ctx) {
  VoxelScene scene;
  scene.resolution_m = WorkingResolution(input, options);
  ctx.Report("voxelize", 0.0, "voxelising at " + std::to_string(scene.resolution_m) + " m");
  VC_ASSIGN_OR_RETURN(scene.occupied, OccupiedKeys(input, scene.resolution_m, options.memory_budget_bytes, ctx));
  std::vector<VoxelIndex> idx(scene.occupied.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = KeyToIndex(scene.occupied[i]);
  const uint64_t list_bytes = scene.occupied.size() * sizeof(VoxelKey);
  if (list_bytes >= options.memory_budget_bytes) {
    return ResourceExhaustedError("the scene has " + std::to_string(scene.occupied.size()) +
                                  " occupied voxels, over the memory budget; use a coarser resolution");
  }
  VC_ASSIGN_OR_RETURN(scene.grid, OccupancyGrid::Build(scene.resolution_m, idx, options.memory_budget_bytes - list_bytes));
  scene.scan_origins = input.scan_origins;
  ctx.Report("voxelize", 1.0, std::to_string(scene.occupied.size()) + " occupied voxels");
  return scene;
}

}  // namespace vc
