// FirstOccupiedBatch: FirstOccupied on many segments at once, one segment per SIMD lane of floats,
// with the instruction set chosen at run time (Google Highway's dynamic dispatch; never
// -march=native). The answers are FirstOccupied's, segment for segment.
//
// Why float lanes give FirstOccupied's answers (docs/VISIBILITY.md, "Many segments at once"):
// - The set-up is the scalar Walk's (walk.h), operation for operation, in double lanes a chunk of
//   segments ahead (Source::Prepare): the start voxel, the steps and the number of boundary
//   crossings per axis are the same integers, and t_delta and the last crossing parameter are the
//   Walk's doubles rounded to float. Only the order in which the crossings of different axes come
//   is decided in float.
// - A lane never accumulates a parameter. The parameter of crossing j of axis i is computed from
//   the parameter of the axis's last crossing: t = T_last - (crossings left after j) * t_delta,
//   one fused multiply-add (or a multiply and an add where the target has no FMA). Its error is at
//   most 4 * 2^-24 (all crossings lie in [0, 1]), whatever the number of steps, so two parameters
//   in float differ from their exact values by less than 2^-21 together.
// - Every decision the lane takes (which axis crosses next; where a jump across a free box of
//   bricks lands) is taken only if the parameters it compares are more than kMargin = 2^-20 apart.
//   Then the lane's order is the exact order of the crossings, and so is the order in
//   FirstOccupied, whose double parameters are within 10^-9 of exact. A decision closer than the
//   margin (a near-tie, or an exact one: lattice-point rays have many) is not taken: the segment is
//   marked and walked by FirstOccupied afterwards.
// - Near-ties that no lane decision looks at lie strictly inside a free box the lane jumped across
//   (its exit is certified), so the voxel between the two crossings is in that box, whichever
//   crossing comes first. FirstOccupied may walk through such a near-tie, or jump across another
//   box around it (walk.h); either order of the two crossings passes through a free voxel and
//   leaves the walk in the same voxel after both, so its answer is the lane's.
// tests/core/raycast/ray_batch_test.cc compares every answer with FirstOccupied, near-ties included.
//
// The lanes' control flow depends on the gathers' answers as little as possible, so that the
// out-of-order core can issue the next voxel's gathers before the last ones have answered (a
// 16-lane gather takes about 13 ns to answer on the AMD EPYC of docs/BENCHMARKS.md):
// - Every lane steps in every pass, whatever its voxel held. A lane whose segment ends (a hit,
//   leaving the grid's box, reaching the end, a near-tie) is marked ended, and a hit's voxel is
//   stored when it is found; the lane's later steps change nothing it reports. It is refilled with
//   the next segment once kRefillBatch lanes of its group have ended, so lanes do not wait for the
//   slowest of their group.
// - The lanes in empty bricks jump across their free boxes of bricks in one pass of five, all
//   of them, with no branch on the gathered entries; in the other passes they step, each step one
//   more certified decision.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "ray_batch.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
// Included once per target by foreach_target.h:
#include <hwy/highway.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vc/raycast/ray_traversal.h"
#include "vc/raycast/walk.h"

// foreach_target.h includes this file once per target; these constants are defined once.
#ifndef VC_CORE_RAY_BATCH_CONSTANTS_
#define VC_CORE_RAY_BATCH_CONSTANTS_
namespace vc::internal {
// Two float parameters closer than this are a near-tie (see the top of this file).
inline constexpr float kMargin = 0x1p-20f;
// Segments the lanes do not take: longer than this many steps per axis (so that the counts stay
// exact in float and the products in int32), or with coordinates beyond +-2^30.
inline constexpr int kMaxLaneSteps = 1 << 22;
inline constexpr double kMaxLaneCoordinate = 0x1p30;
// Passes in which every lane steps, between two passes in which the lanes in empty bricks jump
// across their free boxes; then a group refills its ended lanes if this many have ended (or the
// segments run out). Measured on the hall and geb079 with the widened free boxes
// (docs/BENCHMARKS.md): a jump pass after 3, 4 or 5 step passes beats 0, 1 and 2 (4 kept); 2 and
// 4 ended lanes are alike.
inline constexpr int kStepPasses = 4;
inline constexpr size_t kRefillBatch = 2;
}  // namespace vc::internal
#endif

