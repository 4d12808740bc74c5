// The visibility engine. Definitions: ALGORITHM.md sections 3-6 and docs/VISIBILITY.md.
//
// Work sharing that keeps the definitions exact:
// - A corner's visibility does not depend on which voxel is transparent. If the first occupied
//   voxel h on the ray o->c is the face's own voxel v, then v is one of the 8 voxels around c and
//   the corner counts as visible either way; if the ray passes through v at all, it stays inside
//   v until c (v is convex and c is on its boundary), so with v transparent nothing else is met.
//   So Evaluate (evaluate.cc) casts one ray per distinct lattice corner and viewpoint, shared by up
//   to 24 faces.
// - A voxel whose 6 neighbours are all occupied is never compatible (the ray to its centre must
//   enter through a neighbour) and has no exposed face, so the selection tests skip it.
#include "vc/visibility/visibility.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "subvoxel_internal.h"
#include "vc/base/parallel.h"
#include "vc/base/popcount.h"
#include "vc/raycast/occluders.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/visibility/scanner_limits.h"
#include "vc/visibility/surface_groups.h"
#include "visibility_internal.h"

namespace vc {
namespace {

using Eigen::Vector3d;
using internal::Corner;
using internal::CornerVisibleCached;
using internal::FaceCenterIS;
using internal::FaceValue;
using internal::FromCount;
using internal::InsideOccupied;
using internal::kFaceCorners;
using internal::kHalfPi;
using internal::Neighbour;
using internal::NotEnclosed;
using internal::OccluderCache;
using internal::StageProgress;

bool CompatibleCached(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& v, const ScannerLimits& limits,
                      OccluderCache& cache) {
  const Vector3d target(v.x + 0.5, v.y + 0.5, v.z + 0.5);
  if (limits.active()) {
    // The entry face matters only to the incidence and spacing limits; Passes ignores it otherwise.
    int axis = 0, sign = 1;
    if (limits.JudgesFace()) limits.EntryFace(v, &axis, &sign);
    if (!limits.Passes(target, axis, sign)) return false;
  }
  if (cache.Blocks(uo, target, v)) return false;
  const auto hit = FirstOccupied(g, uo, target);
  if (hit && *hit != v) cache.Add(*hit);
  return hit && *hit == v;
}

// The exposed-or-not faces of v that face o (o strictly outside the face's plane), the one most
// directly facing o first. Returns how many (at most 3).
int FacingFaces(const Vector3d& uo, const VoxelIndex& v, Face faces[3]) {
  double weight[3];
  int n = 0;
  const double lo[3] = {double(v.x), double(v.y), double(v.z)};
  for (int a = 0; a < 3; ++a) {
    if (uo[a] < lo[a]) {
      faces[n] = Face(2 * a);
      weight[n++] = lo[a] - uo[a];
    } else if (uo[a] > lo[a] + 1) {
      faces[n] = Face(2 * a + 1);
      weight[n++] = uo[a] - lo[a] - 1;
    }
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (weight[j] > weight[i]) {
        std::swap(weight[i], weight[j]);
        std::swap(faces[i], faces[j]);
      }
  return n;
}

bool SurfaceVisibleCached(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& v, const ScannerLimits& limits,
                          OccluderCache& cache) {
  Face faces[3];
  const int n = FacingFaces(uo, v, faces);
  for (int i = 0; i < n; ++i) {
    if (g.Occupied(Neighbour(v, faces[i]))) continue;  // not exposed
    const Vector3d target = FaceCenterIS(v, faces[i]);
    if (!limits.Passes(target, internal::FaceAxis(faces[i]), internal::FaceSign(faces[i]))) continue;
    if (cache.Blocks(uo, target, v)) continue;
    const auto hit = FirstOccupied(g, uo, target, &v);
    if (!hit) return true;
    cache.Add(*hit);
  }
  return false;
}

}  // namespace

bool ViewpointInRange(const WorldPoint& o, double resolution_m) {
  if (!o.allFinite() || !(resolution_m > 0)) return false;
  return (o / resolution_m).cwiseAbs().maxCoeff() <= kMaxViewpointIndex;
}

std::string_view SelectionTestName(SelectionTest t) {
  switch (t) {
    case SelectionTest::kCompatibility:
      return "compatibility";
    case SelectionTest::kSubvoxel:
      return "subvoxel";
    case SelectionTest::kSurfaceVisibility:
      break;
  }
  return "surface";
}

Status ScannerModel::Validate(const FieldNamer& namer) const {
  const auto name = [&namer](std::string_view path) { return NameOf(namer, path); };
  const auto num = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
#define VC_CHECK_ROW(type, row, ...) \
  VC_RETURN_IF_ERROR(CheckNamedParameter(VC_PARAMETER_INFO(type, row, __VA_ARGS__), row, namer, "scanner."));
  VC_SCANNER_PARAMETERS(VC_CHECK_ROW)
#undef VC_CHECK_ROW
  if (max_range_m <= min_range_m) {
    return InvalidArgumentError(name("scanner.max_range_m") + " (" + num(max_range_m) + " m) must be greater than " +
                                name("scanner.min_range_m") + " (" + num(min_range_m) + " m)");
  }
  if (vfov_max_deg <= vfov_min_deg) {
    return InvalidArgumentError(name("scanner.vfov_max_deg") + " (" + num(vfov_max_deg) +
                                " deg) must be greater than " + name("scanner.vfov_min_deg") + " (" +
                                num(vfov_min_deg) + " deg)");
  }
  if (max_spacing_m > 0 && !(angular_step_deg > 0)) {
    return InvalidArgumentError(name("scanner.max_spacing_m") + " is set but " + name("scanner.angular_step_deg") +
                                " is 0; give the instrument's angular step (--angular-step) or a preset (--scanner)");
  }
  return Status::Ok();
}

Status CheckViewpointHeadings(const ScannerModel& scanner, size_t viewpoints,
                              const std::vector<Heading>& headings_deg) {
  if (!headings_deg.empty() && headings_deg.size() != viewpoints) {
    return InvalidArgumentError("got " + std::to_string(headings_deg.size()) + " headings for " +
                                std::to_string(viewpoints) + " viewpoints; give one per viewpoint or none");
  }
  for (size_t k = 0; k < viewpoints; ++k) {
    const Heading heading = headings_deg.empty() ? Heading() : headings_deg[k];
    if (heading && !std::isfinite(*heading)) {
      return InvalidArgumentError("viewpoint " + std::to_string(k + 1) + " has a heading that is not finite");
    }
    if (!heading && scanner.HasHorizontalFieldOfView()) {
      return InvalidArgumentError("viewpoint " + std::to_string(k + 1) + " has no heading, but scanner.hfov_deg is " +
                                  std::to_string(scanner.hfov_deg) +
                                  " deg; a field of view below 360 deg needs the azimuth it is centred on");
    }
  }
  return Status::Ok();
}

namespace {

// One selection test for a single (viewpoint, voxel), with the limits of `scanner` or none.
template <typename Test>
bool SingleQuery(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, const ScannerModel* scanner,
                 Test test) {
  if (!ViewpointInRange(o, grid.resolution_m())) return false;
  const Vector3d uo = grid.WorldToIndexSpace(o);
  if (InsideOccupied(grid, uo)) return false;
  const ScannerLimits limits = scanner ? ScannerLimits(*scanner, grid.resolution_m(), uo) : ScannerLimits();
  OccluderCache cache(internal::ShortcutsHold(grid, uo));
  return test(grid, uo, v, limits, cache);
}

}  // namespace

bool IsCompatible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v) {
  return SingleQuery(grid, o, v, nullptr, CompatibleCached);
}

bool IsCompatible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, const ScannerModel& scanner) {
  return SingleQuery(grid, o, v, &scanner, CompatibleCached);
}

