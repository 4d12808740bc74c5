// The sub-voxel test (subvoxel.h) for many voxels from one viewpoint, for ComputeVisibilitySets:
// the answers of the per-ray test (TraceSubvoxel) with less walking. docs/VISIBILITY.md
// ("Sub-voxel surfaces", "The engine") has the measurements.
//
// The segments to the voxels' aim points are walked together by FirstOccupiedBatch (SIMD) to their
// first occupied voxel. Where that is the voxel itself, no blocker comes before it (every blocker
// lies in an occupied voxel's cube, and the trace's walk is FirstOccupied's: the same walk and
// jumps, walk.h), so the voxel is seen, as the trace says (kClear). Any other segment is traced
// from just before the cube of that first occupied voxel: the part before holds no occupied voxel,
// so no blocker. The segments of the box fall-back (a voxel that is not flat and not seen by its
// aim point) go the same way, a face a batch, each batch only for the voxels not seen yet.
//
// Less walking that keeps every answer (docs/VISIBILITY.md "The engine"):
// - the walks start where the segment leaves the viewpoint's free box (GrowFreeBox, shrunk by
//   kBoxMargin): the part before lies in free voxels, so holds no blocker;
// - a segment whose first occupied voxel's blocker alone gives the trace's answer, or that misses
//   it and meets the target or a deciding blocker within the next few cubes (margins:
//   SubvoxelJudgeAtFirst) is not traced;
// - a segment that misses that blocker and the few cubes after it is walked on in batches from
//   just past the last cube followed, where FirstOccupiedBatch certifies the walk, and judged again
//   at its next occupied voxel (JudgeWalkingOn), instead of traced;
// - a box fall-back segment that the blocker which last stopped a segment of its voxel proves
//   blocked (SubvoxelBlockedBy) is not walked.
//
// A trace resumed that way walks the segment from a point on it rather than from o, so at an exact
// tie (the segment passing exactly through a lattice edge or corner) it may step into the other
// voxel than the walk from o does. There a blocker that the segment meets only at that edge is met
// by one walk and not the other; the every-voxel reference (tests/testing/subvoxel_reference.h)
// counts it. On the hall scan this is 1 of the 1.33 million (candidate, voxel) pairs seen, where
// the resumed walk agrees with the reference and the walk from o does not.
#include <Eigen/Core>
#include <algorithm>
#include <optional>
#include <utility>
#include <vector>

#include "subvoxel_internal.h"
#include "vc/raycast/occluders.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/visibility/surface_groups.h"

