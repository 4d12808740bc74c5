// The sub-voxel selection test (subvoxel.h, docs/VISIBILITY.md "Sub-voxel surfaces").
#include "vc/visibility/subvoxel.h"

#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include "subvoxel_internal.h"
#include "vc/base/popcount.h"
#include "vc/raycast/occluders.h"
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
// clear, first blocker on the target's surface, or blocked. The walk starts at parameter
// `s_start` of the segment (0: at uo); the caller knows the part before it meets no occupied voxel.
SubvoxelRay TraceSegment(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                         const Eigen::Vector3d& aim, size_t id, double s_start = 0,
                         const SubvoxelTables* tables = nullptr) {
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  const SurfacePatch& target = patches[id];
  const OccupancyGrid& g = scene.grid;
  const VoxelIndex& lo = g.min_index();
  const int lo3[3] = {lo.x, lo.y, lo.z};
  const uint32_t dims[3] = {uint32_t(g.dims().x()), uint32_t(g.dims().y()), uint32_t(g.dims().z())};
  Walk walk(s_start > 0 ? Eigen::Vector3d(uo + s_start * (aim - uo)) : uo, aim);
  double t_in = s_start, first = kNoHit;
  bool same_at_first = false;
  int64_t first_blocker = -1;
  while (t_in <= first) {
    const VoxelIndex cur{walk.cur[0], walk.cur[1], walk.cur[2]};
    if (cur == v) break;
    const uint32_t rel[3] = {uint32_t(cur.x - lo3[0]), uint32_t(cur.y - lo3[1]), uint32_t(cur.z - lo3[2])};
    const bool in_grid = rel[0] < dims[0] && rel[1] < dims[1] && rel[2] < dims[2];
    const uint64_t brick = in_grid ? g.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3) : 0;
    const uint32_t slot = in_grid ? g.BrickSlot(brick) : 0;
    if (in_grid && slot == 0) {
      // An empty brick: jump across its free box (walk.h), which holds no blocker; the walk's
      // end, v, is occupied, so it does not end inside the box.
      if (!JumpAcrossFreeBrickBox(g, brick, rel, lo3, walk)) break;
    } else if (in_grid && (g.BrickBits(slot)[rel[2] & 7] >> (((rel[1] & 7) << 3) | (rel[0] & 7))) & 1u) {
      const int64_t w = tables ? tables->Id(slot, rel) : scene.IdOf(IndexToKey(cur));
      const SurfacePatch& patch = patches[size_t(w)];
      const double s = tables ? BlockerHit(uo, aim, tables->Box(size_t(w)), patch, tables->Centroid(size_t(w)))
                              : BlockerHit(uo, aim, SubvoxelBoxIS(scene, patches, size_t(w)), patch,
                                           g.WorldToIndexSpace(patch.centroid_m.cast<double>()));
      if (s <= first) {
        const bool same = SameSurface(uo + s * (aim - uo), aim, target, patch);
        // At a tie, the blocker reported is one on the target's surface when there is one.
        if (s < first || (same && !same_at_first)) first_blocker = w;
        same_at_first = s < first ? same : same_at_first || same;
        first = s;
      }
    }
    if (walk.remaining == 0) break;
    // The walk's parameter is along its own segment, from s_start; the blockers' along uo -> aim.
    const double t_walk = std::min({walk.t_max[0], walk.t_max[1], walk.t_max[2]});
    t_in = s_start > 0 ? s_start + t_walk * (1 - s_start) : t_walk;
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

namespace {

// How far (voxels) the points SubvoxelJudgeAtFirst checks keep from the faces they must not meet.
constexpr double kJudgeMargin = 1e-4;

// Whether the resumed trace's start p0 lies where SubvoxelJudgeAtFirst needs it: in the cube of
// `first` (lower corner `lo`) or in its face-neighbour across the entry face (axis a, entered
// upwards when `up`), away from the other faces.
bool ResumeStartClear(const Eigen::Vector3d& p0, const double lo[3], int a, bool up) {
  for (int i = 0; i < 3; ++i) {
    if (i != a && !(p0[i] >= lo[i] + kJudgeMargin && p0[i] <= lo[i] + 1 - kJudgeMargin)) return false;
  }
  return up ? p0[a] >= lo[a] - 1 + kJudgeMargin : p0[a] <= lo[a] + 2 - kJudgeMargin;
}

// How many cubes past `first` JudgePastMissed follows before it leaves the segment to the trace
// (or to a walk resumed past them).
constexpr int kMaxCubesPastMissed = 4;
// How far past the last cube's exit (voxels, along the longest axis) a resumed walk starts: well
// below kJudgeMargin, so that the point lies in the cube after the exit face.
constexpr double kResumeStep = 1e-5;

// SubvoxelJudgeAtFirst where the segment uo + t d (to `end`, inside voxel id's cube) misses the
// blocker of `first` (entered across axis a; the trace resumes at s0). It follows the segment from
// cube to cube as the trace's walk does, each exit through one face at least kJudgeMargin from the
// others (so that every walk takes the same cubes in the same order), for at most
// kMaxCubesPastMissed cubes: 1 where it reaches id's cube first (clear) or meets the blocker of an
// occupied cube well inside it on id's surface (SameSurface), 0 where that blocker is not on it
// (blocked; `*blocker` is that voxel, -1 when clear); -1 where a margin fails or the cubes run out.
// Where the cubes run out and the segment leaves the last one through one face (with the margin),
// `*resume` is a parameter just past that exit, in the next cube (its floor is that cube's index),
// from which a walk may go on (SubvoxelJudgeAtFirst).
int JudgePastMissed(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                    const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, const VoxelIndex& first, int a,
                    double s0, int64_t* blocker, double* resume) {
  const Eigen::Vector3d d = end - uo;
  const OccupancyGrid& g = scene.grid;
  const VoxelIndex& glo = g.min_index();
  const VoxelIndex v = KeyToIndex(scene.occupied[id]);
  double lo[3] = {double(first.x), double(first.y), double(first.z)};
  if (!ResumeStartClear(uo + s0 * d, lo, a, d[a] > 0)) return -1;
  int cur[3] = {first.x, first.y, first.z};
  for (int k = 0;; ++k) {
    // Leave the cube at `cur` (whose blocker, if any, the segment misses) through face b.
    double leave = std::numeric_limits<double>::infinity();
    int b = -1;
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0) continue;
      const double t = ((d[i] > 0 ? lo[i] + 1 : lo[i]) - uo[i]) / d[i];
      if (t < leave) leave = t, b = i;
    }
    if (b < 0 || !(leave < 1)) return -1;
    const Eigen::Vector3d out = uo + leave * d;
    for (int i = 0; i < 3; ++i) {
      if (i != b && !(out[i] >= lo[i] + kJudgeMargin && out[i] <= lo[i] + 1 - kJudgeMargin)) return -1;
    }
    if (k == kMaxCubesPastMissed) {
      // Just past the exit (at most kResumeStep voxels along any axis, less than the margin): in
      // the next cube, where the rounding leaves the point there.
      const double t = leave + kResumeStep / d.lpNorm<Eigen::Infinity>();
      const Eigen::Vector3d p = uo + t * d;
      cur[b] += d[b] > 0 ? 1 : -1;
      if (t < 1 && std::floor(p[0]) == cur[0] && std::floor(p[1]) == cur[1] && std::floor(p[2]) == cur[2]) {
        *resume = t;
      }
      return -1;
    }
    cur[b] += d[b] > 0 ? 1 : -1;
    lo[b] = cur[b];
    if (cur[0] == v.x && cur[1] == v.y && cur[2] == v.z) {
      *blocker = -1;
      return 1;
    }
    const uint32_t rel[3] = {uint32_t(cur[0] - glo.x), uint32_t(cur[1] - glo.y), uint32_t(cur[2] - glo.z)};
    if (!(rel[0] < uint32_t(g.dims().x()) && rel[1] < uint32_t(g.dims().y()) && rel[2] < uint32_t(g.dims().z()))) {
      continue;
    }
    const uint32_t slot = g.BrickSlot(g.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3));
    if (slot == 0 || !((g.BrickBits(slot)[rel[2] & 7] >> (((rel[1] & 7) << 3) | (rel[0] & 7))) & 1u)) continue;
    const size_t w = size_t(tables.Id(slot, rel));
    const double s = BlockerHit(uo, end, tables.Box(w), patches[w], tables.Centroid(w));
    if (s == kNoHit) continue;
    // The hit well inside this cube (past the entry face b, before the others): the walk stops
    // after it, and no other cube's blocker ties with it.
    const Eigen::Vector3d hit = uo + s * d;
    for (int i = 0; i < 3; ++i) {
      if (!(hit[i] >= lo[i] + kJudgeMargin && hit[i] <= lo[i] + 1 - kJudgeMargin)) return -1;
    }
    *blocker = int64_t(w);
    return SameSurface(hit, end, patches[id], patches[w]) ? 1 : 0;
  }
}

}  // namespace

