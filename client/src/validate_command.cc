#include "vc/client/validate_command.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vc/client/parameter_flags.h"
#include "vc/report/plan_report.h"
#include "vc/scene/e57.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/station_file.h"
#include "vc/wire/status_mapping.h"

namespace vc::client {
namespace {

std::string PointFileLabel(const std::string& file, size_t scan_number) {
  return file + " (scan " + std::to_string(scan_number) + ")";
}

// `s` about the file that holds scan `scan_number`, prefixed "FILE (scan N): " (without the file's
// name where the message starts with it already).
Status NamingFile(const Status& s, const std::string& file, size_t scan_number) {
  std::string message = s.message();
  if (message.rfind(file + ": ", 0) == 0) message.erase(0, file.size() + 2);
  return {s.code(), PointFileLabel(file, scan_number) + ": " + message};
}

// Reads the whole file (for the E57 scan listing).
Result<std::string> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError(path + ": cannot open the file");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The station's heading in degrees, if it has one.
Heading HeadingDeg(const KnownStation& station) {
  if (!station.heading_rad) return std::nullopt;
  return *station.heading_rad * 180.0 / std::numbers::pi;
}

// The scans of one E57 file, by the poses it carries. Its points arrive concatenated in scan order;
// they are split by each scan's record count, which holds only when no record was dropped.
Result<std::vector<CapturedScan>> E57Scans(const std::string& file, SceneInput input, size_t first_scan_number) {
  VC_ASSIGN_OR_RETURN(const std::string bytes, ReadBytes(file));
  VC_ASSIGN_OR_RETURN(const std::vector<E57Scan> listed, ReadE57Scans(bytes, file));
  uint64_t declared = 0;
  for (const E57Scan& s : listed) declared += s.point_count;
  if (declared != input.points.size() || listed.size() != input.scan_origins.size()) {
    return InvalidArgumentError(file + ": its scans declare " + std::to_string(declared) + " points but " +
                                std::to_string(input.points.size()) +
                                " are valid and finite; validate cannot tell which scan the dropped records "
                                "belonged to (export the scans as one point file each, with --positions)");
  }
  // The scans' headings, as the stations reader takes them from the poses.
  VC_ASSIGN_OR_RETURN(const std::vector<KnownStation> stations, ParseStationFile(bytes, file));
  std::vector<CapturedScan> scans;
  size_t next = 0;
  for (size_t i = 0; i < listed.size(); ++i) {
    CapturedScan scan;
    if (i < stations.size()) scan.heading_deg = HeadingDeg(stations[i]);
    scan.name = file + ", scan " + std::to_string(first_scan_number + i) +
                (listed[i].name.empty() ? "" : " (" + listed[i].name + ")");
    scan.position_m = input.scan_origins[i];
    scan.points_m.assign(input.points.begin() + long(next), input.points.begin() + long(next + listed[i].point_count));
    next += listed[i].point_count;
    scans.push_back(std::move(scan));
  }
  return scans;
}

// The position of point file `file` (scan `scan_number`): the next row of --positions, else its
// PCD VIEWPOINT.
Result<KnownStation> PointFilePosition(const std::string& file, InputFormat format, size_t scan_number,
                                       const std::vector<KnownStation>* positions, size_t point_file_index) {
  if (positions != nullptr) return (*positions)[point_file_index];
  Result<std::vector<KnownStation>> own = format == InputFormat::kPcd
                                              ? ReadStationFile(file)
                                              : Result<std::vector<KnownStation>>(std::vector<KnownStation>{});
  if (!own.ok() || own->size() != 1) {
    return InvalidArgumentError(PointFileLabel(file, scan_number) +
                                " has no scanner position: give --positions FILE (one position per point file, "
                                "in order), or a PCD file with a VIEWPOINT line");
  }
  return own->front();
}

// The input's points in the scans' common local frame (`frame_origin_m` in the input's frame):
// moved from the file's own local frame, or, when the file is in its own scanner's frame, by the
// scanner's pose (whose translation is local). Points nearer than min_range_m to the scanner are
// dropped and counted, measured in double before the move (many scans hold points on the min_range
// sphere).
std::vector<Eigen::Vector3f> PlacePoints(const SceneInput& input, const Eigen::Vector3d& frame_origin_m,
                                         const WorldPoint& position_m,
                                         const std::optional<Eigen::Isometry3d>& scanner_pose, double min_range_m,
                                         uint64_t* dropped) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(input.points.size());
  const Eigen::Vector3d shift_m =
      scanner_pose ? input.frame_origin_m : Eigen::Vector3d(input.frame_origin_m - frame_origin_m);
  for (const Eigen::Vector3f& p : input.points) {
    const Eigen::Vector3d q = p.cast<double>() + shift_m;
    if ((scanner_pose ? q : Eigen::Vector3d(q - position_m)).norm() < min_range_m) {
      ++*dropped;
      continue;
    }
    out.push_back((scanner_pose ? *scanner_pose * q : q).cast<float>());
  }
  return out;
}

// The common local frame of scans whose points are in their scanners' frames: the readers' rule
// (FrameOriginNear) applied to the first position, so posed points of a georeferenced site stay
// small enough for floats.
Eigen::Vector3d ScannerFrameOrigin(const std::vector<KnownStation>& positions) {
  if (positions.empty()) return Eigen::Vector3d::Zero();
  return FrameOriginNear(positions.front().position_m);
}

Result<std::vector<KnownStation>> ReadPositions(const ValidateInputs& inputs, size_t point_files) {
  if (inputs.positions_file.empty()) return std::vector<KnownStation>{};
  if (point_files == 0) {
    return InvalidArgumentError("--positions " + inputs.positions_file +
                                ": no point file to place (E57 files carry their scans' poses)");
  }
  VC_ASSIGN_OR_RETURN(std::vector<KnownStation> positions, ReadStationFile(inputs.positions_file));
  if (positions.size() != point_files) {
    return InvalidArgumentError("--positions " + inputs.positions_file + " holds " + std::to_string(positions.size()) +
                                " positions but " + std::to_string(point_files) +
                                " point files were given: one position per point file, in order");
  }
  return positions;
}

std::string Ratio(double value, bool meaningful) {
  char b[16];
  std::snprintf(b, sizeof b, "%.3f", value);
  return meaningful ? b : "-";
}

}  // namespace

