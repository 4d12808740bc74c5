#include "vc/report/plan_report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <unordered_set>

#include "floor_plan.h"
#include "raster.h"
#include "vc/plan/keep_out.h"
#include "vc/report/field_exports.h"
#include "vc/report/field_sheet.h"
#include "vc/report/report_html.h"

namespace vc {

namespace {

using Json = nlohmann::ordered_json;
using raster::Image;
using raster::Rgb;

// ---------- plan.json ----------

Json Point(const WorldPoint& p) { return Json::array({p.x(), p.y(), p.z()}); }

// A result's local position in the input's own frame (PlanResult::frame_origin_m added). A zero
// origin leaves the bits as they are (-0.0 + 0.0 would print as 0), so such a plan writes as before.
WorldPoint InputFrame(const PlanResult& r, const WorldPoint& local) {
  return r.frame_origin_m.isZero() ? local : WorldPoint(local + r.frame_origin_m);
}
// A result's local height (a floor level) in the input's own frame; NaN stays NaN.
double InputFrameZ(const PlanResult& r, double local_z) {
  return r.frame_origin_m.z() == 0 ? local_z : local_z + r.frame_origin_m.z();
}
// Heights in the input's own frame.
std::vector<double> InputFrameZ(const PlanResult& r, const std::vector<double>& local_z) {
  std::vector<double> out;
  out.reserve(local_z.size());
  for (double z : local_z) out.push_back(InputFrameZ(r, z));
  return out;
}

Json FiguresJson(const VisibilityFigures& f) {
  return Json{{"global_visibility", f.global_visibility},
              {"fully_visible_fraction", f.fully_visible_fraction},
              {"mean_full_visibility", f.mean_full_visibility},
              {"partially_visible_fraction", f.partially_visible_fraction}};
}

// A parameter row's value in plan.json: numbers and bools as they are, enums by name.
template <typename T>
Json ParameterJson(T v) {
  return Json(v);
}
Json ParameterJson(SelectionTest t) { return std::string(SelectionTestName(t)); }
Json ParameterJson(SelectionSolver s) { return std::string(SelectionSolverName(s)); }
Json ParameterJson(GroundModel m) { return std::string(GroundModelName(m)); }

// plan.json's `ground` (docs/PLANNING.md, "Terrain"): the model the candidates used and why; null
// when the user passed the candidates.
Json GroundJson(const planner::GroundChoice& g) {
  if (g.model == GroundModel::kAuto) return nullptr;
  return Json{{"model", std::string(GroundModelName(g.model))}, {"floor_share", g.floor_share}, {"reason", g.reason}};
}

// plan.json's `optimality` (docs/PLANNING.md, "Exact selection").
Json OptimalityJson(const planner::Optimality& o) {
  auto size = [](const planner::ModelSize& m) {
    return Json{{"candidates", m.candidates}, {"voxel_classes", m.voxel_classes}, {"rows", m.rows}};
  };
  Json j{{"solver", o.solver},     {"status", std::string(planner::OptimalityStatusName(o.status))},
         {"stations", o.stations}, {"lower_bound", o.lower_bound},
         {"gap", o.gap},           {"seconds", o.seconds},
         {"model", size(o.model)}, {"before", size(o.before)},
         {"forced", o.forced},     {"dominated", o.dominated}};
  if (o.covered_bound > 0) j["covered_bound"] = o.covered_bound;
  if (!o.note.empty()) j["note"] = o.note;
  const planner::LocalCandidatesReport& l = o.local_candidates;
  if (!l.stations_per_solve.empty()) {
    j["local_candidates"] = {{"rounds", l.rounds},
                             {"added", l.added},
                             {"stations_per_solve", l.stations_per_solve},
                             {"covered_per_solve", l.covered_per_solve}};
    if (!l.coarse_to_fine.empty()) j["local_candidates"]["coarse_to_fine"] = l.coarse_to_fine;
  }
  return j;
}

#define VC_ROW_TO_JSON(type, name, ...) j[#name] = ParameterJson(o.name);

// The limits that are off are null (docs/PLANNING.md "The scanner model"), and so is the name of
// a custom model (docs/SCANNERS.md).
Json ScannerJson(const ScannerModel& o) {
  Json j = Json::object();
  VC_SCANNER_PARAMETERS(VC_ROW_TO_JSON)
  j["name"] = o.name.empty() ? Json(nullptr) : Json(o.name);
  if (!o.HasVerticalFieldOfView()) j["vfov_min_deg"] = j["vfov_max_deg"] = nullptr;
  if (!o.HasIncidenceLimit()) j["max_incidence_deg"] = nullptr;
  if (!o.HasSpacingLimit()) j["max_spacing_m"] = nullptr;
  if (!o.HasHorizontalFieldOfView()) j["hfov_deg"] = nullptr;
  if (!(o.angular_step_deg > 0)) j["angular_step_deg"] = nullptr;
  return j;
}

// A keep-out zone: {"box": {"min": [x, y, z], "max": [x, y, z]}} or
// {"polygon": {"z_min_m": z, "z_max_m": z, "xy_m": [x1, y1, ...]}}.
Json KeepOutJson(const KeepOutZone& z) {
  if (z.shape == KeepOutShape::kBox) {
    return {{"box", {{"min", {z.min.x(), z.min.y(), z.min.z()}}, {"max", {z.max.x(), z.max.y(), z.max.z()}}}}};
  }
  return {{"polygon", {{"z_min_m", z.min.z()}, {"z_max_m", z.max.z()}, {"xy_m", z.polygon_xy_m}}}};
}

// Every row of VC_PLAN_PARAMETERS, the scanner, the number of user candidates, the tripod heights,
// the keep-out zones and the fixed stations.
Json ParametersJson(const PlanOptions& o) {
  Json j = Json::object();
  VC_PLAN_PARAMETERS(VC_ROW_TO_JSON)
  j["scanner"] = ScannerJson(o.scanner);
  j["user_candidates"] = o.candidates.size();
  j["tripod_heights_m"] = o.tripod_heights_m;
  Json zones = Json::array();
  for (const KeepOutZone& z : o.keep_out) zones.push_back(KeepOutJson(z));
  j["keep_out"] = std::move(zones);
  Json fixed = Json::array();
  for (const WorldPoint& p : o.fixed_stations) fixed.push_back({p.x(), p.y(), p.z()});
  j["fixed_stations"] = std::move(fixed);
  // z NaN (the lowest floor) is written as null.
  j["route_start"] = o.route_start ? Point(*o.route_start) : Json(nullptr);
  return j;
}

#undef VC_ROW_TO_JSON

Status WriteFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) return FailedPreconditionError("cannot open " + path.string() + " for writing");
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  f.close();
  if (!f) return InternalError("writing " + path.string() + " failed");
  return Status::Ok();
}

