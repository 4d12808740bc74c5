// report.html: one self-contained web page showing a plan in 3D (docs/PLANNING.md, "Output
// files"). It opens offline in any browser with WebGL: three.js r111 (Debian's libjs-three, embedded
// into the binary at build time), the page's script and style, and the plan's data are all inlined.
//
// The page draws the occupied voxels coloured by their best V (visibility.ply's colours; at most
// ReportHtmlOptions::max_points of them, a deterministic pseudo-random subset when there are more),
// the stations as numbered markers (plan order, 1-based, as heatmap.png), the scan graph's edges,
// the walking route, the keep-out zones as translucent boxes and a metre grid on the floor; a
// floor selector (fieldsheet.pdf's floors and names) shows one floor's voxels, stations and table
// rows; the side panel holds plan.json's figures, the station table (name, floor, tripod height
// and walking order as fieldsheet.pdf and stations.csv give them), the keep-out zones, the
// coverage curve (an inline SVG with the 80/90/95/99 % milestones) and a glossary in plain
// words. Clicking a station highlights the voxels only it sees (Evaluation::sole_viewer). Printed,
// the page drops its controls and keeps a snapshot of the view, the tables, the curve and the
// glossary.
//
// Data is inlined as JSON with the bulk arrays in base64 (positions quantised to uint16 steps of
// the resolution), in the plan's local frame (WebGL's float32 cannot hold survey coordinates); the
// page adds PlanResult::frame_origin_m wherever it shows a coordinate; every string from the plan (warnings, names) is
// JSON-escaped with '<', '>' and
// '&' as \u escapes, so it can neither end the <script> element nor inject markup, and the page
// inserts it as text, never as HTML. Stateless; safe to call from several threads.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "vc/plan/planner.h"

namespace vc {

struct ReportHtmlOptions {
  // Most voxels drawn: 300,000 points stay smooth on a laptop's integrated GPU (and keep the file
  // a few MB); a larger scene shows a deterministic pseudo-random subset of this size.
  size_t max_points = 300000;
  // The fixed stations' names, in PlanOptions::fixed_stations order, as FieldStations takes them.
  std::vector<std::string> fixed_station_names;
};

// report.html's content for `result`. Uses result.voxel_centers with
// result.evaluation.best_face_values (the shorter of the two; none drawn when either is empty) and
// result.evaluation.sole_viewer when it has one entry per voxel (else the page says the
// highlight is unavailable).
std::string PlanToHtml(const PlanResult& result, const ReportHtmlOptions& options = {});

}  // namespace vc
