// The visibility engine. Definitions: ALGORITHM.md sections 3-6 and docs/VISIBILITY.md.
//
// Work sharing that keeps the definitions exact:
// - A corner's visibility does not depend on which voxel is transparent. If the first occupied
//   voxel h on the ray o->c is the face's own voxel v, then v is one of the 8 voxels around c and
//   the corner counts as visible either way; if the ray passes through v at all, it stays inside
//   v until c (v is convex and c is on its boundary), so with v transparent nothing else is met.
//   So Evaluate casts one ray per distinct lattice corner and viewpoint, shared by up to 24 faces.
// - A voxel whose 6 neighbours are all occupied is never compatible (the ray to its centre must
//   enter through a neighbour) and has no exposed face, so the selection tests skip it.
#include "vc/visibility/visibility.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <memory>
#include <mutex>
#include <random>

#include "vc/base/huge_pages.h"
#include "vc/raycast/occluders.h"
#include "vc/base/parallel.h"
#include "vc/base/popcount.h"
#include "vc/visibility/surface_groups.h"
#include "vc/raycast/ray_traversal.h"

namespace vc {
namespace {

using Eigen::Vector3d;
using internal::OccluderCache;
using planner::ParallelChunks;
using planner::ResolveThreads;

constexpr double kHalfPi = 1.57079632679489661923;
// Exact evaluation gives each thread whole viewpoints once there are this many per thread (fewer
// leave threads idle at the end; see Evaluate).
constexpr uint64_t kEvaluateViewpointsPerThread = 4;
constexpr uint64_t kEvaluateExtraWorkBytes = uint64_t{256} << 20;

// Outward normal axis and sign of a face.
int FaceAxis(Face f) { return int(f) / 2; }
int FaceSign(Face f) { return (int(f) % 2) ? 1 : -1; }

// Centre of face f of voxel v, in index space.
Vector3d FaceCenterIS(const VoxelIndex& v, Face f) {
  Vector3d c(v.x + 0.5, v.y + 0.5, v.z + 0.5);
  const int a = FaceAxis(f);
  c[a] += 0.5 * FaceSign(f);
  return c;
}

VoxelIndex Neighbour(const VoxelIndex& v, Face f) {
  VoxelIndex n = v;
  const int a = FaceAxis(f);
  (a == 0 ? n.x : a == 1 ? n.y : n.z) += FaceSign(f);
  return n;
}

bool Enclosed(const OccupancyGrid& g, const VoxelIndex& v) {
  return g.Occupied(v.x - 1, v.y, v.z) && g.Occupied(v.x + 1, v.y, v.z) && g.Occupied(v.x, v.y - 1, v.z) &&
         g.Occupied(v.x, v.y + 1, v.z) && g.Occupied(v.x, v.y, v.z - 1) && g.Occupied(v.x, v.y, v.z + 1);
}

// Ids of the voxels with at least one free neighbour (the only ones with an exposed face).
std::vector<uint32_t> NotEnclosed(const OccupancyGrid& g, const std::vector<VoxelIndex>& index) {
  std::vector<uint32_t> ids;
  for (size_t i = 0; i < index.size(); ++i)
    if (!Enclosed(g, index[i])) ids.push_back(uint32_t(i));
  return ids;
}

bool InsideOccupied(const OccupancyGrid& g, const Vector3d& u) {
  return g.Occupied(int(std::floor(u.x())), int(std::floor(u.y())), int(std::floor(u.z())));
}

bool CompatibleCached(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& v, OccluderCache& cache) {
  const Vector3d target(v.x + 0.5, v.y + 0.5, v.z + 0.5);
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

bool SurfaceVisibleCached(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& v, OccluderCache& cache) {
  Face faces[3];
  const int n = FacingFaces(uo, v, faces);
  for (int i = 0; i < n; ++i) {
    if (g.Occupied(Neighbour(v, faces[i]))) continue;  // not exposed
    const Vector3d target = FaceCenterIS(v, faces[i]);
    if (cache.Blocks(uo, target, v)) continue;
    const auto hit = FirstOccupied(g, uo, target, &v);
    if (!hit) return true;
    cache.Add(*hit);
  }
  return false;
}

// True if the segment uo->c passes, half a voxel before reaching c's plane along some axis,
// through the interior of an occupied voxel that is not one of the 8 around c. The segment is
// outside the (convex) 2x2x2 block around c there, so the walk meets that voxel before any of
// the 8: c is not seen. This catches the surface's own layer hiding the corners behind it at
// grazing angles, without a walk.
bool LastLayerBlocksCorner(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& c) {
  constexpr double kMargin = internal::kInteriorMargin;
  const Vector3d end(c.x, c.y, c.z);
  for (int a = 0; a < 3; ++a) {
    const double across = std::abs(uo[a] - end[a]);
    if (across < 1) continue;
    const Vector3d p = end + (uo - end) * (0.5 / across);
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

bool CornerVisibleCached(const OccupancyGrid& g, const Vector3d& uo, const VoxelIndex& c, OccluderCache& cache) {
  if (cache.enabled() && LastLayerBlocksCorner(g, uo, c)) return false;  // shortcuts hold (occluders.h)
  // Occluders in the 2x2x2 block around c do not count: once a segment enters that (convex)
  // block it stays inside it up to c, so every voxel outside it is visited first.
  const Vector3d end(c.x, c.y, c.z);
  if (cache.Blocks(uo, end, {c.x - 1, c.y - 1, c.z - 1}, c)) return false;
  const auto hit = FirstOccupied(g, uo, end);
  if (!hit) return true;
  const bool near = (hit->x == c.x || hit->x == c.x - 1) && (hit->y == c.y || hit->y == c.y - 1) &&
                    (hit->z == c.z || hit->z == c.z - 1);
  if (!near) cache.Add(*hit);
  return near;
}

// Corner k (bit 0: +x, bit 1: +y, bit 2: +z) of voxel v.
VoxelIndex Corner(const VoxelIndex& v, int k) { return {v.x + (k & 1), v.y + ((k >> 1) & 1), v.z + ((k >> 2) & 1)}; }

// The 4 corner numbers of each face.
constexpr int kFaceCorners[6][4] = {
    {0, 2, 4, 6},  // -x
    {1, 3, 5, 7},  // +x
    {0, 1, 4, 5},  // -y
    {2, 3, 6, 7},  // +y
    {0, 1, 2, 3},  // -z
    {4, 5, 6, 7},  // +z
};

// The same, as masks over the 8 corner numbers.
constexpr unsigned kFaceCornerMask[6] = {0x55, 0xaa, 0x33, 0xcc, 0x0f, 0xf0};

Perception FromCount(int visible) {
  return visible == 4 ? Perception::kFull : visible > 0 ? Perception::kPartial : Perception::kNone;
}

// V of a face given its perception, from world viewpoint o (s.5).
double FaceValue(Perception p, const WorldPoint& o, const VoxelIndex& v, Face f, double r, const ScannerModel& s) {
  if (p == Perception::kNone) return 0.0;
  const WorldPoint center = FaceCenterIS(v, f) * r;
  const Vector3d ray = center - o;
  const double d = ray.norm();
  Vector3d normal = Vector3d::Zero();
  normal[FaceAxis(f)] = FaceSign(f);
  const double cos_theta = d > 0 ? std::clamp(ray.dot(normal) / d, -1.0, 1.0) : 1.0;
  // The angle only counts for a fully perceived face; the acos is skipped for the others.
  return VisibilityValue(p, d, p == Perception::kFull ? std::acos(cos_theta) : kHalfPi, s);
}

uint64_t PackCorner(const VoxelIndex& c) {
  constexpr int kBias = 1 << 20;
  return (uint64_t(c.z + kBias) << 42) | (uint64_t(c.y + kBias) << 21) | uint64_t(c.x + kBias);
}

VoxelIndex UnpackCorner(uint64_t p) {
  constexpr int kBias = 1 << 20;
  constexpr uint64_t kMask = (uint64_t{1} << 21) - 1;
  return {int(p & kMask) - kBias, int((p >> 21) & kMask) - kBias, int(p >> 42) - kBias};
}

// Accumulates the figures of s.6 over faces.
struct Tally {
  double sum_v = 0;
  double sum_full_v = 0;
  uint64_t full = 0;
  uint64_t partial = 0;
  void Add(Perception p, double v) {
    sum_v += v;
    if (p == Perception::kFull && v > 0) {
      ++full;
      sum_full_v += v;
    } else if (p != Perception::kNone && v > 0) {
      ++partial;
    }
  }
  void Merge(const Tally& o) {
    sum_v += o.sum_v;
    sum_full_v += o.sum_full_v;
    full += o.full;
    partial += o.partial;
  }
  VisibilityFigures Figures(uint64_t faces) const {
    VisibilityFigures f;
    if (faces == 0) return f;
    f.global_visibility = sum_v / double(faces);
    f.fully_visible_fraction = double(full) / double(faces);
    f.mean_full_visibility = full ? sum_full_v / double(full) : 0.0;
    f.partially_visible_fraction = double(partial) / double(faces);
    return f;
  }
};

// Rate-limited, thread-safe progress for one stage.
class StageProgress {
 public:
  StageProgress(const JobContext& ctx, Stage stage, uint64_t total)
      : ctx_(ctx), stage_(stage), total_(std::max<uint64_t>(total, 1)) {}
  void Add(uint64_t n) {
    const uint64_t before = done_.fetch_add(n);
    const uint64_t step = std::max<uint64_t>(total_ / 100, 1);
    if ((before + n) / step != before / step) {
      std::lock_guard<std::mutex> lock(mu_);
      ctx_.Report(stage_, std::min(1.0, double(before + n) / double(total_)));
    }
  }

 private:
  const JobContext& ctx_;
  Stage stage_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::mutex mu_;
};

bool FaceInSet(const OccupancyGrid& g, const VoxelIndex& v, Face f, FaceSet set) {
  return set == FaceSet::kAll || !g.Occupied(Neighbour(v, f));
}

}  // namespace

bool ViewpointInRange(const WorldPoint& o, double resolution_m) {
  if (!o.allFinite() || !(resolution_m > 0)) return false;
  return (o / resolution_m).cwiseAbs().maxCoeff() <= kMaxViewpointIndex;
}

std::string_view SelectionTestName(SelectionTest t) {
  return t == SelectionTest::kCompatibility ? "compatibility" : "surface";
}

Status ScannerModel::Validate() const {
#define VC_CHECK_ROW(type, name, ...) \
  VC_RETURN_IF_ERROR(CheckParameter(VC_PARAMETER_INFO(type, name, __VA_ARGS__), name, "scanner."));
  VC_SCANNER_PARAMETERS(VC_CHECK_ROW)
#undef VC_CHECK_ROW
  if (max_range_m <= min_range_m) {
    return InvalidArgumentError("scanner.max_range_m (" + std::to_string(max_range_m) +
                                " m) must be greater than scanner.min_range_m (" + std::to_string(min_range_m) + " m)");
  }
  return Status::Ok();
}

bool IsCompatible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v) {
  if (!ViewpointInRange(o, grid.resolution_m())) return false;
  const Vector3d uo = grid.WorldToIndexSpace(o);
  if (InsideOccupied(grid, uo)) return false;
  OccluderCache cache(internal::ShortcutsHold(grid, uo));
  return CompatibleCached(grid, uo, v, cache);
}

bool IsSurfaceVisible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v) {
  if (!ViewpointInRange(o, grid.resolution_m())) return false;
  const Vector3d uo = grid.WorldToIndexSpace(o);
  if (InsideOccupied(grid, uo)) return false;
  OccluderCache cache(internal::ShortcutsHold(grid, uo));
  return SurfaceVisibleCached(grid, uo, v, cache);
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
  return FaceValue(PerceiveFace(grid, o, v, f), o, v, f, grid.resolution_m(), scanner);
}

VC_POPCOUNT_CLONES size_t VoxelSet::count() const {
  size_t n = 0;
  for (uint64_t w : words_) n += std::popcount(w);
  return n;
}

VC_POPCOUNT_CLONES size_t VoxelSet::CountAnd(const VoxelSet& other) const {
  size_t n = 0;
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) n += std::popcount(words_[i] & other.words_[i]);
  return n;
}

void VoxelSet::Subtract(const VoxelSet& other) {
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) words_[i] &= ~other.words_[i];
}

