// vc-client's parameter flags, derived from the parameter tables (vc/base/parameter.h): one
// `--<flag>` per row, with the row's help, unit and default; bools as `--<flag>` / `--no-<flag>`;
// enums by name (`--test surface|compatibility`, `--faces all|exposed`). The scanner's rows are
// added with the plan's and the evaluation's. Lists (candidates, viewpoints) are files, added by
// main.cc.
#pragma once

#include <CLI/CLI.hpp>

#include "vc/plan/evaluate_job.h"
#include "vc/plan/plan_options.h"

namespace vc::client {

// Binds every row of VC_PLAN_PARAMETERS and VC_SCANNER_PARAMETERS to `options` (which must outlive
// the parse); the defaults shown are options' current values.
void AddPlanFlags(CLI::App* command, PlanOptions* options);
// The same for VC_EVALUATE_PARAMETERS and VC_SCANNER_PARAMETERS.
void AddEvaluateFlags(CLI::App* command, EvaluateJobOptions* options);

}  // namespace vc::client
