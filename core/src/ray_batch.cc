// FirstOccupiedBatch: FirstOccupied on many segments at once, one segment per SIMD lane, with the
// instruction set chosen at run time (Google Highway's dynamic dispatch; never -march=native).
//
// Every lane performs exactly the operations of the scalar FirstOccupied (ray_traversal.cc) in
// the same order: the Walk set-up (walk.h, shared), the occupancy test per voxel, the jump across
// the free box of bricks whenever the walk enters an empty brick (JumpAcrossBox, re-stated here
// lane-wise with the same IEEE double operations), and the step with OctoMap's tie rule. So each
// answer is bit-for-bit the scalar one, on every target including near-ties; the tests compare
// every compiled target, the forced-scalar one included, against FirstOccupied.
//
// A lane whose segment ends (a hit, leaving the grid's box, reaching the end) is refilled with the
// next segment at once, so lanes do not wait for each other.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ray_batch.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
// Included once per target by foreach_target.h:
#include <hwy/highway.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "vc/core/ray_traversal.h"
#include "walk.h"

HWY_BEFORE_NAMESPACE();
namespace vc {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::ScalableTag<double>;
using DI = hn::RebindToSigned<D>;
using DU = hn::RebindToUnsigned<D>;
using VD = hn::Vec<D>;
using VI = hn::Vec<DI>;
using MI = hn::Mask<DI>;

// The segments still to cast, and where the answers go.
struct Source {
  const Eigen::Vector3d* a;
  const Eigen::Vector3d* b;
  size_t count;
  size_t next;
  std::optional<VoxelIndex>* out;
};

// The grid as the kernel reads it.
struct GridView {
  explicit GridView(const OccupancyGrid& grid)
      : lo{hn::Set(DI(), grid.min_index().x), hn::Set(DI(), grid.min_index().y), hn::Set(DI(), grid.min_index().z)},
        dims{hn::Set(DU(), uint64_t(grid.dims().x())), hn::Set(DU(), uint64_t(grid.dims().y())),
             hn::Set(DU(), uint64_t(grid.dims().z()))},
        bdx(uint64_t(grid.brick_dims().x())),
        bdy(uint64_t(grid.brick_dims().y())),
        // The padding after both arrays (occupancy_grid.h) keeps these 8-byte loads in bounds.
        slots(reinterpret_cast<const uint64_t*>(grid.brick_slots())),
        dists(reinterpret_cast<const uint64_t*>(grid.brick_distances())),
        payload(grid.payload()) {}

  // Brick number (bz * bdy + by) * bdx + bx of in-box relative coordinates. The row number fits
  // in 32 bits (checked by the caller), so 32x32 -> 64-bit products suffice.
  VI BrickNumber(VI rx, VI ry, VI rz) const {
    const DI di;
    const DU du;
    const VI bx = hn::ShiftRight<3>(rx), by = hn::ShiftRight<3>(ry), bz = hn::ShiftRight<3>(rz);
#if HWY_TARGET == HWY_SCALAR
    (void)du;
    const uint64_t row = uint64_t(hn::GetLane(bz)) * bdy + uint64_t(hn::GetLane(by));
    return hn::Set(di, int64_t(row * bdx + uint64_t(hn::GetLane(bx))));
#else
    const hn::Repartition<uint32_t, DU> du32;
    const auto row = hn::Add(hn::MulEven(hn::BitCast(du32, bz), hn::Set(du32, uint32_t(bdy))), hn::BitCast(du, by));
    return hn::BitCast(di, hn::Add(hn::MulEven(hn::BitCast(du32, row), hn::Set(du32, uint32_t(bdx))),
                                   hn::BitCast(du, bx)));
#endif
  }

  VI lo[3];
  hn::Vec<DU> dims[3];
  uint64_t bdx, bdy;
  const uint64_t* slots;
  const uint64_t* dists;
  const uint64_t* payload;
};

// One vector of lanes, each walking its own segment. A lane whose segment has ended is frozen (its
// state stays that of its last voxel, so a hit's voxel is still there) until it is refilled.
class LaneGroup {
 public:
  LaneGroup(const GridView& g, Source& src) : g_(g) {
    for (size_t l = 0; l < hn::Lanes(D()); ++l) Take(l, src);
    Load();
  }