Result<LoadedScans> LoadScans(const ValidateInputs& inputs, double min_range_m) {
  if (inputs.files.empty()) return InvalidArgumentError("validate needs at least one scan file");
  const ReadOptions limits = ReadLimits(kDefaultMaxUploadBytes, kDefaultMemoryBudgetBytes);
  std::vector<SceneInput> read;
  size_t point_files = 0, scans_read = 0;
  for (const std::string& file : inputs.files) {
    Result<SceneInput> input = ReadSceneFile(file, limits);
    if (!input.ok()) return NamingFile(input.status(), file, scans_read + 1);
    if (input->is_octree() || input->format == InputFormat::kOctomapGraph ||
        input->format == InputFormat::kVoxelStream) {
      return InvalidArgumentError(file + " is " + std::string(InputFormatName(input->format)) +
                                  ": validate needs each scan's captured points (E57, PLY, PCD, XYZ or LAS)");
    }
    point_files += input->format != InputFormat::kE57;
    scans_read += input->format == InputFormat::kE57 ? input->scan_origins.size() : 1;
    read.push_back(std::move(*input));
  }
  VC_ASSIGN_OR_RETURN(const std::vector<KnownStation> positions, ReadPositions(inputs, point_files));

  LoadedScans loaded;
  const Eigen::Vector3d frame_origin_m =
      inputs.scanner_frame ? ScannerFrameOrigin(positions) : Eigen::Vector3d(read.front().frame_origin_m);
  loaded.frame_origin_m = frame_origin_m;
  size_t point_file_index = 0;
  for (size_t f = 0; f < read.size(); ++f) {
    const std::string& file = inputs.files[f];
    const Eigen::Vector3d shift_m = read[f].frame_origin_m - frame_origin_m;
    const size_t scan_number = loaded.scans.size() + 1;
    if (read[f].format == InputFormat::kE57) {
      for (Eigen::Vector3f& p : read[f].points) p = (p.cast<double>() + shift_m).cast<float>();
      for (Eigen::Vector3d& o : read[f].scan_origins) o += shift_m;
      VC_ASSIGN_OR_RETURN(std::vector<CapturedScan> scans, E57Scans(file, std::move(read[f]), scan_number));
      for (CapturedScan& s : scans) {
        const size_t before = s.points_m.size();
        std::erase_if(s.points_m,
                      [&](const Eigen::Vector3f& p) { return (p.cast<double>() - s.position_m).norm() < min_range_m; });
        loaded.dropped_near_scanner.push_back(before - s.points_m.size());
        loaded.scans.push_back(std::move(s));
      }
      continue;
    }
    VC_ASSIGN_OR_RETURN(const KnownStation station,
                        PointFilePosition(file, read[f].format, scan_number, positions.empty() ? nullptr : &positions,
                                          point_file_index++));
    const WorldPoint position_m = station.position_m - frame_origin_m;
    std::optional<Eigen::Isometry3d> pose;
    if (inputs.scanner_frame) {
      pose = Eigen::Translation3d(position_m) *
             Eigen::AngleAxisd(station.heading_rad.value_or(0.0), Eigen::Vector3d::UnitZ());
    }
    loaded.dropped_near_scanner.resize(loaded.scans.size() + 1);
    loaded.scans.push_back(
        {file, position_m,
         PlacePoints(read[f], frame_origin_m, position_m, pose, min_range_m, &loaded.dropped_near_scanner.back()),
         HeadingDeg(station)});
  }
  for (size_t i = 0; i < loaded.scans.size(); ++i) {
    if (loaded.scans[i].points_m.empty()) {
      return InvalidArgumentError("scan " + std::to_string(i + 1) + " (" + loaded.scans[i].name +
                                  ") has no point farther than the scanner's min_range_m (" +
                                  std::to_string(min_range_m) + " m) from its scanner position");
    }
  }
  return loaded;
}