HWY_BEFORE_NAMESPACE();
namespace vc {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<D>;
using DU = hn::RebindToUnsigned<D>;
using VF = hn::Vec<D>;
using VI = hn::Vec<DI>;
using MI = hn::Mask<DI>;

using DD = hn::ScalableTag<double>;
using VD = hn::Vec<DD>;

// Segments set up for the lanes, a chunk at a time (structure of arrays): each axis's start voxel,
// step and number of crossings, exactly the scalar Walk's integers (walk.h), and its t_delta and
// last crossing parameter rounded to float from the Walk's double values.
struct Prepared {
  static constexpr size_t kChunk = 128;  // a multiple of any target's double lanes
  alignas(64) int32_t cur[3][kChunk], left[3][kChunk], step[3][kChunk], id[kChunk];
  alignas(64) float delta[3][kChunk], last[3][kChunk];
  size_t size = 0, pos = 0;
};

static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "segment ends are read as packed x, y, z triples");

// The segments still to cast, where the answers go, and the segments left to FirstOccupied.
struct Source {
  const Eigen::Vector3d* a;
  const Eigen::Vector3d* b;
  size_t count;
  size_t next;  // the first segment not yet prepared
  std::optional<VoxelIndex>* out;
  std::vector<size_t>* unsure;
  char* certified;    // may be null: set to 1 for each segment a lane answers
  const int32_t* lo;  // GridView::lo: start voxels are stored relative to the box's corner
  Prepared prep;

  // Whether segments remain, prepared or not.
  bool More() const { return prep.pos < prep.size || next < count; }

  // Whether a prepared segment is ready for a lane (preparing the next chunk if needed).
  bool Ready() {
    if (prep.pos == prep.size && next < count) Prepare();
    return prep.pos < prep.size;
  }

