// The visibility engine (ALGORITHM.md sections 3-6; paper section 2).
//
// - Compatibility (s.3): voxel v is compatible with viewpoint o iff the first occupied voxel on
//   the ray from o to v's centre is v itself. The paper's selection test.
// - Surface visibility (s.3b, our default selection test): v is visible from o iff some exposed
//   face of v that faces o can be reached from o, the segment to that face's centre meeting no
//   occupied voxel.
// - Face perception (s.4): each face's 4 corner rays, the face's own voxel transparent; a corner is
//   visible iff the first occupied voxel on its ray is one of the 8 voxels sharing the corner (or
//   none). 4 visible corners: full; 1-3: partial; 0: none.
// - Sub-voxel visibility (docs/VISIBILITY.md "Sub-voxel surfaces"; vc/visibility/subvoxel.h): aimed
//   at the surface the points give each voxel, blocked only where a beam meets a voxel's surface.
// - Visibility value V (s.5) and global visibility G (s.6).
//
// All functions are deterministic (the traversal's tie rule) and thread-safe on a const scene.
// Bulk computations run on `threads` worker threads, poll the cancel token in `ctx` at least
// every few milliseconds per thread and report progress per stage.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/parameter.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/voxel_set.h"

namespace vc {

enum class SelectionTest {
  kSurfaceVisibility,  // ALGORITHM.md 3b (default)
  kCompatibility,      // ALGORITHM.md 3, the paper's test
  kSubvoxel,           // vc/visibility/subvoxel.h (needs surface patches; surface visibility without)
};
std::string_view SelectionTestName(SelectionTest t);  // "surface", "compatibility", "subvoxel"

// The scanner model's parameters (vc/base/parameter.h): X(type, name, default, unit, flag, check, help).
// Each is a hard limit on what a station sees (docs/PLANNING.md "The scanner model"): selection
// counts a voxel only through a face that passes every limit, and V (ALGORITHM.md s.5) is 0 for a
// face that fails one. The defaults: the range [0.5, 75] m and no other limit (each at its "off"
// end: vfov -90..90, incidence 90, spacing 0, hfov 360). The horizontal field of view is centred on
// each viewpoint's own heading (VisibilitySetsOptions::headings_deg), so an hfov below 360 needs a
// heading for every viewpoint.
#define VC_SCANNER_PARAMETERS(X)                                                                            \
  X(double, min_range_m, 0.5, "m", "min-range", kNonNegative, "scanner minimum range")                      \
  X(double, max_range_m, 75.0, "m", "max-range", kPositive, "scanner maximum range")                        \
  X(double, vfov_min_deg, -90.0, "deg", "vfov-min", kElevationDeg,                                          \
    "lowest elevation the scanner sees (-90 = straight down, no limit)")                                    \
  X(double, vfov_max_deg, 90.0, "deg", "vfov-max", kElevationDeg,                                           \
    "highest elevation the scanner sees (90 = straight up, no limit)")                                      \
  X(double, max_incidence_deg, 90.0, "deg", "max-incidence", kIncidenceDeg,                                 \
    "largest angle between a face's normal and the direction to the scanner (90 = no limit)")               \
  X(double, angular_step_deg, 0.0, "deg", "angular-step", kNonNegative,                                     \
    "the scanner's angular step between points (needed by --max-spacing)")                                  \
  X(double, max_spacing_m, 0.0, "m", "max-spacing", kNonNegative,                                           \
    "largest point spacing a face may get to count: distance x step / cos(incidence) (0 = no requirement)") \
  X(double, hfov_deg, 360.0, "deg", "hfov", kAzimuthSpanDeg,                                                \
    "horizontal field of view, centred on each station's heading (360 = all round, no heading needed)")

// The scanner (ALGORITHM.md s.5, and the limits above).
struct ScannerModel {
  VC_SCANNER_PARAMETERS(VC_DECLARE_PARAMETER)
  // The instrument preset the values came from (vc/visibility/scanner_presets.h), explicit values
  // overriding some of them; empty for a custom model. Not a row: rows are scalars. (The `{}` keeps
  // -Wmissing-field-initializers quiet for positional initialisers such as ScannerModel{2.0, 1.0}.)
  std::string name{};
  // INVALID_ARGUMENT naming the field ("scanner.max_range_m ..."): a row's check,
  // min_range_m >= max_range_m, vfov_min_deg >= vfov_max_deg, or max_spacing_m without
  // angular_step_deg. Fields are named as `namer` shows them (vc/base/parameter.h).
  Status Validate(const FieldNamer& namer = {}) const;
  // Whether a limit other than the range is on.
  bool HasVerticalFieldOfView() const { return vfov_min_deg > -90.0 || vfov_max_deg < 90.0; }
  bool HasIncidenceLimit() const { return max_incidence_deg < 90.0; }
  bool HasSpacingLimit() const { return max_spacing_m > 0.0; }
  bool HasHorizontalFieldOfView() const { return hfov_deg < 360.0; }
};

// A viewpoint's heading: the azimuth of the centre of the scanner's horizontal field of view, in
// degrees counter-clockwise from +x in the scene's frame; none = no azimuth limit.
using Heading = std::optional<double>;

// INVALID_ARGUMENT naming the viewpoint (1-based, as "viewpoint 3") when `headings_deg` is neither
// empty (no viewpoint has a heading) nor one per viewpoint, a heading is not finite, or `scanner`
// has hfov_deg < 360 and a viewpoint has no heading.
[[nodiscard]] Status CheckViewpointHeadings(const ScannerModel& scanner, size_t viewpoints,
                                            const std::vector<Heading>& headings_deg);

// Faces of a voxel, by outward normal.
enum class Face : uint8_t { kNegX = 0, kPosX, kNegY, kPosY, kNegZ, kPosZ };
inline constexpr int kFacesPerVoxel = 6;

enum class Perception : uint8_t { kNone = 0, kPartial, kFull };

// --- Single queries (grid index space for voxels, world frame for viewpoints) ---

// s.3. False if o is inside an occupied voxel. With a scanner: also false unless v's centre passes
// its limits (incidence and spacing judged on the face the ray enters v through). A single query
// has no heading, so its scanner's hfov_deg is not applied.
bool IsCompatible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v);
bool IsCompatible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, const ScannerModel& scanner);
// s.3b. False if o is inside an occupied voxel. With a scanner: only faces that pass its limits
// count. Without one: no limit, not even the range (the paper's definition).
bool IsSurfaceVisible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v);
bool IsSurfaceVisible(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, const ScannerModel& scanner);

