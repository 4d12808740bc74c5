// The sub-voxel selection test (subvoxel.h, docs/VISIBILITY.md "Sub-voxel surfaces").
#include "vc/visibility/subvoxel.h"

#include <cmath>
#include <limits>
#include <numbers>

#include "subvoxel_internal.h"
#include "vc/raycast/walk.h"
#include "visibility_internal.h"

namespace vc {
namespace {

// `p` (index space) moved strictly inside voxel `id`'s cube.
Eigen::Vector3d SubvoxelInside(const VoxelScene& scene, size_t id, const Eigen::Vector3d& p) {
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  const Eigen::Vector3d lo(v.x, v.y, v.z);
  constexpr double kInside = 1e-6;
  return p.cwiseMax(lo + Eigen::Vector3d::Constant(kInside)).cwiseMin(lo + Eigen::Vector3d::Constant(1 - kInside));
}

}  // namespace

Eigen::Vector3d SubvoxelAimIS(const VoxelScene& scene, std::span<const SurfacePatch> patches, size_t id) {
  return SubvoxelInside(scene, id, scene.grid.WorldToIndexSpace(patches[id].centroid_m.cast<double>()));
}

Eigen::AlignedBox3d SubvoxelBoxIS(const VoxelScene& scene, std::span<const SurfacePatch> patches, size_t id) {
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  const Eigen::Vector3d lo(v.x, v.y, v.z), hi = lo + Eigen::Vector3d::Ones();
  const SurfacePatch& p = patches[id];
  Eigen::Vector3d box_lo, box_hi;
  for (int i = 0; i < 3; ++i) {
    // On a side whose face-neighbour is occupied the surface goes on: the box reaches the face.
    box_lo[i] = (p.occupied_neighbours >> (2 * i)) & 1u
                    ? lo[i]
                    : lo[i] + double(p.box_lo[i]) / kPatchBoxSteps - kSubvoxelBoxPad;
    box_hi[i] = (p.occupied_neighbours >> (2 * i + 1)) & 1u
                    ? hi[i]
                    : lo[i] + double(p.box_hi[i]) / kPatchBoxSteps + kSubvoxelBoxPad;
  }
  return {box_lo.cwiseMax(lo), box_hi.cwiseMin(hi)};
}

namespace internal {
namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Where the segment a -> b (index space) first meets the blocker of patch `p` (`box`: its blocking
// box; `center`: its centroid): for a flat patch its plane within the box, else the box with some
// length inside; kNoHit when it does not.
double BlockerHit(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::AlignedBox3d& box,
                  const SurfacePatch& p, const Eigen::Vector3d& center) {
  if (p.flat) {
    const Eigen::Vector3d normal = p.normal.cast<double>();
    const double den = normal.dot(b - a);
    if (den == 0) return kNoHit;
    const double s = normal.dot(center - a) / den;
    if (!(s >= 0 && s <= 1)) return kNoHit;
    const Eigen::Vector3d x = a + s * (b - a);
    for (int i = 0; i < 3; ++i) {
      if (!(x[i] >= box.min()[i] && x[i] <= box.max()[i])) return kNoHit;
    }
    return s;
  }
  double enter = 0, leave = 1;
  for (int i = 0; i < 3; ++i) {
    const double d = b[i] - a[i];
    if (d == 0) {
      if (a[i] < box.min()[i] || a[i] > box.max()[i]) return kNoHit;
      continue;
    }
    double t0 = (box.min()[i] - a[i]) / d, t1 = (box.max()[i] - a[i]) / d;
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
  }
  return enter < leave ? enter : kNoHit;
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

// The segment uo -> aim (index space; aim inside target voxel `id`'s cube) judged by the test:
// clear, first blocker on the target's surface, or blocked.
SubvoxelRay TraceSegment(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                         const Eigen::Vector3d& aim, size_t id) {
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  const SurfacePatch& target = patches[id];
  const OccupancyGrid& g = scene.grid;
  const VoxelIndex& lo = g.min_index();
  const int lo3[3] = {lo.x, lo.y, lo.z};
  const uint32_t dims[3] = {uint32_t(g.dims().x()), uint32_t(g.dims().y()), uint32_t(g.dims().z())};
  Walk walk(uo, aim);
  double t_in = 0, first = kNoHit;
  bool same_at_first = false;
  int64_t first_blocker = -1;
  while (t_in <= first) {
    const VoxelIndex cur{walk.cur[0], walk.cur[1], walk.cur[2]};
    if (cur == v) break;
    const uint32_t rel[3] = {uint32_t(cur.x - lo3[0]), uint32_t(cur.y - lo3[1]), uint32_t(cur.z - lo3[2])};
    const bool in_grid = rel[0] < dims[0] && rel[1] < dims[1] && rel[2] < dims[2];
    const uint64_t brick = in_grid ? g.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3) : 0;
    if (in_grid && g.BrickSlot(brick) == 0) {
      // An empty brick: jump across its free box (walk.h), which holds no blocker; the walk's
      // end, v, is occupied, so it does not end inside the box.
      if (!JumpAcrossFreeBrickBox(g, brick, rel, lo3, walk)) break;
    } else if (in_grid && g.Occupied(cur)) {
      const int64_t w = scene.IdOf(IndexToKey(cur));
      const SurfacePatch& patch = patches[size_t(w)];
      const Eigen::Vector3d center = g.WorldToIndexSpace(patch.centroid_m.cast<double>());
      const double s = BlockerHit(uo, aim, SubvoxelBoxIS(scene, patches, size_t(w)), patch, center);
      if (s <= first) {
        const bool same = SameSurface(uo + s * (aim - uo), aim, target, patch);
        // At a tie, the blocker reported is one on the target's surface when there is one.
        if (s < first || (same && !same_at_first)) first_blocker = w;
        same_at_first = s < first ? same : same_at_first || same;
        first = s;
      }
    }
    if (walk.remaining == 0) break;
    t_in = std::min({walk.t_max[0], walk.t_max[1], walk.t_max[2]});
    walk.Advance();
  }
  SubvoxelRay ray;
  ray.first_blocker = first_blocker;
  ray.blocker_s = first == kNoHit ? 1.0 : first;
  ray.outcome = first == kNoHit ? SubvoxelRay::Outcome::kClear
                : same_at_first ? SubvoxelRay::Outcome::kSameSurface
                                : SubvoxelRay::Outcome::kBlocked;
  return ray;
}

}  // namespace

SubvoxelRay TraceSubvoxel(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                          size_t id, const ScannerLimits& limits) {
  const SurfacePatch& target = patches[id];
  const Eigen::Vector3d aim = SubvoxelAimIS(scene, patches, id);
  const Eigen::Vector3d to_viewpoint = uo - aim;
  int axis = 0, sign = 1;
  NearestFace(target.flat ? target.normal.cast<double>() : to_viewpoint, to_viewpoint, &axis, &sign);
  if (!limits.Passes(aim, axis, sign)) {
    SubvoxelRay ray;
    ray.outcome = SubvoxelRay::Outcome::kOutsideLimits;
    return ray;
  }
  const SubvoxelRay ray = TraceSegment(scene, patches, uo, aim, id);
  if (ray.seen() || target.flat) return ray;
  // A voxel that is not flat is also seen where the centre of a face of its box that faces o is.
  const Eigen::AlignedBox3d box = SubvoxelBoxIS(scene, patches, id);
  for (int i = 0; i < 3; ++i) {
    for (const bool high : {false, true}) {
      const double side = high ? box.max()[i] : box.min()[i];
      if (high ? !(uo[i] > side) : !(uo[i] < side)) continue;
      Eigen::Vector3d face = box.center();
      face[i] = side;
      const SubvoxelRay to_face = TraceSegment(scene, patches, uo, SubvoxelInside(scene, id, face), id);
      if (to_face.seen()) return to_face;
    }
  }
  return ray;
}

bool SubvoxelVisibleFrom(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                         size_t id, const ScannerLimits& limits) {
  return TraceSubvoxel(scene, patches, uo, id, limits).seen();
}

}  // namespace internal

namespace {

SubvoxelRay SubvoxelQuery(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o,
                          size_t id, const ScannerModel* scanner) {
  if (patches.size() != scene.occupied.size() || id >= scene.occupied.size()) return {};
  if (!ViewpointInRange(o, scene.resolution_m)) return {};
  const Eigen::Vector3d uo = scene.grid.WorldToIndexSpace(o);
  if (internal::InsideOccupied(scene.grid, uo)) return {};
  const ScannerLimits limits = scanner ? ScannerLimits(*scanner, scene.resolution_m, uo) : ScannerLimits();
  return internal::TraceSubvoxel(scene, patches, uo, id, limits);
}

}  // namespace

bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id) {
  return SubvoxelQuery(scene, patches, o, id, nullptr).seen();
}

bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id,
                       const ScannerModel& scanner) {
  return SubvoxelQuery(scene, patches, o, id, &scanner).seen();
}

SubvoxelRay ExplainSubvoxel(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o,
                            size_t id, const ScannerModel& scanner) {
  return SubvoxelQuery(scene, patches, o, id, &scanner);
}

}  // namespace vc
