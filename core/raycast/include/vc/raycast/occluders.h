// Internal to vc_core: exact shortcuts that prove a segment blocked without walking it.
//
// If a segment passes through the interior of a box of occupied voxels (by a margin far above
// the traversal's rounding), the Amanatides & Woo walk must visit one of the box's voxels, so
// its first occupied voxel is that one or an earlier one. Used by the visibility engine
// (visibility.cc, surface_groups.cc).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "vc/scene/occupancy_grid.h"

namespace vc::internal {

// An axis-aligned box of voxels [lo, hi] (inclusive indices), all occupied.
struct SolidBox {
  VoxelIndex lo, hi;
  bool Contains(const VoxelIndex& v) const {
    return v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y && v.z >= lo.z && v.z <= hi.z;
  }
  // Whether the box shares a voxel with the box [other_lo, other_hi].
  bool Overlaps(const VoxelIndex& other_lo, const VoxelIndex& other_hi) const {
    return lo.x <= other_hi.x && hi.x >= other_lo.x && lo.y <= other_hi.y && hi.y >= other_lo.y && lo.z <= other_hi.z &&
           hi.z >= other_lo.z;
  }
};

// The shortcuts here and the certificates in surface_groups.cc rely on margins of 1e-6 to 1e-4
// voxels against the walk's rounding. Along a segment of L voxels the walk's crossing parameters
// drift by at most about L^2 * 2^-54 voxels (1.5e-8 at L = 16384). Segments longer than this
// are walked without any shortcut (ShortcutsHold).
inline constexpr double kMaxShortcutLength = 16384;

// True if every segment from uo to a point of the grid's box is at most kMaxShortcutLength voxels
// long, so the shortcuts' margins hold for rays from uo.
inline bool ShortcutsHold(const OccupancyGrid& g, const Eigen::Vector3d& uo) {
  if (!uo.allFinite()) return false;
  double d2 = 0;
  for (int i = 0; i < 3; ++i) {
    const double lo = (i == 0 ? g.min_index().x : i == 1 ? g.min_index().y : g.min_index().z);
    const double hi = lo + g.dims()[i];
    const double far = std::max(std::abs(uo[i] - lo), std::abs(uo[i] - hi));
    d2 += far * far;
  }
  return d2 <= kMaxShortcutLength * kMaxShortcutLength;
}

// Margin, in voxels and in the segment parameter: 1e-5 is far above the walk's rounding (see
// kMaxShortcutLength) and far below anything geometric.
inline constexpr double kInteriorMargin = 1e-5;

// A segment a->b with its direction's reciprocals, for repeated box tests.
struct Segment {
  Eigen::Vector3d a, d, inv;
  Segment(const Eigen::Vector3d& from, const Eigen::Vector3d& to) : a(from), d(to - from) {
    for (int i = 0; i < 3; ++i) inv[i] = std::abs(d[i]) < 1e-12 ? 0.0 : 1.0 / d[i];
  }
};

// True if the segment meets the open box (lo + m, hi + 1 - m) over a parameter interval of
// length > m that lies strictly inside (m, 1 - m): it enters the box's interior after it starts
// and leaves it before it ends.
inline bool PassesThroughInterior(const Segment& s, const SolidBox& box) {
  constexpr double m = kInteriorMargin;
  const double lo[3] = {double(box.lo.x), double(box.lo.y), double(box.lo.z)};
  const double hi[3] = {double(box.hi.x) + 1, double(box.hi.y) + 1, double(box.hi.z) + 1};
  double t0 = 0, t1 = 1;
  for (int i = 0; i < 3; ++i) {
    if (s.inv[i] == 0.0) {
      if (s.a[i] <= lo[i] + m || s.a[i] >= hi[i] - m) return false;
      continue;
    }
    double ta = (lo[i] + m - s.a[i]) * s.inv[i], tb = (hi[i] - m - s.a[i]) * s.inv[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t1 - t0 <= m) return false;
  }
  return t0 > m && t1 < 1 - m;
}

// The box of occupied voxels grown greedily from occupied voxel h, at most `limit` voxels from h
// each way. The sides take turns; each moves out by 1, 2, 4, ... (at most 64) layers at a time
// while the whole new slab is occupied, and by half as many after a slab that is not. A side
// whose next single layer is not all occupied is never tried again: that layer only grows as
// the other sides move, so it keeps the free voxel that stopped it. So no side of the result
// can move out by one layer within the limit. (Growing one layer at a time gave the same kind
// of box at 4-6 % more visibility time on the hall, where walls let boxes grow 32 voxels.)
inline SolidBox GrowSolidBox(const OccupancyGrid& g, const VoxelIndex& h, int limit) {
  SolidBox box{h, h};
  int* lo[3] = {&box.lo.x, &box.lo.y, &box.lo.z};
  int* hi[3] = {&box.hi.x, &box.hi.y, &box.hi.z};
  const int h3[3] = {h.x, h.y, h.z};
  int step[6] = {1, 1, 1, 1, 1, 1};
  unsigned open = 0x3f;  // bit 2 * axis + side: that side may still move
  while (open) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int side = 0; side < 2; ++side) {
        const int k = 2 * axis + side;
        const unsigned bit = 1u << k;
        if (!(open & bit)) continue;
        const int room = side == 0 ? *lo[axis] - (h3[axis] - limit) : (h3[axis] + limit) - *hi[axis];
        const int n = std::min(step[k], room);
        if (n <= 0) {
          open &= ~bit;
          continue;
        }
        int l[3] = {box.lo.x, box.lo.y, box.lo.z}, u[3] = {box.hi.x, box.hi.y, box.hi.z};
        if (side == 0) {
          l[axis] = *lo[axis] - n, u[axis] = *lo[axis] - 1;
        } else {
          l[axis] = *hi[axis] + 1, u[axis] = *hi[axis] + n;
        }
        if (g.AllOccupied({l[0], l[1], l[2]}, {u[0], u[1], u[2]})) {
          (side == 0 ? *lo[axis] : *hi[axis]) += side == 0 ? -n : n;
          step[k] = std::min(2 * step[k], 64);
        } else if (n == 1) {
          open &= ~bit;
        } else {
          step[k] = n / 2;
        }
      }
    }
  }
  return box;
}

