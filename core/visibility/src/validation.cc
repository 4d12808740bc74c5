#include "vc/visibility/validation.h"

#include <cmath>
#include <string>
#include <utility>

#include "vc/scene/occupancy_grid.h"

namespace vc {
namespace {

std::string ScanLabel(const CapturedScan& scan, size_t index) {
  return "scan " + std::to_string(index + 1) + " (\"" + scan.name + "\")";
}

bool IsFinite(const Eigen::Vector3f& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }

Status CheckInputs(const std::vector<CapturedScan>& scans, const ValidationOptions& options) {
  if (scans.empty()) return InvalidArgumentError("validation needs at least one scan");
  if (!std::isfinite(options.resolution_m) || options.resolution_m <= 0) {
    return InvalidArgumentError("validation resolution_m must be > 0, got " + std::to_string(options.resolution_m));
  }
  VC_RETURN_IF_ERROR(options.scanner.Validate());
  for (size_t i = 0; i < scans.size(); ++i) {
    const CapturedScan& scan = scans[i];
    if (!scan.position_m.allFinite()) {
      return InvalidArgumentError(ScanLabel(scan, i) + " has a scanner position that is not finite");
    }
    if (scan.heading_deg && !std::isfinite(*scan.heading_deg)) {
      return InvalidArgumentError(ScanLabel(scan, i) + " has a heading that is not finite");
    }
    if (!scan.heading_deg && options.scanner.HasHorizontalFieldOfView()) {
      return InvalidArgumentError(ScanLabel(scan, i) + " has no heading, but scanner.hfov_deg is " +
                                  std::to_string(options.scanner.hfov_deg) +
                                  " deg: give the scan's yaw (a pose with a rotation, or a yaw column in the "
                                  "positions file), or leave hfov_deg at 360");
    }
    bool any_finite = false;
    for (const auto& p : scan.points_m) {
      if (IsFinite(p)) {
        any_finite = true;
        break;
      }
    }
    if (!any_finite) return InvalidArgumentError(ScanLabel(scan, i) + " has no points (none finite)");
  }
  return Status::Ok();
}

Result<VoxelScene> BuildModel(const std::vector<CapturedScan>& scans, const ValidationOptions& options,
                              const JobContext& ctx) {
  VoxelAccumulator accumulator(options.resolution_m, options.memory_budget_bytes);
  for (size_t i = 0; i < scans.size(); ++i) {
    for (const auto& p : scans[i].points_m) accumulator.Add(p);
    const Status& status = accumulator.status();
    if (!status.ok()) return Status(status.code(), ScanLabel(scans[i], i) + ": " + status.message());
  }
  return accumulator.Finish(ctx);
}

// Distance (m) from p to the box [lo, hi]; 0 inside.
double DistanceToBox(const WorldPoint& p, const WorldPoint& lo, const WorldPoint& hi) {
  const WorldPoint outside = (lo - p).cwiseMax(p - hi).cwiseMax(WorldPoint::Zero());
  return outside.norm();
}

Status CheckPositions(const std::vector<CapturedScan>& scans, const VoxelScene& model, const ScannerModel& scanner) {
  const WorldPoint lo = model.BoundsMin(), hi = model.BoundsMax();
  for (size_t i = 0; i < scans.size(); ++i) {
    const double distance_m = DistanceToBox(scans[i].position_m, lo, hi);
    if (distance_m > scanner.max_range_m || !ViewpointInRange(scans[i].position_m, model.resolution_m)) {
      return InvalidArgumentError(ScanLabel(scans[i], i) + "'s scanner position is " + std::to_string(distance_m) +
                                  " m outside the scans' bounding box, beyond the scanner's max_range_m (" +
                                  std::to_string(scanner.max_range_m) + " m); is it in the points' frame?");
    }
  }
  return Status::Ok();
}

// The model's voxels holding a finite point of `scan`.
VoxelSet CapturedSet(const CapturedScan& scan, const VoxelScene& model) {
  VoxelSet captured(model.occupied.size());
  VoxelKey key;
  for (const auto& p : scan.points_m) {
    if (!IsFinite(p) || !CoordToKey(model.resolution_m, p.cast<double>(), &key)) continue;
    const int64_t id = model.IdOf(key);
    if (id >= 0) captured.set(size_t(id));
  }
  return captured;
}

// The model's voxels in the 26-neighbourhood of a member of `set`, or members themselves.
VoxelSet Dilate(const VoxelSet& set, const VoxelScene& model) {
  VoxelSet dilated(model.occupied.size());
  set.ForEach([&](size_t id) {
    const VoxelIndex v = KeyToIndex(model.occupied[id]);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int64_t n = model.IdOf(IndexToKey({v.x + dx, v.y + dy, v.z + dz}));
          if (n >= 0) dilated.set(size_t(n));
        }
      }
    }
  });
  return dilated;
}

