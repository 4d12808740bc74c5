// Pieces the selection tests (visibility.cc) and the evaluation (evaluate.cc) share: face and
// corner geometry in index space, the corner test with its per-ray shortcuts, V of a face, and
// rate-limited progress. Private to the visibility layer. Everything here is inline so that the
// hot loops of both files inline them as they did when they lived in one file. Thread-safe on a
// const grid; an OccluderCache and a StageProgress belong to their caller.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <vector>

#include "vc/base/progress.h"
#include "vc/raycast/occluders.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/visibility/scanner_limits.h"
#include "vc/visibility/visibility.h"

namespace vc::internal {

inline constexpr double kHalfPi = 1.57079632679489661923;

// Outward normal axis and sign of a face.
inline int FaceAxis(Face f) { return int(f) / 2; }
inline int FaceSign(Face f) { return (int(f) % 2) ? 1 : -1; }

// Centre of face f of voxel v, in index space.
inline Eigen::Vector3d FaceCenterIS(const VoxelIndex& v, Face f) {
  Eigen::Vector3d c(v.x + 0.5, v.y + 0.5, v.z + 0.5);
  const int a = FaceAxis(f);
  c[a] += 0.5 * FaceSign(f);
  return c;
}

inline VoxelIndex Neighbour(const VoxelIndex& v, Face f) {
  VoxelIndex n = v;
  const int a = FaceAxis(f);
  (a == 0 ? n.x : a == 1 ? n.y : n.z) += FaceSign(f);
  return n;
}

inline bool Enclosed(const OccupancyGrid& g, const VoxelIndex& v) {
  return g.Occupied(v.x - 1, v.y, v.z) && g.Occupied(v.x + 1, v.y, v.z) && g.Occupied(v.x, v.y - 1, v.z) &&
         g.Occupied(v.x, v.y + 1, v.z) && g.Occupied(v.x, v.y, v.z - 1) && g.Occupied(v.x, v.y, v.z + 1);
}

// Ids of the voxels with at least one free neighbour (the only ones with an exposed face).
inline std::vector<uint32_t> NotEnclosed(const OccupancyGrid& g, const std::vector<VoxelIndex>& index) {
  std::vector<uint32_t> ids;
  for (size_t i = 0; i < index.size(); ++i)
    if (!Enclosed(g, index[i])) ids.push_back(uint32_t(i));
  return ids;
}

inline bool InsideOccupied(const OccupancyGrid& g, const Eigen::Vector3d& u) {
  return g.Occupied(int(std::floor(u.x())), int(std::floor(u.y())), int(std::floor(u.z())));
}

// True if the segment uo->c passes, half a voxel before reaching c's plane along some axis,
// through the interior of an occupied voxel that is not one of the 8 around c. The segment is
// outside the (convex) 2x2x2 block around c there, so the walk meets that voxel before any of
// the 8: c is not seen. This catches the surface's own layer hiding the corners behind it at
// grazing angles, without a walk.
inline bool LastLayerBlocksCorner(const OccupancyGrid& g, const Eigen::Vector3d& uo, const VoxelIndex& c) {
  constexpr double kMargin = internal::kInteriorMargin;
  const Eigen::Vector3d end(c.x, c.y, c.z);
  for (int a = 0; a < 3; ++a) {
    const double across = std::abs(uo[a] - end[a]);
    if (across < 1) continue;
    const Eigen::Vector3d p = end + (uo - end) * (0.5 / across);
    VoxelIndex h;
    bool interior = true, near = true;
    for (int i = 0; i < 3; ++i) {
      const double f = std::floor(p[i]);
      interior = interior && p[i] - f > kMargin && p[i] - f < 1 - kMargin;
      const int hi = int(f), ci = i == 0 ? c.x : i == 1 ? c.y : c.z;
      near = near && (hi == ci || hi == ci - 1);
      (i == 0 ? h.x : i == 1 ? h.y : h.z) = hi;
    }
    if (interior && !near && g.Occupied(h)) return true;
  }
  return false;
}

// Whether corner c is seen from uo (the 8-voxel corner rule), trying the shortcuts first; an
// occluder a walk meets is handed to remember(hit, c), which may put it (or a box grown from it) in
// the cache.
// Cache: OccluderCache, or anything with its enabled() and Blocks(a, b, keep_lo, keep_hi).
template <typename Cache, typename Remember>
inline bool CornerVisibleCached(const OccupancyGrid& g, const Eigen::Vector3d& uo, const VoxelIndex& c, Cache& cache,
                                Remember&& remember) {
  if (cache.enabled() && LastLayerBlocksCorner(g, uo, c)) return false;  // shortcuts hold (occluders.h)
  // Occluders in the 2x2x2 block around c do not count: once a segment enters that (convex)
  // block it stays inside it up to c, so every voxel outside it is visited first.
  const Eigen::Vector3d end(c.x, c.y, c.z);
  if (cache.Blocks(uo, end, {c.x - 1, c.y - 1, c.z - 1}, c)) return false;
  const auto hit = FirstOccupied(g, uo, end);
  if (!hit) return true;
  const bool near = (hit->x == c.x || hit->x == c.x - 1) && (hit->y == c.y || hit->y == c.y - 1) &&
                    (hit->z == c.z || hit->z == c.z - 1);
  if (!near) remember(*hit, c);
  return near;
}

inline bool CornerVisibleCached(const OccupancyGrid& g, const Eigen::Vector3d& uo, const VoxelIndex& c,
                                OccluderCache& cache) {
  return CornerVisibleCached(g, uo, c, cache, [&](const VoxelIndex& hit, const VoxelIndex&) { cache.Add(hit); });
}

// Corner k (bit 0: +x, bit 1: +y, bit 2: +z) of voxel v.
inline VoxelIndex Corner(const VoxelIndex& v, int k) {
  return {v.x + (k & 1), v.y + ((k >> 1) & 1), v.z + ((k >> 2) & 1)};
}

// The 4 corner numbers of each face.
inline constexpr int kFaceCorners[6][4] = {
    {0, 2, 4, 6},  // -x
    {1, 3, 5, 7},  // +x
    {0, 1, 4, 5},  // -y
    {2, 3, 6, 7},  // +y
    {0, 1, 2, 3},  // -z
    {4, 5, 6, 7},  // +z
};

// The same, as masks over the 8 corner numbers.
inline constexpr unsigned kFaceCornerMask[6] = {0x55, 0xaa, 0x33, 0xcc, 0x0f, 0xf0};

inline Perception FromCount(int visible) {
  return visible == 4 ? Perception::kFull : visible > 0 ? Perception::kPartial : Perception::kNone;
}

// V of a face given its perception, from world viewpoint o (s.5).
// V of face f of v from o (world), 0 where the face centre fails one of the scanner's limits
// (`limits`: those of s for o).
inline double FaceValue(Perception p, const WorldPoint& o, const VoxelIndex& v, Face f, double r, const ScannerModel& s,
                        const ScannerLimits& limits) {
  if (p == Perception::kNone) return 0.0;
  if (!limits.Passes(FaceCenterIS(v, f), FaceAxis(f), FaceSign(f))) return 0.0;
  const WorldPoint center = FaceCenterIS(v, f) * r;
  const Eigen::Vector3d ray = center - o;
  const double d = ray.norm();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal[FaceAxis(f)] = FaceSign(f);
  const double cos_theta = d > 0 ? std::clamp(ray.dot(normal) / d, -1.0, 1.0) : 1.0;
  // The angle only counts for a fully perceived face; the acos is skipped for the others.
  return VisibilityValue(p, d, p == Perception::kFull ? std::acos(cos_theta) : kHalfPi, s);
}

// Rate-limited, thread-safe progress for one stage: a stage done in `total` tasks that stand for `units` of `unit`
// (e.g. tasks of candidates x brick chunks for 858 "candidates"): reported about every 1 % of the tasks, with the
// fraction of tasks done and the count of units done (units x tasks done / tasks, rounded down).
class StageProgress {
 public:
  StageProgress(const JobContext& ctx, Stage stage, uint64_t total, uint64_t units, std::string unit)
      : ctx_(ctx), stage_(stage), total_(std::max<uint64_t>(total, 1)), units_(units), unit_(std::move(unit)) {}
  void Add(uint64_t n) {
    const uint64_t before = done_.fetch_add(n);
    const uint64_t step = std::max<uint64_t>(total_ / 100, 1);
    if ((before + n) / step != before / step) {
      std::lock_guard<std::mutex> lock(mu_);
      const uint64_t done = std::min(before + n, total_);
      // done <= total_ and units_ are far below 2^32 in practice; the product is taken in long
      // double so that it cannot overflow anyway.
      const auto units_done = uint64_t((long double)units_ * (long double)done / (long double)total_);
      if (ctx_.progress)
        ctx_.progress(ProgressEvent{stage_, double(done) / double(total_), {}, units_done, units_, unit_});
    }
  }

 private:
  const JobContext& ctx_;
  Stage stage_;
  uint64_t total_;
  uint64_t units_;
  std::string unit_;
  std::atomic<uint64_t> done_{0};
  std::mutex mu_;
};

}  // namespace vc::internal