Status MakeDir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return FailedPreconditionError("cannot create directory " + dir + ": " + ec.message());
  return Status::Ok();
}

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string Short(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

// Per station: its place in the route (1 = visited first), or 0 when the route leaves it out.
std::vector<int> RoutePositions(const PlanResult& r) {
  std::vector<int> position(r.stations.size(), 0);
  for (size_t k = 0; k < r.route.order.size(); ++k) {
    const int s = r.route.order[k];
    if (s >= 0 && static_cast<size_t>(s) < position.size()) position[s] = static_cast<int>(k) + 1;
  }
  return position;
}

// ---------- visibility.ply ----------

// Voxel centres in the input's own frame; double coordinates when that frame's origin is not zero
// (float holds survey coordinates only to half a metre), float otherwise.
std::string VisibilityPly(const PlanResult& r) {
  const size_t n = std::min(r.voxel_centers.size(), r.evaluation.best_face_values.size());
  const bool shifted = !r.frame_origin_m.isZero();
  std::vector<ColouredPoint> points(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& faces = r.evaluation.best_face_values[i];
    const float v = *std::max_element(faces.begin(), faces.end());
    points[i] = {InputFrame(r, r.voxel_centers[i]), v > 0 ? raster::Viridis(v) : Rgb{128, 128, 128}, v};
  }
  std::vector<std::string> comments = {
      "vc visibility: occupied voxel centres (m); visibility = best V over the voxel's 6 faces",
      "colour: viridis of visibility in [0, 1]; grey = seen by no station (V = 0)",
      "resolution_m " + Fixed(r.resolution_m, 6)};
  if (shifted) {
    comments.push_back("frame_origin_m " + Fixed(r.frame_origin_m.x(), 3) + " " + Fixed(r.frame_origin_m.y(), 3) + " " +
                       Fixed(r.frame_origin_m.z(), 3) + " (coordinates are in the input's frame)");
  }
  return ColouredPointsPly(comments, points, "visibility", shifted ? PlyCoordinates::kDouble : PlyCoordinates::kFloat);
}

// ---------- heatmap.png ----------

// Layout constants (pixels), documented in docs/PLANNING.md.
constexpr int kMarginLeft = 64, kMarginTop = 40, kMarginBottom = 60, kPanelRight = 24, kLegendWidth = 110;
constexpr int kMinPlotHeight = 180, kTargetPlot = 720;
constexpr int kDotRadius = 3;   // the dot at a station whose numbered disc is moved aside
constexpr int kHatchPitch = 6;  // pixels between a keep-out zone's hatch lines, along a row

struct HeatLayout : floor_plan::Floors {
  HeatmapMeaning meaning = HeatmapMeaning::kSeenFromCandidates;
  double cell_m = 1;
  double ppm = 10;  // pixels per metre
  int plot_w = 0, plot_h = 0;
  int width = 0, height = 0;
};

using floor_plan::HighestTripodHeight;

// Pixel positions on heatmap.png: a panel's plot, and a local (x, y) in metres on it.
struct HeatPixels {
  const HeatLayout& L;
  int PanelLeft(int panel) const { return panel * (kMarginLeft + L.plot_w + kPanelRight) + kMarginLeft; }
  int X(int panel, double x) const { return PanelLeft(panel) + static_cast<int>(std::lround((x - L.x0) * L.ppm)); }
  int Y(double y) const { return kMarginTop + static_cast<int>(std::lround((L.y1 - y) * L.ppm)); }
  // The local (x, y) in metres at the centre of pixel (x, y) of `panel`.
  double LocalX(int panel, int x) const { return L.x0 + (x - PanelLeft(panel)) / L.ppm; }
  double LocalY(int y) const { return L.y1 - (y - kMarginTop) / L.ppm; }
};

// The floor plan's shade of a column whose highest voxel in the band stands `above` metres over
// the floor: light grey for low objects, near black for what reaches the tripod (walls).
Rgb FloorPlanShade(double above, double top) {
  const uint8_t g = floor_plan::SliceGrey(above, top);
  return Rgb{g, g, g};
}

// Panels and footprint as floor_plan::ComputeFloors finds them, drawn at a whole number of pixels
// per metre.
HeatLayout ComputeHeatLayout(const PlanResult& r) {
  HeatLayout L;
  L.cell_m = r.heat_map.grid_spacing_m > 0 ? r.heat_map.grid_spacing_m : 1.0;
  static_cast<floor_plan::Floors&>(L) = floor_plan::ComputeFloors(r, L.cell_m / 2);
  const double extent = std::max({L.x1 - L.x0, L.y1 - L.y0, 1e-3});
  L.ppm = std::clamp(std::floor(kTargetPlot / extent), 4.0, 200.0);
  L.plot_w = static_cast<int>(std::ceil((L.x1 - L.x0) * L.ppm));
  L.plot_h = static_cast<int>(std::ceil((L.y1 - L.y0) * L.ppm));
  const int panels = static_cast<int>(L.panel_z.size());
  L.width = panels * (kMarginLeft + L.plot_w + kPanelRight) + kLegendWidth;
  L.height = kMarginTop + std::max(L.plot_h, kMinPlotHeight) + kMarginBottom;
  return L;
}

// A tick step from 1, 2, 5 x 10^k metres with at least `min_px` pixels between ticks.
double TickStep(double ppm, double min_px) {
  for (double decade = 0.01; decade < 1e6; decade *= 10) {
    for (double m : {1.0, 2.0, 5.0}) {
      if (m * decade * ppm >= min_px) return m * decade;
    }
  }
  return 1e6;
}

std::string TickLabel(double v, double step) {
  if (std::fabs(v) < step * 1e-6) v = 0;
  return step >= 1 ? Fixed(v, 0) : Fixed(v, step >= 0.1 ? 1 : 2);
}

// The radius (pixels) of station `number`'s disc: room for the number.
int DiscRadius(int number) { return std::max(10, raster::TextWidth(std::to_string(number)) / 2 + 5); }

// A numbered station disc: white, ringed in `ring`, black number.
void StationDisc(Image& img, int cx, int cy, int number, Rgb ring) {
  const std::string label = std::to_string(number);
  const int radius = DiscRadius(number);
  img.FillCircle(cx, cy, radius + 1, ring);
  img.FillCircle(cx, cy, radius - 1, raster::kWhite);
  img.Text(cx - raster::TextWidth(label) / 2, cy - raster::kGlyphH / 2, label, raster::kBlack);
}

// A colour bar's tick: its height as a fraction of the bar (0 bottom, 1 top) and its label.
struct BarTick {
  double fraction = 0;
  std::string label;
};

// A vertical colour bar at (x, y) of size 16 x h, viridis from 0 (bottom) to 1 (top), with its
// ticks and, above it, its title lines (the last one 14 pixels over the bar).
void ColourBar(Image& img, int x, int y, int h, const std::vector<BarTick>& ticks,
               const std::vector<std::string>& title) {
  for (int k = 0; k < h; ++k) img.HLine(x, x + 15, y + h - 1 - k, raster::Viridis(h > 1 ? double(k) / (h - 1) : 0));
  img.StrokeRect(x, y, x + 16, y + h, raster::kBlack);
  for (const BarTick& t : ticks) {
    const int ty = y + h - 1 - static_cast<int>(std::lround((h - 1) * t.fraction));
    img.HLine(x + 16, x + 19, ty, raster::kBlack);
    img.Text(x + 22, ty - 3, t.label, raster::kBlack);
  }
  for (size_t i = 0; i < title.size(); ++i) {
    img.Text(x - 2, y - 14 - 12 * static_cast<int>(title.size() - 1 - i), title[i], raster::kBlack);
  }
}

// Ticks at a quarter, a half, ... of `max_value`, labelled with the value.
std::vector<BarTick> QuarterTicks(double max_value, bool integer) {
  std::vector<BarTick> ticks;
  for (int i = 0; i <= 4; ++i) {
    const double v = max_value * i / 4.0;
    ticks.push_back({i / 4.0, integer ? Fixed(std::round(v), 0) : Short(v)});
  }
  return ticks;
}

// The smallest step of 1, 2 or 5 x 10^k that divides `span` into at most `max_steps` steps.
double RoundStep(double span, int max_steps) {
  for (double decade = 1e-3; decade < 1e6; decade *= 10) {
    for (double m : {1.0, 2.0, 5.0}) {
      if (span / (m * decade) <= max_steps) return m * decade;
    }
  }
  return 1e6;
}

// heatmap.png's colour bar in plain words: the share of the scene's occupied voxels a tripod at
// the cell sees, in per cent at round steps (1, 2, 5 x 10^k, at most 5 steps), with the top's
// value and its voxel count under the bar; in voxels when the plan does not give the scene's size
// (or its counts exceed it).
void HeatColourBar(Image& img, const HeatLayout& L, const PlanResult& r, uint64_t max_count) {
  const int x = L.width - kLegendWidth + 20, y = kMarginTop + 14;
  const int h = std::max(L.plot_h, kMinPlotHeight) - 14;
  if (L.meaning == HeatmapMeaning::kMissedByStations) {
    ColourBar(img, x, y, h, QuarterTicks(static_cast<double>(max_count), true), {"VOXELS NO", "STATION SEES"});
    return;
  }
  if (max_count == 0 || r.occupied_voxels < max_count) {
    ColourBar(img, x, y, h, QuarterTicks(static_cast<double>(max_count), true), {"VOXELS SEEN", "FROM HERE"});
    return;
  }
  const double top_pct = 100.0 * static_cast<double>(max_count) / static_cast<double>(r.occupied_voxels);
  const double step = RoundStep(top_pct, 5);
  const int decimals = step >= 1 ? 0 : step >= 0.1 ? 1 : step >= 0.01 ? 2 : 3;
  std::vector<BarTick> ticks;
  for (int i = 0; i * step <= top_pct * (1 + 1e-9); ++i)
    ticks.push_back({i * step / top_pct, Fixed(i * step, decimals) + " %"});
  ColourBar(img, x, y, h, ticks, {"SEEN FROM HERE", "% OF THE SCENE"});
  img.Text(x - 2, y + h + 8, "TOP: " + Fixed(top_pct, 1) + " % =", raster::kBlack);
  img.Text(x - 2, y + h + 20, std::to_string(max_count) + " VOXELS", raster::kBlack);
}

// The overlap from which heatmap.png draws a scan graph edge: min_overlap, or 0.3 (the usual
// target-less registration figure) when registration is off.
double ScanGraphDrawThreshold(const PlanResult& r) {
  return r.scan_graph.min_overlap > 0 ? r.scan_graph.min_overlap : 0.3;
}

// Panel `panel`'s floor plan over its cells (so that a cell reaching into a wall does not hide
// it), under the edges, route and stations: each voxel column of the band shaded by the height of
// its highest voxel, at least one pixel wide.
void DrawFloorPlan(Image& img, const HeatLayout& L, const PlanResult& r, int panel, int left, int top) {
  if (r.resolution_m <= 0) return;
  std::vector<float> above(size_t(L.plot_w) * size_t(L.plot_h), -1.f);  // per plot pixel, the highest
  const double half = r.resolution_m / 2;
  for (const WorldPoint& v : r.voxel_centers) {
    if (!((floor_plan::SlicePanels(L, r, v.z()) >> panel) & 1)) continue;
    const auto h = static_cast<float>(v.z() - L.floor_m[size_t(panel)]);
    const int x0 = static_cast<int>(std::floor((v.x() - half - L.x0) * L.ppm));
    const int y0 = static_cast<int>(std::floor((L.y1 - v.y() - half) * L.ppm));
    const int x1 = std::max(x0 + 1, static_cast<int>(std::ceil((v.x() + half - L.x0) * L.ppm)));
    const int y1 = std::max(y0 + 1, static_cast<int>(std::ceil((L.y1 - v.y() + half) * L.ppm)));
    for (int y = std::max(y0, 0); y < std::min(y1, L.plot_h); ++y)
      for (int x = std::max(x0, 0); x < std::min(x1, L.plot_w); ++x) {
        float& a = above[size_t(y) * size_t(L.plot_w) + size_t(x)];
        a = std::max(a, h);
      }
  }
  const double highest = HighestTripodHeight(r);
  for (int y = 0; y < L.plot_h; ++y)
    for (int x = 0; x < L.plot_w; ++x) {
      const float a = above[size_t(y) * size_t(L.plot_w) + size_t(x)];
      if (a >= 0) img.Set(left + x, top + y, FloorPlanShade(a, highest));
    }
}

// Panel `panel`'s keep-out zones (those whose z range meets its slice), over the floor plan and
// clipped to the plot: hatched with black diagonals and outlined in black 2 pixels inside the
// zone's edge. True when it drew one.
bool DrawKeepOutZones(Image& img, const HeatLayout& L, const PlanResult& r, int panel) {
  const HeatPixels P{L};
  const int left = P.PanelLeft(panel), top = kMarginTop;
  bool drawn = false;
  for (const KeepOutZone& z : r.options.keep_out) {
    if (!floor_plan::ZoneOnPanel(L, r, z, panel)) continue;
    const WorldPoint lo = z.min - r.frame_origin_m, hi = z.max - r.frame_origin_m;
    // The zone's pixels, with 2 pixels around them to find its edge; clipped to the plot.
    const int x0 = std::max(left, P.X(panel, lo.x()) - 3), x1 = std::min(left + L.plot_w - 1, P.X(panel, hi.x()) + 3);
    const int y0 = std::max(top, P.Y(hi.y()) - 3), y1 = std::min(top + L.plot_h - 1, P.Y(lo.y()) + 3);
    if (x0 > x1 || y0 > y1) continue;
    const int w = x1 - x0 + 5, h = y1 - y0 + 5;  // the clipped box and 2 pixels each side
    std::vector<char> inside(size_t(w) * size_t(h));
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const WorldPoint p(P.LocalX(panel, x0 - 2 + u) + r.frame_origin_m.x(),
                           P.LocalY(y0 - 2 + v) + r.frame_origin_m.y(), z.min.z());
        inside[size_t(v) * size_t(w) + size_t(u)] = KeepOutContains(z, p) ? 1 : 0;
      }
    auto in = [&](int u, int v) { return inside[size_t(v) * size_t(w) + size_t(u)] != 0; };
    for (int v = 2; v < h - 2; ++v)
      for (int u = 2; u < w - 2; ++u) {
        if (!in(u, v)) continue;
        const bool edge = !in(u - 1, v) || !in(u + 1, v) || !in(u, v - 1) || !in(u, v + 1) || !in(u - 2, v) ||
                          !in(u + 2, v) || !in(u, v - 2) || !in(u, v + 2);
        const int x = x0 - 2 + u, y = y0 - 2 + v;
        if (edge || (x + y) % kHatchPitch == 0) img.Set(x, y, raster::kBlack);
      }
    drawn = true;
  }
  return drawn;
}