  size_t active() const { return active_; }

  // One voxel per lane: the occupancy test (or the jump across an empty brick), then one step.
  void Advance();

  // Records the answers of the lanes whose segment ended and gives them new segments.
  void RefillIfEnded(Source& src) {
    const DI di;
    if (hn::AllFalse(di, done_)) return;
    Store();
    hn::Store(hn::VecFromMask(di, done_), di, s_.done);
    hn::Store(hn::VecFromMask(di, hit_), di, s_.hit);
    for (size_t l = 0; l < hn::Lanes(D()); ++l) {
      if (!s_.done[l]) continue;
      src.out[s_.id[l]] = s_.hit[l] ? std::optional<VoxelIndex>(VoxelIndex{int(s_.x[l]), int(s_.y[l]), int(s_.z[l])})
                                    : std::nullopt;
      --active_;
      Take(l, src);
    }
    Load();
  }

 private:
  // Lane state in memory while lanes are refilled (structure of arrays; 16 >= lanes of any target).
  struct State {
    static constexpr size_t kMax = 16;
    alignas(64) int64_t x[kMax], y[kMax], z[kMax];
    alignas(64) int64_t lx[kMax], ly[kMax], lz[kMax], rem[kMax];
    alignas(64) int64_t sx[kMax], sy[kMax], sz[kMax], was[kMax], id[kMax], hit[kMax], done[kMax];
    alignas(64) double tx[kMax], ty[kMax], tz[kMax], dx[kMax], dy[kMax], dz[kMax];
  };

  // Loads the next segment into lane `l` with the scalar set-up, or parks the lane: far outside
  // the box, never inside, with nothing that reaches zero, so it never ends or touches memory.
  void Take(size_t l, Source& src) {
    if (src.next < src.count) {
      const internal::Walk w(src.a[src.next], src.b[src.next]);
      s_.x[l] = w.cur[0], s_.y[l] = w.cur[1], s_.z[l] = w.cur[2];
      s_.lx[l] = w.left[0], s_.ly[l] = w.left[1], s_.lz[l] = w.left[2], s_.rem[l] = w.remaining;
      s_.sx[l] = w.step[0], s_.sy[l] = w.step[1], s_.sz[l] = w.step[2];
      s_.tx[l] = w.t_max[0], s_.ty[l] = w.t_max[1], s_.tz[l] = w.t_max[2];
      s_.dx[l] = w.t_delta[0], s_.dy[l] = w.t_delta[1], s_.dz[l] = w.t_delta[2];
      s_.id[l] = int64_t(src.next++);
      ++active_;
    } else {
      constexpr int64_t kFar = int64_t{1} << 60;
      s_.x[l] = s_.y[l] = s_.z[l] = -kFar;
      s_.lx[l] = s_.ly[l] = s_.lz[l] = s_.rem[l] = kFar;
      s_.sx[l] = s_.sy[l] = s_.sz[l] = 0;
      s_.tx[l] = s_.ty[l] = s_.tz[l] = internal::kInf;
      s_.dx[l] = s_.dy[l] = s_.dz[l] = 0;
      s_.id[l] = -1;
    }
    s_.was[l] = 0;
    s_.done[l] = 0;
  }

  void Load() {
    const D d;
    const DI di;
    x_ = hn::Load(di, s_.x), y_ = hn::Load(di, s_.y), z_ = hn::Load(di, s_.z);
    lx_ = hn::Load(di, s_.lx), ly_ = hn::Load(di, s_.ly), lz_ = hn::Load(di, s_.lz), rem_ = hn::Load(di, s_.rem);
    sx_ = hn::Load(di, s_.sx), sy_ = hn::Load(di, s_.sy), sz_ = hn::Load(di, s_.sz), was_ = hn::Load(di, s_.was);
    tx_ = hn::Load(d, s_.tx), ty_ = hn::Load(d, s_.ty), tz_ = hn::Load(d, s_.tz);
    dx_ = hn::Load(d, s_.dx), dy_ = hn::Load(d, s_.dy), dz_ = hn::Load(d, s_.dz);
    done_ = hn::MaskFromVec(hn::Load(di, s_.done));
    hit_ = done_;
  }