// s.4: full, partial or no perception of face `f` of voxel v from o.
Perception PerceiveFace(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, Face f);

// s.5: V from a perception class, the distance d (m) to the face centre and the angle theta
// (radians, 0..pi) between the ray to the face centre and the face normal.
double VisibilityValue(Perception p, double distance_m, double theta_rad, const ScannerModel& scanner);

// s.5 for one face: perception, then V with d and theta measured to the face centre; 0 when the
// face centre fails one of the scanner's limits.
double FaceVisibility(const OccupancyGrid& grid, const WorldPoint& o, const VoxelIndex& v, Face f,
                      const ScannerModel& scanner);

// Viewpoints farther than this many voxels from the origin along an axis are refused (Evaluate,
// Plan) or see nothing (ComputeVisibilitySets): ray arithmetic uses int voxel indices, and a
// scene's own voxels lie within OctoMap's 16-bit key range (+-32768).
inline constexpr double kMaxViewpointIndex = 1 << 20;
bool ViewpointInRange(const WorldPoint& o, double resolution_m);

// --- Bulk: many viewpoints x all occupied voxels ---

struct VisibilitySetsOptions {
  SelectionTest test = SelectionTest::kSurfaceVisibility;
  // Worker threads; 0 = hardware concurrency.
  int threads = 0;
  // Surface test: decide every voxel by its own rays instead of by groups of faces (same answers,
  // slower). Sub-voxel test: trace every voxel on its own instead of walking its segments in SIMD
  // batches first (the same answers but at exact lattice ties, docs/VISIBILITY.md; slower). Kept
  // as the reference for tests and benchmarks.
  bool per_voxel = false;
  // The instrument's limits (vc/visibility/scanner_limits.h): a voxel counts only through a face
  // (compatibility: its centre, judged on the face the ray enters by) that passes all of them.
  // None: no limit at all, not even the range (the paper's tests, as the planner used them
  // before the scanner model; the planner always passes its scanner).
  std::optional<ScannerModel> scanner;
  // Per viewpoint, its heading (CheckViewpointHeadings); empty = none has one. Needed for every
  // viewpoint when the scanner's hfov_deg < 360 (INVALID_ARGUMENT otherwise).
  std::vector<Heading> headings_deg;
  // Sub-voxel test only: one patch per voxel id of the scene (ComputeSurfacePatches); must outlive
  // the call. Empty (an octree's scene has no points): the surface test runs instead.
  std::span<const SurfacePatch> surface_patches;
  // Sparse sets (voxel_set.h): each set is kept as a Roaring bitmap when that is at least this
  // many times smaller than its dense words; 0 = every set dense. With it the viewpoints are
  // computed in batches whose dense sets take at most batch_bytes, each compacted before the next.
  double compact_gain = 0;
  uint64_t batch_bytes = uint64_t{256} << 20;
  // RESOURCE_EXHAUSTED as soon as the sets kept exceed this many bytes (0 = no limit).
  uint64_t max_set_bytes = 0;
};