double Ratio(uint64_t part, uint64_t whole) { return whole == 0 ? 0.0 : double(part) / double(whole); }

ScanAgreement Compare(const CapturedScan& scan, const VoxelScene& model, VoxelSet predicted, bool keep_sets) {
  ScanAgreement a;
  a.name = scan.name;
  VoxelSet captured = CapturedSet(scan, model);
  a.captured = captured.count();
  a.predicted = predicted.count();
  a.both = captured.CountAnd(predicted);
  a.captured_near_predicted = captured.CountAnd(Dilate(predicted, model));
  a.predicted_near_captured = predicted.CountAnd(Dilate(captured, model));
  a.recall = Ratio(a.both, a.captured);
  a.precision = Ratio(a.both, a.predicted);
  a.recall_slack = Ratio(a.captured_near_predicted, a.captured);
  a.precision_slack = Ratio(a.predicted_near_captured, a.predicted);
  VoxelKey key;
  a.position_occupied = CoordToKey(model.resolution_m, scan.position_m, &key) && model.IdOf(key) >= 0;
  if (keep_sets) {
    a.captured_set = std::move(captured);
    a.predicted_set = std::move(predicted);
  }
  return a;
}

// Adds to predicted[k] every voxel with a face (of options.count_faces_of) that Evaluate, from
// positions[k] under the scanner's limits, finds fully visible (kFull: V >= 0.5) or at least
// partially visible (kPartial: V > 0).
Status AddVoxelsOfSeenFaces(const VoxelScene& model, const std::vector<WorldPoint>& positions,
                            const std::vector<Heading>& headings_deg, const ValidationOptions& options,
                            std::vector<VoxelSet>& predicted, const JobContext& ctx) {
  EvaluateOptions eo;
  eo.scanner = options.scanner;
  eo.headings_deg = headings_deg;
  eo.faces = options.count_faces_of;
  eo.threads = options.threads;
  eo.keep_sparse_per_viewpoint_values = true;
  VC_ASSIGN_OR_RETURN(Evaluation ev, Evaluate(model, positions, eo, ctx));
  const bool full_only = options.count_faces == ValidationOptions::FaceRule::kFull;
  for (size_t k = 0; k < positions.size(); ++k) {
    const SparseFaceValues& seen = ev.per_viewpoint_sparse_values[k];
    for (size_t i = 0; i < seen.size(); ++i) {
      // V is 0.3 for a partially visible face and at least 0.5 for a fully visible one.
      if (full_only ? seen.values[i] >= 0.5f : seen.values[i] > 0.0f) predicted[k].set(seen.faces[i] / kFacesPerVoxel);
    }
  }
  return Status::Ok();
}

}  // namespace

Result<ValidationReport> ValidateAgainstScans(const std::vector<CapturedScan>& scans, const ValidationOptions& options,
                                              const JobContext& ctx) {
  VC_RETURN_IF_ERROR(CheckInputs(scans, options));
  VC_ASSIGN_OR_RETURN(VoxelScene model, BuildModel(scans, options, ctx));
  VC_RETURN_IF_ERROR(CheckPositions(scans, model, options.scanner));

  std::vector<WorldPoint> positions;
  positions.reserve(scans.size());
  std::vector<Heading> headings;
  for (const CapturedScan& scan : scans) {
    positions.push_back(scan.position_m);
    headings.push_back(scan.heading_deg);
  }
  VisibilitySetsOptions sets_options;
  sets_options.headings_deg = std::move(headings);
  sets_options.test = options.selection_test;
  sets_options.threads = options.threads;
  sets_options.scanner = options.scanner;
  std::vector<SurfacePatch> patches;
  if (options.selection_test == SelectionTest::kSubvoxel) {
    SurfacePatchBuilder builder(model);
    for (const CapturedScan& scan : scans) {
      for (const auto& p : scan.points_m) builder.Add(p);
    }
    patches = builder.Finish();
    sets_options.surface_patches = patches;
  }
  VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> predicted, ComputeVisibilitySets(model, positions, sets_options, ctx));
  if (options.count_faces != ValidationOptions::FaceRule::kNone) {
    VC_RETURN_IF_ERROR(AddVoxelsOfSeenFaces(model, positions, sets_options.headings_deg, options, predicted, ctx));
  }

  ValidationReport report;
  report.resolution_m = model.resolution_m;
  report.selection_test = options.selection_test;
  report.model_voxels = model.occupied.size();
  if (scans.size() == 1) {
    report.precision_meaningful = false;
    report.note =
        "a single scan: the model is the scan itself, so every model voxel is captured and only recall is "
        "meaningful";
  }
  report.scans.reserve(scans.size());
  for (size_t i = 0; i < scans.size(); ++i) {
    report.scans.push_back(Compare(scans[i], model, std::move(predicted[i]), options.keep_sets));
  }
  if (options.keep_sets) report.model = std::move(model);
  return report;
}

}  // namespace vc