  // Sets up the next chunk of segments in double lanes, with the scalar Walk's operations, and
  // sends the segments the lanes cannot hold straight to FirstOccupied: ends beyond
  // +-kMaxLaneCoordinate (or NaN), more than kMaxLaneSteps crossings on an axis, or a crossing
  // parameter too large for a float.
  void Prepare() {
    const DD dd;
    const hn::Rebind<int32_t, DD> d32;
    const hn::Rebind<float, DD> df;
    constexpr size_t kMaxD = 8;  // double lanes of the widest target
    const size_t N = hn::Lanes(dd);
    HWY_ASSERT(N <= kMaxD);
    const VD zero = hn::Zero(dd), one = hn::Set(dd, 1.0), inf = hn::Set(dd, internal::kInf);
    const VD max_coordinate = hn::Set(dd, internal::kMaxLaneCoordinate),
             max_steps = hn::Set(dd, internal::kMaxLaneSteps);
    const VD max_float = hn::Set(dd, 0x1p126);  // below it, a double rounds to a finite float
    prep.size = prep.pos = 0;
    while (next < count && prep.size + N <= Prepared::kChunk) {
      const size_t n = std::min(N, count - next);
      const double* pa = a[next].data();
      const double* pb = b[next].data();
      alignas(64) double tail_a[3 * kMaxD] = {}, tail_b[3 * kMaxD] = {};
      if (n < N) {
        std::copy(pa, pa + 3 * n, tail_a);
        std::copy(pb, pb + 3 * n, tail_b);
        pa = tail_a, pb = tail_b;
      }
      VD av[3], bv[3];
      hn::LoadInterleaved3(dd, pa, av[0], av[1], av[2]);
      hn::LoadInterleaved3(dd, pb, bv[0], bv[1], bv[2]);
      auto ok = hn::FirstN(dd, n);
      VD cur[3], step[3], left[3], delta[3], last[3];
      for (int i = 0; i < 3; ++i) {
        ok = hn::And(ok, hn::And(hn::Lt(hn::Abs(av[i]), max_coordinate), hn::Lt(hn::Abs(bv[i]), max_coordinate)));
        const VD fa = hn::Floor(av[i]), fb = hn::Floor(bv[i]), d = hn::Sub(bv[i], av[i]);
        const auto pos = hn::Gt(d, zero), neg = hn::Lt(d, zero);
        cur[i] = fa;
        step[i] = hn::IfThenElse(pos, one, hn::IfThenElseZero(neg, hn::Neg(one)));
        // Walk: t_delta = 1/d or -1/d; t_max = (fa + 1 - a)/d or (fa - a)/d; left = fb - fa or fa - fb.
        const VD t_delta = hn::Div(one, hn::Abs(d));
        const VD t_max = hn::Div(hn::Sub(hn::IfThenElse(pos, hn::Add(fa, one), fa), av[i]), d);
        left[i] = hn::IfThenElse(pos, hn::Sub(fb, fa), hn::IfThenElseZero(neg, hn::Sub(fa, fb)));
        const auto moving = hn::Gt(left[i], zero);
        const VD t_last = hn::Add(t_max, hn::Mul(hn::Sub(left[i], one), t_delta));
        ok = hn::And(ok, hn::Le(left[i], max_steps));
        ok = hn::And(ok, hn::Or(hn::Not(moving), hn::And(hn::Lt(t_delta, max_float), hn::Lt(t_last, max_float))));
        left[i] = hn::IfThenElseZero(moving, left[i]);
        delta[i] = hn::IfThenElseZero(moving, t_delta);  // an axis that never crosses: 0 and infinity
        last[i] = hn::IfThenElse(moving, t_last, inf);
      }
      // Rejected lanes may hold NaN or values beyond int32 and float: zeroed, so that every
      // conversion below is in range (their results are not stored).
      for (int i = 0; i < 3; ++i) {
        cur[i] = hn::IfThenElseZero(ok, cur[i]), left[i] = hn::IfThenElseZero(ok, left[i]);
        delta[i] = hn::IfThenElseZero(ok, delta[i]), last[i] = hn::IfThenElseZero(ok, last[i]);
      }
      if (n == N && hn::AllTrue(dd, ok)) {
        // Every lane taken (nearly always): plain stores, where a compressing store to memory costs
        // several times as much (perf: three quarters of Prepare's samples on AVX-512).
        for (int i = 0; i < 3; ++i) {
          hn::StoreU(hn::Sub(hn::DemoteTo(d32, cur[i]), hn::Set(d32, lo[i])), d32, prep.cur[i] + prep.size);
          hn::StoreU(hn::DemoteTo(d32, left[i]), d32, prep.left[i] + prep.size);
          hn::StoreU(hn::DemoteTo(d32, step[i]), d32, prep.step[i] + prep.size);
          hn::StoreU(hn::DemoteTo(df, delta[i]), df, prep.delta[i] + prep.size);
          hn::StoreU(hn::DemoteTo(df, last[i]), df, prep.last[i] + prep.size);
        }
        hn::StoreU(hn::Iota(d32, int32_t(next)), d32, prep.id + prep.size);
        prep.size += N;
        next += N;
        continue;
      }
      const auto ok32 = hn::Ne(hn::DemoteTo(d32, hn::IfThenElseZero(ok, one)), hn::Zero(d32));
      const auto okf = hn::RebindMask(df, ok32);
      for (int i = 0; i < 3; ++i) {
        hn::CompressStore(hn::Sub(hn::DemoteTo(d32, cur[i]), hn::Set(d32, lo[i])), ok32, d32, prep.cur[i] + prep.size);
        hn::CompressStore(hn::DemoteTo(d32, left[i]), ok32, d32, prep.left[i] + prep.size);
        hn::CompressStore(hn::DemoteTo(d32, step[i]), ok32, d32, prep.step[i] + prep.size);
        hn::CompressStore(hn::DemoteTo(df, delta[i]), okf, df, prep.delta[i] + prep.size);
        hn::CompressStore(hn::DemoteTo(df, last[i]), okf, df, prep.last[i] + prep.size);
      }
      const size_t kept = hn::CompressStore(hn::Iota(d32, int32_t(next)), ok32, d32, prep.id + prep.size);
      if (kept < n) {
        alignas(64) int32_t taken[kMaxD];
        hn::Store(hn::VecFromMask(d32, ok32), d32, taken);
        for (size_t j = 0; j < n; ++j) {
          if (!taken[j]) unsure->push_back(next + j);
        }
      }
      prep.size += kept;
      next += n;
    }
  }
};

// The grid as the kernel reads it: the brick entries (slot, or minus the distance and the free
// box's extra layers; OccupancyGrid::ExtraBricks) and the payload as 32-bit words (word 2w + h of
// a brick holds rows y = 4h..4h+3 of its 64-bit word w; x86 is little-endian).
struct GridView {
  explicit GridView(const OccupancyGrid& grid)
      : lo{grid.min_index().x, grid.min_index().y, grid.min_index().z},
        dims{hn::Set(DU(), uint32_t(grid.dims().x())), hn::Set(DU(), uint32_t(grid.dims().y())),
             hn::Set(DU(), uint32_t(grid.dims().z()))},
        bdx(hn::Set(DI(), grid.brick_dims().x())),
        bdy(hn::Set(DI(), grid.brick_dims().y())),
        entries(grid.brick_entries()),
        payload(reinterpret_cast<const int32_t*>(grid.payload())) {}