// Where each station's numbered disc goes, panel by panel (PlaceLabels): centred on the station
// where that covers no other station and no other disc, else moved aside within the plot.
std::vector<HeatmapStationPlace> StationPlaces(const HeatLayout& L, const PlanResult& r) {
  const HeatPixels P{L};
  std::vector<HeatmapStationPlace> places(r.stations.size());
  for (size_t p = 0; p < L.panel_z.size(); ++p) {
    const int panel = static_cast<int>(p);
    std::vector<size_t> here;
    std::vector<LabelRequest> requests;
    for (size_t k = 0; k < r.stations.size(); ++k) {
      const WorldPoint& s = r.stations[k].position;
      if (floor_plan::NearestPanel(L, s.z()) != panel) continue;
      // The disc is 2 r + 3 pixels wide; half a pixel more each side keeps a rounded one inside.
      const double side = 2 * DiscRadius(static_cast<int>(k) + 1) + 4;
      requests.push_back({{double(P.X(panel, s.x())), double(P.Y(s.y()))}, kDotRadius + 1.5, side, side});
      here.push_back(k);
    }
    LabelPlacementOptions options;
    options.centred_first = true;
    const double left = P.PanelLeft(panel) - 0.5, top = kMarginTop - 0.5;
    options.bounds = {left, top, left + L.plot_w, top + L.plot_h};
    const std::vector<PlacedLabel> placed = PlaceLabels(requests, {}, options);
    for (size_t i = 0; i < here.size(); ++i) places[here[i]] = {panel, requests[i].anchor, placed[i]};
  }
  return places;
}

// The stations, numbered in plan order, on the panel of their height; fixed stations ringed in
// black, the others in red. A disc moved aside has a black leader line to a dot at the station.
// True when a disc was moved.
bool DrawStations(Image& img, const PlanResult& r, const std::vector<HeatmapStationPlace>& places) {
  auto ring = [&](size_t k) { return r.stations[k].fixed ? raster::kBlack : raster::kRed; };
  auto centre = [&](size_t k) {
    const LabelBox& b = places[k].disc.box;
    return std::pair{static_cast<int>(std::lround(0.5 * (b.x0 + b.x1))),
                     static_cast<int>(std::lround(0.5 * (b.y0 + b.y1)))};
  };
  bool moved = false;
  for (size_t k = 0; k < places.size(); ++k) {
    if (!places[k].disc.leader) continue;
    const auto [cx, cy] = centre(k);
    const int sx = static_cast<int>(places[k].station_px.x), sy = static_cast<int>(places[k].station_px.y);
    img.Line(sx, sy, cx, cy, raster::kBlack, 1);
    moved = true;
  }
  for (size_t k = 0; k < places.size(); ++k) {
    if (!places[k].disc.leader) continue;
    const int sx = static_cast<int>(places[k].station_px.x), sy = static_cast<int>(places[k].station_px.y);
    img.FillCircle(sx, sy, kDotRadius + 1, raster::kWhite);
    img.FillCircle(sx, sy, kDotRadius, ring(k));
  }
  for (size_t k = 0; k < places.size(); ++k) {
    const auto [cx, cy] = centre(k);
    StationDisc(img, cx, cy, static_cast<int>(k) + 1, ring(k));
  }
  return moved;
}