void VoxelSet::Union(const VoxelSet& other) {
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) words_[i] |= other.words_[i];
}

Result<std::vector<VoxelSet>> ComputeVisibilitySets(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                                    const VisibilitySetsOptions& options, const JobContext& ctx) {
  const OccupancyGrid& g = scene.grid;
  const size_t n = scene.occupied.size();
  std::vector<VoxelIndex> index(n);
  for (size_t i = 0; i < n; ++i) index[i] = KeyToIndex(scene.occupied[i]);
  // Voxels that can pass either test.
  const std::vector<uint32_t> candidates = NotEnclosed(g, index);
  std::vector<VoxelSet> sets(viewpoints.size());
  std::vector<Vector3d> uo(viewpoints.size());
  std::vector<char> valid(viewpoints.size()), shortcuts(viewpoints.size());
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    uo[k] = g.WorldToIndexSpace(viewpoints[k]);
    valid[k] = ViewpointInRange(viewpoints[k], g.resolution_m()) && !InsideOccupied(g, uo[k]);
    shortcuts[k] = valid[k] && internal::ShortcutsHold(g, uo[k]);
  }
  const bool grouped = options.test == SelectionTest::kSurfaceVisibility && !options.per_voxel;

  if (grouped) {
    // Grouped, for viewpoints where the shortcuts' margins hold. With enough viewpoints to keep
    // every thread busy, a task is one viewpoint and owns its set. Otherwise tasks are
    // (viewpoint, run of bricks); tasks of one viewpoint share its set's words, so bits are set
    // atomically.
    const internal::SurfaceTargets targets(g, index, candidates);
    const bool task_per_viewpoint = viewpoints.size() >= 8 * uint64_t(ResolveThreads(options.threads, viewpoints.size()));
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
    const uint64_t brick_chunks = std::max<uint64_t>(1, (targets.brick_count() + bricks_per_task - 1) / bricks_per_task);
    const uint64_t tasks = viewpoints.size() * brick_chunks;
    StageProgress progress(ctx, Stage::kVisibility, tasks);
    Status st = ParallelChunks(tasks, 1, options.threads, ctx, [&](uint64_t task, uint64_t, uint64_t) {
      const size_t k = task / brick_chunks, c = task % brick_chunks;
      if (task_per_viewpoint) sets[k].Resize(n);  // in the capacity reserved above
      if (shortcuts[k]) {
        internal::GroupWalk walk;
        walk.around = internal::GrowFreeBox(g, uo[k]);
        const size_t b0 = c * bricks_per_task, b1 = std::min<size_t>(b0 + bricks_per_task, targets.brick_count());
        targets.AppendVisible(uo[k], b0, b1, walk, {sets[k].words().data(), brick_chunks > 1});
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
    chunk_start[c] = std::lower_bound(candidates.begin(), candidates.end(), uint32_t(std::min<uint64_t>(c * kIdsPerChunk, n))) -
                     candidates.begin();
  }
  const uint64_t tasks = viewpoints.size() * id_chunks;
  StageProgress progress(ctx, Stage::kVisibility, tasks);
  const bool compat = options.test == SelectionTest::kCompatibility;
  Status st = ParallelChunks(tasks, 1, options.threads, ctx, [&](uint64_t task, uint64_t, uint64_t) {
    const size_t k = task / id_chunks, c = task % id_chunks;
    if (valid[k] && !(grouped && shortcuts[k])) {
      VoxelSet& set = sets[k];
      OccluderCache cache(shortcuts[k]);
      for (size_t j = chunk_start[c]; j < chunk_start[c + 1]; ++j) {
        const uint32_t id = candidates[j];
        if (compat ? CompatibleCached(g, uo[k], index[id], cache) : SurfaceVisibleCached(g, uo[k], index[id], cache)) {
          set.set(id);
        }
      }
    }
    progress.Add(1);
  });
  VC_RETURN_IF_ERROR(st);
  return sets;
}

namespace {
// A face's best (V, perception) so far: the larger V, and on equal V the better perception. The
// result does not depend on the order in which the viewpoints' values arrive.
template <typename P>
void KeepBest(double val, P p, double& best, P& best_p) {
  if (val > best || (val == best && p > best_p)) {
    best = val;
    best_p = p;
  }
}
}  // namespace

Result<Evaluation> Evaluate(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                            const EvaluateOptions& options, const JobContext& ctx) {
  VC_RETURN_IF_ERROR(options.scanner.Validate());
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    if (!viewpoints[k].allFinite()) {
      return InvalidArgumentError("viewpoint " + std::to_string(k + 1) + " has a non-finite coordinate");
    }
    if (!ViewpointInRange(viewpoints[k], scene.resolution_m)) {
      return InvalidArgumentError("viewpoint " + std::to_string(k + 1) + " is more than " +
                                  std::to_string(int64_t(kMaxViewpointIndex * scene.resolution_m)) +
                                  " m from the origin along an axis; use coordinates in the scene's frame");
    }
  }
  const OccupancyGrid& g = scene.grid;
  const double r = scene.resolution_m;
  const size_t n = scene.occupied.size();
  const size_t nv = viewpoints.size();
  Evaluation ev;
  ev.resolution_m = r;
  std::vector<VoxelIndex> index(n);
  for (size_t i = 0; i < n; ++i) index[i] = KeyToIndex(scene.occupied[i]);

  // F: all faces, or the exposed ones.
  uint64_t faces_total = 0;
  for (size_t i = 0; i < n; ++i)
    for (int f = 0; f < kFacesPerVoxel; ++f) faces_total += FaceInSet(g, index[i], Face(f), options.faces);
  ev.faces_total = faces_total;
  ev.per_viewpoint.resize(nv);
  if (faces_total == 0) return ev;

  std::vector<Vector3d> uo(nv);
  std::vector<char> shortcuts(nv);  // the shortcuts' margins hold for rays from viewpoint k
  for (size_t k = 0; k < nv; ++k) {
    uo[k] = g.WorldToIndexSpace(viewpoints[k]);
    shortcuts[k] = internal::ShortcutsHold(g, uo[k]);
  }

  if (options.sample_faces > 0) {
    // Unbiased uniform sample of F with replacement: pick a voxel id and a face uniformly, and
    // re-draw faces outside F (rejection keeps the distribution uniform over F).
    ev.sampled = true;
    ev.faces_evaluated = options.sample_faces;
    std::mt19937_64 rng(options.seed);
    std::uniform_int_distribution<uint64_t> pick(0, n * kFacesPerVoxel - 1);
    std::vector<std::pair<uint32_t, uint8_t>> sample(options.sample_faces);
    for (auto& s : sample) {
      while (true) {
        const uint64_t p = pick(rng);
        const uint32_t id = uint32_t(p / kFacesPerVoxel);
        const uint8_t f = uint8_t(p % kFacesPerVoxel);
        if (FaceInSet(g, index[id], Face(f), options.faces)) {
          s = {id, f};
          break;
        }
      }
    }
    constexpr uint64_t kChunk = 256;
    const uint64_t chunks = (sample.size() + kChunk - 1) / kChunk;
    std::vector<Tally> overall(chunks);
    std::vector<double> sum_sq(chunks, 0.0);
    std::vector<std::vector<Tally>> per(chunks, std::vector<Tally>(nv));
    StageProgress progress(ctx, Stage::kEvaluation, chunks);
    VC_RETURN_IF_ERROR(ParallelChunks(sample.size(), kChunk, options.threads, ctx, [&](uint64_t c, uint64_t b, uint64_t e) {
      for (uint64_t i = b; i < e; ++i) {
        const VoxelIndex& v = index[sample[i].first];
        const Face f = Face(sample[i].second);
        double best = 0;
        Perception best_p = Perception::kNone;
        for (size_t k = 0; k < nv; ++k) {
          int visible = 0;
          OccluderCache cache(shortcuts[k]);
          for (int q : kFaceCorners[int(f)]) visible += CornerVisibleCached(g, uo[k], Corner(v, q), cache);
          const Perception p = FromCount(visible);
          const double val = FaceValue(p, viewpoints[k], v, f, r, options.scanner);
          per[c][k].Add(p, val);
          KeepBest(val, p, best, best_p);
        }
        overall[c].Add(best_p, best);
        sum_sq[c] += best * best;
      }
      progress.Add(1);
    }));
    Tally total;
    double sq = 0;
    std::vector<Tally> per_total(nv);
    for (uint64_t c = 0; c < chunks; ++c) {
      total.Merge(overall[c]);
      sq += sum_sq[c];
      for (size_t k = 0; k < nv; ++k) per_total[k].Merge(per[c][k]);
    }
    const double m = double(sample.size());
    ev.overall = total.Figures(sample.size());
    const double mean = ev.overall.global_visibility;
    const double var = m > 1 ? std::max(0.0, (sq - m * mean * mean) / (m - 1)) : 0.0;
    ev.global_visibility_ci95 = 1.96 * std::sqrt(var / m);
    for (size_t k = 0; k < nv; ++k) ev.per_viewpoint[k] = per_total[k].Figures(sample.size());
    return ev;
  }

  // Exact mode. Distinct lattice corners of all occupied voxels, and each voxel's 8 corner ids.
  ev.faces_evaluated = faces_total;
  // The voxels are sorted by (z, y, x), so for each corner number q the corners of voxels in id
  // order form a sorted stream (a fixed offset keeps the order). Merging the 8 streams lists the
  // distinct corners in order and gives each voxel its 8 corner ids, without a sort or a search.
  if (std::adjacent_find(scene.occupied.begin(), scene.occupied.end(),
                         [](const VoxelKey& a, const VoxelKey& b) { return !(a < b); }) != scene.occupied.end()) {
    return InvalidArgumentError("the scene's voxels must be sorted and unique (VoxelScene::occupied)");
  }
  std::vector<uint64_t> corners;
  corners.reserve(n * 3);
  std::vector<std::array<uint32_t, 8>> voxel_corners(n);
  {
    constexpr uint64_t kDone = ~uint64_t{0};
    size_t pos[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    uint64_t head[8];
    for (int q = 0; q < 8; ++q) head[q] = n ? PackCorner(Corner(index[0], q)) : kDone;
    while (true) {
      const uint64_t next = *std::min_element(head, head + 8);
      if (next == kDone) break;
      const uint32_t id = uint32_t(corners.size());
      corners.push_back(next);
      for (int q = 0; q < 8; ++q) {
        while (head[q] == next) {
          voxel_corners[pos[q]][q] = id;
          head[q] = ++pos[q] < n ? PackCorner(Corner(index[pos[q]], q)) : kDone;
        }
      }
    }
  }
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("evaluation"));

  // Bit f: face f of the voxel is in options.faces (the same for every viewpoint).
  std::vector<uint8_t> faces_in_set(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (int f = 0; f < kFacesPerVoxel; ++f) {
      if (FaceInSet(g, index[i], Face(f), options.faces)) faces_in_set[i] |= uint8_t(1u << f);
    }
  }
  // Allocated here, in the calling thread, like every large allocation of this mode: running out
  // of memory must not happen in a worker thread. Each viewpoint's values are filled by the
  // thread that evaluates it (huge_pages.h: first touch is the costly part).
  if (options.keep_per_viewpoint_values) {
    ev.per_viewpoint_face_values.resize(nv);
    for (std::vector<float>& values : ev.per_viewpoint_face_values) {
      internal::ReserveOnHugePages(values, n * kFacesPerVoxel);
    }
  }
  constexpr uint64_t kCornerChunk = 64 * 256;
  constexpr uint64_t kVoxelChunk = 4096;
  const uint64_t voxel_chunks = (n + kVoxelChunk - 1) / kVoxelChunk;
  StageProgress progress(ctx, Stage::kEvaluation, nv);
  // Corners that groups of faces decide at once (surface_groups.h), per viewpoint.
  const internal::SurfaceTargets targets(g, index, NotEnclosed(g, index));
  constexpr uint64_t kBricksPerTask = 256;
  const uint64_t brick_chunks = (targets.brick_count() + kBricksPerTask - 1) / kBricksPerTask;

  // What evaluating viewpoints needs besides the scene: the corner bitsets of the viewpoint at
  // hand, and the best V (and its perception) of each face over the viewpoints evaluated so far.
  struct Work {
    Work(size_t corner_words, size_t slots, size_t voxel_chunks)
        : visible_bits(corner_words),
          decided_bits(corner_words),
          tallies(voxel_chunks),
          best(internal::FilledOnHugePages(slots, 0.0)),
          best_p(internal::FilledOnHugePages(slots, uint8_t{0})) {}
    std::vector<uint64_t> visible_bits, decided_bits;
    std::vector<Tally> tallies;  // per chunk of voxels, for the viewpoint at hand
    std::vector<double> best;
    std::vector<uint8_t> best_p;
  };
  const size_t corner_words = (corners.size() + 63) / 64;
  // Viewpoint k into `w`, on `threads` workers (1: all in the calling thread, with no atomics).
  // Its figures do not depend on `threads`: partial sums are merged in chunk order.
  auto evaluate_viewpoint = [&](size_t k, int threads, Work& w) -> Status {
    const bool shared = ResolveThreads(threads, brick_chunks) > 1;  // the group pass runs on several threads
    // 1. Corners decided by face groups, then one ray per remaining corner. With several
    // workers, tasks share words of the bitsets, so the group pass sets bits atomically.
    std::fill(w.visible_bits.begin(), w.visible_bits.end(), 0);
    std::fill(w.decided_bits.begin(), w.decided_bits.end(), 0);
    // A corner is often decided many times (it is shared by up to 24 faces), so BitWriter's
    // plain load before the atomic one pays.
    const internal::BitWriter decided_out{w.decided_bits.data(), shared}, visible_out{w.visible_bits.data(), shared};
    const bool grouped = !options.per_corner && shortcuts[k] && !InsideOccupied(g, uo[k]);
    if (grouped) {
      const internal::FreeBox around = internal::GrowFreeBox(g, uo[k]);  // once, for every chunk
      VC_RETURN_IF_ERROR(ParallelChunks(brick_chunks, 1, threads, ctx, [&](uint64_t task, uint64_t, uint64_t) {
        internal::GroupWalk walk;
        walk.around = around;
        std::vector<internal::SurfaceTargets::CornerDecision> decisions;
        const size_t b0 = task * kBricksPerTask, b1 = std::min<size_t>(b0 + kBricksPerTask, targets.brick_count());
        targets.AppendCornerDecisions(uo[k], b0, b1, walk, decisions);
        for (const auto& d : decisions) {
          auto apply = [&](int q) {
            const uint32_t c = voxel_corners[d.id][q];
            decided_out.Set(c);
            if (d.seen) visible_out.Set(c);
          };
          if (d.face == 0xff) {
            apply(d.corner);
          } else {
            for (int q : kFaceCorners[d.face]) apply(q);
          }
        }
      }));
    }
    VC_RETURN_IF_ERROR(ParallelChunks(corners.size(), kCornerChunk, threads, ctx, [&](uint64_t, uint64_t b, uint64_t e) {
      OccluderCache cache(shortcuts[k]);
      for (uint64_t c = b; c < e; ++c) {
        if ((w.decided_bits[c >> 6] >> (c & 63)) & 1) continue;
        if (CornerVisibleCached(g, uo[k], UnpackCorner(corners[c]), cache)) {
          w.visible_bits[c >> 6] |= uint64_t{1} << (c & 63);
        }
      }
    }));
    // 2. Faces from their corners.
    std::vector<Tally>& tallies = w.tallies;
    std::fill(tallies.begin(), tallies.end(), Tally{});
    std::vector<float>* keep = options.keep_per_viewpoint_values ? &ev.per_viewpoint_face_values[k] : nullptr;
    if (keep) keep->resize(n * kFacesPerVoxel);  // zeros, in the capacity reserved above
    VC_RETURN_IF_ERROR(ParallelChunks(n, kVoxelChunk, threads, ctx, [&](uint64_t chunk, uint64_t b, uint64_t e) {
      Tally& t = tallies[chunk];
      for (uint64_t i = b; i < e; ++i) {
        unsigned corner_bits = 0;  // bit q: corner q of voxel i is visible
        for (int q = 0; q < 8; ++q) {
          const uint32_t c = voxel_corners[i][q];
          corner_bits |= unsigned((w.visible_bits[c >> 6] >> (c & 63)) & 1) << q;
        }
        // No visible corner: every face is unperceived, V = 0, which adds nothing to the tally or
        // the best values, and the kept values are zeros already.
        if (corner_bits == 0) continue;
        for (int f = 0; f < kFacesPerVoxel; ++f) {
          if (!((faces_in_set[i] >> f) & 1)) continue;
          const Perception p = FromCount(std::popcount(corner_bits & kFaceCornerMask[f]));
          const double val = FaceValue(p, viewpoints[k], index[i], Face(f), r, options.scanner);
          t.Add(p, val);
          const size_t slot = i * kFacesPerVoxel + f;
          if (keep) (*keep)[slot] = float(val);
          KeepBest(val, uint8_t(p), w.best[slot], w.best_p[slot]);
        }
      }
    }));
    Tally total;
    for (const Tally& t : tallies) total.Merge(t);
    ev.per_viewpoint[k] = total.Figures(faces_total);
    progress.Add(1);
    return Status::Ok();
  };

  // With enough viewpoints per thread, a task is one viewpoint, evaluated by one thread into
  // that thread's Work (no joins within a viewpoint, no atomics); the threads' best values are
  // merged at the end. Otherwise the viewpoints are evaluated one after another, each on all
  // threads. Both give the same figures: the best (V, perception) pair of a face is the same
  // whatever the order of the viewpoints.
  // Each extra thread's Work costs 9 bytes per face; beyond kEvaluateExtraWorkBytes in all, the
  // viewpoints are evaluated one after another instead.
  const int workers = ResolveThreads(options.threads, nv);
  const uint64_t extra_bytes = uint64_t(workers - 1) * n * kFacesPerVoxel * (sizeof(double) + sizeof(uint8_t));
  std::vector<std::unique_ptr<Work>> works;
  if (workers > 1 && nv >= kEvaluateViewpointsPerThread * uint64_t(workers) && extra_bytes <= kEvaluateExtraWorkBytes) {
    // Allocated here, in the calling thread, so that running out of memory is not a worker's.
    std::vector<Work*> idle;
    for (int t = 0; t < workers; ++t) {
      works.push_back(std::make_unique<Work>(corner_words, n * kFacesPerVoxel, voxel_chunks));
      idle.push_back(works.back().get());
    }
    std::mutex mu;
    Status failed = Status::Ok();
    // The last nv % workers viewpoints are evaluated one after another on all threads, so that
    // no thread ends with a whole viewpoint of its own while the others wait.
    const uint64_t alone = nv - nv % uint64_t(workers);
    VC_RETURN_IF_ERROR(ParallelChunks(alone, 1, workers, ctx, [&](uint64_t k, uint64_t, uint64_t) {
      Work* w = nullptr;
      {
        std::lock_guard<std::mutex> lock(mu);  // at most `workers` tasks run at once
        w = idle.back();
        idle.pop_back();
      }
      const Status st = evaluate_viewpoint(k, 1, *w);
      std::lock_guard<std::mutex> lock(mu);
      if (!st.ok() && failed.ok()) failed = st;
      idle.push_back(w);
    }, "evaluation"));
    VC_RETURN_IF_ERROR(failed);
    for (size_t k = alone; k < nv; ++k) VC_RETURN_IF_ERROR(evaluate_viewpoint(k, workers, *works[0]));
  } else {
    works.push_back(std::make_unique<Work>(corner_words, n * kFacesPerVoxel, voxel_chunks));
    for (size_t k = 0; k < nv; ++k) VC_RETURN_IF_ERROR(evaluate_viewpoint(k, options.threads, *works[0]));
  }
  std::vector<double>& best = works[0]->best;
  std::vector<uint8_t>& best_p = works[0]->best_p;
  for (size_t t = 1; t < works.size(); ++t) {
    for (size_t slot = 0; slot < best.size(); ++slot) KeepBest(works[t]->best[slot], works[t]->best_p[slot], best[slot], best_p[slot]);
  }
  // Overall: the best V of each face over all viewpoints.
  Tally total;
  for (size_t i = 0; i < n; ++i)
    for (int f = 0; f < kFacesPerVoxel; ++f) {
      if (!((faces_in_set[i] >> f) & 1)) continue;
      const size_t slot = i * kFacesPerVoxel + f;
      total.Add(Perception(best_p[slot]), best[slot]);
    }
  ev.overall = total.Figures(faces_total);
  if (options.keep_face_values) {
    ev.best_face_values.resize(n);
    for (size_t i = 0; i < n; ++i)
      for (int f = 0; f < kFacesPerVoxel; ++f) ev.best_face_values[i][f] = float(best[i * kFacesPerVoxel + f]);
  }
  return ev;
}

}  // namespace vc