bool IsSurfaceVisible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v) {
  return SingleQuery(grid, o, v, nullptr, SurfaceVisibleCached);
}

bool IsSurfaceVisible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v,
                      const ScannerModel& scanner) {
  return SingleQuery(grid, o, v, &scanner, SurfaceVisibleCached);
}

Perception PerceiveFace(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, Face f) {
  if (!ViewpointInRange(o, grid.resolution_m())) return Perception::kNone;
  const Vector3d uo = grid.WorldToIndexSpace(o);
  int visible = 0;
  OccluderCache cache(internal::ShortcutsHold(grid, uo));
  for (int k : kFaceCorners[int(f)]) visible += CornerVisibleCached(grid, uo, Corner(v, k), cache);
  return FromCount(visible);
}

double VisibilityValue(Perception p, double d, double theta, const ScannerModel& s) {
  if (p == Perception::kNone || !(d >= s.min_range_m) || !(d <= s.max_range_m)) return 0.0;
  if (p == Perception::kPartial) return 0.3;
  const double D = std::clamp((d - s.min_range_m) / (s.max_range_m - s.min_range_m), 0.0, 1.0);
  const double A = std::clamp(std::abs(theta - kHalfPi) / kHalfPi, 0.0, 1.0);
  return 0.5 + 0.3 * (1.0 - D) + 0.2 * A;
}

