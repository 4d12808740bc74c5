// Internal to vc_core: surface visibility (ALGORITHM.md s.3b) of all voxels of a scene from one
// viewpoint, decided for whole groups of faces at once where that can be proven, and ray by ray
// where it cannot. The answers are those of the per-voxel test (IsSurfaceVisible); the argument
// for each shortcut is in docs/VISIBILITY.md ("Work avoidance that keeps every answer") and the
// tests compare
// the two on synthetic and real scenes.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "vc/raycast/occluders.h"
#include "vc/scene/occupancy_grid.h"
#include "vc/visibility/scanner_limits.h"

namespace vc::internal {

// A box of voxels [lo, hi] (inclusive) that holds no occupied voxel; empty when lo.x > hi.x.
struct FreeBox {
  VoxelIndex lo{0, 0, 0}, hi{-1, -1, -1};
  bool empty() const { return lo.x > hi.x; }
};

// A free box around the voxel that holds uo: each side pushed out 1, 2, 4, ... (at most 64)
// layers at a time while the new slab is free, by fewer when it is not, until no side can move
// by one layer or it is one voxel beyond the grid. Empty if uo is not finite or its voxel is
// occupied.
FreeBox GrowFreeBox(const OccupancyGrid& grid, const Eigen::Vector3d& uo);

// What a walk over face groups carries from one group to the next, for one viewpoint: the
// occluders its rays met, and whether the last group decided was seen. After a seen group the
// free cone is tried before the middle ray, since it usually holds and then spares the ray; after
// a hidden one the ray comes first. Either order gives the same answers.
struct GroupWalk {
  OccluderCache cache;
  FreeBox around;  // a free box around the viewpoint (GrowFreeBox), or empty; see FreeCone
  bool expect_seen = false;
};

// Where AppendVisible records the voxels it finds visible: bit `id` of `words`. When other tasks
// may set bits of the same words at the same time (`shared`), bits are set atomically; the join
// of the parallel loop orders them before any read.
struct BitWriter {
  uint64_t* words = nullptr;
  bool shared = false;
  void Set(uint32_t id) const {
    const uint64_t bit = uint64_t{1} << (id & 63);
    if (!shared) {
      words[id >> 6] |= bit;
      return;
    }
    std::atomic_ref<uint64_t> word(words[id >> 6]);
    // A plain load first skips the locked instruction when the bit is set already.
    if (!(word.load(std::memory_order_relaxed) & bit)) word.fetch_or(bit, std::memory_order_relaxed);
  }
};

class SurfaceTargets {
 public:
  // The voxels `ids` (positions in `index`) that have at least one exposed face, brick by brick.
  SurfaceTargets(const OccupancyGrid& grid, const std::vector<VoxelIndex>& index, const std::vector<uint32_t>& ids);

  size_t brick_count() const { return bricks_.size(); }

  // A corner-visibility decision for voxel `id`: either one corner (face == 0xff; corner number
  // k, bit 0: +x, bit 1: +y, bit 2: +z) or all 4 corners of face `face`.
  struct CornerDecision {
    uint32_t id;
    uint8_t corner;
    uint8_t face;
    bool seen;
  };

  // Sets in `visible` the bit of every target in bricks [brick_begin, brick_end) that is
  // surface-visible from uo (index space; uo must not lie in an occupied voxel, and
  // ShortcutsHold(grid, uo) must be true) through a face that passes `limits` (the scanner's,
  // for uo). `walk` carries state between calls for the same viewpoint.
  void AppendVisible(const Eigen::Vector3d& uo, const ScannerLimits& limits, size_t brick_begin, size_t brick_end,
                     GroupWalk& walk, const BitWriter& visible) const;

  // Appends corner-visibility decisions (ALGORITHM.md s.4, the 8-voxel corner rule) that groups
  // of faces facing uo in bricks [brick_begin, brick_end) prove; corners not mentioned are
  // undecided. One corner may be decided more than once, always the same way. Bricks where no
  // face centre of a target passes `limits`' range are skipped (their corners stay undecided).
  void AppendCornerDecisions(const Eigen::Vector3d& uo, const ScannerLimits& limits, size_t brick_begin,
                             size_t brick_end, GroupWalk& walk, std::vector<CornerDecision>& decisions) const;

  // GrowSolidBox(grid_, h, kGrowLimit), remembered across viewpoints and threads: a box depends
  // only on the grid and h, and the same voxels are hit from many viewpoints (on the hall, 2.1 M
  // growths come from 133k distinct voxels). A direct-mapped table of 2^box_bits_ slots (about
  // one per target, at most 2^18: 8 MiB), allocated at the first growth; a slot holds the last
  // box grown for a voxel that maps to it, and is read and written under its shard's lock. Public
  // for the exact evaluation's corner rays (evaluate.cc), which cache far occluders grown.
  SolidBox GrownBox(const VoxelIndex& h) const;

 private:
  struct Target {
    uint32_t id;
    uint8_t local[3];  // position inside the brick, 0..7 per axis
    uint8_t exposed;   // bit f: face f's neighbour is free
  };
  struct Brick {
    VoxelIndex base;  // smallest voxel index of the brick
    uint32_t begin, end;
    uint8_t lo[3] = {7, 7, 7}, hi[3] = {0, 0, 0};  // bounding box of its targets, local coordinates
  };

  struct CentreKind;
  struct CornerKind;
  template <typename Kind>
  void WalkGroups(const Eigen::Vector3d& uo, const Brick& brick, GroupWalk& walk, Kind& kind) const;

  const OccupancyGrid& grid_;
  std::vector<Target> targets_;
  std::vector<Brick> bricks_;
  struct BoxSlot {
    uint64_t key = 0;  // 0: empty; else 1 + the packed relative coordinates of h
    SolidBox box;
  };
  static constexpr int kMaxBoxBits = 18;
  static constexpr size_t kBoxShards = 64;
  int box_bits_ = 6;
  mutable std::once_flag boxes_allocated_;
  mutable std::vector<BoxSlot> boxes_;
  mutable std::array<std::mutex, kBoxShards> box_locks_;
};

// True if no occupied voxel on the viewer's side of the plane u[axis] = plane comes within
// reach of a segment from uo to a point of the rectangle q0..q1 (q0 <= q1 on every axis;
// viewer_above: uo[axis] > plane, else uo[axis] < plane). The rectangle normally lies on the
// plane; the back-corner test passes one a layer beyond it, and still only o's side is tested.
// Conservative: a false answer proves nothing. `around` must hold no occupied voxel (it is
// trusted): the part of the cone inside it is not scanned. The cone is o + s (q - o), s in
// [0, 1], q in the rectangle; its part with s < from is trusted to be free too (a caller passes
// what an earlier call, on a rectangle holding this one, reported). On a false answer,
// *failed_at (if given) receives an s >= from below which the cone holds no occupied voxel
// that counts, nor does the cone of any rectangle inside this one.
bool FreeCone(const OccupancyGrid& grid, const Eigen::Vector3d& uo, int axis, bool viewer_above, int plane,
              const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const FreeBox& around = FreeBox(), double from = 0,
              double* failed_at = nullptr);

}  // namespace vc::internal
