// evaluate's --plan: the stations, the scanner, the resolution and the CRS of a plan.json that
// submit wrote, so an evaluation of a plan needs no scanner or resolution flags repeated. Flags
// given explicitly override the plan's scanner row by row (TakeScannerFromPlan) and its resolution
// (TakeResolutionFromPlan), and the client says which ones differ.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"
#include "vc/visibility/visibility.h"

namespace vc::client {

// What an evaluation takes from a plan.json (schema vc.plan/1, docs/PLANNING.md).
struct PlanForEvaluation {
  // viewpoints[i].x, y, z: each station's instrument centre in the input's frame (m), in plan.json order.
  std::vector<WorldPoint> stations;
  // parameters.scanner: every row of VC_SCANNER_PARAMETERS (null = the limit off) and the preset's name.
  ScannerModel scanner;
  // crs.definition; empty when the plan names no CRS.
  std::string crs_definition;
  // resolution_m: the voxel size the plan ran at (m).
  double resolution_m = 0;
};

// Parses plan.json's `text`. INVALID_ARGUMENT naming `source` and the field ("plan.json:
// viewpoints[2].z is not a number") when the text is not JSON, not a vc.plan/1 plan, has no
// station, or lacks a field the evaluation needs.
[[nodiscard]] Result<PlanForEvaluation> ParsePlanForEvaluation(std::string_view text, const std::string& source);
// Reads and parses the plan.json at `path`: NOT_FOUND when it cannot be read, else as ParsePlanForEvaluation.
[[nodiscard]] Result<PlanForEvaluation> LoadPlanForEvaluation(const std::string& path);

// Sets each scanner row of `scanner` (bound to `command`'s flags by AddEvaluateFlags) whose flag
// was not given to the plan's value; all of them unless --scanner was given, whose preset then
// stands for the flags. One line per given flag whose value differs from the plan's
// ("--max-range 30 m (the plan: 10 m)"), in row order.
std::vector<std::string> TakeScannerFromPlan(const CLI::App& command, const ScannerModel& plan_scanner,
                                             ScannerModel* scanner);
// Sets `resolution_m` (bound to `command`'s --resolution) to the plan's unless --resolution was
// given; then, when the two differ, the line that says so ("--resolution 0.2 m (the plan: 0.1 m)").
std::vector<std::string> TakeResolutionFromPlan(const CLI::App& command, double plan_resolution_m,
                                                double* resolution_m);

}  // namespace vc::client