// A small cache of occluders recently hit by rays from one viewpoint. Targets are processed in
// spatially coherent order, so neighbouring targets usually share their occluder. Kept in
// order of last use: a box that proves something moves to the front, where the next search
// starts, and a new box replaces the least recently used one. The 4 boxes dropped last are kept
// aside for Blocks (unless keep_dropped is false): outdoors the rays come back to an occluder
// after a few others (fr_campus's selection sets 8-13 % faster, the indoor scenes' the same or
// faster; docs/BENCHMARKS.md, "The occluders a cache dropped").
class OccluderCache {
 public:
  // A disabled cache proves nothing and keeps nothing: for viewpoints where !ShortcutsHold.
  // keep_dropped: whether Blocks also tries the boxes dropped last (Victims below).
  explicit OccluderCache(bool enabled = true, bool keep_dropped = true)
      : enabled_(enabled), keep_dropped_(keep_dropped) {}
  bool enabled() const { return enabled_; }

  // True if segment a->b provably passes through a cached occluder that contains no voxel of the
  // box [keep_lo, keep_hi] (the voxels that may be transparent for this segment).
  bool Blocks(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const VoxelIndex& keep_lo,
              const VoxelIndex& keep_hi) {
    if (count_ == 0 || !enabled_) return false;
    const Segment seg(a, b);
    if (FindIf(
            [&](const SolidBox& box) { return !box.Overlaps(keep_lo, keep_hi) && PassesThroughInterior(seg, box); })) {
      return true;
    }
    const int v = victims_.Find(seg, keep_lo, keep_hi);
    if (v < 0) return false;
    Add(victims_.Take(v));  // back to the front; the least recently used box takes its place
    return true;
  }
  bool Blocks(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const VoxelIndex& keep) {
    return Blocks(a, b, keep, keep);
  }
  // A cached box for which pred(box) holds (now the front one), or nullptr.
  template <typename Pred>
  const SolidBox* FindIf(Pred&& pred) {
    for (int i = 0; i < count_; ++i) {
      if (pred(boxes_[i])) {
        std::rotate(boxes_, boxes_ + i, boxes_ + i + 1);
        return &boxes_[0];
      }
    }
    return nullptr;
  }
  // A cached box that contains voxel h (now the front one), or nullptr.
  const SolidBox* Find(const VoxelIndex& h) {
    return FindIf([&](const SolidBox& box) { return box.Contains(h); });
  }
  void Add(const SolidBox& box) {
    if (!enabled_) return;
    if (count_ == kSize && keep_dropped_) victims_.Put(boxes_[kSize - 1]);
    count_ = std::min(count_ + 1, kSize);
    std::copy_backward(boxes_, boxes_ + count_ - 1, boxes_ + count_);
    boxes_[0] = box;
  }
  void Add(const VoxelIndex& h) {
    if (!Find(h)) Add(SolidBox{h, h});
  }