namespace vc::internal {
namespace {

using Eigen::Vector3d;

// How far inside the viewpoint's free box (voxels) the batched walks start: far above the
// rounding of the start point, so that it lies in a voxel of the box.
constexpr double kBoxMargin = 1e-3;

// The parameter of the segment uo -> end at which the trace resumes, kResumeMargin before it enters
// the cube of its first occupied voxel `w` (up to rounding).
double ResumeBefore(const Vector3d& uo, const Vector3d& end, const VoxelIndex& w) {
  int axis = -1;
  return std::max(0.0, CubeEntry(uo, end - uo, w, &axis) - kResumeMargin);
}

// How many times a segment is walked on past the cubes SubvoxelJudgeAtFirst followed before it is
// traced.
constexpr int kMaxWalksOn = 8;

// A segment SubvoxelJudgeAtFirst left undecided past the cubes it followed: which (i), where its
// trace would resume (s_trace) and where the walk goes on (resume).
struct WalkOn {
  size_t i;
  double s_trace, resume;
};

// The segments of `on` walked on in batches from their resume points to their next occupied voxel
// and judged there by SubvoxelJudgeAtFirst, again and again; where a lane did not certify its walk
// (a near-tie: FirstOccupiedBatch's `certified`), or the judgment fails, the segment is traced as
// without the walk. Every cube before a resume point is free or has a blocker the segment misses,
// and a certified walk passes the cubes in the order of every walk along the segment, so the next
// occupied voxel is the one the trace would test next.
void JudgeWalkingOn(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                    const Vector3d& uo, std::span<const uint32_t> owners, std::span<const Vector3d> ends,
                    std::vector<WalkOn> on, std::vector<char>& seen, std::vector<int64_t>& blocker) {
  std::vector<Vector3d> from, to;
  std::vector<std::optional<VoxelIndex>> first;
  std::vector<char> certified;
  std::vector<WalkOn> next;
  const auto trace = [&](const WalkOn& w) {
    const SubvoxelRay ray = TraceSubvoxelSegment(scene, patches, uo, owners[w.i], ends[w.i], w.s_trace, &tables);
    seen[w.i] = ray.seen();
    blocker[w.i] = ray.first_blocker;
  };
  for (int round = 0; round < kMaxWalksOn && !on.empty(); ++round) {
    from.clear();
    to.clear();
    for (const WalkOn& w : on) {
      from.push_back(uo + w.resume * (ends[w.i] - uo));
      to.push_back(ends[w.i]);
    }
    first.assign(on.size(), std::nullopt);
    certified.assign(on.size(), 0);
    FirstOccupiedBatch(scene.grid, from, to, first, BatchKernel::kAuto, nullptr, certified);
    next.clear();
    for (size_t j = 0; j < on.size(); ++j) {
      const WalkOn& w = on[j];
      const uint32_t id = owners[w.i];
      if (!certified[j] || !first[j]) {
        trace(w);
        continue;
      }
      if (*first[j] == KeyToIndex(scene.occupied[id])) {
        seen[w.i] = 1;
        blocker[w.i] = -1;
        continue;
      }
      double resume = -1;
      const int judged =
          SubvoxelJudgeAtFirst(scene, patches, tables, uo, id, ends[w.i], *first[j], &blocker[w.i], &resume);
      if (judged >= 0) {
        seen[w.i] = char(judged);
      } else if (resume >= 0) {
        next.push_back({w.i, w.s_trace, resume});
      } else {
        trace(w);
      }
    }
    on.swap(next);
  }
  for (const WalkOn& w : on) trace(w);
}

// Segments uo -> ends[i] (ends[i] inside voxel owners[i]'s cube), each judged as one segment of the
// test: seen[i] whether it sees its owner, and where not, blocker[i] the first blocker (or -1).
void JudgeSegments(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                   const Vector3d& uo, std::span<const uint32_t> owners, std::span<const Vector3d> ends,
                   std::vector<char>& seen, std::vector<int64_t>& blocker, const FreeBox& around) {
  std::vector<Vector3d> origins(ends.size(), uo);
  if (!around.empty()) {
    // The box shrunk by kBoxMargin on every side (uo is inside it, SubvoxelVisibleAmong checks):
    // each walk starts where its segment leaves that.
    const double lo[3] = {around.lo.x + kBoxMargin, around.lo.y + kBoxMargin, around.lo.z + kBoxMargin};
    const double hi[3] = {around.hi.x + 1 - kBoxMargin, around.hi.y + 1 - kBoxMargin, around.hi.z + 1 - kBoxMargin};
    for (size_t i = 0; i < ends.size(); ++i) {
      const Vector3d d = ends[i] - uo;
      double leave = 1;
      for (int a = 0; a < 3; ++a) {
        if (d[a] > 0) leave = std::min(leave, (hi[a] - uo[a]) / d[a]);
        if (d[a] < 0) leave = std::min(leave, (lo[a] - uo[a]) / d[a]);
      }
      if (leave > 0 && leave < 1) origins[i] = uo + leave * d;
    }
  }
  std::vector<std::optional<VoxelIndex>> first(ends.size());
  // Walking on pays only where the lanes run and so certify walks (elsewhere every walk on would
  // be walked again by the trace).
  const bool lanes = FirstOccupiedBatch(scene.grid, origins, ends, first).ends_with(" lanes");
  seen.assign(ends.size(), 0);
  blocker.assign(ends.size(), -1);
  std::vector<WalkOn> on;
  for (size_t i = 0; i < ends.size(); ++i) {
    const uint32_t id = owners[i];
    if (first[i] && *first[i] == KeyToIndex(scene.occupied[id])) {
      seen[i] = 1;
      continue;
    }
    double resume = -1;
    if (first[i]) {
      const int judged = SubvoxelJudgeAtFirst(scene, patches, tables, uo, id, ends[i], *first[i], &blocker[i], &resume);
      if (judged >= 0) {
        seen[i] = char(judged);
        continue;
      }
    }
    const double s_start = first[i] ? ResumeBefore(uo, ends[i], *first[i]) : 0.0;
    if (resume >= 0 && lanes) {
      on.push_back({i, s_start, resume});
      continue;
    }
    const SubvoxelRay ray = TraceSubvoxelSegment(scene, patches, uo, id, ends[i], s_start, &tables);
    seen[i] = ray.seen();
    blocker[i] = ray.first_blocker;
  }
  JudgeWalkingOn(scene, patches, tables, uo, owners, ends, std::move(on), seen, blocker);
}

}  // namespace

void SubvoxelVisibleAmong(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                          const Vector3d& uo, const ScannerLimits& limits, std::span<const uint32_t> ids,
                          VoxelSet& set) {
  FreeBox around = ShortcutsHold(scene.grid, uo) ? GrowFreeBox(scene.grid, uo) : FreeBox{};
  // Only with uo inside the box by the margin, so that every segment leaves it once, through the
  // open box before that.
  for (int a = 0; a < 3 && !around.empty(); ++a) {
    const double lo = a == 0 ? around.lo.x : a == 1 ? around.lo.y : around.lo.z;
    const double hi = (a == 0 ? around.hi.x : a == 1 ? around.hi.y : around.hi.z) + 1.0;
    if (!(uo[a] >= lo + kBoxMargin && uo[a] <= hi - kBoxMargin)) around = FreeBox{};
  }
  std::vector<uint32_t> owners;
  std::vector<Vector3d> ends;
  owners.reserve(ids.size());
  ends.reserve(ids.size());
  for (const uint32_t id : ids) {
    const Vector3d& aim = tables.Aim(id);
    if (!SubvoxelAimPasses(patches[id], aim, uo, limits)) continue;
    owners.push_back(id);
    ends.push_back(aim);
  }
  std::vector<char> seen;
  std::vector<int64_t> blocker;
  JudgeSegments(scene, patches, tables, uo, owners, ends, seen, blocker, around);
  // The box fall-back, one face a round: round r takes the r-th face (TraceSubvoxel's order) of
  // each voxel that is not flat and not seen yet. A face's segment that the blocker which last
  // stopped a segment of the voxel proves blocked (SubvoxelBlockedBy) is not walked.
  // Each voxel left: its faces' segment ends (SubvoxelFaceAims, computed once) and the blocker
  // that last stopped one of its segments.
  struct Left {
    uint32_t id;
    int faces;
    int64_t last;
    Eigen::Vector3d face[3];
  };
  std::vector<Left> left, next;
  std::vector<size_t> walked;  // per segment of a round, its voxel's place in `left`
  for (size_t i = 0; i < owners.size(); ++i) {
    if (seen[i]) {
      set.set(owners[i]);
    } else if (!patches[owners[i]].flat) {
      Left& l = left.emplace_back();
      l.id = owners[i];
      l.last = blocker[i];
      l.faces = SubvoxelFaceAims(scene, patches, uo, l.id, l.face, &tables);
      if (l.faces == 0) left.pop_back();
    }
  }
  for (int round = 0; round < 3 && !left.empty(); ++round) {
    owners.clear();
    ends.clear();
    next.clear();
    walked.clear();
    for (size_t j = 0; j < left.size(); ++j) {
      const Left& l = left[j];
      if (l.faces <= round) continue;
      if (SubvoxelBlockedBy(scene, patches, tables, uo, l.id, l.face[round], l.last)) {
        next.push_back(l);
        continue;
      }
      owners.push_back(l.id);
      ends.push_back(l.face[round]);
      walked.push_back(j);
    }
    JudgeSegments(scene, patches, tables, uo, owners, ends, seen, blocker, around);
    for (size_t i = 0; i < owners.size(); ++i) {
      if (seen[i]) {
        set.set(owners[i]);
      } else {
        next.push_back(left[walked[i]]);
        next.back().last = blocker[i];
      }
    }
    left.swap(next);
  }
}

}  // namespace vc::internal