  // Brick number (bz * bdy + by) * bdx + bx of in-box relative coordinates; below 2^31 (checked
  // by the caller).
  VI BrickNumber(VI rx, VI ry, VI rz) const {
    const VI bx = hn::ShiftRight<3>(rx), by = hn::ShiftRight<3>(ry), bz = hn::ShiftRight<3>(rz);
    return hn::Add(hn::Mul(hn::Add(hn::Mul(bz, bdy), by), bdx), bx);
  }

  int32_t lo[3];  // lanes hold voxel coordinates relative to this corner of the box
  hn::Vec<DU> dims[3];
  VI bdx, bdy;
  const int32_t* entries;
  const int32_t* payload;
};

// One vector of lanes, each walking its own segment. A lane whose segment has ended goes on stepping
// until it is refilled; what it reports was recorded when it ended (a hit's voxel in State::h*).
class LaneGroup {
 public:
  LaneGroup(const GridView& g, Source& src) : g_(g) {
    for (size_t l = 0; l < hn::Lanes(D()); ++l) Take(l, src);
    Load();
  }

  size_t active() const { return active_; }

  // One voxel per lane: the occupancy test (and, if kMayJump, the jump of the lanes in empty bricks
  // across their free boxes), then one step.
  template <bool kMayJump>
  void Advance();

  // Records the answers of the lanes whose segment ended and gives them new segments.
  void RefillIfEnded(Source& src) {
    const DI di;
    if (hn::AllFalse(di, done_)) return;
    if (src.More() && hn::CountTrue(di, done_) < std::min(internal::kRefillBatch, hn::Lanes(D()))) return;
    Store();
    const uint64_t ended = Bits(done_), hits = Bits(hit_), unsure = Bits(unsure_);
    for (uint64_t m = ended; m != 0; m &= m - 1) {
      const size_t l = size_t(std::countr_zero(m));
      const uint64_t lane = uint64_t{1} << l;
      if (unsure & lane) {
        src.unsure->push_back(size_t(s_.id[l]));
      } else {
        if (src.certified) src.certified[s_.id[l]] = 1;
        src.out[s_.id[l]] =
            (hits & lane)
                ? std::optional<VoxelIndex>(VoxelIndex{s_.hx[l] + g_.lo[0], s_.hy[l] + g_.lo[1], s_.hz[l] + g_.lo[2]})
                : std::nullopt;
      }
      --active_;
      Take(l, src);
    }
    Load();
  }

 private:
  // Lane state in memory while lanes are refilled (structure of arrays; 16 >= lanes of any target).
  struct State {
    static constexpr size_t kMax = 16;
    alignas(64) int32_t x[kMax], y[kMax], z[kMax], lx[kMax], ly[kMax], lz[kMax];
    alignas(64) int32_t sx[kMax], sy[kMax], sz[kMax], was[kMax], id[kMax];
    alignas(64) int32_t hx[kMax], hy[kMax], hz[kMax];  // the voxel a lane hit, stored when found
    alignas(64) float dx[kMax], dy[kMax], dz[kMax], ex[kMax], ey[kMax], ez[kMax];
  };

  // Loads the next prepared segment into lane `l`, or parks the lane: at -2^30 on every axis
  // relative to the box, so outside it, stepping by 0 along z forever, so it never ends and its
  // gathers read only entry 0.
  void Take(size_t l, Source& src) {
    if (src.Ready()) {
      Prepared& p = src.prep;
      const size_t k = p.pos++;
      s_.x[l] = p.cur[0][k], s_.y[l] = p.cur[1][k], s_.z[l] = p.cur[2][k];
      s_.lx[l] = p.left[0][k], s_.ly[l] = p.left[1][k], s_.lz[l] = p.left[2][k];
      s_.sx[l] = p.step[0][k], s_.sy[l] = p.step[1][k], s_.sz[l] = p.step[2][k];
      s_.dx[l] = p.delta[0][k], s_.dy[l] = p.delta[1][k], s_.dz[l] = p.delta[2][k];
      s_.ex[l] = p.last[0][k], s_.ey[l] = p.last[1][k], s_.ez[l] = p.last[2][k];
      s_.id[l] = p.id[k];
      ++active_;
    } else {
      constexpr int32_t kFar = int32_t{1} << 30;
      s_.x[l] = s_.y[l] = s_.z[l] = -kFar;
      s_.lx[l] = s_.ly[l] = s_.lz[l] = kFar;
      s_.sx[l] = s_.sy[l] = s_.sz[l] = 0;
      s_.dx[l] = s_.dy[l] = s_.dz[l] = 0;
      s_.ex[l] = s_.ey[l] = internal::kInf;
      s_.ez[l] = 0;
      s_.id[l] = -1;
    }
    s_.was[l] = 0;
  }

