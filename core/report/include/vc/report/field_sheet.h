// fieldsheet.pdf: what a survey crew prints and takes to the site (docs/PLANNING.md,
// "fieldsheet.pdf"). One landscape page per floor: the floor's walls and objects in plan view (the
// slice heatmap.png draws), the numbered stations with their names and tripod heights (existing
// stations as squares, new ones as circles), the walking route with arrows, hatched keep-out zones,
// a scale bar, a north arrow, a legend in plain words, the plan's headline figures and the floor's
// station table; rows that do not fit continue on table pages after the floors. Where stations
// stand close, markers and names move aside with leader lines rather than cover each other. Drawn
// with cairo (Debian libcairo2-dev) in shapes and hatching that read in black and white, text in
// DejaVu Sans. The layout is computed apart from the drawing so tests can find a station's marker
// and label on its page.
// Pure functions of their arguments, each call drawing on its own cairo surface: thread-safe.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "vc/base/status.h"
#include "vc/plan/planner.h"
#include "vc/report/field_exports.h"
#include "vc/report/label_placement.h"

namespace vc {

// The sheet of paper, always landscape.
enum class PaperSize { kA3, kA4 };

struct FieldSheetOptions {
  PaperSize paper = PaperSize::kA3;
  // Angle from grid north (+y of the input's frame) to true north, degrees clockwise as seen from
  // above; NaN when unknown, and the sheet then shows grid north only (a CRS can supply it).
  double true_north_from_grid_deg = std::nan("");
};

// Where a station is drawn: its page (0-based) and the station's place in points (1/72 inch) from
// the page's top-left corner, and where its numbered marker and its name label went (PlaceLabels).
struct StationMarkerPlace {
  int page = 0;
  double x_pt = 0;
  double y_pt = 0;
  PlacedLabel number;  // the marker: centred on the station, or moved aside with a leader line to a dot there
  PlacedLabel name;    // "S03  h 1.60 m": beside the marker, or further out with a leader line to it
};

// The sheet's pages and where each station is drawn.
struct FieldSheetLayout {
  double page_width_pt = 0;  // landscape: the longer side
  double page_height_pt = 0;
  int floor_pages = 0;                      // one per floor panel, in ascending height
  int table_pages = 0;                      // continuation pages of station rows that did not fit on their floor's page
  double scale_denominator = 0;             // the drawing's scale 1:N on paper
  std::vector<StationMarkerPlace> markers;  // one per entry of the stations given, in their order
};

// The layout of fieldsheet.pdf for `result` and its field stations (FieldStations).
FieldSheetLayout ComputeFieldSheetLayout(const PlanResult& result, const std::vector<FieldStation>& stations,
                                         const FieldSheetOptions& options = {});

// fieldsheet.pdf's bytes. INTERNAL when cairo fails to draw.
Result<std::string> FieldSheetPdf(const PlanResult& result, const std::vector<FieldStation>& stations,
                                  const FieldSheetOptions& options = {});

}  // namespace vc