 private:
  // The boxes the cache dropped last, tested by Blocks alone (FindIf's other tests, on groups and
  // bricks of faces, cost several segments a box and pay only on the most recent ones), all at once
  // and without branches: the slab test of PassesThroughInterior with each box's faces kept as
  // doubles (the same arithmetic, so the same answers).
  class Victims {
   public:
    static constexpr int kSize = 4;
    // A slot whose box the segment passes through, outside [keep_lo, keep_hi], or -1.
    int Find(const Segment& seg, const VoxelIndex& keep_lo, const VoxelIndex& keep_hi) const {
      if (count_ == 0) return -1;
      constexpr double m = kInteriorMargin;
      double t0[kSize], t1[kSize];
      bool ok[kSize];
      for (int i = 0; i < kSize; ++i) t0[i] = 0, t1[i] = 1, ok[i] = true;
      for (int axis = 0; axis < 3; ++axis) {
        const double *lo = lo_m_[axis], *hi = hi_m_[axis];
        const double from = seg.a[axis], inv = seg.inv[axis];
        if (inv == 0.0) {
          for (int i = 0; i < kSize; ++i) ok[i] = ok[i] & (from > lo[i]) & (from < hi[i]);
          continue;
        }
        for (int i = 0; i < kSize; ++i) {
          const double ta = (lo[i] - from) * inv, tb = (hi[i] - from) * inv;
          const double near = ta < tb ? ta : tb, far = ta < tb ? tb : ta;
          t0[i] = near > t0[i] ? near : t0[i];
          t1[i] = far < t1[i] ? far : t1[i];
        }
      }
      unsigned hits = 0;
      for (int i = 0; i < kSize; ++i)
        hits |= unsigned(ok[i] & (t1[i] - t0[i] > m) & (t0[i] > m) & (t1[i] < 1 - m)) << i;
      for (hits &= (1u << count_) - 1; hits; hits &= hits - 1) {
        const int i = std::countr_zero(hits);
        if (!boxes_[i].Overlaps(keep_lo, keep_hi)) return i;
      }
      return -1;
    }
    // Into the next slot, round the ring.
    void Put(const SolidBox& box) {
      const int i = next_;
      next_ = (next_ + 1) % kSize;
      count_ = std::min(count_ + 1, kSize);
      boxes_[i] = box;
      const int lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
      for (int axis = 0; axis < 3; ++axis) {
        lo_m_[axis][i] = double(lo[axis]) + kInteriorMargin;
        hi_m_[axis][i] = double(hi[axis]) + 1 - kInteriorMargin;
      }
    }
    // Slot i's box; the slot then holds the next box Put (the caller's Add puts one at once).
    SolidBox Take(int i) {
      next_ = i;
      return boxes_[i];
    }

   private:
    SolidBox boxes_[kSize];
    double lo_m_[3][kSize] = {}, hi_m_[3][kSize] = {};  // slots past count_ are tested, their answers dropped
    int count_ = 0, next_ = 0;
  };

  static constexpr int kSize = 4;
  SolidBox boxes_[kSize];
  Victims victims_;
  bool enabled_ = true;
  bool keep_dropped_ = true;
  int count_ = 0;
};