  // The lanes of a mask as bits (lane l is bit l).
  static uint64_t Bits(MI m) {
    uint8_t bytes[8] = {};
    hn::StoreMaskBits(DI(), m, bytes);
    uint64_t bits = 0;
    std::memcpy(&bits, bytes, sizeof(bits));
    return bits;
  }

  void Load() {
    const D d;
    const DI di;
    x_ = hn::Load(di, s_.x), y_ = hn::Load(di, s_.y), z_ = hn::Load(di, s_.z);
    lx_ = hn::Load(di, s_.lx), ly_ = hn::Load(di, s_.ly), lz_ = hn::Load(di, s_.lz);
    sx_ = hn::Load(di, s_.sx), sy_ = hn::Load(di, s_.sy), sz_ = hn::Load(di, s_.sz);
    was_ = hn::MaskFromVec(hn::Load(di, s_.was));
    dx_ = hn::Load(d, s_.dx), dy_ = hn::Load(d, s_.dy), dz_ = hn::Load(d, s_.dz);
    ex_ = hn::Load(d, s_.ex), ey_ = hn::Load(d, s_.ey), ez_ = hn::Load(d, s_.ez);
    done_ = hit_ = unsure_ = hn::FirstN(di, 0);  // every ended lane was refilled or parked
  }

  void Store() {
    const DI di;
    hn::Store(x_, di, s_.x), hn::Store(y_, di, s_.y), hn::Store(z_, di, s_.z);
    hn::Store(lx_, di, s_.lx), hn::Store(ly_, di, s_.ly), hn::Store(lz_, di, s_.lz);
    hn::Store(hn::VecFromMask(di, was_), di, s_.was);
  }

  // Parameter of the crossing of an axis after which `after` crossings are left (after >= 0):
  // T_last - after * t_delta.
  static VF Crossing(VI after, VF delta, VF last) { return hn::NegMulAdd(hn::ConvertTo(D(), after), delta, last); }

  MI JumpAcrossFreeBricks(MI jump, VI entry, const VI rel[3]);

  const GridView& g_;
  State s_;
  size_t active_ = 0;
  VI x_, y_, z_, lx_, ly_, lz_, sx_, sy_, sz_;  // x_, y_, z_: the voxel, relative to GridView::lo
  VF dx_, dy_, dz_, ex_, ey_, ez_;
  MI was_, done_, hit_, unsure_;  // was_: the lane has been inside the box
};

