// An Evaluate job: given viewpoints (e.g. stations already scanned) evaluated on a scene at a
// chosen resolution. Its parameters are declared once in VC_EVALUATE_PARAMETERS (as PlanOptions'
// are, vc/base/parameter.h); RunEvaluation is the one core function the Evaluate RPC calls, as
// Plan is for the Plan RPC.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/parameter.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

// X(type, name, default, unit, flag, check, help).
#define VC_EVALUATE_PARAMETERS(X)                                                                                    \
  X(double, resolution_m, 0.0, "m", "resolution", kNonNegative,                                                      \
    "working resolution (0 = the octree's own, or 0.1 m for clouds)")                                                \
  X(uint64_t, memory_budget_bytes, ::vc::kDefaultMemoryBudgetBytes, "bytes", "memory-budget-bytes", kPositive,       \
    "memory budget of the job (capped by the server's --max-memory-budget-bytes)")                                   \
  X(::vc::FaceSet, faces, ::vc::FaceSet::kAll, "", "faces", kAny, "faces counted in F: all or exposed")              \
  X(uint64_t, sample_faces, 0, "faces", "sample", kAny,                                                              \
    "evaluate a uniform random sample of this many faces, with a 95 % interval (0 = every face)")                    \
  X(uint64_t, seed, 1, "", "seed", kAny, "sampling seed")                                                            \
  X(int32_t, threads, 0, "threads", "threads", kNonNegative, "threads for the job (0 = all, or the server's share)") \
  X(::vc::SelectionTest, test, ::vc::SelectionTest::kSurfaceVisibility, "", "test", kAny,                            \
    "selection test of the seen sets (--export-sets): surface, compatibility, or subvoxel (point clouds only)")

namespace vc {

struct EvaluateJobOptions {
  VC_EVALUATE_PARAMETERS(VC_DECLARE_PARAMETER)
  // The scanner (VC_SCANNER_PARAMETERS), nested as "scanner" in the proto.
  ScannerModel scanner;
  // The viewpoints to evaluate, in the input's own frame (m); at least one.
  std::vector<WorldPoint> viewpoints;
  // Also each viewpoint's seen set under `test` (EvaluateJobResult::seen_sets).
  bool export_sets = false;

  // INVALID_ARGUMENT naming the first bad parameter: no viewpoint, a non-finite viewpoint, a row's
  // check or the scanner's, a scanner hfov_deg below 360 (viewpoints here carry no heading).
  // Fields are named as `namer` shows them (vc/base/parameter.h).
  Status Validate(const FieldNamer& namer = {}) const;
  // The voxelisation and evaluation options this job runs with (exact mode keeps each voxel's best
  // face values and sole viewer, for visibility.ply, heatmap.png and report.html; sampling keeps none).
  VoxelizeOptions voxelize_options() const;
  EvaluateOptions evaluate_options() const;
};

// What an Evaluate job gives: the evaluation and the voxels it was made on.
struct EvaluateJobResult {
  // The test of seen_sets: options.test, or kSurfaceVisibility for kSubvoxel on an input without
  // points (an octree, a vc-voxels stream), with a warning saying so.
  SelectionTest selection_test = SelectionTest::kSurfaceVisibility;
  // With options.export_sets: per viewpoint, in order, the occupied voxels (ids into voxel_centers)
  // that selection_test counts as seen from it (ComputeVisibilitySets with the job's scanner).
  std::vector<VoxelSet> seen_sets;
  std::vector<std::string> warnings;
  // With, in exact mode, best_face_values and sole_viewer for every occupied voxel.
  Evaluation evaluation;
  // The viewpoints as the job was given them, in the input's own frame (m).
  std::vector<WorldPoint> viewpoints;
  // Occupied voxel centres in id order, in the scene's local frame (m).
  std::vector<WorldPoint> voxel_centers;
  // Where the local frame's origin lies in the input's frame (VoxelScene::frame_origin_m, m).
  WorldPoint frame_origin_m = WorldPoint::Zero();
};

// Validates, voxelises `input` at options.resolution_m, moves the viewpoints to the scene's local
// frame (less VoxelScene::frame_origin_m), then vc::Evaluate, and with options.export_sets
// vc::ComputeVisibilitySets (the sub-voxel test on the input's surface patches). Errors as those, and
// RESOURCE_EXHAUSTED, before the evaluation, when the seen sets would take more than half the
// memory budget.
Result<EvaluateJobResult> RunEvaluation(const SceneInput& input, const EvaluateJobOptions& options,
                                        const JobContext& ctx = {});

}  // namespace vc
