// vc-client's parameter flags, derived from the parameter tables (vc/base/parameter.h): one
// `--<flag>` per row, with the row's help, unit and default; bools as `--<flag>` / `--no-<flag>`;
// enums by name (`--test surface|compatibility`, `--faces all|exposed`). The scanner's rows are
// added with the plan's and the evaluation's, with `--scanner NAME` (an instrument preset,
// vc/visibility/scanner_presets.h): the preset fills every scanner row whose flag is not given, so
// explicit flags override it. The client resolves the preset itself and sends the name with every
// field, which the server then takes as they are (docs/SCANNERS.md). `--tripod-heights 1.2,1.6,2.0`
// comes with the plan's rows. The plan's file lists (`--candidates`, `--fixed-stations`,
// `--keep-out`) are PlanFileFlags, read by LoadPlanFiles; the evaluation's viewpoints by main.cc.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "vc/base/status.h"
#include "vc/plan/evaluate_job.h"
#include "vc/plan/plan_options.h"

namespace vc::client {

// Binds every row of VC_PLAN_PARAMETERS and VC_SCANNER_PARAMETERS, and --scanner, to `options`
// (which must outlive the parse); the defaults shown are options' current values. Sets `command`'s
// callback, which applies the preset after the parse: a command that needs its own callback must
// call the one set here first. An unknown --scanner is a CLI::ValidationError.
void AddPlanFlags(CLI::App* command, PlanOptions* options);
// The same for VC_EVALUATE_PARAMETERS and VC_SCANNER_PARAMETERS.
void AddEvaluateFlags(CLI::App* command, EvaluateJobOptions* options);

// Binds --scanner and every row of VC_SCANNER_PARAMETERS to `scanner`, as AddPlanFlags does (the
// same callback rule), for a command that takes the scanner's limits without a plan's rows.
void AddScannerModelFlags(CLI::App* command, ScannerModel* scanner);
// Binds the plan's --test row (the selection test by name, surface|compatibility) to `test`.
void AddSelectionTestFlag(CLI::App* command, SelectionTest* test);

// `vc-client scanners`: one line per preset (name, instrument, range, vertical field of view,
// angular step, scan time, the setting those are for) under a header line.
std::string ScannerPresetsTable();

// The plan's list parameters that come from files (paths; empty = not given).
struct PlanFileFlags {
  std::string candidates;      // stations.csv format: user candidates
  std::string fixed_stations;  // stations already placed: any file ReadStationFile reads (vc/scene/station_file.h)
  std::string keep_out;        // keep-out CSV (docs/PLANNING.md, "Keep-out zones")
  std::string start;           // "x,y" or "x,y,z" (m): where the walking route starts
};
// Binds --candidates, --fixed-stations, --keep-out and --start to `files` (which must outlive the
// parse).
void AddPlanFileFlags(CLI::App* command, PlanFileFlags* files);
// Where LoadPlanFiles found the zones, for messages that name them by line.
struct PlanFileLines {
  std::vector<size_t> keep_out;             // keep_out[i]: the line of zone i in the --keep-out file
  std::vector<std::string> fixed_stations;  // fixed_stations[i]: where station i was read ("file:line", "file, scan 3")
};
// Reads the files named in `files` into options->candidates, fixed_stations and keep_out, and the
// start into options->route_start (z NaN when only x,y is given). NOT_FOUND / INVALID_ARGUMENT
// (naming file:line, or --start) from reading and parsing.
[[nodiscard]] Result<PlanFileLines> LoadPlanFiles(const PlanFileFlags& files, PlanOptions* options);

// evaluate's --viewpoints file (stations.csv format). NOT_FOUND / INVALID_ARGUMENT (naming
// file:line) from reading and parsing.
[[nodiscard]] Result<std::vector<WorldPoint>> LoadViewpoints(const std::string& path);

// The names vc-client's messages give the fields PlanOptions::Validate and
// EvaluateJobOptions::Validate check (vc/base/parameter.h, FieldNamer): each row by its flag
// ("scanner.max_range_m" -> "--max-range"), a keep-out zone by its line ("keep_out[0]" ->
// "--keep-out line 2"), a fixed station by where it was read ("fixed_stations[0]" ->
// "--fixed-stations stations.csv:2"), a list entry by its place ("fixed_stations[0]" without its
// source -> "--fixed-stations station 1", "tripod_heights_m[1]" -> "--tripod-heights value 2"),
// route_start as --start. So
// the client checks before it uploads, with the server's own rules, in the user's words.
[[nodiscard]] FieldNamer PlanFlagNamer(PlanFileLines lines = {});
// `message` (the server's, or Validate's without a namer) with each list entry it names by path
// ("fixed_stations[2]", "keep_out[0]", "candidates[4]") named as `namer` names it
// ("--fixed-stations stations.csv:4"), so a message about a file's entry names its line.
[[nodiscard]] std::string NameListEntries(std::string_view message, const FieldNamer& namer);
[[nodiscard]] FieldNamer EvaluateFlagNamer();

}  // namespace vc::client