// Jumps the lanes in `jump` to the last voxel of their walk inside the free box of bricks around
// their (empty) brick, as JumpAcrossBox (walk.h) does, each decision certified by the margin.
// Lanes whose jump is a near-tie are marked unsure and left as they are. Returns the lanes whose
// segment ends inside their box.
HWY_INLINE MI LaneGroup::JumpAcrossFreeBricks(MI jump, VI entry, const VI rel[3]) {
  const D d;
  const DI di;
  const VI zero = hn::Zero(di), one = hn::Set(di, 1);
  const VF inf = hn::Set(d, internal::kInf), margin = hn::Set(d, internal::kMargin);
  const VI code = hn::Neg(entry);  // distance | extra layers << kExtraShift (occupancy_grid.h)
  const VI k = hn::Sub(hn::And(code, hn::Set(di, 0xff)), one);  // the brick's distance - 1
  VI* cur[3] = {&x_, &y_, &z_};
  VI* left[3] = {&lx_, &ly_, &lz_};
  const VI step[3] = {sx_, sy_, sz_};
  const VF delta[3] = {dx_, dy_, dz_}, last[3] = {ex_, ey_, ez_};
  MI end_inside = hn::Eq(zero, zero);
  VI ste[3];
  VF exit_t[3];  // parameter at which each axis leaves the box (inf if the walk ends first)
  const VI seven = hn::Set(di, OccupancyGrid::kBrick - 1), max_extra = hn::Set(di, OccupancyGrid::kMaxExtra);
  for (int i = 0; i < 3; ++i) {
    // In coordinates relative to the grid: the box spans bricks brick_i - lo .. brick_i + hi, with
    // lo and hi the cube's k plus the extra layers on the side of -axis i and +axis i. So the
    // walk's last voxel is in it iff its brick is, and the steps to the box's face are 8 per brick
    // beyond this one plus those to this brick's face.
    const VI hi = hn::Add(
        k,
        hn::And(hn::ShiftRightSame(code, OccupancyGrid::kExtraShift + OccupancyGrid::kExtraBits * 2 * i), max_extra));
    const VI lo = hn::Add(
        k, hn::And(hn::ShiftRightSame(code, OccupancyGrid::kExtraShift + OccupancyGrid::kExtraBits * (2 * i + 1)),
                   max_extra));
    const VI brick_i = hn::ShiftRight<OccupancyGrid::kBrickShift>(rel[i]);
    const MI pos = hn::Gt(step[i], zero);
    const VI end_rel = hn::Add(rel[i], hn::IfThenElse(pos, *left[i], hn::Neg(*left[i])));      // left = 0 if no step
    const VI end_off = hn::Sub(hn::ShiftRight<OccupancyGrid::kBrickShift>(end_rel), brick_i);  // in bricks
    end_inside =
        hn::And(end_inside, hn::And(hn::Gt(hn::Add(end_off, lo), hn::Set(di, -1)), hn::Gt(hn::Add(hi, one), end_off)));
    const VI in_brick = hn::And(rel[i], seven);
    ste[i] = hn::IfThenElse(pos, hn::Add(hn::ShiftLeft<OccupancyGrid::kBrickShift>(hi), hn::Sub(seven, in_brick)),
                            hn::Add(hn::ShiftLeft<OccupancyGrid::kBrickShift>(lo), in_brick));
    const MI leaves = hn::Gt(*left[i], ste[i]);
    exit_t[i] = hn::IfThenElse(hn::RebindMask(d, leaves),
                               Crossing(hn::Sub(hn::Sub(*left[i], one), ste[i]), delta[i], last[i]), inf);
  }
  const VF t_exit = hn::Min(exit_t[0], hn::Min(exit_t[1], exit_t[2]));
  const VF near = hn::Add(t_exit, margin), below = hn::Sub(t_exit, margin);
  // The axis that leaves the box first must be clear of the others' exits.
  const auto n0 = hn::Le(exit_t[0], near), n1 = hn::Le(exit_t[1], near), n2 = hn::Le(exit_t[2], near);
  auto tie = hn::Or(hn::And(n0, n1), hn::Or(hn::And(n0, n2), hn::And(n1, n2)));
  const MI go = hn::AndNot(end_inside, jump);
  VI n[3];
  for (int i = 0; i < 3; ++i) {
    // Crossings of axis i strictly before t_exit, at most to the box's face or the walk's end: the
    // exit axis goes to its face; another takes ceil((t_exit - t) / t_delta), and both crossings
    // around t_exit must be clear of it.
    const VI limit = hn::Min(ste[i], *left[i]);
    const auto is_exit = hn::Eq(exit_t[i], t_exit);
    const VF t = Crossing(hn::Sub(*left[i], one), delta[i], last[i]);  // the next crossing
    const VF q = hn::Ceil(hn::Div(hn::Sub(t_exit, t), delta[i]));
    const VF nf = hn::IfThenElseZero(hn::Gt(q, hn::Zero(d)), hn::Min(q, hn::ConvertTo(d, limit)));
    n[i] = hn::IfThenElse(hn::RebindMask(di, is_exit), limit, hn::ConvertTo(di, nf));
    const VI after = hn::Sub(*left[i], n[i]);  // crossings left after the jump
    const auto next_late =
        hn::Or(hn::RebindMask(d, hn::Eq(after, zero)), hn::Gt(Crossing(hn::Sub(after, one), delta[i], last[i]), near));
    const auto prev_early =
        hn::Or(hn::RebindMask(d, hn::Eq(n[i], zero)), hn::Lt(Crossing(after, delta[i], last[i]), below));
    const auto moving = hn::RebindMask(d, hn::Ne(*left[i], zero));
    tie = hn::Or(tie, hn::AndNot(is_exit, hn::And(moving, hn::Not(hn::And(next_late, prev_early)))));
  }
  const MI unsure = hn::And(go, hn::RebindMask(di, tie));
  unsure_ = hn::Or(unsure_, unsure);
  const MI move = hn::AndNot(unsure, go);
  for (int i = 0; i < 3; ++i) {
    const MI m = hn::And(move, hn::Ne(n[i], zero));
    const VI signed_n = hn::IfThenElse(hn::Gt(step[i], zero), n[i], hn::Neg(n[i]));
    *cur[i] = hn::IfThenElse(m, hn::Add(*cur[i], signed_n), *cur[i]);
    *left[i] = hn::IfThenElse(m, hn::Sub(*left[i], n[i]), *left[i]);
  }
  return hn::Or(unsure, hn::And(jump, end_inside));
}

