// What vc-client prints after a plan: the stations, how far from the optimum, the scan graph, the walking route and the
// field time. Stations are numbered from 1 in plan order, as on heatmap.png.
#pragma once

#include <string>

#include "vc/plan/planner.h"

namespace vc::client {

// The summary lines, each ending in '\n'; positions in the input's frame (PlanResult::frame_origin_m added).
std::string PlanSummary(const PlanResult& result);

// The coverage table: for 80, 90, 95 and 99 % of the coverable voxels, the scene's share, the
// stations (the plan's first k) and their set-up and scan time ("not reached by this plan" where
// the plan stops short); "" without a coverage curve (an older server).
std::string CoverageTable(const PlanResult& result);
// Which rule stopped station selection, one line ("stopped: target coverage 99 % reached ...").
std::string StopLine(const PlanResult& result);

// How far the selection is from the optimum, one line ("optimal: 37 stations, proven", "37 stations,
// at most 4 more than the optimum (bound 33)"; empty for a greedy selection without a bound),
// after a line on the local-candidates loop when it ran.
std::string OptimalityLine(const PlanResult& result);
// "fanned out: N shard(s) on R replica(s), ..." for a plan fanned out over replicas (visibility and
// reduction shards together); "" otherwise.
std::string DistributionLine(const PlanResult& result);

// Each stage's wall time and the server's peak resident memory during it ("stages: voxelize 0.21 s
// (peak 312 MiB), ...; total 12.30 s"; no peak where the server measured none); "" without timings.
std::string TimingLine(const PlanResult& result);

// A duration as a crew reads it: "45 s", "12 min", "1 h 05 min".
std::string FormatDuration(double seconds);

}  // namespace vc::client