// One panel: its cells, floor plan, keep-out zones, frame, axes in metres and title. True when it
// drew a keep-out zone.
bool DrawPanel(Image& img, const HeatLayout& L, const PlanResult& r, int panel, const std::vector<size_t>& order,
               double denom) {
  const HeatPixels P{L};
  const int left = P.PanelLeft(panel), top = kMarginTop;
  img.FillRect(left, top, left + L.plot_w, top + L.plot_h, Rgb{235, 235, 235});
  // With several heights in ascending count, so a cell shows the best of its heights.
  for (size_t i : order) {
    if (L.candidate_panel[i] != panel) continue;
    const WorldPoint& c = r.heat_map.positions[i];
    const double h = L.cell_m / 2;
    const uint64_t count = i < r.heat_map.visible_voxels.size() ? r.heat_map.visible_voxels[i] : 0;
    img.FillRect(P.X(panel, c.x() - h), P.Y(c.y() + h), P.X(panel, c.x() + h), P.Y(c.y() - h),
                 raster::Viridis(count / denom));
  }
  DrawFloorPlan(img, L, r, panel, left, top);
  const bool zones = DrawKeepOutZones(img, L, r, panel);
  img.StrokeRect(left, top, left + L.plot_w, top + L.plot_h, raster::kBlack);
  const double step = TickStep(L.ppm, 48);
  for (double v = std::ceil(L.x0 / step) * step; v <= L.x1 + 1e-9; v += step) {
    const int x = P.X(panel, v);
    img.VLine(x, top + L.plot_h, top + L.plot_h + 4, raster::kBlack);
    const std::string s = TickLabel(v + r.frame_origin_m.x(), step);
    img.Text(x - raster::TextWidth(s) / 2, top + L.plot_h + 8, s, raster::kBlack);
  }
  for (double v = std::ceil(L.y0 / step) * step; v <= L.y1 + 1e-9; v += step) {
    const int y = P.Y(v);
    img.HLine(left - 5, left - 1, y, raster::kBlack);
    const std::string s = TickLabel(v + r.frame_origin_m.y(), step);
    img.Text(left - 8 - raster::TextWidth(s), y - 3, s, raster::kBlack);
  }
  const std::string xl = "x (m)";
  img.Text(left + L.plot_w / 2 - raster::TextWidth(xl) / 2, top + L.plot_h + 24, xl, raster::kBlack);
  img.TextVertical(left - kMarginLeft + 4, top + L.plot_h / 2 - raster::TextWidth("y (m)") / 2, "y (m)",
                   raster::kBlack);
  std::string title = "VISIBLE VOXELS PER CANDIDATE";
  if (L.meaning == HeatmapMeaning::kMissedByStations) {
    title = "SURFACE VOXELS NO STATION SEES, PER " + Short(L.cell_m) + " M CELL";
  } else if (r.options.tripod_heights_m.size() > 1) {
    title = "VISIBLE VOXELS, BEST OF " + std::to_string(r.options.tripod_heights_m.size()) + " HEIGHTS";
  }
  if (L.panel_z.size() > 1 || !r.floor_levels_m.empty())
    title += "  z = " + Fixed(InputFrameZ(r, L.panel_z[size_t(panel)]), 2) + " m";
  img.Text(left, 10, title, raster::kBlack, 2);
  return zones;
}

// The scan graph's edges at its threshold (0.3 when registration is off), white, between stations
// on one panel; and the walking route, orange, each polyline point on the panel of its floor.
void DrawEdgesAndRoute(Image& img, const HeatLayout& L, const PlanResult& r) {
  const HeatPixels P{L};
  auto panel_of = [&](double z) { return floor_plan::NearestPanel(L, z); };
  const double edge_min = ScanGraphDrawThreshold(r);
  for (const ScanGraph::Edge& e : r.scan_graph.edges) {
    if (e.overlap < edge_min || static_cast<size_t>(std::max(e.i, e.j)) >= r.stations.size()) continue;
    const WorldPoint& a = r.stations[e.i].position;
    const WorldPoint& b = r.stations[e.j].position;
    const int pa = panel_of(a.z()), pb = panel_of(b.z());
    if (pa != pb) continue;
    img.Line(P.X(pa, a.x()), P.Y(a.y()), P.X(pb, b.x()), P.Y(b.y()), raster::kWhite, 1);
  }
  const double lowest_height = floor_plan::LowestTripodHeight(r);
  for (const std::vector<WorldPoint>& line : r.route.polylines) {
    for (size_t k = 1; k < line.size(); ++k) {
      const int pa = panel_of(line[k - 1].z() + lowest_height), pb = panel_of(line[k].z() + lowest_height);
      if (pa != pb) continue;  // the step between two panels (stairs) is not drawn
      img.Line(P.X(pa, line[k - 1].x()), P.Y(line[k - 1].y()), P.X(pb, line[k].x()), P.Y(line[k].y()), raster::kOrange,
               3);
    }
  }
}

Image DrawHeatmap(const PlanResult& r, HeatmapMeaning meaning) {
  HeatLayout L = ComputeHeatLayout(r);
  L.meaning = meaning;
  Image img(L.width, L.height);
  uint64_t max_count = 0;
  for (uint64_t c : r.heat_map.visible_voxels) max_count = std::max(max_count, c);
  const double denom = max_count > 0 ? static_cast<double>(max_count) : 1.0;
  auto count_of = [&](size_t i) { return i < r.heat_map.visible_voxels.size() ? r.heat_map.visible_voxels[i] : 0; };
  std::vector<size_t> order(r.heat_map.positions.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  if (r.options.tripod_heights_m.size() > 1) {
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return count_of(a) < count_of(b); });
  }
  bool zones = false;
  for (size_t p = 0; p < L.panel_z.size(); ++p) zones |= DrawPanel(img, L, r, static_cast<int>(p), order, denom);
  DrawEdgesAndRoute(img, L, r);
  const bool moved = DrawStations(img, r, StationPlaces(L, r));
  // What the lines and marks mean, under the first panel's axis label.
  const int legend_y = kMarginTop + std::max(L.plot_h, kMinPlotHeight) + 42;
  std::string legend = "GREY: WALLS AND OBJECTS (DARKER = TALLER)   ORANGE: WALKING ROUTE";
  if (!r.scan_graph.edges.empty()) legend += "   WHITE: OVERLAP \u2265 " + Short(ScanGraphDrawThreshold(r));
  img.Text(kMarginLeft, legend_y, legend, raster::kBlack);
  std::string marks;
  if (zones) marks += "HATCHED: KEEP-OUT ZONE";
  if (moved) marks += std::string(marks.empty() ? "" : "   ") + "LINE TO DOT: STATION OF A MOVED NUMBER";
  img.Text(kMarginLeft, legend_y + 10, marks, raster::kBlack);
  HeatColourBar(img, L, r, max_count);
  return img;
}

// ---------- reduction.png ----------

constexpr int kRedLeft = 56, kRedTop = 52, kRedBottom = 48, kRedLegend = 120, kRedMinH = 180;
constexpr const char* kRedTitle = "REDUCTION POTENTIAL G(P) - G(P-T)";
constexpr const char* kRedSubtitle = "DIAGONAL: T = [I]   OFF-DIAGONAL: T = [I, J]   RED: REMOVED";

// Cells of 14-48 px while the matrix stays within kRedMaxSide px (146 stations); past that as many
// px as fit, at least 1: a campus plan's 905 stations made a 12,670 px square image at 14 px (a
// 480 MB raster and 5 s of the client's time), 1,810 px now. Values are printed only in cells wide
// enough, and station numbers every few cells, as before.
constexpr int kRedMinCell = 14, kRedMaxCell = 48, kRedMaxSide = 2048;
int ReductionCell(int n) {
  n = std::max(n, 1);
  return n * kRedMinCell <= kRedMaxSide ? std::clamp(480 / n, kRedMinCell, kRedMaxCell) : std::max(kRedMaxSide / n, 1);
}

Image DrawReduction(const PlanResult& r) {
  const int n = r.reduction.size;
  const ImageSize size = ReductionImageSize(n);
  Image img(size.width, size.height);
  const int cell = ReductionCell(n);
  double max_loss = 0;
  for (double v : r.reduction.matrix) max_loss = std::max(max_loss, v);
  const double denom = max_loss > 0 ? max_loss : 1.0;
  std::vector<bool> removed(std::max(n, 0), false);
  for (int k : r.reduction.removed) {
    if (k >= 0 && k < n) removed[k] = true;
  }
  img.Text(kRedLeft, 8, kRedTitle, raster::kBlack, 2);
  img.Text(kRedLeft, 28, kRedSubtitle, raster::kDarkGrey);
  if (n == 0) {
    img.Text(kRedLeft, kRedTop + 10, "NO STATIONS", raster::kBlack);
    return img;
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const size_t idx = static_cast<size_t>(i) * n + j;
      const double v = idx < r.reduction.matrix.size() ? r.reduction.matrix[idx] : 0.0;
      const Rgb c = raster::Viridis(v / denom);
      const int x0 = kRedLeft + j * cell, y0 = kRedTop + i * cell;
      img.FillRect(x0, y0, x0 + cell - 1, y0 + cell - 1, c);
      // The value inside the cell when it fits, dark on light colours and light on dark ones.
      const std::string label = Short(v);
      if (raster::TextWidth(label) + 4 <= cell - 1) {
        const bool light = 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2] > 140;
        img.Text(x0 + (cell - 1 - raster::TextWidth(label)) / 2, y0 + (cell - 1 - raster::kGlyphH) / 2, label,
                 light ? raster::kBlack : raster::kWhite);
      }
    }
  }
  img.StrokeRect(kRedLeft, kRedTop, kRedLeft + n * cell - 1, kRedTop + n * cell - 1, raster::kBlack);
  const int label_every = std::max(1, (raster::TextWidth(std::to_string(n)) + 4 + cell - 1) / cell);
  for (int i = 0; i < n; i += label_every) {
    const std::string s = std::to_string(i + 1);
    const Rgb c = removed[i] ? raster::kRed : raster::kBlack;
    img.Text(kRedLeft + i * cell + cell / 2 - raster::TextWidth(s) / 2, kRedTop + n * cell + 6, s, c);
    img.Text(kRedLeft - 6 - raster::TextWidth(s), kRedTop + i * cell + cell / 2 - 3, s, c);
  }
  for (int i = 0; i < n; ++i) {
    if (!removed[i]) continue;
    if (cell >= 4) {  // a red frame inside its diagonal cell; a smaller cell is filled red
      img.StrokeRect(kRedLeft + i * cell + 1, kRedTop + i * cell + 1, kRedLeft + (i + 1) * cell - 2,
                     kRedTop + (i + 1) * cell - 2, raster::kRed);
    } else {
      img.FillRect(kRedLeft + i * cell, kRedTop + i * cell, kRedLeft + (i + 1) * cell - 1, kRedTop + (i + 1) * cell - 1,
                   raster::kRed);
    }
  }
  img.Text(kRedLeft, kRedTop + n * cell + 22, "STATION (GREEDY ORDER)", raster::kBlack);
  const int bar_h = std::max(n * cell, kRedMinH) - 14;
  ColourBar(img, kRedLeft + n * cell + 24, kRedTop + 14, bar_h, QuarterTicks(max_loss, false), {"G LOST"});
  return img;
}