template <bool kMayJump>
HWY_INLINE void LaneGroup::Advance() {
  const D d;
  const DI di;
  const DU du;
  const VI zero = hn::Zero(di), one = hn::Set(di, 1), three = hn::Set(di, 3), seven = hn::Set(di, 7);
  // ---- The current voxel: occupied, an empty brick to jump across, or outside the box.
  const VI rel[3] = {x_, y_, z_};
  const MI inside = hn::RebindMask(
      di, hn::And(hn::Lt(hn::BitCast(du, rel[0]), g_.dims[0]),
                  hn::And(hn::Lt(hn::BitCast(du, rel[1]), g_.dims[1]), hn::Lt(hn::BitCast(du, rel[2]), g_.dims[2]))));
  was_ = hn::Or(was_, inside);
  const VI brick = hn::IfThenElseZero(inside, g_.BrickNumber(rel[0], rel[1], rel[2]));
  const VI slot = hn::GatherIndex(di, g_.entries, brick);
  const MI filled = hn::And(inside, hn::Gt(slot, zero));
  const VI word_index = hn::IfThenElseZero(
      filled, hn::Add(hn::ShiftLeft<4>(hn::Sub(slot, one)),
                      hn::Add(hn::ShiftLeft<1>(hn::And(rel[2], seven)), hn::ShiftRight<2>(hn::And(rel[1], seven)))));
  const auto word = hn::BitCast(du, hn::GatherIndex(di, g_.payload, word_index));
  const auto bit = hn::BitCast(du, hn::Or(hn::ShiftLeft<3>(hn::And(rel[1], three)), hn::And(rel[0], seven)));
  // A hit of a lane still walking (an ended lane steps on, but reports what it found then).
  const MI hit = hn::AndNot(
      done_,
      hn::And(filled, hn::RebindMask(di, hn::Ne(hn::And(hn::operator>>(word, bit), hn::Set(du, 1)), hn::Zero(du)))));
  hn::BlendedStore(x_, hit, di, s_.hx);
  hn::BlendedStore(y_, hit, di, s_.hy);
  hn::BlendedStore(z_, hit, di, s_.hz);
  hit_ = hn::Or(hit_, hit);
  MI end = hn::Or(hit, hn::AndNot(inside, was_));
  const MI empty = hn::AndNot(done_, hn::AndNot(filled, inside));
  if constexpr (kMayJump) end = hn::Or(end, JumpAcrossFreeBricks(empty, slot, rel));
  done_ = hn::Or(done_, hn::Or(end, hn::Eq(hn::Or(lx_, hn::Or(ly_, lz_)), zero)));

  // ---- One step for every lane: the axis whose crossing comes first. A lane still walking where
  // another axis comes within the margin is unsure and ends. Ended lanes step too (their steps
  // decide nothing), so the next voxel does not wait for this voxel's gathers.
  // Each axis's next crossing. An axis with no crossing left gives the one after its last, beyond
  // the segment's end (t >= 1, and every crossing left lies in [0, 1]), so it is never taken:
  // either another axis comes first by the margin, or the lane is unsure.
  const VF tx = Crossing(hn::Sub(lx_, one), dx_, ex_), ty = Crossing(hn::Sub(ly_, one), dy_, ey_),
           tz = Crossing(hn::Sub(lz_, one), dz_, ez_);
  const VF first = hn::Min(tx, hn::Min(ty, tz));
  const VF near = hn::Add(first, hn::Set(d, internal::kMargin));
  const auto nx = hn::Le(tx, near), ny = hn::Le(ty, near), nz = hn::Le(tz, near);
  const MI tie =
      hn::AndNot(done_, hn::RebindMask(di, hn::Or(hn::And(nx, ny), hn::Or(hn::And(nx, nz), hn::And(ny, nz)))));
  unsure_ = hn::Or(unsure_, tie);
  done_ = hn::Or(done_, tie);
  const MI mz = hn::RebindMask(di, hn::Eq(tz, first));
  const MI my = hn::RebindMask(di, hn::Eq(ty, first));
  const MI mx = hn::RebindMask(di, hn::Eq(tx, first));
  z_ = hn::IfThenElse(mz, hn::Add(z_, sz_), z_);
  y_ = hn::IfThenElse(my, hn::Add(y_, sy_), y_);
  x_ = hn::IfThenElse(mx, hn::Add(x_, sx_), x_);
  lz_ = hn::IfThenElse(mz, hn::Sub(lz_, one), lz_);
  ly_ = hn::IfThenElse(my, hn::Sub(ly_, one), ly_);
  lx_ = hn::IfThenElse(mx, hn::Sub(lx_, one), lx_);
}

