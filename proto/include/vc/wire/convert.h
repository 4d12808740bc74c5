// ToProto / FromProto between the vc.v1 messages and vc_core types: the one place each conversion
// lives. The server converts core results to messages; the client converts them back and hands
// them to vc::WritePlanOutputs / vc::WriteEvaluationOutputs.
//
// Bulk data (the heat map and the per-voxel results) is split into chunks of at most about
// 0.8 MiB each (kCandidatesPerHeatMapChunk, kVoxelsPerChunk) and reassembled by
// PlanResultAssembler and EvaluateResultAssembler, which check that every chunk arrived exactly
// once and in order (both through VoxelChunkAssembler for the voxels).
// Positions on the wire are in the input's own frame (docs/PROTOCOL.md, "Frames"): a result's
// local positions go out plus PlanResult::frame_origin_m and come back less it, so PlanResult is
// local on both sides and its writers (vc/report) add the origin once more. Parameters
// (PlanOptions, EvaluateJobOptions) are in the input's frame on both sides. Peers' ShardRequest
// viewpoints are local (both replicas read the same bytes with the same units, so the same frame).
// Functions are pure; PlanResultAssembler is not thread-safe.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/evaluate_job.h"
#include "vc/plan/planner.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"
#include "vc/v1/planner.pb.h"
#include "vc/visibility/visibility.h"

namespace vc::wire {

// Voxels per VoxelChunk: 48 bytes each (centre + 6 face values), so a chunk is ~0.8 MiB.
inline constexpr size_t kVoxelsPerChunk = 16384;
// Voxel ids per SeenSetChunk: at most 5 bytes each (varint), so a chunk is at most ~0.6 MiB.
inline constexpr size_t kSeenIdsPerChunk = 131072;
// Candidates per HeatMapChunk (~40 bytes each on the wire).
inline constexpr size_t kCandidatesPerHeatMapChunk = 16384;

// A point as it is, in whatever frame the caller holds it.
v1::Point ToProto(const WorldPoint& p);
WorldPoint FromProto(const v1::Point& p);

v1::InputFormat ToProto(InputFormat f);
// INVALID_ARGUMENT for an unknown enum value; UNSPECIFIED is not a format (check it first).
Result<InputFormat> FromProto(v1::InputFormat f);

v1::SelectionTest ToProto(SelectionTest t);
// INVALID_ARGUMENT for UNSPECIFIED or an unknown value.
Result<SelectionTest> FromProto(v1::SelectionTest t);
v1::Stage ToProto(Stage s);
// kUnspecified for UNSPECIFIED or a value this build does not know (a newer server's stage).
Stage FromProto(v1::Stage s);
v1::StopReason ToProto(StopReason r);
// DATA_LOSS for UNSPECIFIED or an unknown value.
Result<StopReason> FromProto(v1::StopReason r);
v1::FaceSet ToProto(FaceSet f);
// Per-viewpoint or overall figures, field for field (also a station's, between replicas).
v1::VisibilityFigures ToProto(const VisibilityFigures& f);
VisibilityFigures FromProto(const v1::VisibilityFigures& f);
// One point of the coverage curve, field for field.
v1::CoveragePoint ToProto(const CoveragePoint& c);
CoveragePoint FromProto(const v1::CoveragePoint& p);
// SelectionSolver <-> its enum (UNSPECIFIED in PlanParameters keeps the default).
v1::SelectionSolver ToProto(SelectionSolver s);
// GroundModel <-> its enum; FromProto takes UNSPECIFIED as auto, INVALID_ARGUMENT for an unknown value.
v1::GroundModel ToProto(GroundModel m);
Result<GroundModel> FromProto(v1::GroundModel m);

// Parameters (generated from the parameter tables, vc/base/parameter.h). ToProto sets every field;
// FromProto applies the fields present in `p` to a default-constructed struct. INVALID_ARGUMENT
// for unknown enum values; the values themselves are checked by Validate().
v1::PlanParameters ToProto(const PlanOptions& options);
Result<PlanOptions> FromProto(const v1::PlanParameters& p);
v1::EvaluateParameters ToProto(const EvaluateJobOptions& options);
Result<EvaluateJobOptions> FromProto(const v1::EvaluateParameters& p);

v1::Progress ToProto(const ProgressEvent& e);
ProgressEvent FromProto(const v1::Progress& p);

// A station at a local position, sent in the input's frame (position + frame_origin_m).
v1::PlannedStation ToProto(const PlannedStation& s, const WorldPoint& frame_origin_m);
// A station as on the wire: its position in the input's frame (streamed picks, for people).
PlannedStation FromProto(const v1::PlannedStation& s);

// Without the per-face values (those travel in VoxelChunk); face_value_voxels is set from them.
v1::Evaluation ToProto(const Evaluation& e);
Evaluation FromProto(const v1::Evaluation& e);

// The heat map (local) in chunks, in order, its positions and floor heights in the input's frame.
std::vector<v1::HeatMapChunk> HeatMapChunks(const HeatMap& heat_map, const WorldPoint& frame_origin_m);
// Calls fn with each VoxelChunk of `centers` (local; sent plus frame_origin_m) with evaluation's
// best_face_values and sole_viewer when it holds one per centre, in order. Stops early and returns
// false when fn returns false.
bool ForEachVoxelChunk(const std::vector<WorldPoint>& centers, const Evaluation& evaluation,
                       const WorldPoint& frame_origin_m, const std::function<bool(v1::VoxelChunk&&)>& fn);
// The chunks of a plan's voxels (result.voxel_centers, result.evaluation).
bool ForEachVoxelChunk(const PlanResult& result, const std::function<bool(v1::VoxelChunk&&)>& fn);
// The chunks of an evaluation's voxels (result.voxel_centers, result.evaluation).
bool ForEachVoxelChunk(const EvaluateJobResult& result, const std::function<bool(v1::VoxelChunk&&)>& fn);
// Calls fn with each SeenSetChunk of result.seen_sets (viewpoints in order, each in order, at least
// one chunk each). Stops early and returns false when fn returns false.
bool ForEachSeenSetChunk(const EvaluateJobResult& result, const std::function<bool(v1::SeenSetChunk&&)>& fn);
// The summary that ends a Plan stream (everything but the chunked parts), in the input's frame
// with result.frame_origin_m as frame_origin.
v1::PlanResult ToProto(const PlanResult& result);

// The voxels of the VoxelChunk messages of one stream (a Plan's or an Evaluate's), in id order.
struct AssembledVoxels {
  std::vector<WorldPoint> centers;                                  // local (less the frame's origin), m
  std::vector<std::array<float, kFacesPerVoxel>> best_face_values;  // empty when none were sent
  std::vector<int32_t> sole_viewer;                                 // empty when none were sent
};

// Puts the VoxelChunk messages of one stream together, checking that each arrived once, in order.
class VoxelChunkAssembler {
 public:
  // DATA_LOSS if the chunk is out of order or inconsistent with the previous ones.
  Status Add(const v1::VoxelChunk& chunk);
  // The voxels, less `frame_origin_m`. DATA_LOSS unless `voxel_count` voxels arrived, with face
  // values for `face_value_voxels` of them (0: whatever came), and every sole viewer names one of
  // `stations` stations.
  Result<AssembledVoxels> Finish(uint64_t voxel_count, uint64_t face_value_voxels, int stations,
                                 const WorldPoint& frame_origin_m) &&;