// ---------- evaluation.json ----------

Json EvaluationJson(const Evaluation& e, const std::vector<WorldPoint>& viewpoints) {
  Json per = Json::array();
  for (size_t i = 0; i < e.per_viewpoint.size(); ++i) {
    Json v{{"index", i}};
    if (i < viewpoints.size()) {
      v["x"] = viewpoints[i].x();
      v["y"] = viewpoints[i].y();
      v["z"] = viewpoints[i].z();
    }
    const Json figures = FiguresJson(e.per_viewpoint[i]);
    for (const auto& item : figures.items()) v[item.key()] = item.value();
    per.push_back(std::move(v));
  }
  Json j{{"resolution_m", e.resolution_m},
         {"faces_total", e.faces_total},
         {"faces_evaluated", e.faces_evaluated},
         {"sampled", e.sampled},
         {"global_visibility", e.overall.global_visibility},
         {"global_visibility_ci95", e.global_visibility_ci95},
         {"fully_visible_fraction", e.overall.fully_visible_fraction},
         {"mean_full_visibility", e.overall.mean_full_visibility},
         {"partially_visible_fraction", e.overall.partially_visible_fraction},
         {"per_viewpoint", std::move(per)}};
  return j;
}

// ---------- CSV parsing ----------

std::string_view Trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

bool ParseDouble(std::string_view s, double* out) {
  s = Trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  const bool commas = line.find(',') != std::string_view::npos || line.find(';') != std::string_view::npos;
  size_t start = 0;
  for (size_t i = 0; i <= line.size(); ++i) {
    const bool sep = i == line.size() ||
                     (commas ? (line[i] == ',' || line[i] == ';') : std::isspace(static_cast<unsigned char>(line[i])));
    if (!sep) continue;
    std::string_view f = Trim(line.substr(start, i - start));
    if (commas || !f.empty()) fields.push_back(f);
    start = i + 1;
  }
  return fields;
}

// The columns a header names x, y and z ("x" or "x_m", any case), when it names all three.
std::optional<std::array<size_t, 3>> XyzColumns(const std::vector<std::string_view>& fields) {
  std::array<int, 3> at{-1, -1, -1};
  for (size_t i = 0; i < fields.size(); ++i) {
    std::string name(fields[i]);
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (name.size() == 3 && name.compare(1, 2, "_m") == 0) name.resize(1);
    if (name.size() != 1 || name[0] < 'x' || name[0] > 'z') continue;
    at[size_t(name[0] - 'x')] = static_cast<int>(i);
  }
  if (at[0] < 0 || at[1] < 0 || at[2] < 0) return std::nullopt;
  return std::array<size_t, 3>{size_t(at[0]), size_t(at[1]), size_t(at[2])};
}

// A station from "x,y,z", or a plan's earlier "x,y,z,route_order" whose fourth column is read and ignored.
Result<WorldPoint> PositionalRow(const std::vector<std::string_view>& fields, std::string_view line,
                                 const std::string& where) {
  double v[4];
  const bool numeric = (fields.size() == 3 || fields.size() == 4) && ParseDouble(fields[0], &v[0]) &&
                       ParseDouble(fields[1], &v[1]) && ParseDouble(fields[2], &v[2]) &&
                       (fields.size() == 3 || ParseDouble(fields[3], &v[3]));
  if (!numeric) {
    return InvalidArgumentError(where +
                                "expected 3 numbers \"x,y,z\" (metres), or a plan's \"x,y,z,route_order\", found \"" +
                                std::string(line) + "\"");
  }
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
    return InvalidArgumentError(where + "coordinates must be finite, found \"" + std::string(line) + "\"");
  }
  return WorldPoint(v[0], v[1], v[2]);
}

// A station from the columns a header named (a plan's stations.csv: x_m, y_m, z_m among others).
Result<WorldPoint> NamedColumnsRow(const std::vector<std::string_view>& fields, const std::array<size_t, 3>& columns,
                                   std::string_view line, const std::string& where) {
  double v[3];
  for (int a = 0; a < 3; ++a) {
    const size_t c = columns[size_t(a)];
    if (c >= fields.size() || !ParseDouble(fields[c], &v[a])) {
      return InvalidArgumentError(where + "expected a number in column " + std::to_string(c + 1) + " (" +
                                  std::string(1, char('x' + a)) + ", metres), found \"" + std::string(line) + "\"");
    }
    if (!std::isfinite(v[a])) {
      return InvalidArgumentError(where + "coordinates must be finite, found \"" + std::string(line) + "\"");
    }
  }
  return WorldPoint(v[0], v[1], v[2]);
}

// plan.json's `coverage.uncoverable_by_cause` (vc/plan/unseen_causes.h): voxel counts per cause.
Json UnseenCausesJson(const UnseenCauses& u) {
  return Json{{"interior", u.interior},
              {"in_keep_out", u.in_keep_out},
              {"no_candidate_on_floor", u.no_candidate_on_floor},
              {"out_of_range", u.out_of_range},
              {"outside_field_of_view", u.outside_field_of_view},
              {"faces_away", u.faces_away},
              {"hidden", u.hidden}};
}

// plan.json's `coverage_curve`: one point per station (vc/plan/coverage_curve.h), with the best k
// stations' bound and the most found where computed (absent otherwise).
Json CoverageCurveJson(const std::vector<CoveragePoint>& curve) {
  Json out = Json::array();
  for (const CoveragePoint& c : curve) {
    Json p = {{"stations", c.stations},
              {"covered_voxels", c.covered_voxels},
              {"coverable_fraction", c.coverable_fraction},
              {"scene_fraction", c.scene_fraction},
              {"setup_scan_s", c.setup_scan_s}};
    if (c.best_voxels_upper_bound) {
      p["best_voxels_upper_bound"] = *c.best_voxels_upper_bound;
      p["best_voxels"] = c.best_voxels.value_or(c.covered_voxels);
      p["best_voxels_optimal"] = c.best_voxels_optimal;
    }
    out.push_back(std::move(p));
  }
  return out;
}

// plan.json's `coverage_milestones`: the stations needed for 80, 90, 95 and 99 % of the coverable
// voxels, with the scene's share and the set-up and scan time there (stations null: never reached),
// and the fewest stations any plan needs for the level by the per-k bound (null: no bound reaches it).
Json CoverageMilestonesJson(const PlanResult& r) {
  Json out = Json::array();
  const std::vector<double> levels(std::begin(kCoverageMilestones), std::end(kCoverageMilestones));
  for (const CoverageMilestone& m : CoverageMilestones(r.coverage_curve, r.coverable_voxels, levels)) {
    out.push_back(
        {{"coverable_fraction", m.coverable_fraction},
         {"stations", m.reached ? Json(m.reached->stations) : Json(nullptr)},
         {"scene_fraction", m.reached ? Json(m.reached->scene_fraction) : Json(nullptr)},
         {"setup_scan_s", m.reached ? Json(m.reached->setup_scan_s) : Json(nullptr)},
         {"fewest_possible_stations", m.fewest_possible_stations ? Json(*m.fewest_possible_stations) : Json(nullptr)}});
  }
  return out;
}

