// vc::Evaluate (ALGORITHM.md s.6; docs/VISIBILITY.md): the exact mode (every face of F, one ray per
// distinct lattice corner and viewpoint, corners first decided by groups of faces) and the sampled
// mode (a uniform random sample of F with replacement, with a 95 % confidence interval) are two
// code paths over shared pieces: viewpoint validation, the scene's voxel indices and |F|, the
// viewpoints in index space with their shortcut margins, and the tallies of s.6. Evaluate
// validates, prepares and dispatches. Thread-safe on a const scene (see visibility.h).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "vc/base/huge_pages.h"
#include "vc/base/parallel.h"
#include "vc/raycast/occluders.h"
#include "vc/visibility/spatial_order.h"
#include "vc/visibility/surface_groups.h"
#include "vc/visibility/visibility.h"
#include "visibility_internal.h"

namespace vc {
namespace {

using Eigen::Vector3d;
using internal::Corner;
using internal::CornerVisibleCached;
using internal::FaceValue;
using internal::FromCount;
using internal::InsideOccupied;
using internal::kFaceCornerMask;
using internal::kFaceCorners;
using internal::Neighbour;
using internal::NotEnclosed;
using internal::OccluderCache;
using internal::StageProgress;

// Exact evaluation gives each thread whole viewpoints once there are this many per thread (fewer
// leave threads idle at the end; see Evaluate).
constexpr uint64_t kEvaluateViewpointsPerThread = 4;
constexpr uint64_t kEvaluateExtraWorkBytes = uint64_t{256} << 20;

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

bool FaceInSet(const OccupancyGrid& g, const VoxelIndex& v, Face f, FaceSet set) {
  return set == FaceSet::kAll || !g.Occupied(Neighbour(v, f));
}

// Who alone sees a voxel, from who alone sees it among two disjoint sets of viewpoints.
int32_t CombineViewers(int32_t a, int32_t b) {
  if (a == kNoViewer) return b;
  if (b == kNoViewer || a == b) return a;
  return kSeveralViewers;
}

// A face's best (V, perception) so far: the larger V, and on equal V the better perception. The
// result does not depend on the order in which the viewpoints' values arrive.
template <typename P>
void KeepBest(double val, P p, double& best, P& best_p) {
  if (val > best || (val == best && p > best_p)) {
    best = val;
    best_p = p;
  }
}

// INVALID_ARGUMENT naming the first viewpoint (1-based) that is not finite or lies out of range.
Status ValidateViewpoints(const std::vector<WorldPoint>& viewpoints, double resolution_m) {
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    if (!viewpoints[k].allFinite()) {
      return InvalidArgumentError("viewpoint " + std::to_string(k + 1) + " has a non-finite coordinate");
    }
    if (!ViewpointInRange(viewpoints[k], resolution_m)) {
      return InvalidArgumentError("viewpoint " + std::to_string(k + 1) + " is more than " +
                                  std::to_string(int64_t(kMaxViewpointIndex * resolution_m)) +
                                  " m from the origin along an axis; use coordinates in the scene's frame");
    }
  }
  return Status::Ok();
}

// What both modes work on: the scene's grid, resolution (m) and voxel count, the viewpoints and
// options, the occupied voxels in index space (id order), |F|, and each viewpoint in index space
// with whether the shortcuts' margins hold for rays from it.
struct EvaluationJob {
  const OccupancyGrid& g;
  double r;
  size_t n;
  size_t nv;
  const std::vector<WorldPoint>& viewpoints;
  const EvaluateOptions& options;
  const JobContext& ctx;
  std::vector<VoxelIndex> index;
  uint64_t faces_total;
  std::vector<Vector3d> uo;
  std::vector<char> shortcuts;
  std::vector<ScannerLimits> limits;  // the scanner's, per viewpoint

  // V of face f of voxel v seen from viewpoint k with perception p (s.6).
  double FaceValueFrom(size_t k, Perception p, const VoxelIndex& v, Face f) const {
    return FaceValue(p, viewpoints[k], v, f, r, options.scanner, limits[k]);
  }
};

// The job of evaluating `viewpoints` on `scene`: voxel indices and |F| always, the viewpoints in
// index space only when |F| > 0.
EvaluationJob Prepare(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                      const EvaluateOptions& options, const JobContext& ctx) {
  const OccupancyGrid& g = scene.grid;
  const size_t n = scene.occupied.size();
  EvaluationJob job{g, scene.resolution_m, n, viewpoints.size(), viewpoints, options, ctx, {}, 0, {}, {}, {}};
  job.index.resize(n);
  for (size_t i = 0; i < n; ++i) job.index[i] = KeyToIndex(scene.occupied[i]);
  for (size_t i = 0; i < n; ++i)
    for (int f = 0; f < kFacesPerVoxel; ++f) job.faces_total += FaceInSet(g, job.index[i], Face(f), options.faces);
  if (job.faces_total == 0) return job;
  job.uo.resize(viewpoints.size());
  job.shortcuts.resize(viewpoints.size());
  job.limits.resize(viewpoints.size());
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    job.uo[k] = g.WorldToIndexSpace(viewpoints[k]);
    job.shortcuts[k] = internal::ShortcutsHold(g, job.uo[k]);
    job.limits[k] = ScannerLimits(options.scanner, job.r, job.uo[k],
                                  options.headings_deg.empty() ? Heading() : options.headings_deg[k]);
  }
  return job;
}