// For each viewpoint, the occupied voxels that pass the selection test. Viewpoints inside an
// occupied voxel get an empty set. INVALID_ARGUMENT from CheckViewpointHeadings (with a scanner),
// or for surface_patches that are neither empty nor one per occupied voxel;
// CANCELLED / DEADLINE_EXCEEDED from ctx.
Result<std::vector<VoxelSet>> ComputeVisibilitySets(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                                    const VisibilitySetsOptions& options, const JobContext& ctx = {});

// RESOURCE_EXHAUSTED when the visibility sets of `positions` viewpoints over `voxels` occupied
// voxels take `set_bytes`, more than `max_set_bytes` (0 = no limit): ComputeVisibilitySets' check
// of VisibilitySetsOptions::max_set_bytes, for sets computed elsewhere too.
[[nodiscard]] Status CheckSetBytes(uint64_t set_bytes, uint64_t positions, uint64_t voxels, uint64_t max_set_bytes);

// Per-viewpoint and overall figures of s.6.
struct VisibilityFigures {
  double global_visibility = 0;           // G = mean over faces of the (best) V
  double fully_visible_fraction = 0;      // faces with full perception / |F|
  double mean_full_visibility = 0;        // mean V over fully visible faces (0 if none)
  double partially_visible_fraction = 0;  // faces with partial (and no full) perception / |F|
};

// Which faces make up F.
enum class FaceSet {
  kAll,      // all 6 faces of every occupied voxel (the paper's |F| = 6 |occupied|)
  kExposed,  // only faces whose neighbour across is free
};

struct EvaluateOptions {
  ScannerModel scanner;
  // Per viewpoint, its heading, as VisibilitySetsOptions::headings_deg.
  std::vector<Heading> headings_deg;
  FaceSet faces = FaceSet::kAll;
  int threads = 0;
  // 0 = exact (every face). Otherwise an unbiased uniform random sample of this many faces (with
  // replacement), reporting a 95 % confidence interval.
  uint64_t sample_faces = 0;
  uint64_t seed = 1;
  // Keep each face's best V (needed by visibility.ply) and each voxel's sole viewer (needed by
  // report.html). Exact mode only.
  bool keep_face_values = false;
  // Keep every viewpoint's V of every face (needed by reduction). Exact mode only; costs
  // 24 bytes per occupied voxel and viewpoint.
  bool keep_per_viewpoint_values = false;
  // Keep every viewpoint's faces with V > 0 (SparseFaceValues: 8 bytes per face it sees, not 24
  // per voxel of the scene; what the reduction holds). Exact mode only; the scene must have fewer
  // than 2^32 / 6 voxels (INVALID_ARGUMENT otherwise).
  bool keep_sparse_per_viewpoint_values = false;
  // Keep each face's best V as the overall figures sum it (double) and its perception
  // (Evaluation::best_values, best_perceptions: 9 bytes per face), so that JoinEvaluations can
  // join this evaluation with one of other viewpoints. Exact mode only.
  bool keep_join_state = false;
  // With keep_sparse_per_viewpoint_values: keep with each viewpoint's faces their V as the figures
  // sum it (double) and their perception too (SparseFaceValues::exact_values, perceptions: 9 bytes
  // more a face seen), so that EvaluationOfSparseValues can build the evaluation of the viewpoints
  // from them (the reduction's values from replicas, joined into the final evaluation).
  bool keep_sparse_join_state = false;
  // Exact mode: decide every lattice corner on its own (its ray, after the per-ray shortcuts: the
  // occluder cache and the grazing-layer test) instead of first by groups of faces (same answers,
  // slower; kept as the reference for tests and benchmarks).
  bool per_corner = false;
};

