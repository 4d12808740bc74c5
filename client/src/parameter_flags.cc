#include "vc/client/parameter_flags.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "vc/plan/keep_out.h"
#include "vc/report/plan_report.h"
#include "vc/scene/station_file.h"
#include "vc/visibility/scanner_presets.h"

namespace vc::client {
namespace {

std::string Help(const ParamInfo& info) {
  std::string help(info.help);
  if (!info.unit.empty()) help += " (" + std::string(info.unit) + ")";
  return help;
}

std::string Flag(const ParamInfo& info) { return "--" + std::string(info.flag); }

template <typename T>
void AddFlag(CLI::App* app, const ParamInfo& info, T* value) {
  app->add_option(Flag(info), *value, Help(info))->capture_default_str();
}

void AddFlag(CLI::App* app, const ParamInfo& info, bool* value) {
  app->add_flag(Flag(info) + ",!--no-" + std::string(info.flag), *value, Help(info))->capture_default_str();
}

// An enum flag that takes the value's name.
template <typename E>
void AddEnumFlag(CLI::App* app, const ParamInfo& info, E* value, const std::map<std::string, E>& names) {
  std::string shown, choices;
  for (const auto& [name, v] : names) {
    if (v == *value) shown = name;
    choices += (choices.empty() ? "" : "|") + name;
  }
  app->add_option(Flag(info), *value, Help(info))
      ->transform(CLI::CheckedTransformer(names, CLI::ignore_case).description(""))
      ->type_name(choices)
      ->default_str(shown);
}

void AddFlag(CLI::App* app, const ParamInfo& info, SelectionTest* value) {
  AddEnumFlag(app, info, value,
              {{"surface", SelectionTest::kSurfaceVisibility},
               {"compatibility", SelectionTest::kCompatibility},
               {"subvoxel", SelectionTest::kSubvoxel}});
}

void AddFlag(CLI::App* app, const ParamInfo& info, SelectionSolver* value) {
  AddEnumFlag(
      app, info, value,
      {{"greedy", SelectionSolver::kGreedy}, {"exact", SelectionSolver::kExact}, {"auto", SelectionSolver::kAuto}});
}

void AddFlag(CLI::App* app, const ParamInfo& info, GroundModel* value) {
  AddEnumFlag(app, info, value,
              {{"auto", GroundModel::kAuto}, {"floors", GroundModel::kFloors}, {"terrain", GroundModel::kTerrain}});
}

void AddFlag(CLI::App* app, const ParamInfo& info, FaceSet* value) {
  AddEnumFlag(app, info, value, {{"all", FaceSet::kAll}, {"exposed", FaceSet::kExposed}});
}

#define VC_ROW_FLAG(type, name, ...) AddFlag(command, VC_PARAMETER_INFO(type, name, __VA_ARGS__), &o->name);

// --scanner NAME and one flag per row. After the parse, a preset fills the rows whose flag was not
// given (CLI11's count), so an explicit flag overrides the preset and a flag's default never does.
void AddScannerFlags(CLI::App* command, ScannerModel* o) {
  std::vector<std::string> names;
  for (const ScannerPreset& p : ScannerPresets()) names.emplace_back(p.name);
  command
      ->add_option("--scanner", o->name,
                   "instrument preset (vc-client scanners lists them; docs/SCANNERS.md): its range, vertical field "
                   "of view and angular step, each overridden by its flag when given")
      ->check(CLI::IsMember(names))
      ->type_name("NAME");
  VC_SCANNER_PARAMETERS(VC_ROW_FLAG)
  command->callback([command, o] {
    if (o->name.empty()) return;
    Result<ScannerModel> preset = ScannerFromPreset(o->name);
    if (!preset.ok()) throw CLI::ValidationError("--scanner", preset.status().message());
#define VC_ROW_FROM_PRESET(type, name, default_value, unit, flag, ...) \
  if (command->get_option("--" flag)->count() == 0) o->name = preset->name;
    VC_SCANNER_PARAMETERS(VC_ROW_FROM_PRESET)
#undef VC_ROW_FROM_PRESET
  });
}

}  // namespace

void AddPlanFlags(CLI::App* command, PlanOptions* o) {
  VC_PLAN_PARAMETERS(VC_ROW_FLAG)
  // --min-gain-voxels-per-minute given alone takes the place of the default area rule; given with
  // --min-gain-m2-per-minute, both > 0 is PlanOptions::Validate's error naming both.
  CLI::Option* area_rule = command->get_option("--min-gain-m2-per-minute");
  command->get_option("--min-gain-voxels-per-minute")->each([o, area_rule](const std::string&) {
    if (area_rule->count() == 0) o->min_gain_m2_per_minute = 0;
  });
  command
      ->add_option("--tripod-heights", o->tripod_heights_m,
                   "several scanner heights above the floor, comma-separated (m); replaces --tripod-height")
      ->delimiter(',')
      ->type_name("H1,H2,...");
  AddScannerFlags(command, &o->scanner);
}

void AddEvaluateFlags(CLI::App* command, EvaluateJobOptions* o) {
  VC_EVALUATE_PARAMETERS(VC_ROW_FLAG)
  AddScannerFlags(command, &o->scanner);
}

void AddScannerModelFlags(CLI::App* command, ScannerModel* scanner) { AddScannerFlags(command, scanner); }

void AddSelectionTestFlag(CLI::App* command, SelectionTest* test) {
#define VC_ROW_IF_TEST(type, name, ...) \
  if (std::string_view(#name) == "selection_test") AddFlag(command, VC_PARAMETER_INFO(type, name, __VA_ARGS__), test);
  VC_PLAN_PARAMETERS(VC_ROW_IF_TEST)
#undef VC_ROW_IF_TEST
}

#undef VC_ROW_FLAG

std::string ScannerPresetsTable() {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-24s %-24s %-13s %-12s %-9s %-8s %s\n", "NAME", "INSTRUMENT", "RANGE (m)",
                "VFOV (deg)", "STEP (deg)", "SCAN (s)", "SETTING");
  out += line;
  for (const ScannerPreset& p : ScannerPresets()) {
    const ScannerModel& m = p.model;
    char range[32], vfov[32];
    std::snprintf(range, sizeof range, "%g-%g", m.min_range_m, m.max_range_m);
    std::snprintf(vfov, sizeof vfov, "%g..%g", m.vfov_min_deg, m.vfov_max_deg);
    std::snprintf(line, sizeof line, "%-24.*s %-24.*s %-13s %-12s %-9g %-8g %.*s\n", int(p.name.size()), p.name.data(),
                  int(p.display_name.size()), p.display_name.data(), range, vfov, m.angular_step_deg, p.scan_time_s,
                  int(p.setting.size()), p.setting.data());
    out += line;
  }
  return out;
}

void AddPlanFileFlags(CLI::App* command, PlanFileFlags* files) {
  command->add_option("--candidates", files->candidates, "CSV of candidate positions x,y,z (replaces the grid)");
  command->add_option("--fixed-stations", files->fixed_stations,
                      "stations already placed, the plan adds to them: a CSV with or without a header naming "
                      "x,y,z (e.g. stations.csv, or a pose table x,y,z,roll,pitch,yaw), an E57 file or an "
                      "OctoMap .graph (its scans' origins), or a PCD file (its VIEWPOINT)");
  command->add_option("--keep-out", files->keep_out,
                      "CSV of keep-out zones, one per line: xmin,ymin,zmin,xmax,ymax,zmax (a box; or box,xmin,...) or "
                      "polygon,zmin,zmax,x1,y1,...; an optional header line");
  command->add_option("--start", files->start,
                      "where the walking route starts: x,y (m; the lowest floor) or x,y,z (the floor nearest z)");
}

namespace {

// The whole file at `path`; NOT_FOUND naming `what` when it cannot be read.
Result<std::string> ReadText(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError("cannot read the " + what + " file " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// "x,y" or "x,y,z" (m) as a point, z NaN when absent; INVALID_ARGUMENT naming --start otherwise.
Result<WorldPoint> ParseStart(const std::string& text) {
  std::vector<std::string> fields;
  for (size_t pos = 0;;) {
    const size_t end = text.find(',', pos);
    fields.push_back(text.substr(pos, end == std::string::npos ? std::string::npos : end - pos));
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  double v[3] = {0, 0, std::numeric_limits<double>::quiet_NaN()};
  bool ok = fields.size() == 2 || fields.size() == 3;
  for (size_t k = 0; ok && k < fields.size(); ++k) {
    char* stop = nullptr;
    v[k] = std::strtod(fields[k].c_str(), &stop);
    ok = !fields[k].empty() && stop == fields[k].c_str() + fields[k].size() && std::isfinite(v[k]);
  }
  if (!ok) return InvalidArgumentError("--start must be \"x,y\" or \"x,y,z\" in metres, got \"" + text + "\"");
  return WorldPoint(v[0], v[1], v[2]);
}

}  // namespace

Result<PlanFileLines> LoadPlanFiles(const PlanFileFlags& files, PlanOptions* o) {
  PlanFileLines lines;
  if (!files.candidates.empty()) {
    VC_ASSIGN_OR_RETURN(std::string text, ReadText(files.candidates, "candidates"));
    VC_ASSIGN_OR_RETURN(o->candidates, ParseStationsCsv(text, files.candidates));
  }
  if (!files.fixed_stations.empty()) {
    VC_ASSIGN_OR_RETURN(const std::vector<KnownStation> stations, ReadStationFile(files.fixed_stations));
    o->fixed_stations.clear();
    for (const KnownStation& s : stations) {
      o->fixed_stations.push_back(s.position_m);
      lines.fixed_stations.push_back(s.source);
    }
  }
  if (!files.keep_out.empty()) {
    VC_ASSIGN_OR_RETURN(std::string text, ReadText(files.keep_out, "keep-out"));
    VC_ASSIGN_OR_RETURN(KeepOutFile zones, ParseKeepOutFile(text, files.keep_out));
    o->keep_out = std::move(zones.zones);
    lines.keep_out = std::move(zones.lines);
  }
  if (!files.start.empty()) {
    VC_ASSIGN_OR_RETURN(o->route_start, ParseStart(files.start));
  }
  return lines;
}

Result<std::vector<WorldPoint>> LoadViewpoints(const std::string& path) {
  VC_ASSIGN_OR_RETURN(const std::string text, ReadText(path, "viewpoints"));
  return ParseStationsCsv(text, path);
}

namespace {

// Each row's field path ("grid_spacing_m", "scanner.max_range_m") and its flag ("--grid-spacing").
using FlagTable = std::map<std::string, std::string, std::less<>>;

FlagTable ScannerFlags() {
  FlagTable flags;
#define VC_SCANNER_ROW_NAME(type, name, default_value, unit, flag, ...) flags.emplace("scanner." #name, "--" flag);
  VC_SCANNER_PARAMETERS(VC_SCANNER_ROW_NAME)
#undef VC_SCANNER_ROW_NAME
  return flags;
}

// "keep_out[2]" as {"keep_out", 2}; {path, npos} when it has no index.
std::pair<std::string_view, size_t> SplitIndex(std::string_view path) {
  const size_t open = path.find('[');
  if (open == std::string_view::npos || path.back() != ']') return {path, std::string_view::npos};
  size_t index = 0;
  for (char c : path.substr(open + 1, path.size() - open - 2)) {
    if (c < '0' || c > '9') return {path, std::string_view::npos};
    index = index * 10 + size_t(c - '0');
  }
  return {path.substr(0, open), index};
}

FieldNamer FlagNamer(FlagTable flags, PlanFileLines lines) {
  return [flags = std::move(flags), lines = std::move(lines)](std::string_view path) -> std::string {
    if (const auto row = flags.find(path); row != flags.end()) return row->second;
    const auto [list, i] = SplitIndex(path);
    if (i == std::string_view::npos) return path == "route_start" ? "--start" : std::string(path);
    const std::string n = std::to_string(i + 1);
    if (list == "keep_out") {
      return "--keep-out " + (i < lines.keep_out.size() ? "line " + std::to_string(lines.keep_out[i]) : "zone " + n);
    }
    if (list == "fixed_stations") {
      return "--fixed-stations " + (i < lines.fixed_stations.size() ? lines.fixed_stations[i] : "station " + n);
    }
    if (list == "candidates") return "--candidates point " + n;
    if (list == "tripod_heights_m") return "--tripod-heights value " + n;
    return std::string(path);
  };
}

}  // namespace

#define VC_ROW_NAME(type, name, default_value, unit, flag, ...) flags.emplace(#name, "--" flag);

FieldNamer PlanFlagNamer(PlanFileLines lines) {
  FlagTable flags = ScannerFlags();
  VC_PLAN_PARAMETERS(VC_ROW_NAME)
  return FlagNamer(std::move(flags), std::move(lines));
}

std::string NameListEntries(std::string_view message, const FieldNamer& namer) {
  std::string out;
  size_t pos = 0;
  while (pos < message.size()) {
    // A path: a lower-case name and an index in brackets ("fixed_stations[12]").
    const size_t open = message.find('[', pos);
    const size_t close = open == std::string_view::npos ? open : message.find(']', open);
    if (close == std::string_view::npos) break;
    size_t start = open;
    while (start > pos && (std::islower(static_cast<unsigned char>(message[start - 1])) || message[start - 1] == '_')) {
      --start;
    }
    const std::string_view path = message.substr(start, close + 1 - start);
    const bool indexed = start < open && SplitIndex(path).second != std::string_view::npos;
    out.append(message.substr(pos, start - pos));
    out += indexed ? namer(path) : std::string(path);
    pos = close + 1;
  }
  out.append(message.substr(std::min(pos, message.size())));
  return out;
}

FieldNamer EvaluateFlagNamer() {
  FlagTable flags = ScannerFlags();
  VC_EVALUATE_PARAMETERS(VC_ROW_NAME)
  return FlagNamer(std::move(flags), {});
}

#undef VC_ROW_NAME

}  // namespace vc::client
