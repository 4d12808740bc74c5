// The sub-voxel selection test (subvoxel.h, docs/VISIBILITY.md "Sub-voxel surfaces").
#include "vc/visibility/subvoxel.h"

#include <cmath>
#include <limits>
#include <numbers>

#include "subvoxel_internal.h"
#include "vc/raycast/walk.h"
#include "visibility_internal.h"

namespace vc {

Eigen::Vector3d SubvoxelAimIS(const VoxelScene& scene, std::span<const SurfacePatch> patches, size_t id) {
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  const Eigen::Vector3d lo(v.x, v.y, v.z);
  const Eigen::Vector3d aim = scene.grid.WorldToIndexSpace(patches[id].centroid_m.cast<double>());
  constexpr double kInside = 1e-6;
  return aim.cwiseMax(lo + Eigen::Vector3d::Constant(kInside)).cwiseMin(lo + Eigen::Vector3d::Constant(1 - kInside));
}

namespace internal {
namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// The parameter s at which the segment a -> b (index space) meets the flat patch `p` of voxel w
// (its plane clipped to w's closed cube), or kNoHit.
double FlatHit(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const VoxelIndex& w, const Eigen::Vector3d& center,
               const Eigen::Vector3d& normal) {
  const double den = normal.dot(b - a);
  if (den == 0) return kNoHit;
  const double s = normal.dot(center - a) / den;
  if (!(s >= 0 && s <= 1)) return kNoHit;
  const Eigen::Vector3d p = a + s * (b - a);
  const Eigen::Vector3d lo(w.x, w.y, w.z);
  for (int i = 0; i < 3; ++i) {
    if (!(p[i] >= lo[i] && p[i] <= lo[i] + 1)) return kNoHit;
  }
  return s;
}

// Whether the hit at `hit` (index space) on flat patch `w` lies on the target's surface `t`.
bool SameSurface(const Eigen::Vector3d& hit, const Eigen::Vector3d& t_center, const SurfacePatch& t,
                 const SurfacePatch& w) {
  static const double kCosMax = std::cos(kSameSurfaceMaxAngleDeg * std::numbers::pi / 180.0);
  if ((hit - t_center).squaredNorm() <= kSameSurfaceTolerance * kSameSurfaceTolerance) return true;
  if (!t.flat || !w.flat) return false;
  const Eigen::Vector3d n = t.normal.cast<double>();
  return std::abs(n.dot(hit - t_center)) <= kSameSurfaceTolerance &&
         std::abs(n.dot(w.normal.cast<double>())) >= kCosMax;
}

// The face (axis, sign) whose outward normal is nearest to `n` turned towards `to_viewpoint`.
void NearestFace(Eigen::Vector3d n, const Eigen::Vector3d& to_viewpoint, int* axis, int* sign) {
  if (n.dot(to_viewpoint) < 0) n = -n;
  int a = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(n[i]) > std::abs(n[a])) a = i;
  }
  *axis = a;
  *sign = n[a] < 0 ? -1 : 1;
}

}  // namespace

bool SubvoxelVisibleFrom(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                         size_t id, const ScannerLimits& limits) {
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  const SurfacePatch& target = patches[id];
  const Eigen::Vector3d aim = SubvoxelAimIS(scene, patches, id);
  const Eigen::Vector3d to_viewpoint = uo - aim;
  int axis = 0, sign = 1;
  NearestFace(target.flat ? target.normal.cast<double>() : to_viewpoint, to_viewpoint, &axis, &sign);
  if (!limits.Passes(aim, axis, sign)) return false;

  const OccupancyGrid& g = scene.grid;
  Walk walk(uo, aim);
  double t_in = 0, first = kNoHit;
  bool same_at_first = false;
  while (t_in <= first) {
    const VoxelIndex cur{walk.cur[0], walk.cur[1], walk.cur[2]};
    if (cur == v) break;
    if (g.Occupied(cur)) {
      const int64_t w = scene.IdOf(IndexToKey(cur));
      const SurfacePatch& patch = patches[size_t(w)];
      const Eigen::Vector3d center = g.WorldToIndexSpace(patch.centroid_m.cast<double>());
      const double s = patch.flat ? FlatHit(uo, aim, cur, center, patch.normal.cast<double>()) : t_in;
      if (s <= first) {
        const bool same = SameSurface(uo + s * (aim - uo), aim, target, patch);
        same_at_first = s < first ? same : same_at_first || same;
        first = s;
      }
    }
    if (walk.remaining == 0) break;
    t_in = std::min({walk.t_max[0], walk.t_max[1], walk.t_max[2]});
    walk.Advance();
  }
  return first == kNoHit || same_at_first;
}

}  // namespace internal

namespace {

bool SubvoxelQuery(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id,
                   const ScannerModel* scanner) {
  if (patches.size() != scene.occupied.size() || id >= scene.occupied.size()) return false;
  if (!ViewpointInRange(o, scene.resolution_m)) return false;
  const Eigen::Vector3d uo = scene.grid.WorldToIndexSpace(o);
  if (internal::InsideOccupied(scene.grid, uo)) return false;
  const ScannerLimits limits = scanner ? ScannerLimits(*scanner, scene.resolution_m, uo) : ScannerLimits();
  return internal::SubvoxelVisibleFrom(scene, patches, uo, id, limits);
}

}  // namespace

bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id) {
  return SubvoxelQuery(scene, patches, o, id, nullptr);
}

bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id,
                       const ScannerModel& scanner) {
  return SubvoxelQuery(scene, patches, o, id, &scanner);
}

}  // namespace vc