// plan.json's `gain_rule`: the rule's parameter and value, and its threshold for one station in
// voxels and minutes of set-up and scan; null when the rule is off.
Json GainRuleJson(const PlanResult& r) {
  const std::optional<GainRule> rule = GainRuleOf(r.options, r.resolution_m);
  if (!rule) return nullptr;
  const double minutes = (r.options.setup_seconds + r.field_time.scan_seconds_per_station) / 60.0;
  return {{"parameter", std::string(rule->parameter)},
          {"value", rule->value},
          {"station_minutes", minutes},
          {"threshold_voxels", rule->voxels_per_minute * minutes}};
}

// A height for plan.json: null when NaN.
Json HeightJson(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// plan.json's and evaluation.json's `crs`: null without one.
Json CrsJson(const CrsInfo* crs) {
  if (crs == nullptr) return nullptr;
  return Json{{"definition", crs->definition},
              {"name", crs->name},
              {"epsg", crs->epsg ? Json(*crs->epsg) : Json(nullptr)},
              {"axis_unit", crs->axis_unit},
              {"metres_per_unit", crs->metres_per_unit}};
}

// plan.json's peak_rss_bytes: per stage the process's peak resident memory during it (null where
// not measured) and `plan`, the largest.
Json PeakRssJson(const std::vector<StageTiming>& timings) {
  Json peak = Json::object();
  uint64_t plan_peak = 0;
  for (const StageTiming& t : timings) {
    peak[std::string(StageName(t.stage))] = t.peak_rss_bytes == 0 ? Json(nullptr) : Json(t.peak_rss_bytes);
    plan_peak = std::max(plan_peak, t.peak_rss_bytes);
  }
  peak["plan"] = plan_peak == 0 ? Json(nullptr) : Json(plan_peak);
  return peak;
}

}  // namespace

std::string PlanToJson(const PlanResult& r, const UploadSummary* upload,
                       const std::vector<std::string>& fixed_station_names, const CrsInfo* crs) {
  const std::vector<int> route_position = RoutePositions(r);
  std::vector<const FieldStation*> field(r.stations.size(), nullptr);
  const std::vector<FieldStation> field_stations = FieldStations(r, fixed_station_names);
  for (const FieldStation& f : field_stations) field[f.index] = &f;
  Json viewpoints = Json::array();
  for (size_t k = 0; k < r.stations.size(); ++k) {
    const PlannedStation& s = r.stations[k];
    const WorldPoint p = InputFrame(r, s.position);
    Json v{{"index", k},
           {"x", p.x()},
           {"y", p.y()},
           {"z", p.z()},
           {"compatible_voxels", s.visible_voxels},
           {"marginal_gain", s.marginal_gain},
           {"cumulative_coverage", s.cumulative_coverage},
           {"global_visibility", s.global_visibility},
           {"candidate_index", s.candidate_index},
           {"fixed", s.fixed},
           {"route_order", route_position[k]}};
    if (k < r.evaluation.per_viewpoint.size()) {
      v["fully_visible_fraction"] = r.evaluation.per_viewpoint[k].fully_visible_fraction;
      v["partially_visible_fraction"] = r.evaluation.per_viewpoint[k].partially_visible_fraction;
    }
    v["station"] = field[k]->number;
    v["name"] = field[k]->name;
    v["floor"] = field[k]->floor.empty() ? Json(nullptr) : Json(field[k]->floor);
    v["floor_z_m"] = HeightJson(field[k]->floor_z_m);
    v["tripod_height_m"] = HeightJson(field[k]->tripod_height_m);
    viewpoints.push_back(std::move(v));
  }
  const double coverable = static_cast<double>(r.coverable_voxels);
  const double occupied = static_cast<double>(r.occupied_voxels);
  Json coverage{{"occupied_voxels", r.occupied_voxels},
                {"coverable_voxels", r.coverable_voxels},
                {"covered_voxels", r.covered_voxels},
                {"uncovered_voxels", r.occupied_voxels - std::min(r.occupied_voxels, r.covered_voxels)},
                {"uncoverable_voxels", r.occupied_voxels - std::min(r.occupied_voxels, r.coverable_voxels)},
                {"covered_fraction_of_coverable", coverable > 0 ? r.covered_voxels / coverable : 0.0},
                {"covered_fraction_of_occupied", occupied > 0 ? r.covered_voxels / occupied : 0.0},
                {"global_visibility", r.evaluation.overall.global_visibility},
                {"fully_visible_fraction", r.evaluation.overall.fully_visible_fraction},
                {"mean_full_visibility", r.evaluation.overall.mean_full_visibility},
                {"partially_visible_fraction", r.evaluation.overall.partially_visible_fraction},
                {"faces_total", r.evaluation.faces_total},
                {"uncoverable_by_cause", UnseenCausesJson(r.unseen_causes)}};
  Json matrix = Json::array();
  for (int i = 0; i < r.reduction.size; ++i) {
    Json row = Json::array();
    for (int j = 0; j < r.reduction.size; ++j) {
      const size_t idx = static_cast<size_t>(i) * r.reduction.size + j;
      row.push_back(idx < r.reduction.matrix.size() ? r.reduction.matrix[idx] : 0.0);
    }
    matrix.push_back(std::move(row));
  }
  Json reduction_positions = Json::array();
  for (const WorldPoint& p : r.reduction.positions) reduction_positions.push_back(Point(InputFrame(r, p)));
  Json reduction{{"size", r.reduction.size},
                 {"stations", std::move(reduction_positions)},
                 {"matrix", std::move(matrix)},
                 {"removed", r.reduction.removed},
                 {"global_visibility_before", r.reduction.global_visibility_before},
                 {"global_visibility_after", r.reduction.global_visibility_after}};
  Json heat = Json::array();
  for (size_t i = 0; i < r.heat_map.positions.size(); ++i) {
    const WorldPoint p = InputFrame(r, r.heat_map.positions[i]);
    heat.push_back({p.x(), p.y(), p.z(), i < r.heat_map.visible_voxels.size() ? r.heat_map.visible_voxels[i] : 0});
  }
  Json candidates{{"count", r.candidate_count},
                  {"grid_spacing_m", r.heat_map.grid_spacing_m},
                  {"floor_levels_m", InputFrameZ(r, r.floor_levels_m)},
                  {"grid_cells", r.grid_cells},
                  {"cells_without_floor", r.cells_without_floor},
                  {"cells_failing_clearance", r.cells_failing_clearance},
                  {"visible_voxels", std::move(heat)}};
  Json edges = Json::array();
  for (const ScanGraph::Edge& e : r.scan_graph.edges) edges.push_back({e.i, e.j, e.overlap});
  Json scan_graph{{"min_overlap", r.scan_graph.min_overlap},
                  {"connected", r.scan_graph.connected},
                  {"components", r.scan_graph.components},
                  {"connecting_stations", r.connecting_stations},
                  {"edges", std::move(edges)}};
  Json polylines = Json::array();
  for (const std::vector<WorldPoint>& line : r.route.polylines) {
    Json points = Json::array();
    for (const WorldPoint& p : line) points.push_back(Point(InputFrame(r, p)));
    polylines.push_back(std::move(points));
  }
  Json route{{"order", r.route.order},
             {"legs_m", r.route.legs_m},
             {"length_m", r.route.length_m},
             {"parts", r.route.parts},
             {"polyline", std::move(polylines)},
             {"start", r.route.start ? Point(InputFrame(r, *r.route.start)) : Json(nullptr)}};
  Json field_time{{"setup", r.field_time.setup_s},
                  {"scan", r.field_time.scan_s},
                  {"walk", r.field_time.walk_s},
                  {"total", r.field_time.total_s},
                  {"scan_per_station", r.field_time.scan_seconds_per_station}};
  Json timings = Json::object();
  for (const StageTiming& t : r.timings) timings[std::string(StageName(t.stage))] = t.seconds;
  timings["total"] = r.total_seconds;
  Json j{{"schema", "vc.plan/1"},
         {"frame",
          {{"origin_m", Point(r.frame_origin_m)},
           {"units", upload == nullptr ? Json(nullptr) : Json(upload->units.empty() ? "m" : upload->units)}}},
         {"crs", CrsJson(crs)},
         {"resolution_m", r.resolution_m},
         {"selection_test", std::string(SelectionTestName(r.selection_test))},
         {"stop_reason", std::string(StopReasonName(r.stop_reason))},
         {"gain_rule", GainRuleJson(r)},
         {"greedy_stations", r.greedy_stations},
         {"consolidated", r.consolidated},
         {"viewpoints", std::move(viewpoints)},
         {"coverage", std::move(coverage)},
         {"reduction", std::move(reduction)},
         {"candidates", std::move(candidates)},
         {"ground", GroundJson(r.ground)},
         {"scan_graph", std::move(scan_graph)},
         {"route", std::move(route)},
         {"field_time_s", std::move(field_time)},
         {"coverage_curve", CoverageCurveJson(r.coverage_curve)},
         {"coverage_milestones", CoverageMilestonesJson(r)},
         {"optimality", OptimalityJson(r.optimality)},
         {"distribution", r.distribution.shards == 0 ? Json(nullptr)
                                                     : Json{{"replicas", r.distribution.replicas},
                                                            {"shards", r.distribution.shards},
                                                            {"retried", r.distribution.retried},
                                                            {"bytes_exchanged", r.distribution.bytes_exchanged}}},
         {"timings_s", std::move(timings)},
         {"peak_rss_bytes", PeakRssJson(r.timings)},
         {"parameters", ParametersJson(r.options)},
         {"upload", upload == nullptr
                        ? Json(nullptr)
                        : Json{{"format", upload->format},
                               {"bytes_sent", upload->bytes_sent},
                               {"file_bytes", upload->file_bytes},
                               {"voxels", upload->voxels},
                               {"resolution_m", upload->resolution_m},
                               {"why_raw", upload->why_raw},
                               {"scene_hash", upload->scene_hash.empty() ? Json(nullptr) : Json(upload->scene_hash)},
                               {"from_cache", upload->from_cache}}},
         {"warnings", r.warnings}};
  return j.dump(2) + "\n";
}