// Far occluders indexed by their direction from one viewpoint, for rays to many targets spread
// around it: a cube map of 6 x kBins x kBins bins, each holding the kPerBin latest boxes registered
// in it. A box is registered in the bins of the rectangle its 8 corners project to on one face of
// the cube (a box spanning two faces or more than kMaxBinsPerBox bins is not registered). Blocks(b)
// tests the boxes of the bin that b's direction falls in. The index only proposes boxes: each is
// tested as OccluderCache tests its own (PassesThroughInterior, outside the keep box), so an index
// that missed or held any box would still give the walk's answer. It catches what the small LRU
// cache has dropped: the boxes behind which a whole region of targets lies, met again when the
// targets' order comes back to that direction (docs/BENCHMARKS.md, "A directional index of far
// occluders"). The bins are allocated at the first box (192 KiB), so a task that meets no far
// occluder pays nothing.
class DirectionalOccluders {
 public:
  static constexpr int kBins = 64, kPerBin = 2, kMaxBinsPerBox = 64;

  explicit DirectionalOccluders(const Eigen::Vector3d& viewpoint) : viewpoint_(viewpoint) {}

  // True if segment viewpoint->b provably passes through an indexed box that contains no voxel of
  // the box [keep_lo, keep_hi].
  bool Blocks(const Eigen::Vector3d& b, const VoxelIndex& keep_lo, const VoxelIndex& keep_hi) const {
    if (boxes_.empty()) return false;
    int face, iu, iv;
    if (!Bin(b - viewpoint_, face, iu, iv)) return false;
    const int32_t* slot = &slots_[SlotIndex(face, iu, iv)];
    if (slot[0] < 0) return false;
    const Segment seg(viewpoint_, b);
    for (int j = 0; j < kPerBin && slot[j] >= 0; ++j) {
      const SolidBox& box = boxes_[size_t(slot[j])];
      if (!box.Overlaps(keep_lo, keep_hi) && PassesThroughInterior(seg, box)) return true;
    }
    return false;
  }

  void Add(const SolidBox& box) {
    int face0 = -1, u0 = kBins, u1 = -1, v0 = kBins, v1 = -1;
    for (int q = 0; q < 8; ++q) {
      const Eigen::Vector3d p(q & 1 ? box.hi.x + 1 : box.lo.x, q & 2 ? box.hi.y + 1 : box.lo.y,
                              q & 4 ? box.hi.z + 1 : box.lo.z);
      int face, iu, iv;
      if (!Bin(p - viewpoint_, face, iu, iv) || (face0 >= 0 && face != face0)) return;
      face0 = face;
      u0 = std::min(u0, iu), u1 = std::max(u1, iu), v0 = std::min(v0, iv), v1 = std::max(v1, iv);
    }
    if ((u1 - u0 + 1) * (v1 - v0 + 1) > kMaxBinsPerBox || boxes_.size() >= size_t(INT32_MAX)) return;
    if (slots_.empty()) slots_.assign(size_t(6) * kBins * kBins * kPerBin, -1);
    const auto id = int32_t(boxes_.size());
    boxes_.push_back(box);
    for (int iu = u0; iu <= u1; ++iu) {
      for (int iv = v0; iv <= v1; ++iv) {
        int32_t* slot = &slots_[SlotIndex(face0, iu, iv)];
        std::copy_backward(slot, slot + kPerBin - 1, slot + kPerBin);
        slot[0] = id;
      }
    }
  }

 private:
  static size_t SlotIndex(int face, int iu, int iv) { return size_t((face * kBins + iu) * kBins + iv) * kPerBin; }
  // The cube face (2 * axis + positive) that direction d leaves through, and its bin there.
  static bool Bin(const Eigen::Vector3d& d, int& face, int& iu, int& iv) {
    const Eigen::Vector3d a = d.cwiseAbs();
    const int m = a.x() >= a.y() && a.x() >= a.z() ? 0 : a.y() >= a.z() ? 1 : 2;
    if (!(a[m] > 0)) return false;
    face = 2 * m + (d[m] > 0);
    const double u = d[(m + 1) % 3] / a[m], v = d[(m + 2) % 3] / a[m];
    iu = std::clamp(int((u + 1) * 0.5 * kBins), 0, kBins - 1);
    iv = std::clamp(int((v + 1) * 0.5 * kBins), 0, kBins - 1);
    return true;
  }

  Eigen::Vector3d viewpoint_;
  std::vector<int32_t> slots_;  // per bin, kPerBin box ids, the latest first; -1: none
  std::vector<SolidBox> boxes_;
};

}  // namespace vc::internal