std::string ValidationTable(const ValidationReport& report) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-4s %10s %10s %10s %7s %9s %9s %11s  %s\n", "SCAN", "CAPTURED", "PREDICTED",
                "BOTH", "RECALL", "PRECISION", "RECALL+1", "PRECISION+1", "NAME");
  out += line;
  const bool precise = report.precision_meaningful;
  for (size_t i = 0; i < report.scans.size(); ++i) {
    const ScanAgreement& a = report.scans[i];
    std::snprintf(line, sizeof line, "%-4zu %10llu %10llu %10llu %7.3f %9s %9.3f %11s  ", i + 1,
                  static_cast<unsigned long long>(a.captured), static_cast<unsigned long long>(a.predicted),
                  static_cast<unsigned long long>(a.both), a.recall, Ratio(a.precision, precise).c_str(),
                  a.recall_slack, Ratio(a.precision_slack, precise).c_str());
    out += line + a.name;
    out += a.position_occupied ? " (scanner position in an occupied voxel: nothing predicted)\n" : "\n";
  }
  std::snprintf(line, sizeof line, "model: %llu voxels of %.3f m; test %s; +1: with one voxel of slack\n",
                static_cast<unsigned long long>(report.model_voxels), report.resolution_m,
                std::string(SelectionTestName(report.selection_test)).c_str());
  out += line;
  if (!report.note.empty()) out += "note: " + report.note + "\n";
  return out;
}