double FaceVisibility(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, Face f,
                      const ScannerModel& scanner) {
  const ScannerLimits limits(scanner, grid.resolution_m(), grid.WorldToIndexSpace(o));
  return FaceValue(PerceiveFace(grid, o, v, f), o, v, f, grid.resolution_m(), scanner, limits);
}

namespace {

// What every batch of viewpoints shares: the voxels' indices, those that can pass either test, and
// (grouped surface test) the targets.
struct SetsContext {
  const VoxelScene& scene;
  const OccupancyGrid& g;
  size_t n;
  std::vector<VoxelIndex> index;
  std::vector<uint32_t> candidates;
  std::optional<internal::SurfaceTargets> targets;
  // Sub-voxel test, unless per voxel: what the traces' walks look up (subvoxel_bulk.cc).
  std::unique_ptr<internal::SubvoxelTables> subvoxel_tables;
};

// The dense sets of `viewpoints` (ComputeVisibilitySets without compaction).
Result<std::vector<VoxelSet>> ComputeDenseSets(const SetsContext& sc, const std::vector<WorldPoint>& viewpoints,
                                               const std::vector<Heading>& headings_deg,
                                               const VisibilitySetsOptions& options, const JobContext& ctx) {
  const OccupancyGrid& g = sc.g;
  const size_t n = sc.n;
  const std::vector<VoxelIndex>& index = sc.index;
  const std::vector<uint32_t>& candidates = sc.candidates;
  std::vector<VoxelSet> sets(viewpoints.size());
  std::vector<Vector3d> uo(viewpoints.size());
  std::vector<ScannerLimits> limits(viewpoints.size());
  std::vector<char> valid(viewpoints.size()), shortcuts(viewpoints.size());
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    uo[k] = g.WorldToIndexSpace(viewpoints[k]);
    const Heading heading = headings_deg.empty() ? Heading() : headings_deg[k];
    if (options.scanner) limits[k] = ScannerLimits(*options.scanner, g.resolution_m(), uo[k], heading);
    valid[k] = ViewpointInRange(viewpoints[k], g.resolution_m()) && !InsideOccupied(g, uo[k]);
    shortcuts[k] = valid[k] && internal::ShortcutsHold(g, uo[k]);
  }
  const bool grouped = options.test == SelectionTest::kSurfaceVisibility && !options.per_voxel;

  if (grouped) {
    // Grouped, for viewpoints where the shortcuts' margins hold. With enough viewpoints to keep
    // every thread busy, a task is one viewpoint and owns its set. Otherwise tasks are
    // (viewpoint, run of bricks); tasks of one viewpoint share its set's words, so bits are set
    // atomically.
    const internal::SurfaceTargets& targets = *sc.targets;
    const bool task_per_viewpoint =
        viewpoints.size() >= 8 * uint64_t(ResolveThreads(options.threads, viewpoints.size()));
    // The sets are allocated here, in the calling thread (running out of memory must not happen
    // in a worker), but a task that owns its viewpoint's set clears it: the first touch of fresh
    // memory is most of the cost (0.14 s in one thread for the hall's 858 sets of 53 KB).
    for (VoxelSet& set : sets) {
      if (task_per_viewpoint) {
        set.words().reserve((n + 63) / 64);
      } else {
        set.Resize(n);
      }
    }
    const uint64_t bricks_per_task = task_per_viewpoint ? std::max<uint64_t>(1, targets.brick_count()) : 256;
    const uint64_t brick_chunks =
        std::max<uint64_t>(1, (targets.brick_count() + bricks_per_task - 1) / bricks_per_task);
    const uint64_t tasks = viewpoints.size() * brick_chunks;
    StageProgress progress(ctx, Stage::kVisibility, tasks, viewpoints.size(), "candidates");
    Status st = ParallelChunks(tasks, 1, options.threads, ctx, [&](uint64_t task, uint64_t, uint64_t) {
      const size_t k = task / brick_chunks, c = task % brick_chunks;
      if (task_per_viewpoint) sets[k].Resize(n);  // in the capacity reserved above
      if (shortcuts[k]) {
        internal::GroupWalk walk;
        walk.around = internal::GrowFreeBox(g, uo[k]);
        const size_t b0 = c * bricks_per_task, b1 = std::min<size_t>(b0 + bricks_per_task, targets.brick_count());
        targets.AppendVisible(uo[k], limits[k], b0, b1, walk, {sets[k].words().data(), brick_chunks > 1});
      }
      progress.Add(1);
    });
    VC_RETURN_IF_ERROR(st);
    if (std::equal(valid.begin(), valid.end(), shortcuts.begin())) return sets;
  } else {
    for (VoxelSet& set : sets) set.Resize(n);
  }