// Bounding boxes (index space) of consecutive blocks of kCullBlock points (voxels in their sorted
// order: a short run of rows; corners in the rays' brick order: part of a brick, or a few), for
// skipping what no face centre in the scanner's range and horizontal field of view needs
// (ScannerLimits::BoxVerdict): outside them V is 0 whatever is seen.
constexpr uint64_t kCullBlock = 256;
struct BlockBoxes {
  std::vector<Vector3d> lo, hi;
  // Block b's box, when each point p of it stands for the box [p - below, p + above].
  template <typename PointOf>
  BlockBoxes(size_t count, const PointOf& point_of, double below, double above) {
    const size_t blocks = (count + kCullBlock - 1) / kCullBlock;
    lo.assign(blocks, Vector3d::Constant(std::numeric_limits<double>::infinity()));
    hi.assign(blocks, Vector3d::Constant(-std::numeric_limits<double>::infinity()));
    for (size_t i = 0; i < count; ++i) {
      const VoxelIndex v = point_of(i);
      const Vector3d p(v.x, v.y, v.z);
      lo[i / kCullBlock] = lo[i / kCullBlock].cwiseMin(p - Vector3d::Constant(below));
      hi[i / kCullBlock] = hi[i / kCullBlock].cwiseMax(p + Vector3d::Constant(above));
    }
  }
  bool OutOfRange(const ScannerLimits& limits, uint64_t block) const {
    return limits.BoxVerdict(lo[block], hi[block]) == ScannerLimits::Verdict::kNone;
  }
};

// The distinct lattice corners of the voxels (packed, ascending) and each voxel's 8 corner ids.
struct LatticeCorners {
  std::vector<uint64_t> corners;
  std::vector<std::array<uint32_t, 8>> voxel_corners;
};