int SubvoxelJudgeAtFirst(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                         const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, const VoxelIndex& first,
                         int64_t* blocker, double* resume) {
  constexpr double kMargin = kJudgeMargin;
  *resume = -1;
  const Eigen::Vector3d d = end - uo;
  if (!(d.lpNorm<Eigen::Infinity>() <= kMaxShortcutLength)) return -1;
  const double lo[3] = {double(first.x), double(first.y), double(first.z)};
  // The entry face (axis a) and parameter, as JudgeSegments's ResumeBefore computes them.
  int a = -1;
  const double enter = CubeEntry(uo, d, first, &a);
  if (a < 0) return -1;
  const OccupancyGrid& g = scene.grid;
  const VoxelIndex& glo = g.min_index();
  const uint32_t rel[3] = {uint32_t(first.x - glo.x), uint32_t(first.y - glo.y), uint32_t(first.z - glo.z)};
  const uint32_t slot = g.BrickSlot(g.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3));
  const size_t w = size_t(tables.Id(slot, rel));
  const SurfacePatch& patch = patches[w];
  const double s = BlockerHit(uo, end, tables.Box(w), patch, tables.Centroid(w));
  const double s0 = std::max(0.0, enter - kResumeMargin);
  if (s == kNoHit) return JudgePastMissed(scene, patches, tables, uo, id, end, first, a, s0, blocker, resume);
  // The resumed trace starts at s0; from there to the hit the segment must stay inside the cube of
  // `first` and of its face-neighbour across the entry face, away from every other face.
  const Eigen::Vector3d p0 = uo + s0 * d, hit = uo + s * d;
  if (!ResumeStartClear(p0, lo, a, d[a] > 0)) return -1;
  for (int i = 0; i < 3; ++i) {
    if (i != a && !(hit[i] >= lo[i] + kMargin && hit[i] <= lo[i] + 1 - kMargin)) return -1;
  }
  if (d[a] > 0 ? !(hit[a] <= lo[a] + 1 - kMargin) : !(hit[a] >= lo[a] + kMargin)) return -1;
  *blocker = int64_t(w);
  return SameSurface(hit, end, patches[id], patch) ? 1 : 0;
}