// One viewpoint's faces with V > 0: their indices in F order (voxel id * 6 + face), ascending,
// and V of each; with EvaluateOptions::keep_sparse_join_state also V as a double (values holds it
// as a float) and the Perception of each (empty otherwise).
struct SparseFaceValues {
  std::vector<uint32_t> faces;
  std::vector<float> values;
  std::vector<double> exact_values;
  std::vector<uint8_t> perceptions;
  size_t size() const { return faces.size(); }
  // Both join-state arrays, one entry per face.
  bool HasJoinState() const { return exact_values.size() == faces.size() && perceptions.size() == faces.size(); }
  uint64_t MemoryBytes() const {
    return faces.capacity() * sizeof(uint32_t) + values.capacity() * sizeof(float) +
           exact_values.capacity() * sizeof(double) + perceptions.capacity() * sizeof(uint8_t);
  }
};

// Evaluation::sole_viewer's values for a voxel no viewpoint sees, and one several viewpoints see.
inline constexpr int32_t kNoViewer = -1;
inline constexpr int32_t kSeveralViewers = -2;

struct Evaluation {
  double resolution_m = 0;
  uint64_t faces_total = 0;      // |F|
  uint64_t faces_evaluated = 0;  // |F| in exact mode, the sample size otherwise
  bool sampled = false;
  VisibilityFigures overall;
  // 95 % confidence half-width of overall.global_visibility (sampling mode; 0 when exact).
  double global_visibility_ci95 = 0;
  std::vector<VisibilityFigures> per_viewpoint;
  // With keep_face_values: per voxel id, the best V of each of its 6 faces (F order: voxel id, then Face).
  std::vector<std::array<float, kFacesPerVoxel>> best_face_values;
  // With keep_per_viewpoint_values: per viewpoint, V of every face at index voxel_id * 6 + face.
  // Faces outside F hold 0.
  std::vector<std::vector<float>> per_viewpoint_face_values;
  // With keep_sparse_per_viewpoint_values: per viewpoint, its faces with V > 0.
  std::vector<SparseFaceValues> per_viewpoint_sparse_values;
  // With keep_face_values: per voxel id, the index of the only viewpoint that gives any of its
  // faces V > 0 ("what only this station sees"); kNoViewer if none does, kSeveralViewers if
  // several do.
  std::vector<int32_t> sole_viewer;
  // With keep_join_state: per face (voxel id * 6 + face), the best V over the viewpoints and its
  // Perception (faces outside F hold 0 and kNone).
  std::vector<double> best_values;
  std::vector<uint8_t> best_perceptions;
};

// Evaluates a set of viewpoints on `scene` (s.6): G of the whole set and figures per viewpoint.
// INVALID_ARGUMENT for a non-finite or out-of-range viewpoint, a bad scanner range, headings that
// CheckViewpointHeadings refuses, or (exact
// mode) a scene whose voxels are not sorted and unique as VoxelScene requires.
Result<Evaluation> Evaluate(const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                            const EvaluateOptions& options, const JobContext& ctx = {});

// The evaluation of `first`'s viewpoints followed by `second`'s, exactly as one Evaluate of them
// all with the same options gives it: the overall figures (summed in face order from the joined
// best values), the per-viewpoint figures and kept values in that order, the best face values and
// the sole viewers (second's indices shifted by first's count), and the join state, so that more
// evaluations can be joined on. Both must be exact evaluations of one scene and face set with
// keep_join_state (and keep_face_values in both or neither); INVALID_ARGUMENT otherwise, naming
// what differs. The reduction joins its batches of stations this way into the final evaluation.
Result<Evaluation> JoinEvaluations(Evaluation first, Evaluation second);

// The evaluation of viewpoints on `scene` from what each sees: their per-viewpoint figures and
// their faces with V > 0 with the join state (EvaluateOptions::keep_sparse_join_state), exactly as
// Evaluate of them with keep_face_values and keep_join_state gives it (the overall figures summed
// in face order from the best values, the best face values, the sole viewers), without the
// per-viewpoint values; `faces` is the face set they were evaluated on. INVALID_ARGUMENT when the
// counts differ, a viewpoint's values lack the join state, or a face is not ascending below
// 6 x the scene's voxels. The reduction builds the evaluation of the stations the replicas
// evaluated this way, to join it as its own batches.
Result<Evaluation> EvaluationOfSparseValues(const VoxelScene& scene, FaceSet faces,
                                            std::vector<VisibilityFigures> per_viewpoint,
                                            const std::vector<SparseFaceValues>& values);

}  // namespace vc