 private:
  AssembledVoxels voxels_;  // centres in the input's frame until Finish
  uint64_t total_ = 0;
};

// Rebuilds a vc::PlanResult from the chunks and the final summary of a Plan stream.
class PlanResultAssembler {
 public:
  // DATA_LOSS if a chunk is out of order or inconsistent with the previous ones, or starts a second
  // heat map (a stream carries exactly one).
  Status AddHeatMap(const v1::HeatMapChunk& chunk);
  Status AddVoxels(const v1::VoxelChunk& chunk);
  // The heat map received so far (complete once all its chunks arrived), in the input's frame.
  const HeatMap& heat_map() const { return heat_map_; }
  // The whole result, every position local (less summary.frame_origin). DATA_LOSS if the chunks
  // received do not add up to what `summary` declares (e.g. no heat map), or the origin is not finite.
  Result<PlanResult> Finish(const v1::PlanResult& summary) &&;

 private:
  HeatMap heat_map_;
  bool heat_map_started_ = false;
  uint64_t heat_map_total_ = 0;
  VoxelChunkAssembler voxels_;
};

// The summary that ends an Evaluate stream (everything but the voxels): the viewpoints as the job
// was given them (the input's frame), result.frame_origin_m as frame_origin.
v1::EvaluateResult ToProto(const EvaluateJobResult& result);

// Rebuilds a vc::EvaluateJobResult from the VoxelChunk messages and the final summary of an
// Evaluate stream.
class EvaluateResultAssembler {
 public:
  // DATA_LOSS if the chunk is out of order or inconsistent with the previous ones.
  Status AddVoxels(const v1::VoxelChunk& chunk);
  // DATA_LOSS if the chunk is out of order (viewpoints, or ids within one), or its ids descend.
  Status AddSeenSet(const v1::SeenSetChunk& chunk);
  // The whole result, its voxel centres local (less summary.frame_origin), its viewpoints as sent,
  // its seen sets (when sent) over the voxels. DATA_LOSS if the chunks received do not add up to
  // what `summary` declares (voxels, seen sets per viewpoint and their sizes), a seen id is not a
  // voxel, or the origin is not finite.
  Result<EvaluateJobResult> Finish(const v1::EvaluateResult& summary) &&;

 private:
  VoxelChunkAssembler voxels_;
  std::vector<std::vector<uint32_t>> seen_ids_;  // per viewpoint, as received
  std::vector<uint64_t> seen_totals_;            // per viewpoint, as declared
};

}  // namespace vc::wire