namespace {

// The parameter interval [*t0, *t1] of the segment uo + t d in the unit cube at `lo`; false when
// it misses it.
bool CubeChord(const Eigen::Vector3d& uo, const Eigen::Vector3d& d, const VoxelIndex& lo, double* t0, double* t1) {
  const double c[3] = {double(lo.x), double(lo.y), double(lo.z)};
  double enter = -std::numeric_limits<double>::infinity(), leave = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0) {
      if (!(uo[i] >= c[i] && uo[i] <= c[i] + 1)) return false;
      continue;
    }
    const double a = (c[i] - uo[i]) / d[i], b = (c[i] + 1 - uo[i]) / d[i];
    enter = std::max(enter, std::min(a, b));
    leave = std::min(leave, std::max(a, b));
  }
  *t0 = enter;
  *t1 = leave;
  return enter < leave;
}

}  // namespace

bool SubvoxelBlockedBy(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                       const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, int64_t w) {
  constexpr double kMargin = 1e-4;
  if (w < 0 || size_t(w) == id) return false;
  const Eigen::Vector3d d = end - uo;
  if (!(d.lpNorm<Eigen::Infinity>() <= kMaxShortcutLength)) return false;
  const SurfacePatch& blocker = patches[size_t(w)];
  const double s = BlockerHit(uo, end, tables.Box(size_t(w)), blocker, tables.Centroid(size_t(w)));
  if (s == kNoHit) return false;
  // Some point of the segment well inside w's cube, so that a walk visits w (or stops before it).
  const VoxelIndex wv = KeyToIndex(scene.occupied[size_t(w)]);
  double w0 = 0, w1 = 0, v0 = 0, v1 = 0;
  if (!CubeChord(uo, d, wv, &w0, &w1) || !CubeChord(uo, d, KeyToIndex(scene.occupied[id]), &v0, &v1)) return false;
  const double s_mid = 0.5 * (w0 + w1);
  const Eigen::Vector3d mid = uo + s_mid * d;
  const double lo[3] = {double(wv.x), double(wv.y), double(wv.z)};
  for (int i = 0; i < 3; ++i) {
    if (!(mid[i] >= lo[i] + kMargin && mid[i] <= lo[i] + 1 - kMargin)) return false;
  }
  // The target's cube is entered after both, so the walk does not stop at it first.
  const double length = d.norm();
  if (!((v0 - std::max(s, s_mid)) * length > kMargin)) return false;
  // No point of the segment up to the hit is on the target's surface (SameSurface): farther than
  // the tolerance from the end, and for a flat target on one side of its plane, farther than the
  // tolerance from it.
  const double away = kSameSurfaceTolerance + kMargin;
  if (!((1 - s) * length > away)) return false;
  if (patches[id].flat) {
    const Eigen::Vector3d n = patches[id].normal.cast<double>();
    const double h0 = n.dot(uo - end), h1 = n.dot(uo + s * d - end);
    if (!((h0 > away && h1 > away) || (h0 < -away && h1 < -away))) return false;
  }
  return true;
}