  // Per voxel: every viewpoint, or (after the grouped pass) those too far for the shortcuts, whose
  // rays are then walked plainly. Each chunk covers one viewpoint and a word-aligned id range, so
  // writes to a set never share a word between chunks.
  constexpr uint64_t kIdsPerChunk = 64 * 64;
  const uint64_t id_chunks = (n + kIdsPerChunk - 1) / kIdsPerChunk;
  // Start offsets into `candidates` for each id chunk.
  std::vector<size_t> chunk_start(id_chunks + 1);
  for (uint64_t c = 0; c <= id_chunks; ++c) {
    chunk_start[c] =
        std::lower_bound(candidates.begin(), candidates.end(), uint32_t(std::min<uint64_t>(c * kIdsPerChunk, n))) -
        candidates.begin();
  }
  const uint64_t tasks = viewpoints.size() * id_chunks;
  StageProgress progress(ctx, Stage::kVisibility, tasks, viewpoints.size(), "candidates");
  const bool compat = options.test == SelectionTest::kCompatibility;
  const bool subvoxel = options.test == SelectionTest::kSubvoxel;
  Status st = ParallelChunks(tasks, 1, options.threads, ctx, [&](uint64_t task, uint64_t, uint64_t) {
    const size_t k = task / id_chunks, c = task % id_chunks;
    if (valid[k] && subvoxel && sc.subvoxel_tables) {
      const std::span<const uint32_t> ids(candidates.data() + chunk_start[c], chunk_start[c + 1] - chunk_start[c]);
      internal::SubvoxelVisibleAmong(sc.scene, options.surface_patches, *sc.subvoxel_tables, uo[k], limits[k], ids,
                                     sets[k]);
    } else if (valid[k] && subvoxel) {
      for (size_t j = chunk_start[c]; j < chunk_start[c + 1]; ++j) {
        const uint32_t id = candidates[j];
        if (internal::SubvoxelVisibleFrom(sc.scene, options.surface_patches, uo[k], id, limits[k])) sets[k].set(id);
      }
    } else if (valid[k] && !(grouped && shortcuts[k])) {
      VoxelSet& set = sets[k];
      OccluderCache cache(shortcuts[k]);
      for (size_t j = chunk_start[c]; j < chunk_start[c + 1]; ++j) {
        const uint32_t id = candidates[j];
        if (compat ? CompatibleCached(g, uo[k], index[id], limits[k], cache)
                   : SurfaceVisibleCached(g, uo[k], index[id], limits[k], cache)) {
          set.set(id);
        }
      }
    }
    progress.Add(1);
  });
  VC_RETURN_IF_ERROR(st);
  return sets;
}

}  // namespace

Status CheckSetBytes(uint64_t set_bytes, uint64_t positions, uint64_t voxels, uint64_t max_set_bytes) {
  if (max_set_bytes == 0 || set_bytes <= max_set_bytes) return Status::Ok();
  return ResourceExhaustedError("the visibility sets of " + std::to_string(positions) + " positions x " +
                                std::to_string(voxels) + " occupied voxels need more than " +
                                std::to_string(max_set_bytes >> 20) +
                                " MiB even where kept sparse; raise grid_spacing_m or resolution_m, lower "
                                "max_range_m, or raise the memory budget");
}