// The voxels are sorted by (z, y, x), so for each corner number q the corners of voxels in id
// order form a sorted stream (a fixed offset keeps the order). Merging the 8 streams lists the
// distinct corners in order and gives each voxel its 8 corner ids, without a sort or a search.
// `index` must come from sorted, unique voxels.
LatticeCorners ListCorners(const std::vector<VoxelIndex>& index) {
  constexpr uint64_t kDone = ~uint64_t{0};
  const size_t n = index.size();
  LatticeCorners out;
  out.corners.reserve(n * 3);
  out.voxel_corners.resize(n);
  size_t pos[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  uint64_t head[8];
  for (int q = 0; q < 8; ++q) head[q] = n ? PackCorner(Corner(index[0], q)) : kDone;
  while (true) {
    const uint64_t next = *std::min_element(head, head + 8);
    if (next == kDone) break;
    const uint32_t id = uint32_t(out.corners.size());
    out.corners.push_back(next);
    for (int q = 0; q < 8; ++q) {
      while (head[q] == next) {
        out.voxel_corners[pos[q]][q] = id;
        head[q] = ++pos[q] < n ? PackCorner(Corner(index[pos[q]], q)) : kDone;
      }
    }
  }
  return out;
}

// Bit f of entry i: face f of voxel i is in `faces` (the same for every viewpoint).
std::vector<uint8_t> FacesInSetMask(const OccupancyGrid& g, const std::vector<VoxelIndex>& index, FaceSet faces) {
  const size_t n = index.size();
  std::vector<uint8_t> faces_in_set(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (int f = 0; f < kFacesPerVoxel; ++f) {
      if (FaceInSet(g, index[i], Face(f), faces)) faces_in_set[i] |= uint8_t(1u << f);
    }
  }
  return faces_in_set;
}

// Unbiased uniform sample of F with replacement, as (voxel id, face) pairs: pick a voxel id and a
// face uniformly, and re-draw faces outside F (rejection keeps the distribution uniform over F).
std::vector<std::pair<uint32_t, uint8_t>> DrawSample(const EvaluationJob& job) {
  std::mt19937_64 rng(job.options.seed);
  std::uniform_int_distribution<uint64_t> pick(0, job.n * kFacesPerVoxel - 1);
  std::vector<std::pair<uint32_t, uint8_t>> sample(job.options.sample_faces);
  for (auto& s : sample) {
    while (true) {
      const uint64_t p = pick(rng);
      const uint32_t id = uint32_t(p / kFacesPerVoxel);
      const uint8_t f = uint8_t(p % kFacesPerVoxel);
      if (FaceInSet(job.g, job.index[id], Face(f), job.options.faces)) {
        s = {id, f};
        break;
      }
    }
  }
  return sample;
}

// Sampled mode into `ev` (resolution, |F| and per_viewpoint's size already set).
Result<Evaluation> EvaluateSampled(const EvaluationJob& job, Evaluation ev) {
  const size_t nv = job.nv;
  ev.sampled = true;
  ev.faces_evaluated = job.options.sample_faces;
  const std::vector<std::pair<uint32_t, uint8_t>> sample = DrawSample(job);
  constexpr uint64_t kChunk = 256;
  const uint64_t chunks = (sample.size() + kChunk - 1) / kChunk;
  std::vector<Tally> overall(chunks);
  std::vector<double> sum_sq(chunks, 0.0);
  std::vector<std::vector<Tally>> per(chunks, std::vector<Tally>(nv));
  StageProgress progress(job.ctx, Stage::kEvaluation, chunks, sample.size(), "faces");
  VC_RETURN_IF_ERROR(
      ParallelChunks(sample.size(), kChunk, job.options.threads, job.ctx, [&](uint64_t c, uint64_t b, uint64_t e) {
        for (uint64_t i = b; i < e; ++i) {
          const VoxelIndex& v = job.index[sample[i].first];
          const Face f = Face(sample[i].second);
          double best = 0;
          Perception best_p = Perception::kNone;
          for (size_t k = 0; k < nv; ++k) {
            int visible = 0;
            OccluderCache cache(job.shortcuts[k]);
            for (int q : kFaceCorners[int(f)]) visible += CornerVisibleCached(job.g, job.uo[k], Corner(v, q), cache);
            const Perception p = FromCount(visible);
            const double val = job.FaceValueFrom(k, p, v, f);
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

// Exact mode's chunks: corners per ray-casting task, voxels per face-valuing task (whole blocks
// of kCullBlock), and bricks of face groups per group task.
constexpr uint64_t kCornerChunk = 64 * 256;
constexpr uint64_t kVoxelChunk = 4096;
constexpr uint64_t kBricksPerTask = 256;
// See CastRaysToUndecidedCorners: on fr_campus the corner rays' occluders are mostly met far from
// their corners (ground and walls between tripod and target), on the hall near them.
constexpr int kGrowOccluderBeyond = 8;

// The corner rays' cache: the last few occluders (OccluderCache), then the far ones indexed by their
// direction from the viewpoint (DirectionalOccluders), which outlive the small cache (and serve
// these rays better than the cache's dropped boxes, which it therefore does not keep).
struct CornerRayCache {
  OccluderCache recent;
  internal::DirectionalOccluders far;
  CornerRayCache(bool enabled, const Vector3d& viewpoint) : recent(enabled, /*keep_dropped=*/false), far(viewpoint) {}
  bool enabled() const { return recent.enabled(); }
  // `far` holds nothing when the cache is disabled (AddFar), so it proves nothing then either.
  bool Blocks(const Vector3d& a, const Vector3d& b, const VoxelIndex& keep_lo, const VoxelIndex& keep_hi) {
    return recent.Blocks(a, b, keep_lo, keep_hi) || far.Blocks(b, keep_lo, keep_hi);
  }
  void AddFar(const internal::SolidBox& box) {
    recent.Add(box);
    if (recent.enabled()) far.Add(box);
  }
};
static_assert(kCornerChunk % kCullBlock == 0 && kVoxelChunk % kCullBlock == 0);

// Exact mode over one job whose voxels are sorted and unique. Per viewpoint: the visible lattice
// corners (first those that groups of faces decide, then one ray per remaining corner), then each
// face's V from its corners, keeping each face's best V over the viewpoints; the overall figures
// come from the best values. Run once; viewpoints may be evaluated on several threads at once,
// each into its own Work.
class ExactEvaluation {
 public:
  // `ev` has resolution, |F| and per_viewpoint's size set; `lattice` is ListCorners(job.index).
  // Every large allocation of this mode happens here or in the calling thread of Run: running out
  // of memory must not happen in a worker thread.
  ExactEvaluation(const EvaluationJob& job, LatticeCorners lattice, Evaluation ev);

  // Evaluates every viewpoint, then the overall figures (and the kept values the options ask for).
  Result<Evaluation> Run();

 private:
  // What evaluating viewpoints needs besides the scene: the corner bitsets of the viewpoint at
  // hand, and the best V (and its perception) of each face over the viewpoints evaluated so far.
  struct Work {
    Work(size_t corner_words, size_t slots, size_t voxel_chunks, size_t viewer_slots)
        : visible_bits(corner_words),
          decided_bits(corner_words),
          tallies(voxel_chunks),
          best(internal::FilledOnHugePages(slots, 0.0)),
          best_p(internal::FilledOnHugePages(slots, uint8_t{0})),
          viewer(viewer_slots, kNoViewer) {}
    std::vector<uint64_t> visible_bits, decided_bits;
    std::vector<Tally> tallies;  // per chunk of voxels, for the viewpoint at hand
    std::vector<double> best;
    std::vector<uint8_t> best_p;
    // With keep_face_values: per voxel, the viewpoint that alone gives it V > 0 so far (or
    // kNoViewer / kSeveralViewers).
    std::vector<int32_t> viewer;
  };

  // Voxels with a sole-viewer slot in a Work: all with keep_face_values, else none.
  size_t ViewerSlots() const { return job_.options.keep_face_values ? job_.n : 0; }
  std::unique_ptr<Work> NewWork() const;

  // Every viewpoint into works_ (at least one); the best values are spread over them until
  // MergeWorks.
  Status EvaluateViewpoints();
  // The first nv - nv % workers viewpoints one per thread, each into a Work of its own, then the
  // rest one after another on all threads.
  Status EvaluateViewpointsPerThread(int workers);

  // Viewpoint k into `w`, on `threads` workers (1: all in the calling thread, with no atomics).
  // Its figures do not depend on `threads`: partial sums are merged in chunk order.
  Status EvaluateViewpoint(size_t k, int threads, Work& w);
  // Into w's bitsets, the corners that groups of faces decide for viewpoint k (and whether each
  // is seen). With several workers, tasks share words of the bitsets, so bits are set atomically.
  Status DecideCornersByGroups(size_t k, int threads, Work& w) const;
  // One ray from viewpoint k to each corner in the scanner's range that is not decided yet.
  Status CastRaysToUndecidedCorners(size_t k, int threads, Work& w) const;
  // Each face's V from viewpoint k, from its visible corners: into w's tallies and best values,
  // the sole viewers, and the per-viewpoint values the options keep.
  Status ValueFaces(size_t k, int threads, Work& w);

  // Folds the best values and sole viewers of every Work into the first.
  void MergeWorks();
  // Each viewpoint's sparse values: its chunks in order, so faces ascending.
  void JoinSparseValues();
  // The overall figures from the best V of each face over all viewpoints, and the kept values.
  Evaluation Finish();

  const EvaluationJob& job_;
  const LatticeCorners lattice_;
  Evaluation ev_;
  const std::vector<uint8_t> faces_in_set_;
  // The corner rays' order (internal::CornersByBrick); corner_boxes_'s blocks are runs of it.
  const std::vector<uint32_t> corner_order_;
  // The scanner's range, block by block. A face centre lies in its voxel's cube [v, v + 1] and
  // within 1 (per axis) of each of its corners: a block of voxels whose cubes, or of corners whose
  // boxes [c - 1, c + 1], are all out of range holds nothing that changes a face's V (> 0), so it
  // is skipped; skipped corners count as unseen, which only faces out of range could notice.
  const BlockBoxes corner_boxes_;
  const BlockBoxes voxel_boxes_;
  const uint64_t voxel_chunks_;
  // With keep_sparse_per_viewpoint_values: per viewpoint and chunk of voxels, the faces with V > 0,
  // joined in chunk order at the end, in the calling thread (the workers only fill chunk-sized pieces).
  std::vector<std::vector<SparseFaceValues>> sparse_chunks_;
  StageProgress progress_;
  // Corners that groups of faces decide at once (surface_groups.h), per viewpoint.
  const internal::SurfaceTargets targets_;
  const uint64_t brick_chunks_;
  const size_t corner_words_;
  std::vector<std::unique_ptr<Work>> works_;
};

ExactEvaluation::ExactEvaluation(const EvaluationJob& job, LatticeCorners lattice, Evaluation ev)
    : job_(job),
      lattice_(std::move(lattice)),
      ev_(std::move(ev)),
      faces_in_set_(FacesInSetMask(job.g, job.index, job.options.faces)),
      corner_order_(internal::CornersByBrick(lattice_.corners.size(),
                                             [&](size_t c) { return UnpackCorner(lattice_.corners[c]); })),
      corner_boxes_(
          corner_order_.size(), [&](size_t i) { return UnpackCorner(lattice_.corners[corner_order_[i]]); }, 1.0, 1.0),
      voxel_boxes_(
          job.n, [&](size_t i) { return job.index[i]; }, 0.0, 1.0),
      voxel_chunks_((job.n + kVoxelChunk - 1) / kVoxelChunk),
      progress_(job.ctx, Stage::kEvaluation, job.nv, job.nv, "stations"),
      targets_(job.g, job.index, NotEnclosed(job.g, job.index)),
      brick_chunks_((targets_.brick_count() + kBricksPerTask - 1) / kBricksPerTask),
      corner_words_((lattice_.corners.size() + 63) / 64) {
  // Each viewpoint's values are filled by the thread that evaluates it (huge_pages.h: first touch
  // is the costly part).
  if (job.options.keep_per_viewpoint_values) {
    ev_.per_viewpoint_face_values.resize(job.nv);
    for (std::vector<float>& values : ev_.per_viewpoint_face_values) {
      internal::ReserveOnHugePages(values, job.n * kFacesPerVoxel);
    }
  }
  if (job.options.keep_sparse_per_viewpoint_values) {
    sparse_chunks_.assign(job.nv, std::vector<SparseFaceValues>(voxel_chunks_));
  }
}

Result<Evaluation> ExactEvaluation::Run() {
  VC_RETURN_IF_ERROR(EvaluateViewpoints());
  MergeWorks();
  if (job_.options.keep_sparse_per_viewpoint_values) JoinSparseValues();
  return Finish();
}

std::unique_ptr<ExactEvaluation::Work> ExactEvaluation::NewWork() const {
  return std::make_unique<Work>(corner_words_, job_.n * kFacesPerVoxel, voxel_chunks_, ViewerSlots());
}

// With enough viewpoints per thread, a task is one viewpoint, evaluated by one thread into
// that thread's Work (no joins within a viewpoint, no atomics); the threads' best values are
// merged at the end. Otherwise the viewpoints are evaluated one after another, each on all
// threads. Both give the same figures: the best (V, perception) pair of a face is the same
// whatever the order of the viewpoints.
// Each extra thread's Work costs 9 bytes per face (and 4 per voxel for the sole viewers); beyond
// kEvaluateExtraWorkBytes in all, the viewpoints are evaluated one after another instead.
Status ExactEvaluation::EvaluateViewpoints() {
  const size_t n = job_.n, nv = job_.nv;
  const int workers = ResolveThreads(job_.options.threads, nv);
  const uint64_t extra_bytes = uint64_t(workers - 1) * (n * kFacesPerVoxel * (sizeof(double) + sizeof(uint8_t)) +
                                                        ViewerSlots() * sizeof(int32_t));
  if (workers > 1 && nv >= kEvaluateViewpointsPerThread * uint64_t(workers) && extra_bytes <= kEvaluateExtraWorkBytes) {
    return EvaluateViewpointsPerThread(workers);
  }
  works_.push_back(NewWork());
  for (size_t k = 0; k < nv; ++k) VC_RETURN_IF_ERROR(EvaluateViewpoint(k, job_.options.threads, *works_[0]));
  return Status::Ok();
}

Status ExactEvaluation::EvaluateViewpointsPerThread(int workers) {
  const size_t nv = job_.nv;
  // Allocated here, in the calling thread, so that running out of memory is not a worker's.
  std::vector<Work*> idle;
  for (int t = 0; t < workers; ++t) {
    works_.push_back(NewWork());
    idle.push_back(works_.back().get());
  }
  std::mutex mu;
  Status failed = Status::Ok();
  // The last nv % workers viewpoints are evaluated one after another on all threads, so that
  // no thread ends with a whole viewpoint of its own while the others wait.
  const uint64_t alone = nv - nv % uint64_t(workers);
  VC_RETURN_IF_ERROR(ParallelChunks(
      alone, 1, workers, job_.ctx,
      [&](uint64_t k, uint64_t, uint64_t) {
        Work* w = nullptr;
        {
          std::lock_guard<std::mutex> lock(mu);  // at most `workers` tasks run at once
          w = idle.back();
          idle.pop_back();
        }
        const Status st = EvaluateViewpoint(k, 1, *w);
        std::lock_guard<std::mutex> lock(mu);
        if (!st.ok() && failed.ok()) failed = st;
        idle.push_back(w);
      },
      "evaluation"));
  VC_RETURN_IF_ERROR(failed);
  for (size_t k = alone; k < nv; ++k) VC_RETURN_IF_ERROR(EvaluateViewpoint(k, workers, *works_[0]));
  return Status::Ok();
}

Status ExactEvaluation::EvaluateViewpoint(size_t k, int threads, Work& w) {
  std::fill(w.visible_bits.begin(), w.visible_bits.end(), 0);
  std::fill(w.decided_bits.begin(), w.decided_bits.end(), 0);
  const bool grouped = !job_.options.per_corner && job_.shortcuts[k] && !InsideOccupied(job_.g, job_.uo[k]);
  if (grouped) VC_RETURN_IF_ERROR(DecideCornersByGroups(k, threads, w));
  VC_RETURN_IF_ERROR(CastRaysToUndecidedCorners(k, threads, w));
  VC_RETURN_IF_ERROR(ValueFaces(k, threads, w));
  Tally total;
  for (const Tally& t : w.tallies) total.Merge(t);
  ev_.per_viewpoint[k] = total.Figures(job_.faces_total);
  progress_.Add(1);
  return Status::Ok();
}

Status ExactEvaluation::DecideCornersByGroups(size_t k, int threads, Work& w) const {
  const bool shared = ResolveThreads(threads, brick_chunks_) > 1;  // the group pass runs on several threads
  // A corner is often decided many times (it is shared by up to 24 faces), so BitWriter's
  // plain load before the atomic one pays.
  const internal::BitWriter decided_out{w.decided_bits.data(), shared}, visible_out{w.visible_bits.data(), shared};
  const internal::FreeBox around = internal::GrowFreeBox(job_.g, job_.uo[k]);  // once, for every chunk
  // On one thread the chunks run in turn and share one walk: its occluder cache goes on from one
  // run of bricks to the next (they are neighbours on the Z-order curve) instead of starting empty.
  std::optional<internal::GroupWalk> one_walk;
  if (!shared) one_walk.emplace();
  return ParallelChunks(brick_chunks_, 1, threads, job_.ctx, [&](uint64_t task, uint64_t, uint64_t) {
    std::optional<internal::GroupWalk> own;
    internal::GroupWalk& walk = one_walk ? *one_walk : own.emplace();
    walk.around = around;
    std::vector<internal::SurfaceTargets::CornerDecision> decisions;
    const size_t b0 = task * kBricksPerTask, b1 = std::min<size_t>(b0 + kBricksPerTask, targets_.brick_count());
    targets_.AppendCornerDecisions(job_.uo[k], job_.limits[k], b0, b1, walk, decisions);
    for (const auto& d : decisions) {
      auto apply = [&](int q) {
        const uint32_t c = lattice_.voxel_corners[d.id][q];
        decided_out.Set(c);
        if (d.seen) visible_out.Set(c);
      };
      if (d.face == 0xff) {
        apply(d.corner);
      } else {
        for (int q : kFaceCorners[d.face]) apply(q);
      }
    }
  });
}

Status ExactEvaluation::CastRaysToUndecidedCorners(size_t k, int threads, Work& w) const {
  const std::vector<uint64_t>& corners = lattice_.corners;
  // Tasks take runs of the brick order, whose corners share words of the bitset with other tasks'.
  const bool shared = ResolveThreads(threads, (corners.size() + kCornerChunk - 1) / kCornerChunk) > 1;
  const internal::BitWriter visible_out{w.visible_bits.data(), shared};
  // On one thread the chunks share one cache, which goes on from one run of corners to the next.
  std::optional<CornerRayCache> one_cache;
  if (!shared) one_cache.emplace(job_.shortcuts[k], job_.uo[k]);
  return ParallelChunks(corners.size(), kCornerChunk, threads, job_.ctx, [&](uint64_t, uint64_t b, uint64_t e) {
    std::optional<CornerRayCache> own;
    CornerRayCache& cache = one_cache ? *one_cache : own.emplace(job_.shortcuts[k], job_.uo[k]);
    // An occluder met more than kGrowOccluderBeyond voxels before its corner is cached as the solid
    // box grown from it (SurfaceTargets::GrownBox, remembered across viewpoints), which proves more
    // of the next corners' rays blocked than the voxel alone, and indexed by its direction; one met
    // nearer, as the voxel (growing those did not pay on the hall). docs/BENCHMARKS.md, "Grown
    // occluders for the corner rays" and "A directional index of far occluders".
    auto remember = [&](const VoxelIndex& hit, const VoxelIndex& c) {
      const int before = std::max({std::abs(hit.x - c.x), std::abs(hit.y - c.y), std::abs(hit.z - c.z)});
      if (before <= kGrowOccluderBeyond) {
        cache.recent.Add(hit);  // the voxel, unless a cached box holds it
      } else if (!cache.recent.Find(hit)) {
        cache.AddFar(targets_.GrownBox(hit));
      }
    };
    for (uint64_t block_begin = b; block_begin < e; block_begin += kCullBlock) {
      if (corner_boxes_.OutOfRange(job_.limits[k], block_begin / kCullBlock)) continue;
      for (uint64_t i = block_begin; i < std::min(block_begin + kCullBlock, e); ++i) {
        const uint32_t c = corner_order_[i];
        if ((w.decided_bits[c >> 6] >> (c & 63)) & 1) continue;
        if (CornerVisibleCached(job_.g, job_.uo[k], UnpackCorner(corners[c]), cache, remember)) visible_out.Set(c);
      }
    }
  });
}

Status ExactEvaluation::ValueFaces(size_t k, int threads, Work& w) {
  std::vector<Tally>& tallies = w.tallies;
  std::fill(tallies.begin(), tallies.end(), Tally{});
  std::vector<float>* keep = job_.options.keep_per_viewpoint_values ? &ev_.per_viewpoint_face_values[k] : nullptr;
  if (keep) keep->resize(job_.n * kFacesPerVoxel);  // zeros, in the capacity reserved above
  const bool keep_sparse = job_.options.keep_sparse_per_viewpoint_values;
  return ParallelChunks(job_.n, kVoxelChunk, threads, job_.ctx, [&](uint64_t chunk, uint64_t b, uint64_t e) {
    Tally& t = tallies[chunk];
    SparseFaceValues* sparse = keep_sparse ? &sparse_chunks_[k][chunk] : nullptr;
    for (uint64_t i = b; i < e; ++i) {
      if (i % kCullBlock == 0 && voxel_boxes_.OutOfRange(job_.limits[k], i / kCullBlock)) {
        i += kCullBlock - 1;  // the whole block (chunks hold whole blocks)
        continue;
      }
      unsigned corner_bits = 0;  // bit q: corner q of voxel i is visible
      for (int q = 0; q < 8; ++q) {
        const uint32_t c = lattice_.voxel_corners[i][q];
        corner_bits |= unsigned((w.visible_bits[c >> 6] >> (c & 63)) & 1) << q;
      }
      // No visible corner: every face is unperceived, V = 0, which adds nothing to the tally or
      // the best values, and the kept values are zeros already.
      if (corner_bits == 0) continue;
      bool seen = false;
      for (int f = 0; f < kFacesPerVoxel; ++f) {
        if (!((faces_in_set_[i] >> f) & 1)) continue;
        const Perception p = FromCount(std::popcount(corner_bits & kFaceCornerMask[f]));
        const double val = job_.FaceValueFrom(k, p, job_.index[i], Face(f));
        t.Add(p, val);
        const size_t slot = i * kFacesPerVoxel + f;
        if (keep) (*keep)[slot] = float(val);
        if (sparse && val > 0) {
          sparse->faces.push_back(uint32_t(slot));
          sparse->values.push_back(float(val));
          if (job_.options.keep_sparse_join_state) {
            sparse->exact_values.push_back(val);
            sparse->perceptions.push_back(uint8_t(p));
          }
        }
        KeepBest(val, uint8_t(p), w.best[slot], w.best_p[slot]);
        seen |= val > 0;
      }
      if (seen && !w.viewer.empty()) w.viewer[i] = CombineViewers(w.viewer[i], int32_t(k));
    }
  });
}

void ExactEvaluation::MergeWorks() {
  Work& first = *works_[0];
  for (size_t t = 1; t < works_.size(); ++t) {
    for (size_t slot = 0; slot < first.best.size(); ++slot)
      KeepBest(works_[t]->best[slot], works_[t]->best_p[slot], first.best[slot], first.best_p[slot]);
    for (size_t i = 0; i < first.viewer.size(); ++i)
      first.viewer[i] = CombineViewers(first.viewer[i], works_[t]->viewer[i]);
  }
}

void ExactEvaluation::JoinSparseValues() {
  ev_.per_viewpoint_sparse_values.resize(job_.nv);
  for (size_t k = 0; k < job_.nv; ++k) {
    SparseFaceValues& out = ev_.per_viewpoint_sparse_values[k];
    size_t count = 0;
    for (const SparseFaceValues& c : sparse_chunks_[k]) count += c.size();
    const bool join_state = job_.options.keep_sparse_join_state;
    out.faces.reserve(count);
    out.values.reserve(count);
    out.exact_values.reserve(join_state ? count : 0);
    out.perceptions.reserve(join_state ? count : 0);
    for (SparseFaceValues& c : sparse_chunks_[k]) {
      out.faces.insert(out.faces.end(), c.faces.begin(), c.faces.end());
      out.values.insert(out.values.end(), c.values.begin(), c.values.end());
      out.exact_values.insert(out.exact_values.end(), c.exact_values.begin(), c.exact_values.end());
      out.perceptions.insert(out.perceptions.end(), c.perceptions.begin(), c.perceptions.end());
      c = SparseFaceValues{};
    }
  }
}

Evaluation ExactEvaluation::Finish() {
  const size_t n = job_.n;
  const std::vector<double>& best = works_[0]->best;
  const std::vector<uint8_t>& best_p = works_[0]->best_p;
  Tally total;
  for (size_t i = 0; i < n; ++i)
    for (int f = 0; f < kFacesPerVoxel; ++f) {
      if (!((faces_in_set_[i] >> f) & 1)) continue;
      const size_t slot = i * kFacesPerVoxel + f;
      total.Add(Perception(best_p[slot]), best[slot]);
    }
  ev_.overall = total.Figures(job_.faces_total);
  if (job_.options.keep_face_values) {
    ev_.best_face_values.resize(n);
    for (size_t i = 0; i < n; ++i)
      for (int f = 0; f < kFacesPerVoxel; ++f) ev_.best_face_values[i][f] = float(best[i * kFacesPerVoxel + f]);
    ev_.sole_viewer = std::move(works_[0]->viewer);
  }
  if (job_.options.keep_join_state) {
    ev_.best_values = std::move(works_[0]->best);
    ev_.best_perceptions = std::move(works_[0]->best_p);
  }
  return std::move(ev_);
}

// Exact mode into `ev` (resolution, |F| and per_viewpoint's size already set); the scene's
// voxels are sorted and unique.
Result<Evaluation> EvaluateExact(const EvaluationJob& job, Evaluation ev) {
  ev.faces_evaluated = job.faces_total;
  LatticeCorners lattice = ListCorners(job.index);
  VC_RETURN_IF_ERROR(job.ctx.CheckCancelled("evaluation"));
  ExactEvaluation exact(job, std::move(lattice), std::move(ev));
  return exact.Run();
}

}  // namespace

Result<Evaluation> Evaluate(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                            const EvaluateOptions& options, const JobContext& ctx) {
  VC_RETURN_IF_ERROR(options.scanner.Validate());
  VC_RETURN_IF_ERROR(ValidateViewpoints(viewpoints, scene.resolution_m));
  VC_RETURN_IF_ERROR(CheckViewpointHeadings(options.scanner, viewpoints.size(), options.headings_deg));
  const EvaluationJob job = Prepare(scene, viewpoints, options, ctx);
  Evaluation ev;
  ev.resolution_m = scene.resolution_m;
  ev.faces_total = job.faces_total;
  ev.per_viewpoint.resize(viewpoints.size());
  if (options.keep_sparse_per_viewpoint_values) ev.per_viewpoint_sparse_values.resize(viewpoints.size());
  if (job.faces_total == 0) return ev;
  if (options.sample_faces > 0) return EvaluateSampled(job, std::move(ev));
  // Exact mode lists lattice corners by merging sorted streams, so it needs VoxelScene's order.
  if (std::adjacent_find(scene.occupied.begin(), scene.occupied.end(),
                         [](const VoxelKey& a, const VoxelKey& b) { return !(a < b); }) != scene.occupied.end()) {
    return InvalidArgumentError("the scene's voxels must be sorted and unique (VoxelScene::occupied)");
  }
  if (options.keep_sparse_per_viewpoint_values && scene.occupied.size() * kFacesPerVoxel > UINT32_MAX) {
    return InvalidArgumentError("the scene has " + std::to_string(scene.occupied.size()) +
                                " occupied voxels; sparse face values index at most 715,827,882: use a coarser "
                                "resolution");
  }
  return EvaluateExact(job, std::move(ev));
}

namespace {

// OK when `first` and `second` can be joined (JoinEvaluations), else what differs.
Status CheckJoinable(const Evaluation& first, const Evaluation& second) {
  auto refuse = [](const std::string& what) {
    return InvalidArgumentError("cannot join the two evaluations: " + what);
  };
  if (first.sampled || second.sampled) return refuse("a sampled evaluation has no per-face values to join");
  if (first.resolution_m != second.resolution_m || first.faces_total != second.faces_total) {
    return refuse("they are of different scenes or face sets (|F| " + std::to_string(first.faces_total) + " and " +
                  std::to_string(second.faces_total) + ")");
  }
  for (const Evaluation* e : {&first, &second}) {
    if (e->best_perceptions.size() != e->best_values.size() || (e->faces_total > 0 && e->best_values.empty())) {
      return refuse("evaluate both with EvaluateOptions::keep_join_state");
    }
  }
  if (first.best_values.size() != second.best_values.size()) {
    return refuse("they are of scenes of " + std::to_string(first.best_values.size() / kFacesPerVoxel) + " and " +
                  std::to_string(second.best_values.size() / kFacesPerVoxel) + " voxels");
  }
  if (first.sole_viewer.size() != second.sole_viewer.size() ||
      first.best_face_values.size() != second.best_face_values.size()) {
    return refuse("evaluate both with keep_face_values, or neither");
  }
  if (first.per_viewpoint_face_values.empty() != second.per_viewpoint_face_values.empty() ||
      first.per_viewpoint_sparse_values.empty() != second.per_viewpoint_sparse_values.empty()) {
    return refuse("they keep different per-viewpoint values");
  }
  return Status::Ok();
}

template <typename T>
void Append(std::vector<T>& to, std::vector<T>& from) {
  to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
}

}  // namespace

Result<Evaluation> JoinEvaluations(Evaluation first, Evaluation second) {
  VC_RETURN_IF_ERROR(CheckJoinable(first, second));
  const int32_t shift = static_cast<int32_t>(first.per_viewpoint.size());
  // The best (V, perception) of a face does not depend on the order the viewpoints come in
  // (KeepBest), and faces outside F hold (0, kNone), which add nothing to a tally: summed in face
  // order, the figures are those of Finish over all the viewpoints.
  Tally total;
  for (size_t slot = 0; slot < first.best_values.size(); ++slot) {
    KeepBest(second.best_values[slot], second.best_perceptions[slot], first.best_values[slot],
             first.best_perceptions[slot]);
    total.Add(Perception(first.best_perceptions[slot]), first.best_values[slot]);
  }
  first.overall = total.Figures(first.faces_total);
  for (size_t i = 0; i < first.best_face_values.size(); ++i) {
    for (int f = 0; f < kFacesPerVoxel; ++f) {
      first.best_face_values[i][f] = float(first.best_values[i * kFacesPerVoxel + f]);
    }
  }
  for (size_t i = 0; i < first.sole_viewer.size(); ++i) {
    const int32_t b = second.sole_viewer[i];
    first.sole_viewer[i] = CombineViewers(first.sole_viewer[i], b >= 0 ? b + shift : b);
  }
  Append(first.per_viewpoint, second.per_viewpoint);
  Append(first.per_viewpoint_face_values, second.per_viewpoint_face_values);
  Append(first.per_viewpoint_sparse_values, second.per_viewpoint_sparse_values);
  return first;
}

Result<Evaluation> EvaluationOfSparseValues(const VoxelScene& scene, FaceSet faces,
                                            std::vector<VisibilityFigures> per_viewpoint,
                                            const std::vector<SparseFaceValues>& values) {
  if (per_viewpoint.size() != values.size()) {
    return InvalidArgumentError("evaluation of sparse values: " + std::to_string(per_viewpoint.size()) +
                                " viewpoints' figures for " + std::to_string(values.size()) + " viewpoints' values");
  }
  const size_t n = scene.occupied.size();
  const uint64_t slots = uint64_t(n) * kFacesPerVoxel;
  Evaluation ev;
  ev.resolution_m = scene.resolution_m;
  std::vector<uint8_t> in_set(slots, 0);  // the faces of F, by slot
  for (size_t i = 0; i < n; ++i) {
    const VoxelIndex v = KeyToIndex(scene.occupied[i]);
    for (int f = 0; f < kFacesPerVoxel; ++f) {
      in_set[i * kFacesPerVoxel + f] = FaceInSet(scene.grid, v, Face(f), faces);
      ev.faces_total += in_set[i * kFacesPerVoxel + f];
    }
  }
  ev.faces_evaluated = ev.faces_total;
  ev.per_viewpoint = std::move(per_viewpoint);
  if (ev.faces_total == 0) return ev;  // as Evaluate: nothing more
  std::vector<double> best(slots, 0.0);
  std::vector<uint8_t> best_p(slots, uint8_t(Perception::kNone));
  ev.sole_viewer.assign(n, kNoViewer);
  for (size_t k = 0; k < values.size(); ++k) {
    const SparseFaceValues& s = values[k];
    if (!s.HasJoinState()) {
      return InvalidArgumentError("evaluation of sparse values: viewpoint " + std::to_string(k + 1) +
                                  "'s values carry no double-precision V and perception (keep_sparse_join_state)");
    }
    for (size_t j = 0; j < s.size(); ++j) {
      const uint32_t slot = s.faces[j];
      if (slot >= slots || (j > 0 && s.faces[j - 1] >= slot)) {
        return InvalidArgumentError("evaluation of sparse values: viewpoint " + std::to_string(k + 1) + "'s face " +
                                    std::to_string(slot) + " is not ascending below " + std::to_string(slots));
      }
      if (!in_set[slot]) {  // Evaluate values only the faces of F: such a value is not Evaluate's
        return InvalidArgumentError("evaluation of sparse values: viewpoint " + std::to_string(k + 1) + "'s face " +
                                    std::to_string(slot) + " is not in the evaluated face set");
      }
      KeepBest(s.exact_values[j], s.perceptions[j], best[slot], best_p[slot]);
      const size_t voxel = slot / kFacesPerVoxel;
      ev.sole_viewer[voxel] = CombineViewers(ev.sole_viewer[voxel], int32_t(k));
    }
  }
  // Faces outside F (refused above) and faces no viewpoint sees hold (0, kNone), which add nothing to a tally: summed
  // in face order, the figures are those of Evaluate's Finish.
  Tally total;
  for (uint64_t slot = 0; slot < slots; ++slot) total.Add(Perception(best_p[slot]), best[slot]);
  ev.overall = total.Figures(ev.faces_total);
  ev.best_face_values.resize(n);
  for (size_t i = 0; i < n; ++i)
    for (int f = 0; f < kFacesPerVoxel; ++f) ev.best_face_values[i][f] = float(best[i * kFacesPerVoxel + f]);
  ev.best_values = std::move(best);
  ev.best_perceptions = std::move(best_p);
  return ev;
}

}  // namespace vc