bool SubvoxelAimPasses(const SurfacePatch& target, const Eigen::Vector3d& aim, const Eigen::Vector3d& uo,
                       const ScannerLimits& limits) {
  const Eigen::Vector3d to_viewpoint = uo - aim;
  int axis = 0, sign = 1;
  NearestFace(target.flat ? target.normal.cast<double>() : to_viewpoint, to_viewpoint, &axis, &sign);
  return limits.Passes(aim, axis, sign);
}

bool SubvoxelAimPasses(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                       size_t id, const ScannerLimits& limits, Eigen::Vector3d* aim) {
  *aim = SubvoxelAimIS(scene, patches, id);
  return SubvoxelAimPasses(patches[id], *aim, uo, limits);
}

int SubvoxelFaceAims(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                     size_t id, Eigen::Vector3d faces[3], const SubvoxelTables* tables) {
  if (patches[id].flat) return 0;
  const Eigen::AlignedBox3d box = tables ? tables->Box(id) : SubvoxelBoxIS(scene, patches, id);
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    for (const bool high : {false, true}) {
      const double side = high ? box.max()[i] : box.min()[i];
      if (high ? !(uo[i] > side) : !(uo[i] < side)) continue;
      Eigen::Vector3d face = box.center();
      face[i] = side;
      faces[n++] = SubvoxelInside(scene, id, face);
    }
  }
  return n;
}

SubvoxelRay TraceSubvoxelSegment(const VoxelScene& scene, std::span<const SurfacePatch> patches,
                                 const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, double s_start,
                                 const SubvoxelTables* tables) {
  return TraceSegment(scene, patches, uo, end, id, s_start, tables);
}

SubvoxelRay TraceSubvoxel(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                          size_t id, const ScannerLimits& limits) {
  Eigen::Vector3d aim;
  if (!SubvoxelAimPasses(scene, patches, uo, id, limits, &aim)) {
    SubvoxelRay ray;
    ray.outcome = SubvoxelRay::Outcome::kOutsideLimits;
    return ray;
  }
  const SubvoxelRay ray = TraceSegment(scene, patches, uo, aim, id);
  if (ray.seen()) return ray;
  // A voxel that is not flat is also seen where the centre of a face of its box that faces o is.
  Eigen::Vector3d faces[3];
  const int n = SubvoxelFaceAims(scene, patches, uo, id, faces);
  for (int f = 0; f < n; ++f) {
    const SubvoxelRay to_face = TraceSegment(scene, patches, uo, faces[f], id);
    if (to_face.seen()) return to_face;
  }
  return ray;
}

SubvoxelTables::SubvoxelTables(const VoxelScene& scene, std::span<const SurfacePatch> patches) : grid_(&scene.grid) {
  const OccupancyGrid& g = scene.grid;
  const uint64_t slots = g.occupied_bricks();
  start_.assign(slots + 1, 0);
  for (uint64_t k = 0; k < slots; ++k) {
    uint32_t count = 0;
    for (int z = 0; z < OccupancyGrid::kBrick; ++z) count += uint32_t(std::popcount(g.payload()[k * 8 + z]));
    start_[k + 1] = start_[k] + count;
  }
  ids_.assign(start_[slots], 0);
  const VoxelIndex& lo = g.min_index();
  for (size_t id = 0; id < scene.occupied.size(); ++id) {
    const VoxelIndex v = KeyToIndex(scene.occupied[id]);
    const uint32_t rel[3] = {uint32_t(v.x - lo.x), uint32_t(v.y - lo.y), uint32_t(v.z - lo.z)};
    const uint32_t slot = g.BrickSlot(g.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3));
    ids_[start_[slot - 1] + Rank(slot, rel)] = uint32_t(id);
  }
  boxes_.resize(scene.occupied.size());
  centroids_.resize(scene.occupied.size());
  aims_.resize(scene.occupied.size());
  for (size_t id = 0; id < scene.occupied.size(); ++id) {
    boxes_[id] = SubvoxelBoxIS(scene, patches, id);
    centroids_[id] = g.WorldToIndexSpace(patches[id].centroid_m.cast<double>());
    aims_[id] = SubvoxelAimIS(scene, patches, id);
  }
}

VC_POPCOUNT_CLONES uint32_t SubvoxelTables::Rank(uint32_t slot, const uint32_t rel[3]) const {
  const uint64_t* words = grid_->BrickBits(slot);
  const uint32_t z = rel[2] & 7, bit = ((rel[1] & 7) << 3) | (rel[0] & 7);
  uint32_t rank = uint32_t(std::popcount(words[z] & ((uint64_t{1} << bit) - 1)));
  for (uint32_t k = 0; k < z; ++k) rank += uint32_t(std::popcount(words[k]));
  return rank;
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