  void Store() {
    const D d;
    const DI di;
    hn::Store(x_, di, s_.x), hn::Store(y_, di, s_.y), hn::Store(z_, di, s_.z);
    hn::Store(lx_, di, s_.lx), hn::Store(ly_, di, s_.ly), hn::Store(lz_, di, s_.lz), hn::Store(rem_, di, s_.rem);
    hn::Store(was_, di, s_.was);
    hn::Store(tx_, d, s_.tx), hn::Store(ty_, d, s_.ty), hn::Store(tz_, d, s_.tz);
  }

  MI JumpAcrossFreeBricks(MI jump, VI brick, const VI rel[3]);

  const GridView& g_;
  State s_;
  size_t active_ = 0;
  VI x_, y_, z_, lx_, ly_, lz_, rem_, sx_, sy_, sz_, was_;
  VD tx_, ty_, tz_, dx_, dy_, dz_;
  MI done_, hit_;
};

// Lane-wise JumpAcrossBox (walk.h) for the lanes in `jump`, over the free box of bricks around
// each lane's empty brick: the same double operations in the same order. Returns the lanes whose
// segment ends inside their box.
HWY_INLINE MI LaneGroup::JumpAcrossFreeBricks(MI jump, VI brick, const VI rel[3]) {
  const D d;
  const DI di;
  const DU du;
  const VI zero = hn::Zero(di), one = hn::Set(di, 1);
  const VD inf = hn::Set(d, internal::kInf);
  const VI k = hn::Sub(hn::BitCast(di, hn::And(hn::GatherOffset(du, g_.dists, brick), hn::Set(du, 0xFF))), one);
  VD t_exit = inf;
  VI exit_axis = hn::Set(di, -1);
  MI end_inside = hn::Eq(zero, zero);
  VI ste[3];
  VI* cur[3] = {&x_, &y_, &z_};
  VI* left[3] = {&lx_, &ly_, &lz_};
  VD* t_max[3] = {&tx_, &ty_, &tz_};
  const VI step[3] = {sx_, sy_, sz_};
  const VD t_delta[3] = {dx_, dy_, dz_};
  for (int i = 0; i < 3; ++i) {
    const VI brick_i = hn::ShiftRight<OccupancyGrid::kBrickShift>(rel[i]);
    const VI box_lo = hn::Add(g_.lo[i], hn::ShiftLeft<OccupancyGrid::kBrickShift>(hn::Sub(brick_i, k)));
    const VI box_hi =
        hn::Sub(hn::Add(g_.lo[i], hn::ShiftLeft<OccupancyGrid::kBrickShift>(hn::Add(hn::Add(brick_i, k), one))), one);
    const MI pos = hn::Gt(step[i], zero), neg = hn::Lt(step[i], zero);
    const VI end_i = hn::Add(*cur[i], hn::IfThenElse(pos, *left[i], hn::IfThenElseZero(neg, hn::Neg(*left[i]))));
    end_inside = hn::And(end_inside, hn::Not(hn::Or(hn::Lt(end_i, box_lo), hn::Gt(end_i, box_hi))));
    ste[i] = hn::IfThenElse(pos, hn::Sub(box_hi, *cur[i]), hn::IfThenElseZero(neg, hn::Sub(*cur[i], box_lo)));
    const MI moving = hn::And(hn::Or(pos, neg), hn::Gt(*left[i], ste[i]));
    const VD t = hn::Add(*t_max[i], hn::Mul(hn::ConvertTo(d, ste[i]), t_delta[i]));
    const auto earlier = hn::And(hn::RebindMask(d, moving), hn::Lt(t, t_exit));
    t_exit = hn::IfThenElse(earlier, t, t_exit);
    exit_axis = hn::IfThenElse(hn::RebindMask(di, earlier), hn::Set(di, i), exit_axis);
  }
  const MI go = hn::AndNot(end_inside, jump);
  for (int i = 0; i < 3; ++i) {
    const auto crosses = hn::And(hn::RebindMask(d, hn::And(go, hn::Ne(*left[i], zero))), hn::Lt(*t_max[i], t_exit));
    const VI limit = hn::Min(ste[i], *left[i]);
    const VD q = hn::Ceil(hn::Div(hn::Sub(t_exit, *t_max[i]), t_delta[i]));
    const VD nd = hn::IfThenElseZero(hn::Gt(q, hn::Zero(d)), hn::Min(q, hn::ConvertTo(d, limit)));
    const VI n = hn::IfThenElse(hn::Eq(exit_axis, hn::Set(di, i)), limit, hn::ConvertTo(di, nd));
    const MI move = hn::And(hn::RebindMask(di, crosses), hn::Ne(n, zero));
    const VI signed_n = hn::IfThenElse(hn::Gt(step[i], zero), n, hn::Neg(n));
    *cur[i] = hn::IfThenElse(move, hn::Add(*cur[i], signed_n), *cur[i]);
    *left[i] = hn::IfThenElse(move, hn::Sub(*left[i], n), *left[i]);
    rem_ = hn::IfThenElse(move, hn::Sub(rem_, n), rem_);
    const VD moved = hn::IfThenElse(hn::RebindMask(d, hn::Eq(*left[i], zero)), inf,
                                    hn::Add(*t_max[i], hn::Mul(hn::ConvertTo(d, n), t_delta[i])));
    *t_max[i] = hn::IfThenElse(hn::RebindMask(d, move), moved, *t_max[i]);
  }
  return hn::And(jump, end_inside);
}

HWY_INLINE void LaneGroup::Advance() {
  const D d;
  const DI di;
  const DU du;
  const VI zero = hn::Zero(di), one = hn::Set(di, 1), seven = hn::Set(di, 7);
  const VD inf = hn::Set(d, internal::kInf);
  // ---- The current voxel: occupied, an empty brick to jump across, or outside the box.
  const VI rel[3] = {hn::Sub(x_, g_.lo[0]), hn::Sub(y_, g_.lo[1]), hn::Sub(z_, g_.lo[2])};
  const MI inside = hn::RebindMask(di, hn::And(hn::Lt(hn::BitCast(du, rel[0]), g_.dims[0]),
                                               hn::And(hn::Lt(hn::BitCast(du, rel[1]), g_.dims[1]),
                                                       hn::Lt(hn::BitCast(du, rel[2]), g_.dims[2]))));
  was_ = hn::Or(was_, hn::VecFromMask(di, inside));
  const VI brick = hn::IfThenElseZero(inside, g_.BrickNumber(rel[0], rel[1], rel[2]));
  const VI slot =
      hn::BitCast(di, hn::And(hn::GatherOffset(du, g_.slots, hn::ShiftLeft<2>(brick)), hn::Set(du, 0xFFFFFFFFu)));
  const MI filled = hn::And(inside, hn::Ne(slot, zero));
  const VI word_index =
      hn::IfThenElseZero(filled, hn::Add(hn::ShiftLeft<3>(hn::Sub(slot, one)), hn::And(rel[2], seven)));
  const auto word = hn::GatherIndex(du, g_.payload, word_index);
  const auto bit = hn::BitCast(du, hn::Or(hn::ShiftLeft<3>(hn::And(rel[1], seven)), hn::And(rel[0], seven)));
  hit_ = hn::And(filled, hn::RebindMask(di, hn::Ne(hn::And(hn::operator>>(word, bit), hn::Set(du, 1)), hn::Zero(du))));
  MI end = hn::Or(hit_, hn::AndNot(inside, hn::MaskFromVec(was_)));
  const MI empty = hn::AndNot(done_, hn::AndNot(filled, inside));
  if (!hn::AllFalse(di, empty)) end = hn::Or(end, JumpAcrossFreeBricks(empty, brick, rel));
  done_ = hn::Or(done_, hn::Or(end, hn::Eq(rem_, zero)));

  // ---- One step for the lanes still walking (scalar: FirstOccupied's loop, or Walk::Advance
  // after a jump), with OctoMap's tie rule.
  const auto z_first = hn::And(hn::Le(tz_, ty_), hn::Le(tz_, tx_));
  const auto y_first = hn::AndNot(z_first, hn::Le(ty_, tx_));
  const auto x_first = hn::Not(hn::Or(z_first, y_first));
  const MI mz = hn::AndNot(done_, hn::RebindMask(di, z_first));
  const MI my = hn::AndNot(done_, hn::RebindMask(di, y_first));
  const MI mx = hn::AndNot(done_, hn::RebindMask(di, x_first));
  z_ = hn::IfThenElse(mz, hn::Add(z_, sz_), z_);
  y_ = hn::IfThenElse(my, hn::Add(y_, sy_), y_);
  x_ = hn::IfThenElse(mx, hn::Add(x_, sx_), x_);
  lz_ = hn::IfThenElse(mz, hn::Sub(lz_, one), lz_);
  ly_ = hn::IfThenElse(my, hn::Sub(ly_, one), ly_);
  lx_ = hn::IfThenElse(mx, hn::Sub(lx_, one), lx_);
  tz_ = hn::IfThenElse(hn::RebindMask(d, mz), hn::IfThenElse(hn::RebindMask(d, hn::Eq(lz_, zero)), inf, hn::Add(tz_, dz_)), tz_);
  ty_ = hn::IfThenElse(hn::RebindMask(d, my), hn::IfThenElse(hn::RebindMask(d, hn::Eq(ly_, zero)), inf, hn::Add(ty_, dy_)), ty_);
  tx_ = hn::IfThenElse(hn::RebindMask(d, mx), hn::IfThenElse(hn::RebindMask(d, hn::Eq(lx_, zero)), inf, hn::Add(tx_, dx_)), tx_);
  rem_ = hn::IfThenElse(done_, rem_, hn::Sub(rem_, one));
}

// Whether the lanes beat the scalar walk on this target. Measured on the hall (BENCHMARKS.md):
// AVX-512's 8 lanes 1.8x the scalar walk; AVX2's 4 lanes and SSE4's 2 about 0.9x (AVX2 lacks
// 64-bit unsigned compares, min and conversions, which Highway emulates); SSSE3 and the scalar
// target about 0.5x.
constexpr bool kLanesPay = HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL;

// Returns the target it was compiled for, and in *lanes whether it used the lanes, so callers and
// tests see what the dispatch chose.
int64_t FirstOccupiedBatchImpl(const OccupancyGrid& grid, const Eigen::Vector3d* a, const Eigen::Vector3d* b,
                               size_t count, std::optional<VoxelIndex>* out, bool force_lanes, bool* lanes) {
  *lanes = kLanesPay || force_lanes;
  if (!*lanes) {
    for (size_t i = 0; i < count; ++i) out[i] = FirstOccupied(grid, a[i], b[i]);
    return HWY_TARGET;
  }
  HWY_ASSERT(hn::Lanes(D()) <= 16);
  const GridView view(grid);
  Source src{a, b, count, 0, out};
  // Two independent groups, so that one group's gathers overlap the other's arithmetic (1.3x over
  // one group on the hall; three are no faster than two: docs/BENCHMARKS.md).
  LaneGroup g0(view, src), g1(view, src);
  while (g0.active() + g1.active() > 0) {
    g0.Advance();
    g1.Advance();
    g0.RefillIfEnded(src);
    g1.RefillIfEnded(src);
  }
  return HWY_TARGET;
}

}  // namespace HWY_NAMESPACE
}  // namespace vc
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vc {

HWY_EXPORT(FirstOccupiedBatchImpl);

std::string FirstOccupiedBatch(const OccupancyGrid& grid, std::span<const Eigen::Vector3d> a,
                               std::span<const Eigen::Vector3d> b, std::span<std::optional<VoxelIndex>> out,
                               BatchKernel kernel) {
  const size_t n = std::min({a.size(), b.size(), out.size()});
  // The kernel forms brick numbers with 32x32-bit products (row = bz * by_count + by).
  const bool fits = uint64_t(grid.brick_dims().y()) * uint64_t(grid.brick_dims().z()) < (uint64_t{1} << 32);
  if (!fits || grid.brick_count() == 0) {
    for (size_t i = 0; i < n; ++i) out[i] = FirstOccupied(grid, a[i], b[i]);
    return "per segment (grid too large for the lanes)";
  }
  bool lanes = false;
  const int64_t target = HWY_DYNAMIC_DISPATCH(FirstOccupiedBatchImpl)(grid, a.data(), b.data(), n, out.data(),
                                                                      kernel == BatchKernel::kLanes, &lanes);
  return std::string(hwy::TargetName(target)) + (lanes ? " lanes" : " per segment");
}

}  // namespace vc
#endif  // HWY_ONCE