Result<std::string> HeatmapPng(const PlanResult& result, HeatmapMeaning meaning) {
  return raster::EncodePng(DrawHeatmap(result, meaning));
}

std::vector<HeatmapStationPlace> HeatmapStationPlaces(const PlanResult& result) {
  return StationPlaces(ComputeHeatLayout(result), result);
}

ImageSize HeatmapImageSize(const PlanResult& result) {
  const HeatLayout L = ComputeHeatLayout(result);
  return {L.width, L.height};
}

ImageSize ReductionImageSize(int stations) {
  const int n = std::max(stations, 0);
  const int cell = ReductionCell(n);
  const int title_w = std::max(raster::TextWidth(kRedTitle, 2), raster::TextWidth(kRedSubtitle)) + 2 * kRedLeft;
  return {std::max(kRedLeft + n * cell + kRedLegend, title_w), kRedTop + std::max(n * cell, kRedMinH) + kRedBottom};
}

std::string ColouredPointsPly(const std::vector<std::string>& comments, const std::vector<ColouredPoint>& points,
                              std::string_view value_name, PlyCoordinates coordinates) {
  const bool doubles = coordinates == PlyCoordinates::kDouble;
  const std::string type = doubles ? "double" : "float";
  std::string out = "ply\nformat binary_little_endian 1.0\n";
  for (const std::string& c : comments) out += "comment " + c + "\n";
  out += "element vertex " + std::to_string(points.size()) + "\nproperty " + type + " x\nproperty " + type +
         " y\nproperty " + type +
         " z\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (!value_name.empty()) out += "property float " + std::string(value_name) + "\n";
  out += "end_header\n";
  out.reserve(out.size() + points.size() * ((doubles ? 27 : 15) + (value_name.empty() ? 0 : 4)));
  auto put_float = [&out](float f) {
    char b[4];
    std::memcpy(b, &f, 4);  // x86-64 and ARM64 hosts are little-endian
    out.append(b, 4);
  };
  auto put_double = [&out](double d) {
    char b[8];
    std::memcpy(b, &d, 8);
    out.append(b, 8);
  };
  for (const ColouredPoint& p : points) {
    for (int a = 0; a < 3; ++a) doubles ? put_double(p.position_m[a]) : put_float(static_cast<float>(p.position_m[a]));
    out.append(reinterpret_cast<const char*>(p.rgb.data()), 3);
    if (!value_name.empty()) put_float(p.value);
  }
  return out;
}

namespace {

// The angle from grid north to true north, degrees clockwise (FieldSheetOptions'), at the mean of
// the plan's stations in the input's frame (the scene's origin when it has none).
Result<double> TrueNorthAtSiteDeg(const PlanResult& result, const Crs& crs) {
  WorldPoint site = WorldPoint::Zero();
  for (const PlannedStation& s : result.stations) site += s.position;
  if (!result.stations.empty()) site /= static_cast<double>(result.stations.size());
  site += result.frame_origin_m;
  VC_ASSIGN_OR_RETURN(const double ccw_rad, crs.TrueNorthFromGridNorthRad(site.x(), site.y()));
  return -ccw_rad * 180.0 / M_PI;
}

// The crew's files of a plan or an evaluation: stations.csv, stations.dxf, stations.geojson (with
// `crs`) and fieldsheet.pdf.
Status WriteStationFiles(const PlanResult& result, const std::filesystem::path& dir,
                         const std::vector<std::string>& fixed_station_names, const Crs* crs,
                         const FieldSheetOptions& field_sheet) {
  const CrsInfo* crs_info = crs == nullptr ? nullptr : &crs->info();
  const std::vector<FieldStation> field_stations = FieldStations(result, fixed_station_names);
  VC_RETURN_IF_ERROR(WriteFile(dir / "stations.csv", FieldStationsCsv(field_stations, crs_info)));
  VC_RETURN_IF_ERROR(WriteFile(dir / "stations.dxf", StationsDxf(result, field_stations)));
  if (crs != nullptr) {
    VC_ASSIGN_OR_RETURN(const std::string geojson, StationsGeoJson(result, field_stations, *crs));
    VC_RETURN_IF_ERROR(WriteFile(dir / "stations.geojson", geojson));
  }
  FieldSheetOptions sheet_options = field_sheet;
  if (crs != nullptr && std::isnan(sheet_options.true_north_from_grid_deg)) {
    VC_ASSIGN_OR_RETURN(sheet_options.true_north_from_grid_deg, TrueNorthAtSiteDeg(result, *crs));
  }
  VC_ASSIGN_OR_RETURN(std::string sheet, FieldSheetPdf(result, field_stations, sheet_options));
  return WriteFile(dir / "fieldsheet.pdf", sheet);
}

// The per-voxel files of a plan or an evaluation: visibility.ply, heatmap.png and report.html.
// FAILED_PRECONDITION unless there is a best_face_values entry per voxel centre.
Status WriteVisibilityFiles(const PlanResult& result, const std::filesystem::path& dir,
                            const std::vector<std::string>& fixed_station_names, HeatmapMeaning meaning) {
  if (result.voxel_centers.size() != result.evaluation.best_face_values.size()) {
    return FailedPreconditionError("visibility.ply needs one best_face_values entry per voxel centre (" +
                                   std::to_string(result.voxel_centers.size()) + " centres, " +
                                   std::to_string(result.evaluation.best_face_values.size()) + " face values)");
  }
  VC_RETURN_IF_ERROR(WriteFile(dir / "visibility.ply", VisibilityPly(result)));
  VC_ASSIGN_OR_RETURN(std::string heat, HeatmapPng(result, meaning));
  VC_RETURN_IF_ERROR(WriteFile(dir / "heatmap.png", heat));
  ReportHtmlOptions report_options;
  report_options.fixed_station_names = fixed_station_names;
  return WriteFile(dir / "report.html", PlanToHtml(result, report_options));
}

// Packs a voxel's integer index (its centre is (index + 0.5) x the resolution) into one word, 21 bits an axis.
uint64_t PackedKey(int64_t x, int64_t y, int64_t z) {
  constexpr int64_t kMask = (int64_t{1} << 21) - 1;
  return (uint64_t(x & kMask) << 42) | (uint64_t(y & kMask) << 21) | uint64_t(z & kMask);
}

// Per voxel: whether some face of it has no occupied neighbour (the surface of the scene).
std::vector<bool> ExposedVoxels(const std::vector<WorldPoint>& centers, double resolution_m) {
  std::vector<std::array<int64_t, 3>> keys(centers.size());
  std::unordered_set<uint64_t> occupied;
  occupied.reserve(centers.size());
  for (size_t i = 0; i < centers.size(); ++i) {
    for (int a = 0; a < 3; ++a) keys[i][a] = std::llround(centers[i][a] / resolution_m - 0.5);  // (k + 0.5) res
    occupied.insert(PackedKey(keys[i][0], keys[i][1], keys[i][2]));
  }
  std::vector<bool> exposed(centers.size(), false);
  for (size_t i = 0; i < centers.size(); ++i) {
    const auto& k = keys[i];
    for (int a = 0; a < 3 && !exposed[i]; ++a) {
      for (int step : {-1, 1}) {
        std::array<int64_t, 3> n = k;
        n[a] += step;
        if (!occupied.contains(PackedKey(n[0], n[1], n[2]))) exposed[i] = true;
      }
    }
  }
  return exposed;
}

// The top of the highest voxel in the column of `station` (centres within half a voxel in x and y)
// at most kMaxDropM below it (m, local); NaN when there is none.
double FloorUnder(const WorldPoint& station, const std::vector<WorldPoint>& centers, double resolution_m) {
  constexpr double kMaxDropM = 3.0;
  const double half = resolution_m / 2;
  const double reach = half + 1e-6;  // a station on a voxel boundary stands over both columns
  double top = std::nan("");
  for (const WorldPoint& v : centers) {
    if (std::fabs(v.x() - station.x()) > reach || std::fabs(v.y() - station.y()) > reach) continue;
    const double voxel_top = v.z() + half;
    if (voxel_top > station.z() || voxel_top < station.z() - kMaxDropM) continue;
    if (!(voxel_top <= top)) top = voxel_top;
  }
  return top;
}

}  // namespace

