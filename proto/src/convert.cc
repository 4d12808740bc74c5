#include "vc/wire/convert.h"

#include <algorithm>
#include <string>

#include "vc/visibility/scanner_presets.h"

namespace vc::wire {

v1::Point ToProto(const WorldPoint& p) {
  v1::Point out;
  out.set_x_m(p.x());
  out.set_y_m(p.y());
  out.set_z_m(p.z());
  return out;
}

WorldPoint FromProto(const v1::Point& p) { return {p.x_m(), p.y_m(), p.z_m()}; }

v1::InputFormat ToProto(InputFormat f) {
  switch (f) {
    case InputFormat::kPly:
      return v1::INPUT_FORMAT_PLY;
    case InputFormat::kPcd:
      return v1::INPUT_FORMAT_PCD;
    case InputFormat::kXyz:
      return v1::INPUT_FORMAT_XYZ;
    case InputFormat::kLas:
      return v1::INPUT_FORMAT_LAS;
    case InputFormat::kOctomapBinary:
      return v1::INPUT_FORMAT_OCTOMAP_BT;
    case InputFormat::kOctomapText:
      return v1::INPUT_FORMAT_OCTOMAP_OT;
    case InputFormat::kOctomapGraph:
      return v1::INPUT_FORMAT_OCTOMAP_GRAPH;
    case InputFormat::kE57:
      return v1::INPUT_FORMAT_E57;
    case InputFormat::kVoxelStream:
      return v1::INPUT_FORMAT_VC_VOXELS;
  }
  return v1::INPUT_FORMAT_UNSPECIFIED;
}

Result<InputFormat> FromProto(v1::InputFormat f) {
  switch (f) {
    case v1::INPUT_FORMAT_PLY:
      return InputFormat::kPly;
    case v1::INPUT_FORMAT_PCD:
      return InputFormat::kPcd;
    case v1::INPUT_FORMAT_XYZ:
      return InputFormat::kXyz;
    case v1::INPUT_FORMAT_LAS:
      return InputFormat::kLas;
    case v1::INPUT_FORMAT_OCTOMAP_BT:
      return InputFormat::kOctomapBinary;
    case v1::INPUT_FORMAT_OCTOMAP_OT:
      return InputFormat::kOctomapText;
    case v1::INPUT_FORMAT_OCTOMAP_GRAPH:
      return InputFormat::kOctomapGraph;
    case v1::INPUT_FORMAT_E57:
      return InputFormat::kE57;
    case v1::INPUT_FORMAT_VC_VOXELS:
      return InputFormat::kVoxelStream;
    default:
      break;
  }
  return InvalidArgumentError("unknown input format value " + std::to_string(int(f)) +
                              " in the upload spec; leave it unset to detect the format from the content");
}

v1::SelectionTest ToProto(SelectionTest t) {
  switch (t) {
    case SelectionTest::kCompatibility:
      return v1::SELECTION_TEST_COMPATIBILITY;
    case SelectionTest::kSubvoxel:
      return v1::SELECTION_TEST_SUBVOXEL;
    case SelectionTest::kSurfaceVisibility:
      break;
  }
  return v1::SELECTION_TEST_SURFACE_VISIBILITY;
}

v1::FaceSet ToProto(FaceSet f) { return f == FaceSet::kExposed ? v1::FACE_SET_EXPOSED : v1::FACE_SET_ALL; }

v1::SelectionSolver ToProto(SelectionSolver s) {
  switch (s) {
    case SelectionSolver::kExact:
      return v1::SELECTION_SOLVER_EXACT;
    case SelectionSolver::kAuto:
      return v1::SELECTION_SOLVER_AUTO;
    case SelectionSolver::kGreedy:
      break;
  }
  return v1::SELECTION_SOLVER_GREEDY;
}

v1::GroundModel ToProto(GroundModel m) {
  switch (m) {
    case GroundModel::kFloors:
      return v1::GROUND_MODEL_FLOORS;
    case GroundModel::kTerrain:
      return v1::GROUND_MODEL_TERRAIN;
    case GroundModel::kAuto:
      break;
  }
  return v1::GROUND_MODEL_AUTO;
}

Result<GroundModel> FromProto(v1::GroundModel m) {
  switch (m) {
    case v1::GROUND_MODEL_UNSPECIFIED:
    case v1::GROUND_MODEL_AUTO:
      return GroundModel::kAuto;
    case v1::GROUND_MODEL_FLOORS:
      return GroundModel::kFloors;
    case v1::GROUND_MODEL_TERRAIN:
      return GroundModel::kTerrain;
    default:
      break;
  }
  return InvalidArgumentError("unknown ground model value " + std::to_string(int(m)) + "; use AUTO, FLOORS or TERRAIN");
}

v1::VisibilityFigures ToProto(const VisibilityFigures& f) {
  v1::VisibilityFigures out;
  out.set_global_visibility(f.global_visibility);
  out.set_fully_visible_fraction(f.fully_visible_fraction);
  out.set_mean_full_visibility(f.mean_full_visibility);
  out.set_partially_visible_fraction(f.partially_visible_fraction);
  return out;
}

VisibilityFigures FromProto(const v1::VisibilityFigures& f) {
  VisibilityFigures out;
  out.global_visibility = f.global_visibility();
  out.fully_visible_fraction = f.fully_visible_fraction();
  out.mean_full_visibility = f.mean_full_visibility();
  out.partially_visible_fraction = f.partially_visible_fraction();
  return out;
}

namespace {

// A local position in the input's frame, and back. A zero origin leaves the bits as they are
// (-0.0 + 0.0 would be +0.0), so a scene near its origin travels exactly as before.
WorldPoint PlusOrigin(const WorldPoint& p, const WorldPoint& origin) {
  return origin.isZero() ? p : WorldPoint(p + origin);
}
WorldPoint LessOrigin(const WorldPoint& p, const WorldPoint& origin) {
  return origin.isZero() ? p : WorldPoint(p - origin);
}
double PlusOrigin(double z, double origin_z) { return origin_z == 0 ? z : z + origin_z; }
double LessOrigin(double z, double origin_z) { return origin_z == 0 ? z : z - origin_z; }

// A parameter row's value to its proto field's type and back (vc/base/parameter.h). Numbers and
// bools are the same on both sides; enums map through ToProto / FromProto, and an UNSPECIFIED
// enum leaves the default in place.
template <typename T>
T ToWire(T v) {
  return v;
}
v1::SelectionTest ToWire(SelectionTest t) { return ToProto(t); }
v1::FaceSet ToWire(FaceSet f) { return ToProto(f); }
v1::SelectionSolver ToWire(SelectionSolver s) { return ToProto(s); }
v1::GroundModel ToWire(GroundModel m) { return ToProto(m); }

template <typename T>
Status FromWire(T wire, T* out) {
  *out = wire;
  return Status::Ok();
}
Status FromWire(v1::SelectionTest wire, SelectionTest* out) {
  if (wire == v1::SELECTION_TEST_UNSPECIFIED) return Status::Ok();
  VC_ASSIGN_OR_RETURN(*out, FromProto(wire));
  return Status::Ok();
}
Status FromWire(v1::SelectionSolver wire, SelectionSolver* out) {
  switch (wire) {
    case v1::SELECTION_SOLVER_UNSPECIFIED:
      return Status::Ok();
    case v1::SELECTION_SOLVER_GREEDY:
      *out = SelectionSolver::kGreedy;
      return Status::Ok();
    case v1::SELECTION_SOLVER_EXACT:
      *out = SelectionSolver::kExact;
      return Status::Ok();
    case v1::SELECTION_SOLVER_AUTO:
      *out = SelectionSolver::kAuto;
      return Status::Ok();
    default:
      break;
  }
  return InvalidArgumentError("unknown solver value " + std::to_string(int(wire)) + "; use GREEDY, EXACT or AUTO");
}
Status FromWire(v1::GroundModel wire, GroundModel* out) {
  if (wire == v1::GROUND_MODEL_UNSPECIFIED) return Status::Ok();
  VC_ASSIGN_OR_RETURN(*out, FromProto(wire));
  return Status::Ok();
}
Status FromWire(v1::FaceSet wire, FaceSet* out) {
  switch (wire) {
    case v1::FACE_SET_UNSPECIFIED:
      return Status::Ok();
    case v1::FACE_SET_ALL:
      *out = FaceSet::kAll;
      return Status::Ok();
    case v1::FACE_SET_EXPOSED:
      *out = FaceSet::kExposed;
      return Status::Ok();
    default:
      break;
  }
  return InvalidArgumentError("unknown face set value " + std::to_string(int(wire)) + "; use ALL or EXPOSED");
}

// Every row of a table to the message `p` from the options `o`, and back (only the fields set).
#define VC_ROW_TO_PROTO(type, name, ...) p.set_##name(ToWire(o.name));
#define VC_ROW_FROM_PROTO(type, name, ...) \
  if (p.has_##name()) VC_RETURN_IF_ERROR(FromWire(p.name(), &o.name));

v1::ScannerModel ToProto(const ScannerModel& o) {
  v1::ScannerModel p;
  VC_SCANNER_PARAMETERS(VC_ROW_TO_PROTO)
  p.set_name(o.name);
  return p;
}

// A name first sets the whole model from its preset; the fields that are set override it.
Status Apply(const v1::ScannerModel& p, ScannerModel* scanner) {
  ScannerModel& o = *scanner;
  if (!p.name().empty()) {
    VC_ASSIGN_OR_RETURN(o, ScannerFromPreset(p.name()));
  }
  VC_SCANNER_PARAMETERS(VC_ROW_FROM_PROTO)
  return Status::Ok();
}

v1::Reduction ToProto(const Reduction& r, const WorldPoint& frame_origin_m) {
  v1::Reduction out;
  out.mutable_matrix()->Add(r.matrix.begin(), r.matrix.end());
  out.set_size(r.size);
  out.mutable_removed()->Add(r.removed.begin(), r.removed.end());
  out.set_global_visibility_before(r.global_visibility_before);
  out.set_global_visibility_after(r.global_visibility_after);
  for (const auto& p : r.positions) *out.add_positions() = wire::ToProto(PlusOrigin(p, frame_origin_m));
  return out;
}

Reduction FromProto(const v1::Reduction& r, const WorldPoint& frame_origin_m) {
  Reduction out;
  out.matrix.assign(r.matrix().begin(), r.matrix().end());
  out.size = r.size();
  out.removed.assign(r.removed().begin(), r.removed().end());
  out.global_visibility_before = r.global_visibility_before();
  out.global_visibility_after = r.global_visibility_after();
  for (const auto& p : r.positions()) out.positions.push_back(LessOrigin(wire::FromProto(p), frame_origin_m));
  return out;
}

v1::KeepOutZone ToProto(const KeepOutZone& z) {
  v1::KeepOutZone p;
  if (z.shape == KeepOutShape::kBox) {
    *p.mutable_box()->mutable_min() = wire::ToProto(z.min);
    *p.mutable_box()->mutable_max() = wire::ToProto(z.max);
  } else {
    v1::KeepOutPolygon* poly = p.mutable_polygon();
    poly->set_z_min_m(z.min.z());
    poly->set_z_max_m(z.max.z());
    poly->mutable_xy_m()->Add(z.polygon_xy_m.begin(), z.polygon_xy_m.end());
  }
  return p;
}

// INVALID_ARGUMENT for a zone without a shape; the values are checked by PlanOptions::Validate.
Result<KeepOutZone> FromProto(const v1::KeepOutZone& p, size_t index) {
  switch (p.shape_case()) {
    case v1::KeepOutZone::kBox:
      return KeepOutBox(wire::FromProto(p.box().min()), wire::FromProto(p.box().max()));
    case v1::KeepOutZone::kPolygon:
      return KeepOutPolygon(p.polygon().z_min_m(), p.polygon().z_max_m(),
                            std::vector<double>(p.polygon().xy_m().begin(), p.polygon().xy_m().end()));
    default:
      break;
  }
  return InvalidArgumentError("keep_out[" + std::to_string(index) + "] has neither a box nor a polygon");
}

Status ChunkError(const std::string& what) {
  return DataLossError("the server's result stream is inconsistent (" + what +
                       "); retry, and report it if it persists");
}

v1::ModelSize ToProto(const planner::ModelSize& m) {
  v1::ModelSize p;
  p.set_candidates(m.candidates);
  p.set_voxel_classes(m.voxel_classes);
  p.set_rows(m.rows);
  return p;
}
planner::ModelSize FromProto(const v1::ModelSize& p) { return {p.candidates(), p.voxel_classes(), p.rows()}; }

v1::Optimality ToProto(const planner::Optimality& o) {
  v1::Optimality p;
  p.set_solver(o.solver);
  switch (o.status) {
    case planner::OptimalityStatus::kHeuristic:
      p.set_status(v1::Optimality::STATUS_HEURISTIC);
      break;
    case planner::OptimalityStatus::kFeasible:
      p.set_status(v1::Optimality::STATUS_FEASIBLE);
      break;
    case planner::OptimalityStatus::kOptimal:
      p.set_status(v1::Optimality::STATUS_OPTIMAL);
      break;
  }
  p.set_stations(o.stations);
  p.set_lower_bound(o.lower_bound);
  p.set_gap(o.gap);
  p.set_covered_bound(o.covered_bound);
  p.set_seconds(o.seconds);
  *p.mutable_before() = ToProto(o.before);
  *p.mutable_model() = ToProto(o.model);
  p.set_forced(o.forced);
  p.set_dominated(o.dominated);
  p.set_note(o.note);
  const planner::LocalCandidatesReport& l = o.local_candidates;
  if (!l.stations_per_solve.empty()) {
    v1::LocalCandidates* pl = p.mutable_local_candidates();
    pl->set_rounds(l.rounds);
    pl->set_added(l.added);
    for (int s : l.stations_per_solve) pl->add_stations_per_solve(s);
    for (uint64_t c : l.covered_per_solve) pl->add_covered_per_solve(c);
    pl->set_coarse_to_fine(l.coarse_to_fine);
  }
  return p;
}

Result<planner::Optimality> FromProto(const v1::Optimality& p) {
  planner::Optimality o;
  switch (p.status()) {
    case v1::Optimality::STATUS_UNSPECIFIED:  // a server from before the exact selector: greedy
    case v1::Optimality::STATUS_HEURISTIC:
      o.status = planner::OptimalityStatus::kHeuristic;
      break;
    case v1::Optimality::STATUS_FEASIBLE:
      o.status = planner::OptimalityStatus::kFeasible;
      break;
    case v1::Optimality::STATUS_OPTIMAL:
      o.status = planner::OptimalityStatus::kOptimal;
      break;
    default:
      return DataLossError("the server's result carries an unknown optimality status (" +
                           std::to_string(int(p.status())) + "); update vc-client");
  }
  if (!p.solver().empty()) o.solver = p.solver();
  o.stations = p.stations();
  o.lower_bound = p.lower_bound();
  o.gap = p.gap();
  o.covered_bound = p.covered_bound();
  o.seconds = p.seconds();
  o.before = FromProto(p.before());
  o.model = FromProto(p.model());
  o.forced = p.forced();
  o.dominated = p.dominated();
  o.note = p.note();
  const v1::LocalCandidates& pl = p.local_candidates();
  o.local_candidates.rounds = pl.rounds();
  o.local_candidates.added = pl.added();
  o.local_candidates.stations_per_solve.assign(pl.stations_per_solve().begin(), pl.stations_per_solve().end());
  o.local_candidates.covered_per_solve.assign(pl.covered_per_solve().begin(), pl.covered_per_solve().end());
  o.local_candidates.coarse_to_fine = pl.coarse_to_fine();
  return o;
}

}  // namespace

v1::PlanParameters ToProto(const PlanOptions& o) {
  v1::PlanParameters p;
  VC_PLAN_PARAMETERS(VC_ROW_TO_PROTO)
  *p.mutable_scanner() = ToProto(o.scanner);
  for (const auto& c : o.candidates) *p.add_candidates() = ToProto(c);
  p.mutable_tripod_heights_m()->Add(o.tripod_heights_m.begin(), o.tripod_heights_m.end());
  for (const auto& z : o.keep_out) *p.add_keep_out() = ToProto(z);
  for (const auto& f : o.fixed_stations) *p.add_fixed_stations() = ToProto(f);
  if (o.route_start) *p.mutable_route_start() = ToProto(*o.route_start);
  return p;
}

Result<PlanOptions> FromProto(const v1::PlanParameters& p) {
  PlanOptions o;
  VC_PLAN_PARAMETERS(VC_ROW_FROM_PROTO)
  // The voxel gain rule, given alone, takes the place of the default area rule.
  if (o.min_gain_voxels_per_minute > 0 && !p.has_min_gain_m2_per_minute()) o.min_gain_m2_per_minute = 0;
  if (p.has_scanner()) VC_RETURN_IF_ERROR(Apply(p.scanner(), &o.scanner));
  for (const auto& c : p.candidates()) o.candidates.push_back(FromProto(c));
  o.tripod_heights_m.assign(p.tripod_heights_m().begin(), p.tripod_heights_m().end());
  for (int i = 0; i < p.keep_out_size(); ++i) {
    VC_ASSIGN_OR_RETURN(KeepOutZone zone, FromProto(p.keep_out(i), static_cast<size_t>(i)));
    o.keep_out.push_back(std::move(zone));
  }
  for (const auto& f : p.fixed_stations()) o.fixed_stations.push_back(FromProto(f));
  if (p.has_route_start()) o.route_start = FromProto(p.route_start());
  return o;
}

v1::EvaluateParameters ToProto(const EvaluateJobOptions& o) {
  v1::EvaluateParameters p;
  VC_EVALUATE_PARAMETERS(VC_ROW_TO_PROTO)
  *p.mutable_scanner() = ToProto(o.scanner);
  for (const auto& v : o.viewpoints) *p.add_viewpoints() = ToProto(v);
  p.set_export_sets(o.export_sets);
  return p;
}

Result<EvaluateJobOptions> FromProto(const v1::EvaluateParameters& p) {
  EvaluateJobOptions o;
  VC_EVALUATE_PARAMETERS(VC_ROW_FROM_PROTO)
  if (p.has_scanner()) VC_RETURN_IF_ERROR(Apply(p.scanner(), &o.scanner));
  for (const auto& v : p.viewpoints()) o.viewpoints.push_back(FromProto(v));
  o.export_sets = p.export_sets();
  return o;
}

// vc::Stage and v1::Stage share their numbers (kRead = STAGE_READ = 1, ...).
v1::Stage ToProto(Stage s) { return static_cast<v1::Stage>(s); }

Stage FromProto(v1::Stage s) {
  return s > v1::STAGE_UNSPECIFIED && s <= v1::STAGE_ROUTE ? static_cast<Stage>(s) : Stage::kUnspecified;
}

v1::CoveragePoint ToProto(const CoveragePoint& c) {
  v1::CoveragePoint p;
  p.set_stations(c.stations);
  p.set_covered_voxels(c.covered_voxels);
  p.set_coverable_fraction(c.coverable_fraction);
  p.set_scene_fraction(c.scene_fraction);
  p.set_setup_scan_s(c.setup_scan_s);
  if (c.best_voxels_upper_bound) p.set_best_voxels_upper_bound(*c.best_voxels_upper_bound);
  if (c.best_voxels) p.set_best_voxels(*c.best_voxels);
  p.set_best_voxels_optimal(c.best_voxels_optimal);
  return p;
}

CoveragePoint FromProto(const v1::CoveragePoint& p) {
  CoveragePoint c;
  c.stations = p.stations();
  c.covered_voxels = p.covered_voxels();
  c.coverable_fraction = p.coverable_fraction();
  c.scene_fraction = p.scene_fraction();
  c.setup_scan_s = p.setup_scan_s();
  if (p.has_best_voxels_upper_bound()) c.best_voxels_upper_bound = p.best_voxels_upper_bound();
  if (p.has_best_voxels()) c.best_voxels = p.best_voxels();
  c.best_voxels_optimal = p.best_voxels_optimal();
  return c;
}

v1::StopReason ToProto(StopReason r) {
  switch (r) {
    case StopReason::kExhausted:
      return v1::STOP_REASON_EXHAUSTED;
    case StopReason::kTargetReached:
      return v1::STOP_REASON_TARGET_REACHED;
    case StopReason::kMaxStations:
      return v1::STOP_REASON_MAX_STATIONS;
    case StopReason::kMinGain:
      return v1::STOP_REASON_MIN_GAIN;
    case StopReason::kGainRule:
      return v1::STOP_REASON_GAIN_RULE;
  }
  return v1::STOP_REASON_UNSPECIFIED;
}

Result<StopReason> FromProto(v1::StopReason r) {
  switch (r) {
    case v1::STOP_REASON_EXHAUSTED:
      return StopReason::kExhausted;
    case v1::STOP_REASON_TARGET_REACHED:
      return StopReason::kTargetReached;
    case v1::STOP_REASON_MAX_STATIONS:
      return StopReason::kMaxStations;
    case v1::STOP_REASON_MIN_GAIN:
      return StopReason::kMinGain;
    case v1::STOP_REASON_GAIN_RULE:
      return StopReason::kGainRule;
    default:
      break;
  }
  return DataLossError("the server's result carries an unknown stop reason (" + std::to_string(int(r)) +
                       "); update vc-client");
}

Result<SelectionTest> FromProto(v1::SelectionTest t) {
  switch (t) {
    case v1::SELECTION_TEST_SURFACE_VISIBILITY:
      return SelectionTest::kSurfaceVisibility;
    case v1::SELECTION_TEST_COMPATIBILITY:
      return SelectionTest::kCompatibility;
    case v1::SELECTION_TEST_SUBVOXEL:
      return SelectionTest::kSubvoxel;
    default:
      break;
  }
  return InvalidArgumentError("unknown selection test value " + std::to_string(int(t)) +
                              "; use SURFACE_VISIBILITY, COMPATIBILITY or SUBVOXEL");
}

v1::Progress ToProto(const ProgressEvent& e) {
  v1::Progress p;
  p.set_stage(ToProto(e.stage));
  p.set_fraction(e.fraction);
  p.set_message(e.message);
  p.set_done(e.done);
  p.set_total(e.total);
  p.set_unit(e.unit);
  return p;
}

ProgressEvent FromProto(const v1::Progress& p) {
  return {FromProto(p.stage()), p.fraction(), p.message(), p.done(), p.total(), p.unit()};
}

v1::PlannedStation ToProto(const PlannedStation& s, const WorldPoint& frame_origin_m) {
  v1::PlannedStation p;
  *p.mutable_position() = ToProto(PlusOrigin(s.position, frame_origin_m));
  p.set_visible_voxels(s.visible_voxels);
  p.set_marginal_gain(s.marginal_gain);
  p.set_cumulative_coverage(s.cumulative_coverage);
  p.set_global_visibility(s.global_visibility);
  p.set_candidate_index(s.candidate_index);
  p.set_fixed(s.fixed);
  if (std::isfinite(s.floor_z_m)) p.set_floor_z_m(PlusOrigin(s.floor_z_m, frame_origin_m.z()));
  return p;
}

PlannedStation FromProto(const v1::PlannedStation& p) {
  PlannedStation s;
  s.position = FromProto(p.position());
  s.visible_voxels = p.visible_voxels();
  s.marginal_gain = p.marginal_gain();
  s.cumulative_coverage = p.cumulative_coverage();
  s.global_visibility = p.global_visibility();
  s.candidate_index = p.candidate_index();
  s.fixed = p.fixed();
  if (p.has_floor_z_m()) s.floor_z_m = p.floor_z_m();
  return s;
}

v1::Evaluation ToProto(const Evaluation& e) {
  v1::Evaluation p;
  p.set_resolution_m(e.resolution_m);
  p.set_faces_total(e.faces_total);
  p.set_faces_evaluated(e.faces_evaluated);
  p.set_sampled(e.sampled);
  *p.mutable_overall() = ToProto(e.overall);
  p.set_global_visibility_ci95(e.global_visibility_ci95);
  for (const auto& f : e.per_viewpoint) *p.add_per_viewpoint() = ToProto(f);
  p.set_face_value_voxels(e.best_face_values.size());
  return p;
}

Evaluation FromProto(const v1::Evaluation& p) {
  Evaluation e;
  e.resolution_m = p.resolution_m();
  e.faces_total = p.faces_total();
  e.faces_evaluated = p.faces_evaluated();
  e.sampled = p.sampled();
  e.overall = FromProto(p.overall());
  e.global_visibility_ci95 = p.global_visibility_ci95();
  for (const auto& f : p.per_viewpoint()) e.per_viewpoint.push_back(FromProto(f));
  return e;
}

std::vector<v1::HeatMapChunk> HeatMapChunks(const HeatMap& h, const WorldPoint& frame_origin_m) {
  std::vector<v1::HeatMapChunk> chunks;
  const size_t n = h.positions.size();
  for (size_t first = 0; first < n; first += kCandidatesPerHeatMapChunk) {
    v1::HeatMapChunk c;
    c.set_first_index(first);
    c.set_total_candidates(n);
    c.set_grid_spacing_m(h.grid_spacing_m);
    const size_t end = std::min(n, first + kCandidatesPerHeatMapChunk);
    for (size_t i = first; i < end; ++i) {
      *c.add_positions() = ToProto(PlusOrigin(h.positions[i], frame_origin_m));
      c.add_visible_voxels(i < h.visible_voxels.size() ? h.visible_voxels[i] : 0);
      if (h.floor_z_m.size() == n) c.add_floor_z_m(PlusOrigin(h.floor_z_m[i], frame_origin_m.z()));
    }
    chunks.push_back(std::move(c));
  }
  return chunks;
}

bool ForEachVoxelChunk(const std::vector<WorldPoint>& centers, const Evaluation& evaluation,
                       const WorldPoint& frame_origin_m, const std::function<bool(v1::VoxelChunk&&)>& fn) {
  const auto& values = evaluation.best_face_values;
  const auto& viewers = evaluation.sole_viewer;
  const bool with_values = values.size() == centers.size();
  const size_t n = centers.size();
  for (size_t first = 0; first < n; first += kVoxelsPerChunk) {
    const size_t end = std::min(n, first + kVoxelsPerChunk);
    v1::VoxelChunk c;
    c.set_first_voxel_id(first);
    c.set_total_voxels(n);
    c.mutable_centers_xyz_m()->Reserve(int((end - first) * 3));
    for (size_t i = first; i < end; ++i) {
      for (int a = 0; a < 3; ++a) c.add_centers_xyz_m(PlusOrigin(centers[i][a], frame_origin_m[a]));
    }
    if (with_values) {
      c.mutable_best_face_values()->Reserve(int((end - first) * kFacesPerVoxel));
      for (size_t i = first; i < end; ++i) {
        for (float v : values[i]) c.add_best_face_values(v);
      }
    }
    if (with_values && viewers.size() == n) {
      c.mutable_sole_viewer()->Add(viewers.begin() + std::ptrdiff_t(first), viewers.begin() + std::ptrdiff_t(end));
    }
    if (!fn(std::move(c))) return false;
  }
  return true;
}

bool ForEachVoxelChunk(const PlanResult& result, const std::function<bool(v1::VoxelChunk&&)>& fn) {
  return ForEachVoxelChunk(result.voxel_centers, result.evaluation, result.frame_origin_m, fn);
}

bool ForEachVoxelChunk(const EvaluateJobResult& result, const std::function<bool(v1::VoxelChunk&&)>& fn) {
  return ForEachVoxelChunk(result.voxel_centers, result.evaluation, result.frame_origin_m, fn);
}

v1::PlanResult ToProto(const PlanResult& r) {
  v1::PlanResult p;
  const WorldPoint& origin = r.frame_origin_m;
  *p.mutable_options() = ToProto(r.options);
  *p.mutable_frame_origin() = ToProto(origin);
  p.set_resolution_m(r.resolution_m);
  p.set_selection_test(ToProto(r.selection_test));
  for (const auto& s : r.stations) *p.add_stations() = ToProto(s, origin);
  *p.mutable_reduction() = ToProto(r.reduction, origin);
  p.set_candidate_count(r.candidate_count);
  p.set_occupied_voxels(r.occupied_voxels);
  p.set_coverable_voxels(r.coverable_voxels);
  p.set_covered_voxels(r.covered_voxels);
  *p.mutable_evaluation() = ToProto(r.evaluation);
  if (r.evaluation.best_face_values.size() != r.voxel_centers.size()) {
    p.mutable_evaluation()->set_face_value_voxels(0);  // not streamed (see ForEachVoxelChunk)
  }
  for (const auto& t : r.timings) {
    auto* pt = p.add_timings();
    pt->set_stage(ToProto(t.stage));
    pt->set_seconds(t.seconds);
    pt->set_peak_rss_bytes(t.peak_rss_bytes);
  }
  for (const auto& w : r.warnings) p.add_warnings(w);
  p.set_heat_map_candidates(r.heat_map.positions.size());
  p.set_voxel_count(r.voxel_centers.size());
  for (double z : r.floor_levels_m) p.add_floor_levels_m(PlusOrigin(z, origin.z()));
  p.mutable_ground()->set_model(ToProto(r.ground.model));
  p.mutable_ground()->set_floor_share(r.ground.floor_share);
  p.mutable_ground()->set_reason(r.ground.reason);
  p.set_stop_reason(ToProto(r.stop_reason));
  p.set_total_seconds(r.total_seconds);
  p.set_greedy_stations(r.greedy_stations);
  p.set_consolidated(r.consolidated);
  *p.mutable_optimality() = ToProto(r.optimality);
  if (r.distribution.shards > 0) {
    v1::Distribution* d = p.mutable_distribution();
    d->set_replicas(r.distribution.replicas);
    d->set_shards(r.distribution.shards);
    d->set_retried(r.distribution.retried);
    d->set_bytes_exchanged(r.distribution.bytes_exchanged);
  }
  p.set_grid_cells(r.grid_cells);
  p.set_cells_without_floor(r.cells_without_floor);
  p.set_cells_failing_clearance(r.cells_failing_clearance);
  v1::ScanGraph* graph = p.mutable_scan_graph();
  graph->set_min_overlap(r.scan_graph.min_overlap);
  graph->set_connected(r.scan_graph.connected);
  for (const auto& c : r.scan_graph.components) graph->add_components()->mutable_stations()->Add(c.begin(), c.end());
  for (const auto& e : r.scan_graph.edges) {
    v1::ScanGraphEdge* pe = graph->add_edges();
    pe->set_i(e.i);
    pe->set_j(e.j);
    pe->set_overlap(e.overlap);
  }
  p.set_connecting_stations(r.connecting_stations);
  v1::WalkingRoute* route = p.mutable_route();
  route->mutable_order()->Add(r.route.order.begin(), r.route.order.end());
  route->mutable_legs_m()->Add(r.route.legs_m.begin(), r.route.legs_m.end());
  route->set_length_m(r.route.length_m);
  for (const auto& line : r.route.polylines) {
    v1::Polyline* pl = route->add_polylines();
    for (const auto& q : line) *pl->add_points() = ToProto(PlusOrigin(q, origin));
  }
  route->set_parts(r.route.parts);
  if (r.route.start) *route->mutable_start() = ToProto(PlusOrigin(*r.route.start, origin));
  v1::FieldTime* t = p.mutable_field_time();
  t->set_setup_s(r.field_time.setup_s);
  t->set_scan_s(r.field_time.scan_s);
  t->set_walk_s(r.field_time.walk_s);
  t->set_total_s(r.field_time.total_s);
  t->set_scan_seconds_per_station(r.field_time.scan_seconds_per_station);
  for (const CoveragePoint& c : r.coverage_curve) *p.add_coverage_curve() = ToProto(c);
  v1::UnseenCauses* u = p.mutable_unseen_causes();
  u->set_interior(r.unseen_causes.interior);
  u->set_in_keep_out(r.unseen_causes.in_keep_out);
  u->set_no_candidate_on_floor(r.unseen_causes.no_candidate_on_floor);
  u->set_out_of_range(r.unseen_causes.out_of_range);
  u->set_outside_field_of_view(r.unseen_causes.outside_field_of_view);
  u->set_faces_away(r.unseen_causes.faces_away);
  u->set_hidden(r.unseen_causes.hidden);
  return p;
}

Status PlanResultAssembler::AddHeatMap(const v1::HeatMapChunk& c) {
  if (c.first_index() == 0 && heat_map_started_) return ChunkError("a second heat map arrived (it is sent once)");
  if (c.first_index() != heat_map_.positions.size()) return ChunkError("heat map chunk out of order");
  heat_map_started_ = true;
  if (c.positions_size() != c.visible_voxels_size()) return ChunkError("heat map chunk sizes differ");
  heat_map_total_ = c.total_candidates();
  heat_map_.grid_spacing_m = c.grid_spacing_m();
  for (int i = 0; i < c.positions_size(); ++i) {
    heat_map_.positions.push_back(FromProto(c.positions(i)));
    heat_map_.visible_voxels.push_back(c.visible_voxels(i));
    if (c.floor_z_m_size() == c.positions_size()) heat_map_.floor_z_m.push_back(c.floor_z_m(i));
  }
  if (heat_map_.positions.size() > heat_map_total_) return ChunkError("more heat map candidates than declared");
  return Status::Ok();
}

Status VoxelChunkAssembler::Add(const v1::VoxelChunk& c) {
  std::vector<WorldPoint>& centers = voxels_.centers;
  auto& face_values = voxels_.best_face_values;
  auto& sole_viewers = voxels_.sole_viewer;
  if (c.first_voxel_id() != centers.size()) return ChunkError("voxel chunk out of order");
  if (c.centers_xyz_m_size() % 3 != 0) return ChunkError("voxel chunk with a partial centre");
  const int n = c.centers_xyz_m_size() / 3;
  const bool with_values = c.best_face_values_size() > 0;
  if (with_values && c.best_face_values_size() != n * kFacesPerVoxel) {
    return ChunkError("voxel chunk with face values for a different number of voxels");
  }
  if (with_values != (face_values.size() == centers.size()) && !centers.empty()) {
    return ChunkError("face values present in some voxel chunks only");
  }
  const bool with_viewers = c.sole_viewer_size() > 0;
  if (with_viewers && (!with_values || c.sole_viewer_size() != n)) {
    return ChunkError("voxel chunk with sole viewers for a different number of voxels");
  }
  if (with_viewers != (sole_viewers.size() == centers.size()) && !centers.empty()) {
    return ChunkError("sole viewers present in some voxel chunks only");
  }
  for (int32_t v : c.sole_viewer()) {
    if (v < kSeveralViewers) return ChunkError("voxel chunk with a sole viewer below -2");
  }
  sole_viewers.insert(sole_viewers.end(), c.sole_viewer().begin(), c.sole_viewer().end());
  total_ = c.total_voxels();
  for (int i = 0; i < n; ++i) {
    centers.emplace_back(c.centers_xyz_m(3 * i), c.centers_xyz_m(3 * i + 1), c.centers_xyz_m(3 * i + 2));
    if (with_values) {
      std::array<float, kFacesPerVoxel> v{};
      for (int f = 0; f < kFacesPerVoxel; ++f) v[f] = c.best_face_values(kFacesPerVoxel * i + f);
      face_values.push_back(v);
    }
  }
  if (centers.size() > total_) return ChunkError("more voxels than declared");
  return Status::Ok();
}

Result<AssembledVoxels> VoxelChunkAssembler::Finish(uint64_t voxel_count, uint64_t face_value_voxels, int stations,
                                                    const WorldPoint& frame_origin_m) && {
  AssembledVoxels& v = voxels_;
  if (v.centers.size() != voxel_count) {
    return ChunkError("received " + std::to_string(v.centers.size()) + " voxels of " + std::to_string(voxel_count));
  }
  if (face_value_voxels != 0 && v.best_face_values.size() != face_value_voxels) {
    return ChunkError("received face values for " + std::to_string(v.best_face_values.size()) + " voxels of " +
                      std::to_string(face_value_voxels));
  }
  if (!v.sole_viewer.empty() && v.sole_viewer.size() != v.best_face_values.size()) {
    return ChunkError("received sole viewers for " + std::to_string(v.sole_viewer.size()) + " voxels of " +
                      std::to_string(v.best_face_values.size()));
  }
  for (int32_t viewer : v.sole_viewer) {
    if (viewer >= stations) {
      return ChunkError("a sole viewer names station " + std::to_string(viewer) + " of " + std::to_string(stations));
    }
  }
  for (WorldPoint& q : v.centers) q = LessOrigin(q, frame_origin_m);
  return std::move(v);
}

Status PlanResultAssembler::AddVoxels(const v1::VoxelChunk& c) { return voxels_.Add(c); }

Result<PlanResult> PlanResultAssembler::Finish(const v1::PlanResult& p) && {
  if (heat_map_.positions.size() != p.heat_map_candidates()) {
    return ChunkError("received " + std::to_string(heat_map_.positions.size()) + " heat map candidates of " +
                      std::to_string(p.heat_map_candidates()));
  }
  PlanResult r;
  r.frame_origin_m = FromProto(p.frame_origin());
  const WorldPoint& origin = r.frame_origin_m;
  if (!origin.allFinite()) return ChunkError("the frame's origin is not finite");
  VC_ASSIGN_OR_RETURN(
      AssembledVoxels voxels,
      std::move(voxels_).Finish(p.voxel_count(), p.evaluation().face_value_voxels(), p.stations_size(), origin));
  VC_ASSIGN_OR_RETURN(r.options, FromProto(p.options()));
  r.resolution_m = p.resolution_m();
  VC_ASSIGN_OR_RETURN(r.selection_test, FromProto(p.selection_test()));
  for (const auto& s : p.stations()) {
    r.stations.push_back(FromProto(s));
    r.stations.back().position = LessOrigin(r.stations.back().position, origin);
    r.stations.back().floor_z_m = LessOrigin(r.stations.back().floor_z_m, origin.z());
  }
  r.heat_map = std::move(heat_map_);
  for (WorldPoint& q : r.heat_map.positions) q = LessOrigin(q, origin);
  for (double& z : r.heat_map.floor_z_m) z = LessOrigin(z, origin.z());
  r.reduction = FromProto(p.reduction(), origin);
  r.candidate_count = p.candidate_count();
  r.occupied_voxels = p.occupied_voxels();
  r.coverable_voxels = p.coverable_voxels();
  r.covered_voxels = p.covered_voxels();
  r.evaluation = FromProto(p.evaluation());
  r.evaluation.best_face_values = std::move(voxels.best_face_values);
  r.evaluation.sole_viewer = std::move(voxels.sole_viewer);
  for (const auto& t : p.timings()) r.timings.push_back({FromProto(t.stage()), t.seconds(), t.peak_rss_bytes()});
  r.total_seconds = p.total_seconds();
  r.warnings.assign(p.warnings().begin(), p.warnings().end());
  for (double z : p.floor_levels_m()) r.floor_levels_m.push_back(LessOrigin(z, origin.z()));
  VC_ASSIGN_OR_RETURN(r.ground.model, FromProto(p.ground().model()));
  r.ground.floor_share = p.ground().floor_share();
  r.ground.reason = p.ground().reason();
  VC_ASSIGN_OR_RETURN(r.stop_reason, FromProto(p.stop_reason()));
  r.greedy_stations = p.greedy_stations();
  r.consolidated = p.consolidated();
  VC_ASSIGN_OR_RETURN(r.optimality, FromProto(p.optimality()));
  r.distribution = {p.distribution().replicas(), p.distribution().shards(), p.distribution().retried(),
                    p.distribution().bytes_exchanged()};
  r.grid_cells = p.grid_cells();
  r.cells_without_floor = p.cells_without_floor();
  r.cells_failing_clearance = p.cells_failing_clearance();
  const int stations = p.stations_size();
  auto station_index = [&](int32_t i, const char* what) -> Status {
    if (i < 0 || i >= stations) return ChunkError(std::string(what) + " names station " + std::to_string(i));
    return Status::Ok();
  };
  r.scan_graph.min_overlap = p.scan_graph().min_overlap();
  r.scan_graph.connected = p.scan_graph().connected();
  for (const auto& c : p.scan_graph().components()) {
    for (int32_t i : c.stations()) VC_RETURN_IF_ERROR(station_index(i, "a scan graph component"));
    r.scan_graph.components.emplace_back(c.stations().begin(), c.stations().end());
  }
  for (const auto& e : p.scan_graph().edges()) {
    VC_RETURN_IF_ERROR(station_index(e.i(), "a scan graph edge"));
    VC_RETURN_IF_ERROR(station_index(e.j(), "a scan graph edge"));
    r.scan_graph.edges.push_back({e.i(), e.j(), e.overlap()});
  }
  r.connecting_stations = p.connecting_stations();
  const v1::WalkingRoute& route = p.route();
  for (int32_t i : route.order()) VC_RETURN_IF_ERROR(station_index(i, "the route"));
  if (route.legs_m_size() != route.order_size() || route.polylines_size() != route.order_size()) {
    return ChunkError("the route's legs, paths and order differ in length");
  }
  r.route.order.assign(route.order().begin(), route.order().end());
  r.route.legs_m.assign(route.legs_m().begin(), route.legs_m().end());
  r.route.length_m = route.length_m();
  for (const auto& line : route.polylines()) {
    std::vector<WorldPoint>& out = r.route.polylines.emplace_back();
    for (const auto& q : line.points()) out.push_back(LessOrigin(FromProto(q), origin));
  }
  r.route.parts = route.parts();
  if (route.has_start()) r.route.start = LessOrigin(FromProto(route.start()), origin);
  r.field_time = {p.field_time().setup_s(), p.field_time().scan_s(), p.field_time().walk_s(), p.field_time().total_s(),
                  p.field_time().scan_seconds_per_station()};
  for (const v1::CoveragePoint& c : p.coverage_curve()) r.coverage_curve.push_back(FromProto(c));
  const v1::UnseenCauses& u = p.unseen_causes();
  r.unseen_causes = {u.interior(),     u.in_keep_out(),           u.no_candidate_on_floor(),
                     u.out_of_range(), u.outside_field_of_view(), u.faces_away(),
                     u.hidden()};
  r.voxel_centers = std::move(voxels.centers);
  return r;
}

v1::EvaluateResult ToProto(const EvaluateJobResult& result) {
  v1::EvaluateResult r;
  *r.mutable_evaluation() = ToProto(result.evaluation);
  if (result.evaluation.best_face_values.size() != result.voxel_centers.size()) {
    r.mutable_evaluation()->set_face_value_voxels(0);  // not streamed (see ForEachVoxelChunk)
  }
  for (const auto& v : result.viewpoints) *r.add_viewpoints() = ToProto(v);
  r.set_voxel_count(result.voxel_centers.size());
  *r.mutable_frame_origin() = ToProto(result.frame_origin_m);
  r.set_selection_test(ToProto(result.selection_test));
  for (const VoxelSet& s : result.seen_sets) r.add_seen_voxels(s.count());
  for (const auto& w : result.warnings) r.add_warnings(w);
  return r;
}

bool ForEachSeenSetChunk(const EvaluateJobResult& result, const std::function<bool(v1::SeenSetChunk&&)>& fn) {
  for (size_t k = 0; k < result.seen_sets.size(); ++k) {
    const VoxelSet& set = result.seen_sets[k];
    const uint64_t total = set.count();
    v1::SeenSetChunk c;
    uint64_t sent = 0;
    auto start = [&] {
      c = v1::SeenSetChunk();
      c.set_viewpoint(uint32_t(k));
      c.set_first_index(sent);
      c.set_total_voxels(total);
    };
    start();
    bool ok = true;
    set.ForEach([&](size_t id) {
      if (!ok) return;
      c.add_voxel_ids(uint32_t(id));
      ++sent;
      if (size_t(c.voxel_ids_size()) == kSeenIdsPerChunk && sent < total) {
        ok = fn(std::move(c));
        start();
      }
    });
    if (!ok || !fn(std::move(c))) return false;
  }
  return true;
}

Status EvaluateResultAssembler::AddSeenSet(const v1::SeenSetChunk& c) {
  const size_t k = c.viewpoint();
  if (k == seen_ids_.size() && c.first_index() == 0) {
    seen_ids_.emplace_back();
    seen_totals_.push_back(c.total_voxels());
  } else if (k + 1 != seen_ids_.size() || c.first_index() != seen_ids_.back().size() ||
             c.total_voxels() != seen_totals_.back()) {
    return ChunkError("seen set chunk out of order");
  }
  std::vector<uint32_t>& ids = seen_ids_.back();
  for (uint32_t id : c.voxel_ids()) {
    if (!ids.empty() && id <= ids.back()) return ChunkError("seen set chunk with ids out of order");
    ids.push_back(id);
  }
  if (ids.size() > seen_totals_.back()) return ChunkError("more seen voxels than declared");
  return Status::Ok();
}

Status EvaluateResultAssembler::AddVoxels(const v1::VoxelChunk& chunk) { return voxels_.Add(chunk); }

Result<EvaluateJobResult> EvaluateResultAssembler::Finish(const v1::EvaluateResult& p) && {
  EvaluateJobResult r;
  r.frame_origin_m = FromProto(p.frame_origin());
  if (!r.frame_origin_m.allFinite()) return ChunkError("the frame's origin is not finite");
  VC_ASSIGN_OR_RETURN(AssembledVoxels voxels,
                      std::move(voxels_).Finish(p.voxel_count(), p.evaluation().face_value_voxels(),
                                                p.viewpoints_size(), r.frame_origin_m));
  r.evaluation = FromProto(p.evaluation());
  r.evaluation.best_face_values = std::move(voxels.best_face_values);
  r.evaluation.sole_viewer = std::move(voxels.sole_viewer);
  r.voxel_centers = std::move(voxels.centers);
  for (const auto& v : p.viewpoints()) r.viewpoints.push_back(FromProto(v));
  VC_ASSIGN_OR_RETURN(r.selection_test, FromProto(p.selection_test() == v1::SELECTION_TEST_UNSPECIFIED
                                                      ? v1::SELECTION_TEST_SURFACE_VISIBILITY
                                                      : p.selection_test()));
  r.warnings.assign(p.warnings().begin(), p.warnings().end());
  if (size_t(p.seen_voxels_size()) != seen_ids_.size() ||
      (!seen_ids_.empty() && seen_ids_.size() != r.viewpoints.size())) {
    return ChunkError("received seen sets of " + std::to_string(seen_ids_.size()) +
                      " viewpoints; the result declares " + std::to_string(p.seen_voxels_size()) + " of " +
                      std::to_string(r.viewpoints.size()));
  }
  for (size_t k = 0; k < seen_ids_.size(); ++k) {
    const std::vector<uint32_t>& ids = seen_ids_[k];
    if (ids.size() != p.seen_voxels(int(k)) || ids.size() != seen_totals_[k]) {
      return ChunkError("received " + std::to_string(ids.size()) + " seen voxels of viewpoint " +
                        std::to_string(k + 1) + ", declared " + std::to_string(p.seen_voxels(int(k))));
    }
    VoxelSet set(r.voxel_centers.size());
    for (uint32_t id : ids) {
      if (id >= set.size())
        return ChunkError("a seen set names voxel " + std::to_string(id) + " of " + std::to_string(set.size()));
      set.set(id);
    }
    r.seen_sets.push_back(std::move(set));
  }
  return r;
}

}  // namespace vc::wire
