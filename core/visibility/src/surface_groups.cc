// Grouped surface visibility. Within a brick, the exposed faces that face the viewpoint o are
// grouped by orientation and plane (e.g. the 64 top faces of a floor brick). A group, or a
// quadrant of it, is decided at once by one of two certificates, each exact:
//
// - Free cone. Let the faces lie on the plane u[a] = P, with o strictly on one side. The walk
//   from o to a face centre stays on o's side of the plane until its last voxel (a face's own
//   voxel on the far side, which is transparent, or its free neighbour on o's side): the face
//   centre lies on the plane, so the walk's last step along a is its final step. Every voxel the
//   walk visits meets the segment up to rounding (below 2e-8 voxels while ShortcutsHold, which
//   callers check). So if no occupied voxel on
//   o's side comes within 1e-4 of any segment from o to the group's rectangle, every face of the
//   group is reached: visible. FreeCone checks this over a cover of the cone by boxes.
// - Solid occluder. If the segments from o to the rectangle's 4 corners all pass through the
//   interior of a box of occupied voxels that holds none of the group's voxels, every segment to
//   a point of the rectangle does too (the set of points q for which [o, q] meets a convex body
//   is convex), so every face of the group is blocked.
//
// Each group first casts one exact ray to its middle face; the answer picks which certificate to
// try (after a seen group, the free cone is tried before that ray). Groups that neither
// certificate decides are split in four, down to a few faces; what is left is decided ray by ray
// as IsSurfaceVisible does.
#include "vc/visibility/surface_groups.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <optional>

#include "vc/raycast/ray_traversal.h"
#include "vc/raycast/walk.h"
#include "vc/visibility/spatial_order.h"