std::string ValidationToJson(const ValidationReport& report, const ValidateInputs& inputs, const LoadedScans& loaded,
                             const ScannerModel& scanner) {
  nlohmann::ordered_json j;
  j["files"] = inputs.files;
  j["positions_file"] = inputs.positions_file;
  j["scanner_frame"] = inputs.scanner_frame;
  j["selection_test"] = std::string(SelectionTestName(report.selection_test));
  j["resolution_m"] = report.resolution_m;
  j["scanner"] = {{"name", scanner.name},
                  {"min_range_m", scanner.min_range_m},
                  {"max_range_m", scanner.max_range_m},
                  {"vfov_min_deg", scanner.vfov_min_deg},
                  {"vfov_max_deg", scanner.vfov_max_deg},
                  {"max_incidence_deg", scanner.max_incidence_deg},
                  {"angular_step_deg", scanner.angular_step_deg},
                  {"max_spacing_m", scanner.max_spacing_m},
                  {"hfov_deg", scanner.hfov_deg}};
  j["frame_origin_m"] = {loaded.frame_origin_m.x(), loaded.frame_origin_m.y(), loaded.frame_origin_m.z()};
  j["model_voxels"] = report.model_voxels;
  j["precision_meaningful"] = report.precision_meaningful;
  j["note"] = report.note;
  nlohmann::ordered_json scans = nlohmann::ordered_json::array();
  for (size_t i = 0; i < report.scans.size(); ++i) {
    const ScanAgreement& a = report.scans[i];
    const WorldPoint p = loaded.scans[i].position_m + loaded.frame_origin_m;
    scans.push_back({{"scan", i + 1},
                     {"name", a.name},
                     {"position_m", {p.x(), p.y(), p.z()}},
                     {"heading_deg", loaded.scans[i].heading_deg ? nlohmann::ordered_json(*loaded.scans[i].heading_deg)
                                                                 : nlohmann::ordered_json(nullptr)},
                     {"points", loaded.scans[i].points_m.size()},
                     {"points_dropped_near_scanner", loaded.dropped_near_scanner[i]},
                     {"captured", a.captured},
                     {"predicted", a.predicted},
                     {"both", a.both},
                     {"recall", a.recall},
                     {"precision", a.precision},
                     {"captured_near_predicted", a.captured_near_predicted},
                     {"predicted_near_captured", a.predicted_near_captured},
                     {"recall_slack", a.recall_slack},
                     {"precision_slack", a.precision_slack},
                     {"position_occupied", a.position_occupied},
                     {"ply", "validation_" + std::to_string(i + 1) + ".ply"}});
  }
  j["scans"] = std::move(scans);
  return j.dump(2) + "\n";
}

Result<std::string> ValidationPly(const ValidationReport& report, size_t scan, const WorldPoint& frame_origin_m) {
  if (scan >= report.scans.size()) {
    return InvalidArgumentError("no scan " + std::to_string(scan + 1) + " in a report of " +
                                std::to_string(report.scans.size()));
  }
  const ScanAgreement& a = report.scans[scan];
  const size_t n = report.model.occupied.size();
  if (n == 0 || a.captured_set.size() != n || a.predicted_set.size() != n) {
    return FailedPreconditionError("validation_<n>.ply needs the report's model and sets (keep_sets)");
  }
  std::vector<ColouredPoint> points(n);
  for (size_t id = 0; id < n; ++id) {
    const bool captured = a.captured_set.test(id), predicted = a.predicted_set.test(id);
    const std::array<uint8_t, 3> rgb = captured && predicted ? kAgreeRgb
                                       : captured            ? kMissedRgb
                                       : predicted           ? kOverPredictedRgb
                                                             : kNeitherRgb;
    points[id] = {report.model.Center(id), rgb, 0.0f};
  }
  char resolution[32];
  std::snprintf(resolution, sizeof resolution, "%.6f", report.resolution_m);
  std::vector<std::string> comments = {"vc validate: the model's voxel centres (m); scan " + std::to_string(scan + 1) +
                                           ": " + a.name + "; test " +
                                           std::string(SelectionTestName(report.selection_test)),
                                       "colour: green 40 180 40 = agree (captured and predicted)",
                                       "colour: red 230 40 40 = missed (captured, not predicted)",
                                       "colour: blue 40 90 230 = over-predicted (predicted, not captured)",
                                       "colour: grey 160 160 160 = neither (another scan's voxel, not predicted)",
                                       std::string("resolution_m ") + resolution};
  if (!frame_origin_m.isZero()) {
    char origin[128];
    std::snprintf(origin, sizeof origin, "frame_origin_m %.3f %.3f %.3f", frame_origin_m.x(), frame_origin_m.y(),
                  frame_origin_m.z());
    comments.push_back(std::string(origin) + " (vertices are local: add it for the input's frame)");
  }
  return ColouredPointsPly(comments, points);
}

