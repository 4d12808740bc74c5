// The files a user gets from a plan or an evaluation (written by vc-client from the streamed
// result, and usable directly from core): plan.json, stations.csv, stations.dxf, stations.geojson (with a CRS),
// fieldsheet.pdf (vc/report/field_sheet.h), visibility.ply, heatmap.png, reduction.png, report.html
// (vc/report/report_html.h), evaluation.json. Schemas are documented in docs/PLANNING.md and docs/PROTOCOL.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"
#include "vc/plan/evaluate_job.h"
#include "vc/plan/planner.h"
#include "vc/report/crs.h"
#include "vc/report/field_sheet.h"
#include "vc/report/label_placement.h"
#include "vc/visibility/visibility.h"

namespace vc {

// How the scene reached the server, for plan.json's `upload` (filled by vc-client, which chose it).
struct UploadSummary {
  std::string format;       // "vc-voxels" (a compact upload) or "raw" (the file's bytes as they are)
  uint64_t bytes_sent = 0;  // bytes of the scene sent (before the transport's gzip)
  uint64_t file_bytes = 0;  // bytes of the file the user named
  uint64_t voxels = 0;      // vc-voxels: voxels sent; 0 for raw
  double resolution_m = 0;  // vc-voxels: their edge (m); 0 for raw
  std::string why_raw;      // raw: why (e.g. "--raw-upload", "an octree is uploaded as it is")
  std::string scene_hash;   // SHA-256 of what was (or would have been) sent; empty without the cache
  bool from_cache = false;  // the server held the scene: bytes_sent is 0
  std::string units;        // the input's units as given (vc-client --units; MetresPerUnit); empty = metres
};

// plan.json's content (documented schema). `upload` null when not given. Every position is in the
// input's own frame (the result's local positions plus PlanResult::frame_origin_m), and "frame"
// says where the local frame lies (docs/PLANNING.md, "Outputs in the input's frame").
// `fixed_station_names` name the fixed stations as FieldStations (vc/report/field_exports.h) does.
// `crs`: the CRS the input's frame is in, for plan.json's `crs` (null when not given).
std::string PlanToJson(const PlanResult& result, const UploadSummary* upload = nullptr,
                       const std::vector<std::string>& fixed_station_names = {}, const CrsInfo* crs = nullptr);

// Writes plan.json, stations.csv, stations.dxf, fieldsheet.pdf (laid out as `field_sheet` says), visibility.ply,
// heatmap.png, reduction.png and report.html into
// `out_dir` (created if missing), every coordinate in the input's own frame (stations.csv and stations.dxf to the
// micrometre; visibility.ply in double precision when the frame's origin is not zero). `fixed_station_names`: the
// fixed stations' names from their file, in PlanOptions::fixed_stations order (may be empty). visibility.ply needs
// result.voxel_centers and result.evaluation.best_face_values. With `crs` (the CRS of the input's frame), also
// stations.geojson, and plan.json and stations.csv name the CRS. INTERNAL / FAILED_PRECONDITION with the path on
// I/O errors; INVALID_ARGUMENT when PROJ cannot place a station on the earth.
Status WritePlanOutputs(const PlanResult& result, const std::string& out_dir, const UploadSummary* upload = nullptr,
                        const std::vector<std::string>& fixed_station_names = {}, const Crs* crs = nullptr,
                        const FieldSheetOptions& field_sheet = {});

// One point of a coloured PLY: its position (m), its colour and, when the PLY has one, its value.
struct ColouredPoint {
  WorldPoint position_m{0, 0, 0};
  std::array<uint8_t, 3> rgb{0, 0, 0};
  float value = 0;
};
// How a PLY stores x, y, z: float, or double for coordinates float cannot hold (survey coordinates).
enum class PlyCoordinates { kFloat, kDouble };
// A binary little-endian PLY of `points` (the writer of visibility.ply): one header comment line per
// entry of `comments`, then x y z (m) as `coordinates` say, uchar red green blue and, when
// `value_name` is not empty, a float property of that name holding each point's value.
std::string ColouredPointsPly(const std::vector<std::string>& comments, const std::vector<ColouredPoint>& points,
                              std::string_view value_name = "", PlyCoordinates coordinates = PlyCoordinates::kFloat);

// evaluation.json's content: resolution_m, global_visibility, per_viewpoint[...] and more;
// `viewpoints` as the job was given them (the input's own frame); `crs` (null when not given) the CRS
// of that frame, as plan.json's `crs`.
std::string EvaluationToJson(const Evaluation& evaluation, const std::vector<WorldPoint>& viewpoints,
                             const CrsInfo* crs = nullptr);

// The heat map of what an evaluation misses (heatmap.png's cells for evaluate): per level of the
// stations (their heights grouped as heatmap.png groups candidates: a gap over 0.5 m starts a new
// level; its floor the lowest floor_z_m of its stations, else its lowest station less the lowest
// tripod height) and per `cell_m` square column of the local frame, the exposed voxels (some face
// without an occupied neighbour) from that floor's top voxel layer up to the next level's that no
// station sees (best V 0 on every face). One cell per column with an exposed voxel on the level (0
// when all are seen), at the level's floor plus the lowest tripod height, with that floor as its
// floor_z_m; local frame. Empty without best face values.
HeatMap MissedVoxelsHeatMap(const PlanResult& result, double cell_m);

// An evaluation as a plan of its viewpoints, for the writers of a plan's files: the viewpoints
// (local) are its stations, in the order given, each with its G and, as floor_z_m, the top of the
// highest voxel in its column at most 3 m below it (NaN when none); the voxels, the evaluation and
// the frame as they are; each station's cumulative_coverage NaN (it was not selected, so it has no
// gain: stations.csv leaves both cells empty, report.html shows a dash); covered_voxels the voxels some station sees
// (best V > 0), of all the occupied ones (coverable_voxels: an evaluation has no candidates to bound what can be seen);
// the heat map MissedVoxelsHeatMap's at the default grid spacing; `scanner` (the job's) as the plan's scanner, and the
// field time of set-up and scans it gives (ComputeFieldTime; no walk: an evaluation has no route). The default
// PlanOptions otherwise.
PlanResult EvaluationAsPlan(const EvaluateJobResult& result, const ScannerModel& scanner = {});

// Writes evaluation.json, stations.csv (the crew's format, as WritePlanOutputs'), stations.dxf,
// fieldsheet.pdf (laid out as `field_sheet` says) and, with `crs` (the CRS of the input's frame),
// stations.geojson, of EvaluationAsPlan(result) through WritePlanOutputs' writers; and, when the
// evaluation kept the best face values of every voxel (exact mode), visibility.ply, heatmap.png
// (what the stations miss) and report.html. Errors as WritePlanOutputs'.
// `scanner` is the job's (EvaluateJobOptions::scanner): the field sheet's scan time comes from it.
Status WriteEvaluationOutputs(const EvaluateJobResult& result, const std::string& out_dir, const Crs* crs = nullptr,
                              const FieldSheetOptions& field_sheet = {}, const ScannerModel& scanner = {});

// Pixel size of a picture.
struct ImageSize {
  int width = 0;
  int height = 0;
};
// What heatmap.png's cells count (the title and the colour bar say it).
enum class HeatmapMeaning {
  kSeenFromCandidates,  // a plan's heat map: the voxels a tripod at the cell sees
  kMissedByStations,    // an evaluation's (MissedVoxelsHeatMap): the surface voxels no station sees
};
// heatmap.png's bytes: the cells under the floor plan and keep-out zones of each level, the scan
// graph's edges, the walking route, the stations and a colour bar (for a plan, in per cent of the
// scene; docs/PLANNING.md, "heatmap.png").
Result<std::string> HeatmapPng(const PlanResult& result, HeatmapMeaning meaning = HeatmapMeaning::kSeenFromCandidates);
// Where heatmap.png draws a station, in pixels from the picture's top-left corner: its panel, the
// station's own pixel, and the box of its numbered disc (centred on the station, or moved aside
// with a leader line back to it, PlaceLabels).
struct HeatmapStationPlace {
  int panel = 0;
  LabelPoint station_px;
  PlacedLabel disc;
};
// One place per station of `result`, in plan order.
std::vector<HeatmapStationPlace> HeatmapStationPlaces(const PlanResult& result);
// Size of heatmap.png for `result` (layout in docs/PLANNING.md: one panel per floor level).
ImageSize HeatmapImageSize(const PlanResult& result);
// Size of reduction.png for a |P| x |P| matrix.
ImageSize ReductionImageSize(int stations);

// Parses a stations CSV: "x,y,z" per line (an earlier plan's "x,y,z,route_order": the fourth column
// ignored), or, after a header naming x, y and z columns ("x" or "x_m", any order, as a plan's
// stations.csv does), those columns of each row, the others ignored; '#' comments; one optional
// header line. INVALID_ARGUMENT naming `source` and the line on a malformed or non-finite row, or
// when there is no station.
Result<std::vector<WorldPoint>> ParseStationsCsv(std::string_view text, std::string_view source);

}  // namespace vc