namespace vc::internal {
namespace {

using Eigen::Vector3d;

constexpr int kMinSplit = 4;     // groups this small are not split further
constexpr int kGrowLimit = 32;   // how far a solid occluder box grows from the voxel hit (8-64 measured: 32)
constexpr double kConeStep = 8;  // length (voxels) of each box of the cone's cover (8 measured best of 2-32)
constexpr double kConeMargin = 1e-4;

int At(const VoxelIndex& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

// The centre of voxel v's face on the plane u[axis] = plane (At(v, axis) or At(v, axis) + 1): the
// end of the face's ray in surface visibility.
Vector3d FaceCentre(const VoxelIndex& v, int axis, int plane) {
  Vector3d c(v.x + 0.5, v.y + 0.5, v.z + 0.5);
  c[axis] = plane;
  return c;
}

// floor(x) as an int, for |x| well inside the int range (index-space coordinates here): cheaper
// than std::floor without SSE4.1, and exact.
int FloorInt(double x) {
  const int i = int(x);
  return i - (x < double(i));
}

// True if mask has more than k bits set.
bool MoreThan(uint64_t mask, int k) {
  for (int i = 0; i < k && mask; ++i) mask &= mask - 1;
  return mask != 0;
}

// Positions p = u * 8 + w with u in [u0, u1] and w in [w0, w1].
uint64_t RectMask(int u0, int u1, int w0, int w1) {
  const uint64_t row = ((uint64_t{2} << w1) - (uint64_t{1} << w0)) * 0x0101010101010101ull;
  const uint64_t rows =
      (u1 == 7 ? ~uint64_t{0} : (uint64_t{1} << (8 * (u1 + 1))) - 1) & ~((uint64_t{1} << (8 * u0)) - 1);
  return row & rows;
}

// The segments from uo to the 4 corners of the rectangle q0..q1 on plane u[a] = q0[a]. The
// corners share their coordinate along a and, in pairs, each other one, so each distinct
// component of d and its reciprocal is computed once: the values Segment(uo, corner) holds.
std::array<Segment, 4> RectSegments(const Vector3d& uo, int a, const Vector3d& q0, const Vector3d& q1) {
  const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
  const Segment first(uo, q0);
  std::array<Segment, 4> segments{first, first, first, first};
  const Segment far(uo, q1);  // its b1 and b2 components are those of the other corners
  for (int c = 1; c < 4; ++c) {
    if (c & 1) segments[c].d[b1] = far.d[b1], segments[c].inv[b1] = far.inv[b1];
    if (c & 2) segments[c].d[b2] = far.d[b2], segments[c].inv[b2] = far.inv[b2];
  }
  return segments;
}

// The solid-occluder certificate: the box holds none of the voxels [keep_lo, keep_hi] and every
// segment to the rectangle's corners passes through its interior, so every segment to a point of
// the rectangle does (the set of such end points is convex).
bool BlocksRect(const SolidBox& box, const std::array<Segment, 4>& corners, const VoxelIndex& keep_lo,
                const VoxelIndex& keep_hi) {
  if (box.Overlaps(keep_lo, keep_hi)) return false;
  for (const Segment& c : corners)
    if (!PassesThroughInterior(c, box)) return false;
  return true;
}

// True if the box holds none of the voxels [lo, hi] and the segments from uo to the 8 corners of
// their bounding box all pass through its interior. Then every segment from uo to a point of
// that bounding box does, as BlocksRect argues for a rectangle (the end points q for which
// [uo, q] meets a convex body form a convex set). So the walk to a face centre there (a face
// facing uo, whose own voxel the walk visits, if at all, last) meets an occupied voxel of the
// box first: the face is hidden.
bool Shadows(const SolidBox& box, const Vector3d& uo, const VoxelIndex& lo, const VoxelIndex& hi) {
  if (box.Overlaps(lo, hi)) return false;
  for (int c = 0; c < 8; ++c) {
    const Vector3d q(c & 1 ? hi.x + 1 : lo.x, c & 2 ? hi.y + 1 : lo.y, c & 4 ? hi.z + 1 : lo.z);
    if (!PassesThroughInterior(Segment(uo, q), box)) return false;
  }
  return true;
}

// The 4 side planes of the pyramid from uo to the rectangle q0..q1 on plane u[axis] = q0[axis],
// each through uo and one edge of the rectangle. The box cover in FreeCone holds more than the
// pyramid; a voxel of the cover that lies wholly outside one side plane, by more than the cone's
// margin, is not within that margin of any segment to the rectangle and cannot block one.
class ConeSides {
 public:
  ConeSides(const Vector3d& uo, int axis, Vector3d q0, Vector3d q1) {
    const int b1 = (axis + 1) % 3, b2 = (axis + 2) % 3;
    if (!(uo[axis] != q0[axis])) return;  // uo on the rectangle's plane (callers exclude it): no planes
    // A rectangle one row wide is widened by a quarter voxel each way, so that every side plane
    // is well defined. A wider pyramid holds the narrower one: it only rules out fewer voxels.
    for (int b : {b1, b2}) {
      if (q1[b] - q0[b] < 0.5) q0[b] -= 0.25, q1[b] += 0.25;
    }
    // The corners run counter-clockwise about the axis (b1 x b2 = axis). So, for a point m of
    // the rectangle, (c_i - uo) x (c_i+1 - uo) . (m - uo) has the sign of q0[axis] - uo[axis]:
    // the orientation follows from the side uo is on, exactly, with no rounded test.
    Vector3d c[4] = {q0, q0, q1, q0};
    c[1][b1] = q1[b1];
    c[3][b2] = q1[b2];
    const bool inward = q0[axis] > uo[axis];
    // Rounding. The corners and uo are exact, so each computed normal n is within 1.6e-15 *
    // reach^2 of the exact one N, where reach bounds |c - uo| per axis. Every point z of the
    // pyramid has N.(z - uo) <= 0 and lies within sqrt(3) reach of uo, so n.(z - uo) / |n| is
    // at most 2.7e-15 * reach^3 / |n|: a cube beyond the computed plane by margin + slack is
    // more than the margin from the pyramid while that is below kSideSlack. A plane is used
    // only where 1e-14 * reach^2 (reach + 2) < kSideSlack |n|, which keeps it below 0.27 of the
    // slack; evaluating n.v and n.uo in absolute coordinates adds about 1e-10 |n|. A plane
    // through uo and an edge whose line passes near uo is ill defined and is skipped, which
    // only rules out fewer voxels.
    double reach = 0;
    for (const Vector3d& ci : c) reach = std::max(reach, (ci - uo).cwiseAbs().maxCoeff());
    const double rounding = 1e-14 * reach * reach * (reach + 2);
    for (int i = 0; i < 4; ++i) {
      Vector3d n = (c[i] - uo).cross(c[(i + 1) % 4] - uo);
      const double norm = n.norm();
      if (!(rounding < kSideSlack * norm)) continue;
      if (inward) n = -n;
      // Voxel v (the cube [v, v + 1]) is outside by more than the margin if the smallest n.x
      // over the cube, n.v + (sum of n's negative components), exceeds n.uo + margin |n|.
      normal_[count_] = n;
      limit_[count_] = n.dot(uo) + (kConeMargin + kSideSlack) * norm - std::min(n.x(), 0.0) - std::min(n.y(), 0.0) -
                       std::min(n.z(), 0.0);
      ++count_;
    }
  }

  // True if voxel v lies outside the pyramid by more than the margin.
  bool Excludes(const VoxelIndex& v) const {
    const Vector3d p(v.x, v.y, v.z);
    for (int i = 0; i < count_; ++i)
      if (normal_[i].dot(p) > limit_[i]) return true;
    return false;
  }

 private:
  static constexpr double kSideSlack = 1e-5;
  Vector3d normal_[4];
  double limit_[4];
  int count_ = 0;
};

}  // namespace

FreeBox GrowFreeBox(const OccupancyGrid& grid, const Vector3d& uo) {
  FreeBox box;
  if (!uo.allFinite()) return box;
  const VoxelIndex v{FloorInt(uo.x()), FloorInt(uo.y()), FloorInt(uo.z())};
  if (grid.Occupied(v)) return box;
  box.lo = box.hi = v;
  int* lo[3] = {&box.lo.x, &box.lo.y, &box.lo.z};
  int* hi[3] = {&box.hi.x, &box.hi.y, &box.hi.z};
  const VoxelIndex& gmin = grid.min_index();
  // Beyond the grid everything is free; the box need not reach further than one voxel out.
  const int limit_lo[3] = {gmin.x - 1, gmin.y - 1, gmin.z - 1};
  const int limit_hi[3] = {gmin.x + grid.dims()[0], gmin.y + grid.dims()[1], gmin.z + grid.dims()[2]};
  int step[6] = {1, 1, 1, 1, 1, 1};
  for (bool any = true; any;) {
    any = false;
    for (int side = 0; side < 6; ++side) {
      if (step[side] == 0) continue;
      any = true;
      const int a = side >> 1;
      const bool up = side & 1;
      const int room = up ? limit_hi[a] - *hi[a] : *lo[a] - limit_lo[a];
      const int n = std::min(step[side], room);
      if (n <= 0) {
        step[side] = 0;
        continue;
      }
      VoxelIndex slo = box.lo, shi = box.hi;
      int* sl[3] = {&slo.x, &slo.y, &slo.z};
      int* sh[3] = {&shi.x, &shi.y, &shi.z};
      if (up) {
        *sl[a] = *hi[a] + 1, *sh[a] = *hi[a] + n;
      } else {
        *sl[a] = *lo[a] - n, *sh[a] = *lo[a] - 1;
      }
      if (grid.AnyOccupied(slo, shi)) {
        step[side] /= 2;
      } else {
        (up ? *hi[a] : *lo[a]) += up ? n : -n;
        step[side] = std::min(2 * step[side], 64);
      }
    }
  }
  return box;
}

bool FreeCone(const OccupancyGrid& grid, const Vector3d& uo, int axis, bool viewer_above, int plane, const Vector3d& q0,
              const Vector3d& q1, const FreeBox& around, double from, double* failed_at) {
  double len = 0;
  for (int i = 0; i < 3; ++i) len = std::max({len, std::abs(q0[i] - uo[i]), std::abs(q1[i] - uo[i])});
  if (!(len > 0)) return false;
  const VoxelIndex& gmin = grid.min_index();
  const int gmin3[3] = {gmin.x, gmin.y, gmin.z};
  // The part of the cone between parameters s0 and s1 lies in the box spanned by its 8 extreme
  // points (o + s (q - o) is linear in s and in q), widened by the margin, cut to o's side of the
  // plane.
  auto piece = [&](double s0, double s1, int lo[3], int hi[3]) {
    for (int i = 0; i < 3; ++i) {  // q0 <= q1 and s >= 0: the low end comes from q0, the high from q1
      const double l0 = uo[i] + s0 * (q0[i] - uo[i]), l1 = uo[i] + s1 * (q0[i] - uo[i]);
      const double h0 = uo[i] + s0 * (q1[i] - uo[i]), h1 = uo[i] + s1 * (q1[i] - uo[i]);
      lo[i] = FloorInt(std::min(l0, l1) - kConeMargin);
      hi[i] = FloorInt(std::max(h0, h1) + kConeMargin);
    }
    if (viewer_above) {
      lo[axis] = std::max(lo[axis], plane);
    } else {
      hi[axis] = std::min(hi[axis], plane - 1);
    }
  };
  // The largest s >= s0 for which the piece from s0 to s lies inside the free box [flo, fhi]
  // (so needs no test), or s0 if there is none. The box's bound is solved for, on the sides the
  // cone leaves it by, then checked with the pieces' own rounding.
  auto free_until = [&](double s0, const int flo[3], const int fhi[3]) {
    double s = 1 / 0.999;
    for (int i = 0; i < 3; ++i) {
      if (q0[i] < uo[i]) s = std::min(s, (uo[i] - kConeMargin - flo[i]) / (uo[i] - q0[i]));
      if (q1[i] > uo[i]) s = std::min(s, (fhi[i] + 1 - kConeMargin - uo[i]) / (q1[i] - uo[i]));
    }
    s = std::min(1.0, 0.999 * s);
    if (!(s > s0)) return s0;
    int lo[3], hi[3];
    piece(s0, s, lo, hi);
    for (int i = 0; i < 3; ++i)
      if (lo[i] < flo[i] || hi[i] > fhi[i]) return s0;
    return s;
  };
  std::optional<ConeSides> sides;
  double s0 = std::max(0.0, from);
  if (!around.empty()) {
    // The part of the cone near o lies inside the free box around o.
    const int flo[3] = {around.lo.x, around.lo.y, around.lo.z};
    const int fhi[3] = {around.hi.x, around.hi.y, around.hi.z};
    s0 = std::max(s0, free_until(0, flo, fhi));
  }
  while (s0 < 1) {
    int lo[3], hi[3];
    // Empty-space skipping: an empty brick lies in a free box of bricks (the cube within its
    // distance - 1, widened by its extra layers, as the walks jump across); a piece whose box
    // lies inside it needs no test. A jump shorter than a voxel is not taken, which bounds the
    // number of pieces by the cone's length.
    const Vector3d c = uo + s0 * (0.5 * (q0 + q1) - uo);
    uint32_t rel[3];
    bool in_grid = true;
    for (int i = 0; i < 3; ++i) {
      const int r = FloorInt(c[i]) - gmin3[i];
      in_grid = in_grid && r >= 0 && r < grid.dims()[i];
      rel[i] = uint32_t(r);
    }
    if (in_grid) {
      const uint64_t brick = grid.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3);
      if (grid.BrickDistance(brick) > 0) {  // an empty brick
        int flo[3], fhi[3];
        FreeBrickBox(grid, brick, rel, gmin3, flo, fhi);
        const double s1 = free_until(s0, flo, fhi);
        if (s1 - s0 >= 1 / len) {
          s0 = s1;
          continue;
        }
      }
    }
    const double s1 = std::min(1.0, s0 + kConeStep / len);
    piece(s0, s1, lo, hi);
    // A box of the cover holds more than the cone: its occupied voxels are tested against the
    // cone's side planes before they count.
    if (lo[axis] <= hi[axis] &&
        grid.AnyOccupiedWhere({lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}, [&](const VoxelIndex& v) {
          if (!sides) sides.emplace(uo, axis, q0, q1);
          return !sides->Excludes(v);
        })) {
      if (failed_at) *failed_at = s0;
      return false;
    }
    s0 = s1;
  }
  return true;
}

SurfaceTargets::SurfaceTargets(const OccupancyGrid& grid, const std::vector<VoxelIndex>& index,
                               const std::vector<uint32_t>& ids)
    : grid_(grid) {
  const VoxelIndex& m = grid.min_index();
  // Bricks along the 3-D Z-order curve: a task's run of bricks is a compact block of the scene,
  // where its occluder cache serves (docs/BENCHMARKS.md, "Corner rays brick by brick").
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  keyed.reserve(ids.size());
  for (uint32_t id : ids) {
    const VoxelIndex& v = index[id];
    const uint32_t rx = uint32_t(v.x - m.x), ry = uint32_t(v.y - m.y), rz = uint32_t(v.z - m.z);
    keyed.emplace_back(ZOrder3(rx >> 3, ry >> 3, rz >> 3), id);
  }
  std::sort(keyed.begin(), keyed.end());
  targets_.reserve(keyed.size());
  uint64_t brick_key = ~uint64_t{0};
  for (size_t i = 0; i < keyed.size(); ++i) {
    const VoxelIndex& v = index[keyed[i].second];
    uint8_t exposed = 0;
    const int d[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
    for (int f = 0; f < 6; ++f)
      if (!grid.Occupied(v.x + d[f][0], v.y + d[f][1], v.z + d[f][2])) exposed |= uint8_t(1u << f);
    if (exposed == 0) continue;
    const int lx = (v.x - m.x) & 7, ly = (v.y - m.y) & 7, lz = (v.z - m.z) & 7;
    if (keyed[i].first != brick_key) {
      brick_key = keyed[i].first;
      const uint32_t at = uint32_t(targets_.size());
      if (!bricks_.empty()) bricks_.back().end = at;
      bricks_.push_back({{v.x - lx, v.y - ly, v.z - lz}, at, at});
    }
    targets_.push_back({keyed[i].second, {uint8_t(lx), uint8_t(ly), uint8_t(lz)}, exposed});
    Brick& brick = bricks_.back();
    for (int a = 0; a < 3; ++a) {
      brick.lo[a] = std::min(brick.lo[a], targets_.back().local[a]);
      brick.hi[a] = std::max(brick.hi[a], targets_.back().local[a]);
    }
  }
  if (!bricks_.empty()) bricks_.back().end = uint32_t(targets_.size());
  // A hit voxel is a target's neighbour or a target: about one slot per target, at most 2^18.
  while (box_bits_ < kMaxBoxBits && (size_t{1} << box_bits_) < targets_.size()) ++box_bits_;
}

SolidBox SurfaceTargets::GrownBox(const VoxelIndex& h) const {
  const VoxelIndex& m = grid_.min_index();
  const uint64_t rx = uint64_t(int64_t(h.x) - m.x), ry = uint64_t(int64_t(h.y) - m.y),
                 rz = uint64_t(int64_t(h.z) - m.z);
  constexpr uint64_t kField = uint64_t{1} << 21;
  if (rx >= kField || ry >= kField || rz >= kField) return GrowSolidBox(grid_, h, kGrowLimit);  // not packable
  const uint64_t key = 1 + (rx | ry << 21 | rz << 42);
  std::call_once(boxes_allocated_, [&] { boxes_.resize(size_t{1} << box_bits_); });
  const size_t slot = size_t((key * 0x9E3779B97F4A7C15ull) >> (64 - box_bits_));
  std::mutex& lock = box_locks_[slot % kBoxShards];
  {
    const std::lock_guard<std::mutex> guard(lock);
    if (boxes_[slot].key == key) return boxes_[slot].box;
  }
  const SolidBox box = GrowSolidBox(grid_, h, kGrowLimit);
  const std::lock_guard<std::mutex> guard(lock);
  boxes_[slot] = {key, box};
  return box;
}

// The walk over a brick's face groups shared by both uses. A face group is one plane of a
// brick, held as a 64-bit mask over the plane's 8x8 positions p = u * 8 + w (u, w: the local
// coordinates along the plane's axes b1 = (a+1) % 3 and b2 = (a+2) % 3). `Kind` says which
// points of a face the rays go to and records the decisions:
//   Rect(...)        the rectangle of those points for the faces in [umin,umax] x [wmin,wmax],
//                    and the box of voxels that may be transparent for (or near the end of)
//                    its rays; a solid occluder must not overlap it;
//   Mid(...)         one exact ray to a point of face (j, a, sp): seen, or the occluder hit;
//   Skip(j)          the face's voxel needs no decision (surface visibility: seen already);
//   Decided(...)     the group's faces decided seen and blocked.
template <typename Kind>
void SurfaceTargets::WalkGroups(const Vector3d& uo, const Brick& brick, GroupWalk& walk, Kind& kind) const {
  OccluderCache& cache = walk.cache;
  uint64_t members[3][2][8];
  uint16_t slot[3][8][64];  // target at position p of layer `layer` of axis a
  const Target* t = &targets_[brick.begin];
  const int n = int(brick.end - brick.begin);
  const int base[3] = {brick.base.x, brick.base.y, brick.base.z};
  std::fill_n(&members[0][0][0], 3 * 2 * 8, 0);
  for (int j = 0; j < n; ++j) {
    for (int a = 0; a < 3; ++a) {
      const int layer = t[j].local[a];
      const int sp = kind.facing[a][layer];
      if (sp < 0 || !((t[j].exposed >> (2 * a + sp)) & 1) || kind.Excluded(j, 2 * a + sp)) continue;
      const int p = t[j].local[(a + 1) % 3] * 8 + t[j].local[(a + 2) % 3];
      members[a][sp][layer] |= uint64_t{1} << p;
      slot[a][layer][p] = uint16_t(j);
    }
  }

  for (int a = 0; a < 3; ++a) {
    for (int sp = 0; sp < 2; ++sp) {
      for (int layer = 0; layer < 8; ++layer) {
        uint64_t undecided = members[a][sp][layer];
        if (undecided == 0) continue;
        if constexpr (Kind::kMinGroup > 1) {
          if (std::popcount(undecided) < Kind::kMinGroup) continue;  // left to the kind's own rays
        }
        const uint16_t* at = slot[a][layer];
        for (uint64_t m = undecided; m; m &= m - 1) {
          if (kind.Skip(at[std::countr_zero(m)])) undecided &= ~(m & -m);
        }
        uint64_t seen = 0;
        const int voxel_a = base[a] + layer;
        const int plane = sp ? voxel_a + 1 : voxel_a;
        // Decides the undecided faces inside the local rectangle [u0,u1] x [w0,w1].
        // cone_from: the cone parameter up to which an enclosing rectangle's cone test found no
        // occupied voxel that counts; the rectangle's own cone, a part of that one, is free there too.
        auto decide = [&](auto&& self, int u0, int u1, int w0, int w1, double cone_from) -> void {
          const uint64_t sub = undecided & RectMask(u0, u1, w0, w1);
          if (sub == 0) return;
          const int umin = std::countr_zero(sub) >> 3, umax = (63 - std::countl_zero(sub)) >> 3;
          uint64_t cols = sub | (sub >> 32);
          cols |= cols >> 16;
          cols |= cols >> 8;
          cols &= 0xff;
          const int wmin = std::countr_zero(cols), wmax = 31 - std::countl_zero(uint32_t(cols));
          Vector3d q0, q1;
          VoxelIndex klo, khi;
          kind.Rect(a, base, plane, voxel_a, umin, umax, wmin, wmax, q0, q1, klo, khi);
          const std::array<Segment, 4> corners = RectSegments(uo, a, q0, q1);
          auto blocks_all = [&](const SolidBox& box) { return BlocksRect(box, corners, klo, khi); };
          const bool single = (sub & (sub - 1)) == 0;
          if (!single) {
            if (const SolidBox* box = cache.FindIf(blocks_all)) {
              walk.expect_seen = false;
              undecided &= ~sub;  // all blocked
              kind.BlockedGroup(a, sp, plane, umin, umax, wmin, wmax, sub, at, *box);
              return;
            }
          }
          auto seen_group = [&] {
            seen |= sub;
            undecided &= ~sub;
            kind.SeenGroup(a, sp, plane, umin, umax, wmin, wmax, sub, at);
          };
          const bool cone_first = !single && walk.expect_seen;
          if (cone_first && FreeCone(grid_, uo, a, sp == 1, plane, q0, q1, walk.around, cone_from, &cone_from)) {
            return seen_group();
          }
          // A lone face whose ray would decide only itself is left to the batched rays after the
          // walk (AppendVisible's LeftoverRays: the same answer, walked in SIMD lanes where they
          // run; 3-5 % of fr_campus's set time, 1-3 % of geb079's and the hall scan's, the same sets).
          if (kind.kMidDecidesFace && single) return;
          // One exact ray to the face nearest the rectangle's middle.
          const int cu2 = umin + umax, cw2 = wmin + wmax;
          int mid = -1, best = 1 << 30;
          for (uint64_t m = sub; m; m &= m - 1) {
            const int p = std::countr_zero(m);
            const int d = std::abs(2 * (p >> 3) - cu2) + std::abs(2 * (p & 7) - cw2);
            if (d < best) best = d, mid = p;
          }
          std::optional<VoxelIndex> occluder;
          const bool mid_seen = kind.Mid(at[mid], a, sp, plane, cache, occluder);
          walk.expect_seen = mid_seen;
          if (kind.kMidDecidesFace) {
            undecided &= ~(uint64_t{1} << mid);
            if (mid_seen) seen |= uint64_t{1} << mid;
          }
          if (mid_seen) {
            if (!cone_first && FreeCone(grid_, uo, a, sp == 1, plane, q0, q1, walk.around, cone_from, &cone_from)) {
              return seen_group();
            }
          } else if (occluder) {
            const SolidBox* cached = cache.Find(*occluder);
            const SolidBox box = cached ? *cached : GrownBox(*occluder);
            if (!cached) cache.Add(box);
            if (blocks_all(box)) {
              undecided &= ~sub;
              kind.BlockedGroup(a, sp, plane, umin, umax, wmin, wmax, sub, at, box);
              return;
            }
          }
          if (single || !MoreThan(sub, kMinSplit)) return;
          const int um = (u0 + u1) / 2, wm = (w0 + w1) / 2;
          self(self, u0, um, w0, wm, cone_from);
          if (um < u1) self(self, um + 1, u1, w0, wm, cone_from);
          if (wm < w1) self(self, u0, um, wm + 1, w1, cone_from);
          if (um < u1 && wm < w1) self(self, um + 1, u1, wm + 1, w1, cone_from);
        };
        decide(decide, 0, 7, 0, 7, 0.0);
        kind.Decided(a, sp, members[a][sp][layer] & ~undecided, seen, at);
      }
    }
  }
}

namespace {

// Which face of a voxel in layer l of a brick faces o along axis a: 1 (+a), 0 (-a) or -1.
void FacingTable(const Vector3d& uo, const int base[3], int8_t facing[3][8]) {
  for (int a = 0; a < 3; ++a)
    for (int l = 0; l < 8; ++l) {
      const int voxel_a = base[a] + l;
      facing[a][l] = int8_t(uo[a] > voxel_a + 1 ? 1 : uo[a] < voxel_a ? 0 : -1);
    }
}

}  // namespace

// Surface visibility: rays to face centres; a face's own voxel is transparent.
struct SurfaceTargets::CentreKind {
  static constexpr bool kMidDecidesFace = true;
  // A plane of a brick with fewer faces facing o than this goes to the batched lone-face rays
  // (LeftoverRays): the hall scan's sets 13-19 % faster, fr_campus's about 2 %, the others the same
  // (docs/BENCHMARKS.md, "Small face groups left to the rays").
  static constexpr int kMinGroup = 4;
  const OccupancyGrid& grid;
  const Vector3d& uo;
  const Target* t;
  const int* base;
  int8_t facing[3][8];
  std::array<uint64_t, 8> visible;  // bit j: target j is visible
  std::array<uint8_t, 512> tried;   // bit f: face f is decided blocked, or its own ray was cast

  VoxelIndex VoxelOf(int j) const {
    return {base[0] + t[j].local[0], base[1] + t[j].local[1], base[2] + t[j].local[2]};
  }
  bool Skip(int j) const { return (visible[j >> 6] >> (j & 63)) & 1; }
  // Face f of target j fails the scanner's limits (marked in `tried` before the walk).
  bool Excluded(int j, int f) const { return (tried[j] >> f) & 1; }
  void Rect(int a, const int b[3], int plane, int voxel_a, int umin, int umax, int wmin, int wmax, Vector3d& q0,
            Vector3d& q1, VoxelIndex& klo, VoxelIndex& khi) const {
    const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    q0[a] = q1[a] = plane;
    q0[b1] = b[b1] + umin + 0.5, q1[b1] = b[b1] + umax + 0.5;
    q0[b2] = b[b2] + wmin + 0.5, q1[b2] = b[b2] + wmax + 0.5;
    int lo[3], hi[3];
    lo[a] = hi[a] = voxel_a;
    lo[b1] = b[b1] + umin, hi[b1] = b[b1] + umax;
    lo[b2] = b[b2] + wmin, hi[b2] = b[b2] + wmax;
    klo = {lo[0], lo[1], lo[2]}, khi = {hi[0], hi[1], hi[2]};
  }
  bool Mid(int j, int a, int, int plane, OccluderCache& cache, std::optional<VoxelIndex>& occluder) {
    const VoxelIndex v = VoxelOf(j);
    const Vector3d target = FaceCentre(v, a, plane);
    if (cache.Blocks(uo, target, v)) return false;
    occluder = FirstOccupied(grid, uo, target, &v);
    return !occluder;
  }
  void SeenGroup(int, int, int, int, int, int, int, uint64_t, const uint16_t*) {}
  void BlockedGroup(int, int, int, int, int, int, int, uint64_t, const uint16_t*, const SolidBox&) {}
  void Decided(int a, int sp, uint64_t decided, uint64_t seen, const uint16_t* at) {
    const uint8_t face_bit = uint8_t(1u << (2 * a + sp));
    for (uint64_t m = decided; m; m &= m - 1) {
      const int p = std::countr_zero(m);
      if ((seen >> p) & 1) {
        visible[at[p] >> 6] |= uint64_t{1} << (at[p] & 63);
      } else {
        tried[at[p]] |= face_bit;
      }
    }
  }
};

namespace {

// The faces that no group decided, one ray each as IsSurfaceVisible casts them, walked in batches
// by FirstOccupiedBatch. A voxel's faces that face o are tried in axis order, and the next one
// only when the last was blocked, as there; faces that a cached occluder proves blocked get no
// ray. The order in which rays are cast changes only what the cache holds, never an answer.
//
// The batch walks without the face's own voxel v being transparent. That changes nothing: the
// segment ends at the face's centre on the plane between v and its free neighbour, so a walk
// visits v, if at all, as its last voxel (the last step along the face's axis comes at the
// segment's end and every other axis's last crossing is at least half a voxel before it; see
// docs/VISIBILITY.md). A batch answer of v is therefore "reached": the answer FirstOccupied gives
// with v transparent.
class LeftoverRays {
 public:
  LeftoverRays(const OccupancyGrid& grid, const Vector3d& uo, OccluderCache& cache, const BitWriter& visible)
      : grid_(grid), uo_(uo), cache_(cache), visible_(visible) {}

  // Voxel v (target id) with the faces `faces` (bit f: face f, exposed, facing o, not decided)
  // still to try.
  void Add(uint32_t id, const VoxelIndex& v, uint8_t faces) {
    if (Queue({id, v, faces}, pending_) && pending_.size() >= kBatch) Flush();
  }

  // Casts every queued ray, and the further rays their answers call for.
  void Flush() {
    while (!pending_.empty()) {
      from_.assign(pending_.size(), uo_);
      to_.resize(pending_.size());
      hits_.resize(pending_.size());
      for (size_t i = 0; i < pending_.size(); ++i) to_[i] = Target(pending_[i]);
      FirstOccupiedBatch(grid_, from_, to_, hits_);
      next_.clear();
      for (size_t i = 0; i < pending_.size(); ++i) {
        Entry& e = pending_[i];
        const std::optional<VoxelIndex>& hit = hits_[i];
        if (!hit || *hit == e.v) {
          visible_.Set(e.id);
          continue;
        }
        cache_.Add(*hit);
        e.faces &= uint8_t(e.faces - 1);  // that face is blocked: on to the next
        Queue(e, next_);
      }
      pending_.swap(next_);
    }
  }

 private:
  static constexpr size_t kBatch = 256;
  struct Entry {
    uint32_t id;
    VoxelIndex v;
    uint8_t faces;  // the lowest bit is the face whose ray is queued
  };

  Vector3d Target(const Entry& e) const {
    const int f = std::countr_zero(unsigned(e.faces)), a = f >> 1;
    return FaceCentre(e.v, a, At(e.v, a) + (f & 1));
  }

  // Drops the faces a cached occluder proves blocked, then queues the ray to the first face left.
  // False if none is left: the voxel is not visible.
  bool Queue(Entry e, std::vector<Entry>& into) const {
    for (; e.faces; e.faces &= uint8_t(e.faces - 1)) {
      if (!cache_.Blocks(uo_, Target(e), e.v)) {
        into.push_back(e);
        return true;
      }
    }
    return false;
  }

  const OccupancyGrid& grid_;
  const Vector3d& uo_;
  OccluderCache& cache_;
  const BitWriter& visible_;
  std::vector<Entry> pending_, next_;
  std::vector<Vector3d> from_, to_;
  std::vector<std::optional<VoxelIndex>> hits_;
};

}  // namespace

void SurfaceTargets::AppendVisible(const Vector3d& uo, const ScannerLimits& limits, size_t brick_begin,
                                   size_t brick_end, GroupWalk& walk, const BitWriter& visible) const {
  LeftoverRays rays(grid_, uo, walk.cache, visible);
  for (size_t b = brick_begin; b < brick_end; ++b) {
    const Brick& brick = bricks_[b];
    const int base[3] = {brick.base.x, brick.base.y, brick.base.z};
    const int n = int(brick.end - brick.begin);
    // A brick whose targets all lie in the shadow of a cached solid box has no visible voxel
    // (Shadows): every face centre of a target lies in their bounding box.
    const VoxelIndex lo{base[0] + brick.lo[0], base[1] + brick.lo[1], base[2] + brick.lo[2]};
    const VoxelIndex hi{base[0] + brick.hi[0], base[1] + brick.hi[1], base[2] + brick.hi[2]};
    if (walk.cache.FindIf([&](const SolidBox& box) { return Shadows(box, uo, lo, hi); })) continue;
    // The scanner's limits: a brick wholly out of range has no visible voxel; in a brick that the
    // range does not decide whole, each facing face is judged by itself, and one that fails is
    // marked decided-blocked before the walk, so no group holds it and no ray goes to it.
    const ScannerLimits::Verdict verdict =
        limits.BoxVerdict(Vector3d(lo.x, lo.y, lo.z), Vector3d(hi.x + 1, hi.y + 1, hi.z + 1));
    if (verdict == ScannerLimits::Verdict::kNone) continue;
    CentreKind kind{grid_, uo, &targets_[brick.begin], base, {}, {}, {}};
    FacingTable(uo, base, kind.facing);
    kind.visible.fill(0);
    std::fill_n(kind.tried.begin(), n, 0);
    if (verdict == ScannerLimits::Verdict::kSome) {
      for (int j = 0; j < n; ++j) {
        const VoxelIndex v = kind.VoxelOf(j);
        for (int a = 0; a < 3; ++a) {
          const int sp = kind.facing[a][kind.t[j].local[a]];
          if (sp < 0 || !((kind.t[j].exposed >> (2 * a + sp)) & 1)) continue;
          const int plane = At(v, a) + sp;
          if (!limits.Passes(FaceCentre(v, a, plane), a, sp ? 1 : -1)) kind.tried[j] |= uint8_t(1u << (2 * a + sp));
        }
      }
    }
    WalkGroups(uo, brick, walk, kind);

    // What no group decided: a ray per face, in batches. facing_bits[a][l]: the face of a
    // voxel in layer l along axis a that faces o, as a face bit (0 if neither does).
    uint8_t facing_bits[3][8];
    for (int a = 0; a < 3; ++a)
      for (int l = 0; l < 8; ++l) {
        const int sp = kind.facing[a][l];
        facing_bits[a][l] = sp >= 0 ? uint8_t(1u << (2 * a + sp)) : 0;
      }
    const Target* t = kind.t;
    for (int word = 0; word * 64 < n; ++word) {
      const uint64_t in_brick = n - word * 64 >= 64 ? ~uint64_t{0} : (uint64_t{1} << (n - word * 64)) - 1;
      for (uint64_t m = kind.visible[word]; m; m &= m - 1) visible.Set(t[word * 64 + std::countr_zero(m)].id);
      for (uint64_t m = ~kind.visible[word] & in_brick; m; m &= m - 1) {
        const int j = word * 64 + std::countr_zero(m);
        const uint8_t faces =
            (facing_bits[0][t[j].local[0]] | facing_bits[1][t[j].local[1]] | facing_bits[2][t[j].local[2]]) &
            t[j].exposed & ~kind.tried[j];
        if (faces) rays.Add(t[j].id, kind.VoxelOf(j), faces);
      }
    }
  }
  rays.Flush();
}

// Corner visibility (ALGORITHM.md s.4): rays to lattice corners; a corner counts as seen when the
// first occupied voxel is none or one of the 8 voxels around it. With the faces' plane at
// u[a] = P and o strictly on one side, a walk to a corner on that plane stays on o's side until
// it is within rounding of the corner, where every voxel it visits is one of those 8. So the
// free cone proves every corner of its faces seen, and a solid box outside the 8-voxel blocks of
// all the group's corners proves them all blocked (a walk meets it before it enters the convex
// block around its corner, and never leaves that block again).
struct SurfaceTargets::CornerKind {
  static constexpr bool kMidDecidesFace = false;
  // A plane of a brick with fewer faces facing o than this is left to the corner rays
  // (evaluate.cc), which since they go brick by brick with their cache decide such faces' corners
  // for less than the group tests cost: fr_campus's evaluation 5-9 % faster, the hall scan's
  // 13-17 %, geb079's 3-14 % (docs/BENCHMARKS.md, "Small face groups left to the rays").
  static constexpr int kMinGroup = 8;
  const OccupancyGrid& grid;
  const Vector3d& uo;
  const Target* t;
  const int* base;
  int8_t facing[3][8];
  std::vector<CornerDecision>& out;
  const FreeBox& around;

  bool Skip(int) const { return false; }
  bool Excluded(int, int) const { return false; }
  void Rect(int a, const int b[3], int plane, int, int umin, int umax, int wmin, int wmax, Vector3d& q0, Vector3d& q1,
            VoxelIndex& klo, VoxelIndex& khi) const {
    const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    q0[a] = q1[a] = plane;
    q0[b1] = b[b1] + umin, q1[b1] = b[b1] + umax + 1;
    q0[b2] = b[b2] + wmin, q1[b2] = b[b2] + wmax + 1;
    int lo[3], hi[3];
    lo[a] = plane - 1, hi[a] = plane;
    lo[b1] = b[b1] + umin - 1, hi[b1] = b[b1] + umax + 1;
    lo[b2] = b[b2] + wmin - 1, hi[b2] = b[b2] + wmax + 1;
    klo = {lo[0], lo[1], lo[2]}, khi = {hi[0], hi[1], hi[2]};
  }
  // The ray to the face's corner with the smallest in-plane coordinates.
  bool Mid(int j, int a, int sp, int plane, OccluderCache& cache, std::optional<VoxelIndex>& occluder) {
    VoxelIndex c{base[0] + t[j].local[0], base[1] + t[j].local[1], base[2] + t[j].local[2]};
    (a == 0 ? c.x : a == 1 ? c.y : c.z) = plane;
    const Vector3d end(c.x, c.y, c.z);
    bool seen = false;
    if (!cache.Blocks(uo, end, {c.x - 1, c.y - 1, c.z - 1}, c)) {
      const auto hit = FirstOccupied(grid, uo, end);
      const bool near = hit && (hit->x == c.x || hit->x == c.x - 1) && (hit->y == c.y || hit->y == c.y - 1) &&
                        (hit->z == c.z || hit->z == c.z - 1);
      seen = !hit || near;
      if (hit && !near) occluder = hit;
    }
    // Corner number of c in voxel j: bit a set on the + side, other bits 0.
    out.push_back({t[j].id, uint8_t(sp ? 1u << a : 0u), 0xff, seen});
    return seen;
  }
  void Decided(int a, int sp, uint64_t decided, uint64_t seen, const uint16_t* at) {
    for (uint64_t m = decided; m; m &= m - 1) {
      const int p = std::countr_zero(m);
      out.push_back({t[at[p]].id, 0, uint8_t(2 * a + sp), bool((seen >> p) & 1)});
    }
  }
  // The back corners: the group's voxels' corners on their other plane (back = plane -+ 1),
  // one layer beyond the faces. A walk to a back corner crosses the front plane, then the
  // voxel layer; when every segment of the group moves less than one voxel along the plane per
  // voxel across it (by a margin), the part inside the layer stays among the 8 voxels around
  // its corner. So the front plane's certificates carry over to the back corners' rectangle.
  void BackRect(int a, int sp, int plane, int umin, int umax, int wmin, int wmax, Vector3d& q0, Vector3d& q1,
                VoxelIndex& klo, VoxelIndex& khi) const {
    Rect(a, base, plane, 0, umin, umax, wmin, wmax, q0, q1, klo, khi);
    const int back = sp ? plane - 1 : plane + 1;
    q0[a] = q1[a] = back;
    (a == 0 ? klo.x : a == 1 ? klo.y : klo.z) = back - 1;
    (a == 0 ? khi.x : a == 1 ? khi.y : khi.z) = back;
  }
  bool Steep(int a, const Vector3d& q0, const Vector3d& q1) const {
    constexpr double kSlopeMargin = 1e-6;
    const double across = std::abs(q0[a] - uo[a]) * (1 - kSlopeMargin);
    for (int i = 0; i < 3; ++i) {
      if (i == a) continue;
      if (std::abs(q0[i] - uo[i]) >= across || std::abs(q1[i] - uo[i]) >= across) return false;
    }
    return true;
  }
  void BackDecided(int a, int sp, uint64_t sub, const uint16_t* at, bool seen) {
    for (uint64_t m = sub; m; m &= m - 1)
      out.push_back({t[at[std::countr_zero(m)]].id, 0, uint8_t(2 * a + (1 - sp)), seen});
  }
  void SeenGroup(int a, int sp, int plane, int umin, int umax, int wmin, int wmax, uint64_t sub, const uint16_t* at) {
    Vector3d q0, q1;
    VoxelIndex klo, khi;
    BackRect(a, sp, plane, umin, umax, wmin, wmax, q0, q1, klo, khi);
    if (Steep(a, q0, q1) && FreeCone(grid, uo, a, sp == 1, plane, q0, q1, around)) BackDecided(a, sp, sub, at, true);
  }
  void BlockedGroup(int a, int sp, int plane, int umin, int umax, int wmin, int wmax, uint64_t sub, const uint16_t* at,
                    const SolidBox& box) {
    Vector3d q0, q1;
    VoxelIndex klo, khi;
    BackRect(a, sp, plane, umin, umax, wmin, wmax, q0, q1, klo, khi);
    if (BlocksRect(box, RectSegments(uo, a, q0, q1), klo, khi)) BackDecided(a, sp, sub, at, false);
  }
};

void SurfaceTargets::AppendCornerDecisions(const Vector3d& uo, const ScannerLimits& limits, size_t brick_begin,
                                           size_t brick_end, GroupWalk& walk,
                                           std::vector<CornerDecision>& decisions) const {
  for (size_t b = brick_begin; b < brick_end; ++b) {
    const Brick& brick = bricks_[b];
    const int base[3] = {brick.base.x, brick.base.y, brick.base.z};
    const Vector3d lo(base[0] + brick.lo[0], base[1] + brick.lo[1], base[2] + brick.lo[2]);
    const Vector3d hi(base[0] + brick.hi[0] + 1, base[1] + brick.hi[1] + 1, base[2] + brick.hi[2] + 1);
    if (limits.BoxVerdict(lo, hi) == ScannerLimits::Verdict::kNone) continue;
    CornerKind kind{grid_, uo, &targets_[brick.begin], base, {}, decisions, walk.around};
    FacingTable(uo, base, kind.facing);
    WalkGroups(uo, brick, walk, kind);
  }
}

}  // namespace vc::internal
