// Validation: a selection test's prediction measured against what scanners captured (issue 34,
// docs/VISIBILITY.md "Measured against captured points").
//
// Given scans whose scanner positions are known, every voxel holding a point of scan i was,
// physically, seen from scan i's position. ValidateAgainstScans builds the model (a VoxelScene)
// from the union of all scans' points, predicts with ComputeVisibilitySets which of the model's
// voxels each scan's position sees under the chosen selection test and scanner limits, voxelizes
// each scan's own points on the same grid (its captured set) and compares the two: recall = both /
// captured, precision = both / predicted, each also with one voxel of slack (a captured voxel
// counts as predicted when a predicted voxel lies in its 26-neighbourhood or is itself, and vice
// versa). With a single scan the model is the scan itself, so every model voxel is captured and
// precision says nothing about over-prediction: the report flags it.
//
// A scan that covers less than 360 deg of azimuth is predicted with the scanner's hfov_deg centred
// on the scan's heading (from its pose); with hfov_deg 360 (the default) it is predicted to see all
// round, and its precision is then low by the share of the model outside its field of view.
//
// Thread-safety: a pure function; the visibility sets run on `threads` worker threads.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"
#include "vc/visibility/voxel_set.h"

namespace vc {

// One scan: its points and where the scanner stood, both in one world frame (m).
struct CapturedScan {
  // Names the scan in the report and in errors (a file name, "scan 2").
  std::string name;
  // The scanner's position (world, m).
  WorldPoint position_m{0, 0, 0};
  // The captured points (world, m); non-finite points are ignored.
  std::vector<Eigen::Vector3f> points_m;
  // The azimuth the scanner's horizontal field of view is centred on (degrees, counter-clockwise
  // from +x, world frame; the yaw of the scan's pose); needed when scanner.hfov_deg < 360.
  Heading heading_deg{};
};

struct ValidationOptions {
  // Edge of the model's voxels (m), > 0.
  double resolution_m = kDefaultResolutionM;
  // The test whose prediction is measured (the planner's default: surface visibility); subvoxel
  // builds the model's surface patches from all scans' points.
  SelectionTest selection_test = SelectionTest::kSurfaceVisibility;
  // The scanner's limits applied to the prediction (default: range [0.5, 75] m, no other limit).
  ScannerModel scanner;
  // Worker threads for the visibility sets; 0 = hardware concurrency.
  int threads = 0;
  // Bound on the model (bytes), as VoxelizeOptions::memory_budget_bytes.
  uint64_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
  // Faces (paper s.2.2.1, ALGORITHM.md s.4: corner rays, a voxel's own cube transparent) that also
  // make a voxel count as predicted, on top of the selection test's set: none (the default), a
  // face fully visible (4 corners) or a face at least partially visible (1-4 corners), each within
  // the scanner's range and field of view (V > 0 and V >= 0.5 in Evaluate's terms). For
  // measuring what counting partial faces would do (docs/VISIBILITY.md "Partial faces").
  enum class FaceRule { kNone, kFull, kPartial };
  FaceRule count_faces = FaceRule::kNone;
  // Which faces count_faces looks at (all six, as G's F, or the exposed ones).
  FaceSet count_faces_of = FaceSet::kAll;
  // Keep the model and each scan's captured and predicted sets in the report (for pictures of
  // where they disagree, and for measurements the counts cannot give).
  bool keep_sets = false;
};

// One scan's agreement. Counts are voxels of the model.
struct ScanAgreement {
  std::string name;
  // Voxels holding a point of this scan; voxels the test predicts this scan's position sees; both.
  uint64_t captured = 0;
  uint64_t predicted = 0;
  uint64_t both = 0;
  // Captured voxels with a predicted voxel within one voxel (26-neighbourhood or itself), and
  // predicted voxels with a captured voxel within one voxel.
  uint64_t captured_near_predicted = 0;
  uint64_t predicted_near_captured = 0;
  // both / captured and both / predicted (0 when the denominator is 0).
  double recall = 0;
  double precision = 0;
  // With one voxel of slack: captured_near_predicted / captured, predicted_near_captured / predicted.
  double recall_slack = 0;
  double precision_slack = 0;
  // The scanner position lies in an occupied voxel of the model, so the test predicts nothing.
  bool position_occupied = false;
  // With keep_sets: the captured and predicted sets (ids of report.model's voxels).
  VoxelSet captured_set;
  VoxelSet predicted_set;
};

struct ValidationReport {
  double resolution_m = 0;
  SelectionTest selection_test = SelectionTest::kSurfaceVisibility;
  // Voxels of the model (the union of all scans).
  uint64_t model_voxels = 0;
  // False with a single scan: its model is the scan itself, so only recall is meaningful.
  bool precision_meaningful = true;
  // Why precision_meaningful is false, for people; empty otherwise.
  std::string note;
  // One per scan, in the input's order.
  std::vector<ScanAgreement> scans;
  // With keep_sets: the model.
  VoxelScene model;
};

// Measures the prediction of `options.selection_test` against `scans` (see the file comment).
// INVALID_ARGUMENT naming the scan for a scan with no finite point, a non-finite position or
// heading, no heading with scanner.hfov_deg < 360, or a position farther than scanner.max_range_m from the model's
// bounding box; INVALID_ARGUMENT for no scans, a bad resolution or scanner (ScannerModel::Validate); otherwise as
// Voxelize (RESOURCE_EXHAUSTED over the memory budget) and ComputeVisibilitySets (CANCELLED / DEADLINE_EXCEEDED from
// ctx).
Result<ValidationReport> ValidateAgainstScans(const std::vector<CapturedScan>& scans, const ValidationOptions& options,
                                              const JobContext& ctx = {});

}  // namespace vc
