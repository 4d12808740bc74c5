// The sub-voxel test's per-ray reference (vc/visibility/subvoxel.h): docs/VISIBILITY.md
// "Sub-voxel surfaces" read literally, every occupied voxel of the scene tested against each
// segment, no traversal; it shares only the aim point (SubvoxelAimIS) with the engine. Slow and plain; for tests of the
// engine and of what uses it (evaluate's seen sets).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/subvoxel.h"

namespace vc::testing {

inline constexpr double kNever = std::numeric_limits<double>::infinity();

// The reference over `scene` with one patch per voxel (ComputeSurfacePatches); no scanner limits.
struct SubvoxelReference {
  const VoxelScene& scene;
  const std::vector<SurfacePatch>& patches;

  // A point (m, the scene's local frame) in index space.
  Eigen::Vector3d IS(const Eigen::Vector3f& p_m) const { return p_m.cast<double>() / scene.resolution_m; }

  // Whether the voxel next to c along axis i (side -1 or +1) is occupied.
  bool Occupied(const VoxelIndex& c, int i, int side) const {
    VoxelIndex n = c;
    (i == 0 ? n.x : i == 1 ? n.y : n.z) += side;
    return scene.IdOf(IndexToKey(n)) >= 0;
  }

  // Voxel w's box: its points' box grown by kSubvoxelBoxPad edges, clipped to its cube, and reaching
  // the cube's face on each side whose face-neighbour is occupied.
  void Box(size_t w, Eigen::Vector3d* lo, Eigen::Vector3d* hi) const {
    const VoxelIndex c = KeyToIndex(scene.occupied[w]);
    const Eigen::Vector3d cube(c.x, c.y, c.z);
    for (int i = 0; i < 3; ++i) {
      (*lo)[i] = std::max(cube[i], cube[i] + double(patches[w].box_lo[i]) / kPatchBoxSteps - kSubvoxelBoxPad);
      (*hi)[i] = std::min(cube[i] + 1, cube[i] + double(patches[w].box_hi[i]) / kPatchBoxSteps + kSubvoxelBoxPad);
      if (Occupied(c, i, -1)) (*lo)[i] = cube[i];
      if (Occupied(c, i, +1)) (*hi)[i] = cube[i] + 1;
    }
  }

  // Where the segment a -> b first lies in voxel w's blocker, or kNever.
  double Meets(const Eigen::Vector3d& a, const Eigen::Vector3d& b, size_t w) const {
    Eigen::Vector3d lo, hi;
    Box(w, &lo, &hi);
    const SurfacePatch& p = patches[w];
    if (p.flat) {
      const Eigen::Vector3d n = p.normal.cast<double>();
      const double den = n.dot(b - a);
      if (den == 0) return kNever;
      const double s = n.dot(IS(p.centroid_m) - a) / den;
      if (!(s >= 0 && s <= 1)) return kNever;
      const Eigen::Vector3d x = a + s * (b - a);
      return ((x.array() >= lo.array()) && (x.array() <= hi.array())).all() ? s : kNever;
    }
    double enter = 0, leave = 1;  // the segment clipped to the box, slab by slab
    for (int i = 0; i < 3; ++i) {
      const double d = b[i] - a[i];
      if (d == 0) {
        if (a[i] < lo[i] || a[i] > hi[i]) return kNever;
        continue;
      }
      double t0 = (lo[i] - a[i]) / d, t1 = (hi[i] - a[i]) / d;
      if (t0 > t1) std::swap(t0, t1);
      enter = std::max(enter, t0);
      leave = std::min(leave, t1);
    }
    return enter < leave ? enter : kNever;  // no length inside: no block
  }

  // Whether the segment uo -> aim (aim inside voxel v) sees v: no blocker of another voxel, or the
  // first one (any at a tie) on v's surface.
  bool SegmentSees(const Eigen::Vector3d& uo, const Eigen::Vector3d& aim, size_t v) const {
    const SurfacePatch& t = patches[v];
    double first = kNever;
    bool same = false;
    for (size_t w = 0; w < scene.occupied.size(); ++w) {
      if (w == v) continue;
      const double s = Meets(uo, aim, w);
      if (s == kNever || s > first) continue;
      const Eigen::Vector3d hit = uo + s * (aim - uo);
      const Eigen::Vector3d n = t.normal.cast<double>();
      const bool near_aim = (hit - aim).squaredNorm() <= kSameSurfaceTolerance * kSameSurfaceTolerance;
      const bool on = near_aim || (t.flat && patches[w].flat && std::abs(n.dot(hit - aim)) <= kSameSurfaceTolerance &&
                                   std::abs(n.dot(patches[w].normal.cast<double>())) >=
                                       std::cos(kSameSurfaceMaxAngleDeg * std::numbers::pi / 180));
      same = s < first ? on : same || on;
      first = s;
    }
    return first == kNever || same;
  }

  // Whether voxel v is seen from uo (index space): by the segment to its centroid, or, when its
  // patch is not flat, to the centre of a face of its box that faces uo.
  bool Seen(const Eigen::Vector3d& uo, size_t v) const {
    if (SegmentSees(uo, SubvoxelAimIS(scene, patches, v), v)) return true;
    if (patches[v].flat) return false;
    Eigen::Vector3d lo, hi;
    Box(v, &lo, &hi);
    const VoxelIndex c = KeyToIndex(scene.occupied[v]);
    const Eigen::Vector3d cube(c.x, c.y, c.z);
    for (int i = 0; i < 3; ++i) {
      for (const double side : {lo[i], hi[i]}) {
        if (!(side == lo[i] ? uo[i] < side : uo[i] > side)) continue;
        Eigen::Vector3d face = (lo + hi) / 2;
        face[i] = side;
        face =
            face.cwiseMax(cube + Eigen::Vector3d::Constant(1e-6)).cwiseMin(cube + Eigen::Vector3d::Constant(1 - 1e-6));
        if (SegmentSees(uo, face, v)) return true;
      }
    }
    return false;
  }
};

}  // namespace vc::testing