Status WritePlanOutputs(const PlanResult& result, const std::string& out_dir, const UploadSummary* upload,
                        const std::vector<std::string>& fixed_station_names, const Crs* crs,
                        const FieldSheetOptions& field_sheet) {
  VC_RETURN_IF_ERROR(MakeDir(out_dir));
  const std::filesystem::path dir(out_dir);
  const CrsInfo* crs_info = crs == nullptr ? nullptr : &crs->info();
  VC_RETURN_IF_ERROR(WriteFile(dir / "plan.json", PlanToJson(result, upload, fixed_station_names, crs_info)));
  VC_RETURN_IF_ERROR(WriteStationFiles(result, dir, fixed_station_names, crs, field_sheet));
  VC_RETURN_IF_ERROR(WriteVisibilityFiles(result, dir, fixed_station_names, HeatmapMeaning::kSeenFromCandidates));
  VC_ASSIGN_OR_RETURN(std::string red, raster::EncodePng(DrawReduction(result)));
  return WriteFile(dir / "reduction.png", red);
}

HeatMap MissedVoxelsHeatMap(const PlanResult& result, double cell_m) {
  HeatMap map;
  map.grid_spacing_m = cell_m;
  const auto& values = result.evaluation.best_face_values;
  if (result.stations.empty() || values.size() != result.voxel_centers.size() || result.resolution_m <= 0) return map;
  // Levels: the stations' heights, a gap over 0.5 m starting a new one (as floor_plan groups candidates).
  std::vector<double> zs;
  for (const PlannedStation& s : result.stations) zs.push_back(s.position.z());
  std::sort(zs.begin(), zs.end());
  std::vector<std::pair<double, double>> levels;  // [lowest, highest] station z
  for (double z : zs) {
    if (levels.empty() || z - levels.back().second > 0.5) levels.push_back({z, z});
    levels.back().second = z;
  }
  // Each level's floor: the lowest floor found under its stations, else its lowest station less the
  // lowest tripod height.
  const double lowest_tripod = floor_plan::LowestTripodHeight(result);
  std::vector<double> floors;
  for (const auto& [lo, hi] : levels) {
    double floor = lo - lowest_tripod;
    bool found = false;
    for (const PlannedStation& s : result.stations) {
      if (s.position.z() < lo || s.position.z() > hi || !std::isfinite(s.floor_z_m)) continue;
      floor = found ? std::min(floor, s.floor_z_m) : s.floor_z_m;
      found = true;
    }
    floors.push_back(floor);
  }
  const std::vector<bool> exposed = ExposedVoxels(result.voxel_centers, result.resolution_m);
  std::map<std::array<int64_t, 3>, uint64_t> missed;  // (level, column x, column y) -> voxels missed there
  for (size_t i = 0; i < values.size(); ++i) {
    if (!exposed[i]) continue;
    const WorldPoint& v = result.voxel_centers[i];
    int level = -1;  // the highest whose floor's top voxel layer or more lies under v
    while (level + 1 < int(levels.size()) && v.z() >= floors[size_t(level + 1)] - result.resolution_m) ++level;
    if (level < 0) continue;  // below the lowest floor: the ground under the site
    const bool seen = *std::max_element(values[i].begin(), values[i].end()) > 0;
    missed[{level, int64_t(std::floor(v.x() / cell_m)), int64_t(std::floor(v.y() / cell_m))}] += seen ? 0 : 1;
  }
  for (const auto& [cell, count] : missed) {
    const double floor = floors[size_t(cell[0])];
    map.positions.emplace_back((double(cell[1]) + 0.5) * cell_m, (double(cell[2]) + 0.5) * cell_m,
                               floor + lowest_tripod);
    map.visible_voxels.push_back(count);
    map.floor_z_m.push_back(floor);
  }
  return map;
}

PlanResult EvaluationAsPlan(const EvaluateJobResult& result, const ScannerModel& scanner) {
  PlanResult plan;
  plan.options.scanner = scanner;
  plan.frame_origin_m = result.frame_origin_m;
  plan.resolution_m = result.evaluation.resolution_m;
  plan.evaluation = result.evaluation;
  plan.voxel_centers = result.voxel_centers;
  for (size_t i = 0; i < result.viewpoints.size(); ++i) {
    PlannedStation& s = plan.stations.emplace_back();
    s.position = result.viewpoints[i] - result.frame_origin_m;
    s.cumulative_coverage = std::nan("");  // not a selection: no gains in an order
    s.floor_z_m = FloorUnder(s.position, result.voxel_centers, result.evaluation.resolution_m);
    if (i < result.evaluation.per_viewpoint.size()) {
      s.global_visibility = result.evaluation.per_viewpoint[i].global_visibility;
    }
  }
  plan.occupied_voxels = result.voxel_centers.size();
  plan.coverable_voxels = plan.occupied_voxels;
  for (const auto& faces : result.evaluation.best_face_values) {
    plan.covered_voxels += *std::max_element(faces.begin(), faces.end()) > 0 ? 1 : 0;
  }
  plan.heat_map = MissedVoxelsHeatMap(plan, plan.options.grid_spacing_m);
  plan.field_time = ComputeFieldTime(plan.stations.size(), 0.0, plan.options);
  return plan;
}

std::string EvaluationToJson(const Evaluation& evaluation, const std::vector<WorldPoint>& viewpoints,
                             const CrsInfo* crs) {
  Json j = EvaluationJson(evaluation, viewpoints);
  j["crs"] = CrsJson(crs);
  return j.dump(2) + "\n";
}

Status WriteEvaluationOutputs(const EvaluateJobResult& result, const std::string& out_dir, const Crs* crs,
                              const FieldSheetOptions& field_sheet, const ScannerModel& scanner) {
  VC_RETURN_IF_ERROR(MakeDir(out_dir));
  const std::filesystem::path dir(out_dir);
  const CrsInfo* crs_info = crs == nullptr ? nullptr : &crs->info();
  VC_RETURN_IF_ERROR(
      WriteFile(dir / "evaluation.json", EvaluationToJson(result.evaluation, result.viewpoints, crs_info)));
  const PlanResult plan = EvaluationAsPlan(result, scanner);
  VC_RETURN_IF_ERROR(WriteStationFiles(plan, dir, {}, crs, field_sheet));
  if (plan.evaluation.best_face_values.empty()) return Status::Ok();  // sampled: no per-voxel values
  return WriteVisibilityFiles(plan, dir, {}, HeatmapMeaning::kMissedByStations);
}

Result<std::vector<WorldPoint>> ParseStationsCsv(std::string_view text, std::string_view source) {
  std::vector<WorldPoint> out;
  bool seen_data_line = false;
  std::optional<std::array<size_t, 3>> named;  // the x, y, z columns a header names
  size_t line_no = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    line = Trim(line);
    if (line.empty()) {
      if (end == text.size()) break;
      continue;
    }
    const std::vector<std::string_view> fields = SplitFields(line);
    const std::string where = std::string(source) + ":" + std::to_string(line_no) + ": ";
    // One header line is allowed, before any station: fields without digits (e.g. "x,y,z").
    const bool header = !seen_data_line && std::none_of(line.begin(), line.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c));
    });
    if (header) {
      seen_data_line = true;
      named = XyzColumns(fields);
      continue;
    }
    VC_ASSIGN_OR_RETURN(const WorldPoint p,
                        named ? NamedColumnsRow(fields, *named, line, where) : PositionalRow(fields, line, where));
    seen_data_line = true;
    out.push_back(p);
    if (end == text.size()) break;
  }
  if (out.empty()) return InvalidArgumentError(std::string(source) + ": no station found (expected lines \"x,y,z\")");
  return out;
}

}  // namespace vc