Status WriteValidationOutputs(const ValidationReport& report, const ValidateInputs& inputs, const LoadedScans& loaded,
                              const ScannerModel& scanner, const std::string& out_dir) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return InternalError(out_dir + ": cannot create the directory (" + ec.message() + ")");
  auto write = [](const std::filesystem::path& path, const std::string& bytes) -> Status {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) return InternalError(path.string() + ": cannot write the file");
    return Status::Ok();
  };
  const std::filesystem::path dir(out_dir);
  VC_RETURN_IF_ERROR(write(dir / "validation.json", ValidationToJson(report, inputs, loaded, scanner)));
  for (size_t i = 0; i < report.scans.size(); ++i) {
    VC_ASSIGN_OR_RETURN(const std::string ply, ValidationPly(report, i, loaded.frame_origin_m));
    VC_RETURN_IF_ERROR(write(dir / ("validation_" + std::to_string(i + 1) + ".ply"), ply));
  }
  return Status::Ok();
}

CLI::App* AddValidateCommand(CLI::App& app, ValidateCommand* command) {
  auto* validate = app.add_subcommand(
      "validate",
      "measure a selection test's prediction against your own scans, locally (no server: the scans are your "
      "files and the work is one visibility pass per scan): recall and precision per scan");
  validate
      ->add_option("FILES", command->inputs.files,
                   "E57 files (their scans and poses), or point files (PLY, PCD, XYZ, LAS), one scan per file")
      ->required();
  validate->add_option("--positions", command->inputs.positions_file,
                       "scanner positions of the point files, one per file in order (a stations CSV, a pose table "
                       "x,y,z[,yaw], an E57, a .graph or a PCD); default: each PCD's VIEWPOINT. The yaw (degrees) is "
                       "the scan's heading, which --hfov below 360 needs");
  validate->add_flag("--scanner-frame", command->inputs.scanner_frame,
                     "each point file is in its own scanner's frame: move it by its position and heading (yaw)");
  validate->add_option("--resolution", command->options.resolution_m, "voxel edge (m)")->capture_default_str();
  validate->add_option("--threads", command->options.threads, "threads for the visibility sets (0 = all)")
      ->capture_default_str();
  validate->add_option("--out", command->out_dir, "also write validation.json and validation_<n>.ply here");
  AddSelectionTestFlag(validate, &command->options.selection_test);
  AddScannerModelFlags(validate, &command->options.scanner);
  return validate;
}

int RunValidate(const ValidateCommand& command) {
  auto fail = [](const std::string& what, const Status& s) {
    std::cerr << "vc-client: " << what << ": " << s.message() << "\n";
    return int(wire::ToGrpcCode(s.code()));
  };
  Result<LoadedScans> loaded = LoadScans(command.inputs, command.options.scanner.min_range_m);
  if (!loaded.ok()) return fail("validate", loaded.status());
  ValidationOptions options = command.options;
  options.keep_sets = !command.out_dir.empty();
  Result<ValidationReport> report = ValidateAgainstScans(loaded->scans, options);
  if (!report.ok()) return fail("validate", report.status());
  std::fputs(ValidationTable(*report).c_str(), stdout);
  for (size_t i = 0; i < loaded->scans.size(); ++i) {
    if (loaded->dropped_near_scanner[i] == 0) continue;
    std::printf("scan %zu: %llu points nearer than min_range_m (%.2f m) to its scanner dropped (the platform's)\n",
                i + 1, static_cast<unsigned long long>(loaded->dropped_near_scanner[i]), options.scanner.min_range_m);
  }
  if (command.out_dir.empty()) return 0;
  const Status written = WriteValidationOutputs(*report, command.inputs, *loaded, options.scanner, command.out_dir);
  if (!written.ok()) return fail("cannot write the validation outputs", written);
  std::printf("wrote validation.json and validation_1..%zu.ply to %s\n", report->scans.size(), command.out_dir.c_str());
  return 0;
}

}  // namespace vc::client