// Whether the lanes beat the scalar walk on this target (measured on the hall, BENCHMARKS.md).
constexpr bool kLanesPay = HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL;

// Returns the target it was compiled for, and in *lanes whether it used the lanes, so callers and
// tests see what the dispatch chose. Segments the lanes leave go to `unsure`; those they answer are
// marked in `certified` (if not null).
int64_t FirstOccupiedBatchImpl(const OccupancyGrid& grid, const Eigen::Vector3d* a, const Eigen::Vector3d* b,
                               size_t count, std::optional<VoxelIndex>* out, bool force_lanes, bool* lanes,
                               std::vector<size_t>* unsure, char* certified) {
  *lanes = kLanesPay || force_lanes;
  if (!*lanes) {
    for (size_t i = 0; i < count; ++i) out[i] = FirstOccupied(grid, a[i], b[i]);
    return HWY_TARGET;
  }
  HWY_ASSERT(hn::Lanes(D()) <= 16);
  const GridView view(grid);
  Source src{a, b, count, 0, out, unsure, certified, view.lo, {}};
  // Two independent groups, so that one group's gathers overlap the other's arithmetic; the lanes
  // in empty bricks jump in one pass of kStepPasses + 1 (see the top of this file).
  LaneGroup g0(view, src), g1(view, src);
  while (g0.active() + g1.active() > 0) {
    for (int pass = 0; pass < internal::kStepPasses; ++pass) {
      g0.Advance<false>();
      g1.Advance<false>();
    }
    g0.Advance<true>();
    g1.Advance<true>();
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

static_assert(std::endian::native == std::endian::little, "the lanes read a brick's 64-bit words as 32-bit halves");

HWY_EXPORT(FirstOccupiedBatchImpl);

std::string FirstOccupiedBatch(const OccupancyGrid& grid, std::span<const Eigen::Vector3d> a,
                               std::span<const Eigen::Vector3d> b, std::span<std::optional<VoxelIndex>> out,
                               BatchKernel kernel, size_t* rechecked, std::span<char> certified) {
  const size_t n = std::min({a.size(), b.size(), out.size()});
  if (rechecked) *rechecked = 0;
  HWY_ASSERT(certified.empty() || certified.size() >= n);
  std::fill_n(certified.data(), certified.empty() ? 0 : n, char{0});
  // The kernel forms brick numbers, payload word numbers, segment numbers and voxel coordinates
  // relative to the box's corner (a voxel within +-2^30, plus at most kMaxLaneSteps, minus the
  // corner) in int32: so the box must lie within +-2^29.
  const VoxelIndex lo = grid.min_index();
  const bool near =
      std::abs(int64_t(lo.x)) < (int64_t{1} << 29) && std::abs(int64_t(lo.y)) < (int64_t{1} << 29) &&
      std::abs(int64_t(lo.z)) < (int64_t{1} << 29) && int64_t(lo.x) + grid.dims().x() < (int64_t{1} << 29) &&
      int64_t(lo.y) + grid.dims().y() < (int64_t{1} << 29) && int64_t(lo.z) + grid.dims().z() < (int64_t{1} << 29);
  const bool fits = grid.brick_count() < (uint64_t{1} << 31) && grid.occupied_bricks() < (uint64_t{1} << 26) && near &&
                    n < (size_t{1} << 31);
  if (!fits || grid.brick_count() == 0) {
    for (size_t i = 0; i < n; ++i) out[i] = FirstOccupied(grid, a[i], b[i]);
    return "per segment (grid too large or too far out for the lanes)";
  }
  bool lanes = false;
  std::vector<size_t> unsure;
  const int64_t target = HWY_DYNAMIC_DISPATCH(FirstOccupiedBatchImpl)(grid, a.data(), b.data(), n, out.data(),
                                                                      kernel == BatchKernel::kLanes, &lanes, &unsure,
                                                                      certified.empty() ? nullptr : certified.data());
  for (size_t i : unsure) out[i] = FirstOccupied(grid, a[i], b[i]);
  if (rechecked) *rechecked = unsure.size();
  return std::string(hwy::TargetName(target)) + (lanes ? " lanes" : " per segment");
}

}  // namespace vc
#endif  // HWY_ONCE
