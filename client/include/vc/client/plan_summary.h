// What vc-client prints after a plan: the stations, the scan graph, the walking route and the
// field time. Stations are numbered from 1 in plan order, as on heatmap.png.
#pragma once

#include <string>

#include "vc/plan/planner.h"

namespace vc::client {

// The summary lines, each ending in '\n'.
std::string PlanSummary(const PlanResult& result);

// A duration as a crew reads it: "45 s", "12 min", "1 h 05 min".
std::string FormatDuration(double seconds);

}  // namespace vc::client