Result<std::vector<VoxelSet>> ComputeVisibilitySets(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                                    const VisibilitySetsOptions& requested, const JobContext& ctx) {
  if (requested.scanner)
    VC_RETURN_IF_ERROR(CheckViewpointHeadings(*requested.scanner, viewpoints.size(), requested.headings_deg));
  if (!requested.surface_patches.empty() && requested.surface_patches.size() != scene.occupied.size()) {
    return InvalidArgumentError("got " + std::to_string(requested.surface_patches.size()) + " surface patches for " +
                                std::to_string(scene.occupied.size()) + " occupied voxels; give one per voxel or none");
  }
  VisibilitySetsOptions options = requested;
  if (options.test == SelectionTest::kSubvoxel && options.surface_patches.empty()) {
    options.test = SelectionTest::kSurfaceVisibility;  // no points, no patches (subvoxel.h)
  }
  SetsContext sc{scene, scene.grid, scene.occupied.size(), std::vector<VoxelIndex>(scene.occupied.size()), {}, {}, {}};
  for (size_t i = 0; i < sc.n; ++i) sc.index[i] = KeyToIndex(scene.occupied[i]);
  if (options.test == SelectionTest::kSubvoxel) {
    // Every voxel: a voxel enclosed by occupied cubes can still be reached past flat patches.
    sc.candidates.resize(sc.n);
    for (size_t i = 0; i < sc.n; ++i) sc.candidates[i] = uint32_t(i);
  } else {
    sc.candidates = NotEnclosed(sc.g, sc.index);
  }
  if (options.test == SelectionTest::kSurfaceVisibility && !options.per_voxel) {
    sc.targets.emplace(sc.g, sc.index, sc.candidates);
  }
  if (options.test == SelectionTest::kSubvoxel && !options.per_voxel) {
    sc.subvoxel_tables = std::make_unique<internal::SubvoxelTables>(scene, options.surface_patches);
  }
  auto check_bytes = [&](uint64_t bytes) {
    return CheckSetBytes(bytes, viewpoints.size(), sc.n, options.max_set_bytes);
  };
  if (options.compact_gain <= 0) {
    VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> sets,
                        ComputeDenseSets(sc, viewpoints, options.headings_deg, options, ctx));
    uint64_t bytes = 0;
    for (const VoxelSet& s : sets) bytes += s.MemoryBytes();
    VC_RETURN_IF_ERROR(check_bytes(bytes));
    return sets;
  }
  // Batches whose dense sets fit batch_bytes, each compacted before the next is computed, so the
  // dense form of all sets never exists at once.
  const uint64_t dense_bytes = std::max<uint64_t>(8, (sc.n + 63) / 64 * 8);
  const size_t batch = size_t(std::max<uint64_t>(1, options.batch_bytes / dense_bytes));
  std::vector<VoxelSet> out;
  out.reserve(viewpoints.size());
  uint64_t kept = 0;
  const size_t total = viewpoints.size();
  for (size_t b0 = 0; b0 < total; b0 += batch) {
    const size_t b1 = std::min(total, b0 + batch);
    JobContext sub{ctx.cancel, {}};
    if (ctx.progress) {
      sub.progress = [&, b0, b1](const ProgressEvent& e) {
        ProgressEvent m = e;
        m.fraction = (double(b0) + e.fraction * double(b1 - b0)) / double(total);
        m.done = b0 + e.done;
        m.total = total;
        ctx.progress(m);
      };
    }
    const std::vector<WorldPoint> part(viewpoints.begin() + std::ptrdiff_t(b0),
                                       viewpoints.begin() + std::ptrdiff_t(b1));
    const std::vector<Heading> part_headings =
        options.headings_deg.empty() ? std::vector<Heading>()
                                     : std::vector<Heading>(options.headings_deg.begin() + std::ptrdiff_t(b0),
                                                            options.headings_deg.begin() + std::ptrdiff_t(b1));
    VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> sets, ComputeDenseSets(sc, part, part_headings, options, sub));
    for (VoxelSet& s : sets) {
      s.Compact(options.compact_gain);
      if (!s.sparse()) s.words().shrink_to_fit();
      kept += s.MemoryBytes();
      out.push_back(std::move(s));
    }
    VC_RETURN_IF_ERROR(check_bytes(kept));
  }
  return out;
}

}  // namespace vc
