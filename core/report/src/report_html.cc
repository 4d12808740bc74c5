#include "vc/report/report_html.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string_view>
#include <utility>
#include <vector>

#include "floor_plan.h"
#include "raster.h"
#include "report_assets.h"
#include "vc/plan/coverage_curve.h"
#include "vc/plan/keep_out.h"
#include "vc/report/field_exports.h"

namespace vc {

namespace {

using Json = nlohmann::ordered_json;

// Runs before everything else: collects uncaught errors, rejected promises and console.error
// calls into window.vcReport.errors and the page (#errors, <body data-errors>), so a headless
// browser's --dump-dom shows them.
constexpr std::string_view kErrorCaptureJs = R"js(
window.vcReport = {ready: false, stationMarkers: 0, pointsDrawn: 0, errors: []};
(function () {
  var R = window.vcReport;
  function add(message) {
    R.errors.push(String(message));
    var list = document.getElementById('errors');
    if (list) list.textContent = R.errors.join('\n');
    if (document.body) document.body.setAttribute('data-errors', String(R.errors.length));
  }
  window.addEventListener('error', function (e) {
    add('error: ' + (e.message || e.type) + (e.lineno ? ' (line ' + e.lineno + ')' : ''));
  });
  window.addEventListener('unhandledrejection', function (e) { add('unhandled rejection: ' + e.reason); });
  var consoleError = console.error;
  console.error = function () {
    add('console.error: ' + Array.prototype.map.call(arguments, String).join(' '));
    return consoleError.apply(console, arguments);
  };
})();
)js";

// The 3D view and, for print, its snapshot (report_page.js fills it before printing).
constexpr std::string_view kViewHtml =
    R"html(<div id="view"><div id="hint">drag: rotate &middot; right-drag: pan &middot; wheel: zoom &middot; click a station: the voxels only it sees</div></div>
<img id="snapshot" alt="The 3D view as it was when printed">
<p id="scale"></p>
)html";

// The side panel down to the coverage curve; report_page.js fills its tables and lists.
constexpr std::string_view kPanelHtml =
    R"html(<aside id="panel">
<h1>vc plan report</h1>
<table id="figures"></table>
<h2>View</h2>
<label id="floor-choice">Show <select id="floor"><option value="all">All floors</option></select></label>
<div id="legend"></div>
<div id="controls"></div>
<p id="points-note" class="note"></p>
<h2>Stations</h2>
<p class="note">&ldquo;#&rdquo; numbers the stations in plan order, as the markers in the view and heatmap.png; &ldquo;walking order&rdquo; is the station's number on fieldsheet.pdf and in stations.csv (the order to set them up in); the tripod height is the instrument's height above the floor it stands on.</p>
<p id="selection" class="note"></p>
<div class="table-box"><table id="stations"><thead><tr><th>#</th><th>name</th><th>floor</th><th>tripod height (m)</th><th>walking order</th><th>x (m)</th><th>y (m)</th><th>z (m)</th><th>score alone</th><th>new voxels</th><th>seen only here</th></tr></thead><tbody></tbody></table></div>
<h2>Keep-out zones</h2>
<p class="note">Places no station may stand (drawn as translucent red boxes); coordinates in metres.</p>
<ul id="zones"></ul>
<h2>Coverage curve</h2>
<p class="note">How much of what can be covered the first stations of the plan cover together (plan order): the stations for 80, 90, 95 and 99 % are marked.</p>
)html";

// The glossary and the warnings, after the coverage curve.
constexpr std::string_view kGlossaryHtml =
    R"html(<h2>Glossary</h2>
<dl id="glossary">
<dt>Voxel</dt><dd>A small cube of the model (the resolution above is its edge): every occupied one is drawn as a point.</dd>
<dt>Visibility score</dt><dd>How well a surface is seen from the best station, from 0 to 1: 0 when no station sees it, 0.3 when a station sees part of it, 0.5 to 1 when one sees it whole (more when closer and more head-on). A voxel's colour is the best score of its six faces; the plan's score (G) is the mean over all faces, and &ldquo;score alone&rdquo; is what one station would reach by itself.</dd>
<dt>Coverable</dt><dd>The voxels that some possible station position (a candidate) sees at all; the others (inside walls, behind closed doors, out of the scanner's range) no plan can cover.</dd>
<dt>Coverage</dt><dd>The share of the coverable voxels that at least one station of the plan sees.</dd>
<dt>New voxels</dt><dd>The voxels a station adds to those the stations before it (plan order) already see.</dd>
<dt>Tripod height</dt><dd>The scanner's optical centre above the floor under the station, in metres.</dd>
<dt>Floor</dt><dd>The levels L0 (lowest), L1, &hellip; as on fieldsheet.pdf; the selector above shows one at a time.</dd>
<dt>Walking order</dt><dd>The order to visit the stations along the walking route (orange), as numbered on fieldsheet.pdf.</dd>
<dt>Field time</dt><dd>The estimate for the site: setting up and scanning each station plus walking the route between them.</dd>
<dt>Colours</dt><dd><span class="swatch viridis"></span>dark purple to yellow: a voxel's score from low to high; <span class="swatch" style="background:#808080"></span>grey: no station sees it (red with the checkbox); <span class="swatch" style="background:#ff1ad9"></span>magenta: the voxels only the selected station sees; <span class="swatch ring-red"></span>red ring: a new station, <span class="swatch ring-black"></span>black ring: an existing one; <span class="swatch" style="background:#ff8c00"></span>orange: the walking route; <span class="swatch" style="background:#7fd4ff"></span>light blue: pairs of stations that overlap enough to register; <span class="swatch" style="background:rgba(255,40,40,0.35)"></span>translucent red: keep-out zones; <span class="swatch" style="background:#9aa0a6"></span>grey grid: the metre grid on the floor.</dd>
</dl>
<h2>Warnings</h2>
<ul id="warnings"></ul>
<pre id="errors"></pre>
</aside>
)html";

constexpr char kBase64Alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string Base64(const void* data, size_t size) {
  const auto* p = static_cast<const uint8_t*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= size; i += 3) {
    const uint32_t v = (uint32_t(p[i]) << 16) | (uint32_t(p[i + 1]) << 8) | p[i + 2];
    for (int shift : {18, 12, 6, 0}) out += kBase64Alphabet[(v >> shift) & 63];
  }
  if (i < size) {
    const uint32_t v = (uint32_t(p[i]) << 16) | (i + 1 < size ? uint32_t(p[i + 1]) << 8 : 0);
    out += kBase64Alphabet[(v >> 18) & 63];
    out += kBase64Alphabet[(v >> 12) & 63];
    out += i + 1 < size ? kBase64Alphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// The bytes of `v` in base64; the page reads them as typed arrays, so little-endian like every
// host we build for (x86-64, ARM64; visibility.ply assumes the same).
template <typename T>
std::string Base64Of(const std::vector<T>& v) {
  return Base64(v.data(), v.size() * sizeof(T));
}

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The voxel ids drawn, ascending: all n when n <= cap, else the cap ids of smallest SplitMix64
// hash, a deterministic subset with no spatial pattern (a stride over the sorted ids would draw
// stripes).
std::vector<uint32_t> DrawnVoxels(size_t n, size_t cap) {
  std::vector<uint32_t> ids(n);
  std::iota(ids.begin(), ids.end(), 0u);
  if (n <= cap) return ids;
  auto by_hash = [](uint32_t a, uint32_t b) { return SplitMix64(a) < SplitMix64(b); };
  std::nth_element(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(cap), ids.end(), by_hash);
  ids.resize(cap);
  std::sort(ids.begin(), ids.end());
  return ids;
}

// A voxel's best V (over its 6 faces) as a byte: 0 only for V = 0 (no station sees it), else
// 1..255 for V in (0, 1].
uint8_t VisibilityByte(const std::array<float, kFacesPerVoxel>& faces) {
  const float v = *std::max_element(faces.begin(), faces.end());
  if (!(v > 0)) return 0;
  return static_cast<uint8_t>(std::clamp<long>(std::lround(v * 255.0), 1, 255));
}

// The colour of each VisibilityByte, 256 x RGB: visibility.ply's scale (viridis of V; grey 128
// for V = 0).
std::string PaletteBase64() {
  std::vector<uint8_t> rgb;
  for (int q = 0; q < 256; ++q) {
    const raster::Rgb c = q == 0 ? raster::Rgb{128, 128, 128} : raster::Viridis(q / 255.0);
    rgb.insert(rgb.end(), c.begin(), c.end());
  }
  return Base64Of(rgb);
}

Json PointJson(const WorldPoint& p) { return Json::array({p.x(), p.y(), p.z()}); }

// The voxels: count, the drawn subset as uint16 steps from the lowest corner of all centres
// (step_m = the resolution, coarser only if the scene spans more than 65,535 voxels), their
// VisibilityByte and, with sole_viewer, 1 + the index of their only station (0 for none or
// several). Counts each station's sole voxels (over all voxels) into `sole_counts`.
Json PointsJson(const PlanResult& r, size_t cap, bool with_sole, std::vector<uint64_t>* sole_counts) {
  const size_t n = std::min(r.voxel_centers.size(), r.evaluation.best_face_values.size());
  WorldPoint lo = WorldPoint::Zero(), hi = WorldPoint::Zero();
  uint64_t unseen = 0;
  for (size_t i = 0; i < n; ++i) {
    lo = i == 0 ? r.voxel_centers[i] : WorldPoint(lo.cwiseMin(r.voxel_centers[i]));
    hi = i == 0 ? r.voxel_centers[i] : WorldPoint(hi.cwiseMax(r.voxel_centers[i]));
    if (VisibilityByte(r.evaluation.best_face_values[i]) == 0) ++unseen;
  }
  if (with_sole) {
    for (size_t i = 0; i < n; ++i) {
      const int32_t s = r.evaluation.sole_viewer[i];
      if (s >= 0 && static_cast<size_t>(s) < sole_counts->size()) ++(*sole_counts)[s];
    }
  }
  const double extent = (hi - lo).maxCoeff();
  const double step_m = std::max({r.resolution_m > 0 ? r.resolution_m : 0.01, extent / 65535.0, 1e-9});
  const std::vector<uint32_t> drawn = DrawnVoxels(n, cap);
  std::vector<uint16_t> cells;
  std::vector<uint8_t> values;
  std::vector<uint16_t> sole;
  cells.reserve(3 * drawn.size());
  values.reserve(drawn.size());
  uint64_t unseen_drawn = 0;
  for (uint32_t id : drawn) {
    for (int a = 0; a < 3; ++a) {
      const double steps = std::round((r.voxel_centers[id][a] - lo[a]) / step_m);
      cells.push_back(static_cast<uint16_t>(std::clamp(steps, 0.0, 65535.0)));
    }
    values.push_back(VisibilityByte(r.evaluation.best_face_values[id]));
    if (values.back() == 0) ++unseen_drawn;
    if (with_sole) {
      const int32_t s = r.evaluation.sole_viewer[id];
      sole.push_back(s >= 0 && s < 65535 ? static_cast<uint16_t>(s + 1) : 0);
    }
  }
  return Json{{"total", n},
              {"drawn", drawn.size()},
              {"cap", cap},
              {"unseen_total", unseen},
              {"unseen_drawn", unseen_drawn},
              {"origin", PointJson(lo)},
              {"step_m", step_m},
              {"xyz", Base64Of(cells)},
              {"v", Base64Of(values)},
              {"sole", with_sole ? Json(Base64Of(sole)) : Json(nullptr)}};
}

// How far below a floor's top its voxels begin (m): the slab under the floor belongs to it, and the
// floor below ends there, so that floor shows without the ceiling the slab makes.
constexpr double kSlabM = 0.5;

// The page's floors (fieldsheet.pdf's panels and names), local frame: each floor's top `floor_z`
// and the band of voxels it shows, [from_z, to_z) (null: unbounded).
Json FloorsJson(const floor_plan::Floors& floors, const std::vector<std::string>& names) {
  Json out = Json::array();
  const size_t n = floors.floor_m.size();
  for (size_t p = 0; p < n; ++p) {
    out.push_back({{"name", names[p]},
                   {"floor_z", floors.floor_m[p]},
                   {"from_z", p == 0 ? Json(nullptr) : Json(floors.floor_m[p] - kSlabM)},
                   {"to_z", p + 1 < n ? Json(floors.floor_m[p + 1] - kSlabM) : Json(nullptr)}});
  }
  return out;
}

// The keep-out zones (PlanOptions::keep_out, in the input's frame) in the local frame: each one's
// outline in x, y (x1, y1, x2, y2, ...) and its z range.
Json KeepOutZonesJson(const PlanResult& r) {
  Json out = Json::array();
  const WorldPoint& o = r.frame_origin_m;
  for (size_t k = 0; k < r.options.keep_out.size(); ++k) {
    const KeepOutZone& z = r.options.keep_out[k];
    const bool box = z.shape == KeepOutShape::kBox;
    std::vector<double> xy = box ? std::vector<double>{z.min.x(), z.min.y(), z.max.x(), z.min.y(),
                                                       z.max.x(), z.max.y(), z.min.x(), z.max.y()}
                                 : z.polygon_xy_m;
    for (size_t i = 0; i + 1 < xy.size(); i += 2) xy[i] -= o.x(), xy[i + 1] -= o.y();
    out.push_back({{"number", k + 1},
                   {"shape", box ? "box" : "polygon"},
                   {"outline", std::move(xy)},
                   {"min", PointJson(WorldPoint(z.min - o))},
                   {"max", PointJson(WorldPoint(z.max - o))}});
  }
  return out;
}

// The stations in plan order, each with its field-sheet row (name, walking number, floor, tripod
// height) and the page's floor it is drawn on.
Json StationsJson(const PlanResult& r, const std::vector<FieldStation>& field, const std::vector<int>& field_panel,
                  const std::vector<uint64_t>& sole_counts, bool with_sole) {
  std::vector<int> route_order(r.stations.size(), 0);  // as stations.csv: 1 = visited first, 0 = left out
  for (size_t k = 0; k < r.route.order.size(); ++k) {
    const int s = r.route.order[k];
    if (s >= 0 && static_cast<size_t>(s) < route_order.size()) route_order[s] = static_cast<int>(k) + 1;
  }
  std::vector<size_t> row_of(r.stations.size(), field.size());
  for (size_t i = 0; i < field.size(); ++i) {
    if (field[i].index < row_of.size()) row_of[field[i].index] = i;
  }
  auto height = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  Json stations = Json::array();
  for (size_t k = 0; k < r.stations.size(); ++k) {
    const PlannedStation& s = r.stations[k];
    Json j{{"number", k + 1},
           {"route_order", route_order[k]},
           {"position", PointJson(s.position)},
           {"global_visibility", s.global_visibility},
           {"marginal_gain", std::isfinite(s.cumulative_coverage) ? Json(s.marginal_gain) : Json(nullptr)},
           {"cumulative_coverage", s.cumulative_coverage},
           {"fixed", s.fixed},
           {"sole_voxels", with_sole ? Json(sole_counts[k]) : Json(nullptr)}};
    if (row_of[k] < field.size()) {
      const FieldStation& f = field[row_of[k]];
      j["name"] = f.name;
      j["walk_number"] = f.number;
      j["floor"] = f.floor.empty() ? Json(nullptr) : Json(f.floor);
      j["tripod_height_m"] = height(f.tripod_height_m);
      j["page_floor"] = field_panel[row_of[k]];
    }
    stations.push_back(std::move(j));
  }
  return stations;
}

Json ReportData(const PlanResult& r, const ReportHtmlOptions& options) {
  const size_t voxels = std::min(r.voxel_centers.size(), r.evaluation.best_face_values.size());
  const bool with_sole = voxels > 0 && r.evaluation.sole_viewer.size() == r.voxel_centers.size();
  std::vector<uint64_t> sole_counts(r.stations.size(), 0);
  Json points = PointsJson(r, options.max_points, with_sole, &sole_counts);

  const std::vector<FieldStation> field = FieldStations(r, options.fixed_station_names);
  const double cell_m = r.heat_map.grid_spacing_m > 0 ? r.heat_map.grid_spacing_m : 1.0;
  const floor_plan::Floors floors = floor_plan::ComputeFloors(r, cell_m / 2);
  const std::vector<int> field_panel = floor_plan::StationPanels(floors, r, field);
  Json stations = StationsJson(r, field, field_panel, sole_counts, with_sole);
  int fixed = 0;
  for (const PlannedStation& s : r.stations) fixed += s.fixed ? 1 : 0;
  // The scan graph's links drawn, as heatmap.png: overlap >= min_overlap, or >= 0.3 (the usual
  // target-less registration figure) when registration is off.
  const double edge_min = r.scan_graph.min_overlap > 0 ? r.scan_graph.min_overlap : 0.3;
  Json edges = Json::array();
  for (const ScanGraph::Edge& e : r.scan_graph.edges) {
    if (e.overlap >= edge_min && e.i >= 0 && e.j >= 0) edges.push_back({e.i, e.j, e.overlap});
  }
  Json route = Json::array();
  for (const std::vector<WorldPoint>& line : r.route.polylines) {
    if (line.size() < 2) continue;
    Json flat = Json::array();
    for (const WorldPoint& p : line) flat.insert(flat.end(), {p.x(), p.y(), p.z()});
    route.push_back(std::move(flat));
  }
  const double coverable = static_cast<double>(r.coverable_voxels);
  const double occupied = static_cast<double>(r.occupied_voxels);
  Json figures{{"fixed_stations", fixed},
               {"occupied_voxels", r.occupied_voxels},
               {"coverable_voxels", r.coverable_voxels},
               {"covered_voxels", r.covered_voxels},
               {"covered_fraction_of_coverable", coverable > 0 ? r.covered_voxels / coverable : 0.0},
               {"covered_fraction_of_occupied", occupied > 0 ? r.covered_voxels / occupied : 0.0},
               {"global_visibility", r.evaluation.overall.global_visibility},
               {"fully_visible_fraction", r.evaluation.overall.fully_visible_fraction},
               {"partially_visible_fraction", r.evaluation.overall.partially_visible_fraction},
               {"field_time_s",
                {{"setup", r.field_time.setup_s},
                 {"scan", r.field_time.scan_s},
                 {"walk", r.field_time.walk_s},
                 {"total", r.field_time.total_s}}},
               {"route_length_m", r.route.length_m},
               {"route_parts", r.route.parts},
               {"min_overlap", r.scan_graph.min_overlap},
               {"scan_graph_connected", r.scan_graph.connected}};
  return Json{{"schema", "vc.report/1"},
              {"frame_origin_m", PointJson(r.frame_origin_m)},
              {"resolution_m", r.resolution_m},
              {"selection_test", std::string(SelectionTestName(r.selection_test))},
              {"figures", std::move(figures)},
              {"stations", std::move(stations)},
              {"edge_min_overlap", edge_min},
              {"edges", std::move(edges)},
              {"route", std::move(route)},
              {"points", std::move(points)},
              {"palette", PaletteBase64()},
              {"warnings", r.warnings},
              {"floors", FloorsJson(floors, floor_plan::PanelNames(floors, field, field_panel))},
              {"keep_out", KeepOutZonesJson(r)}};
}

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

// "1 h 05 min", "35 min", "40 s".
std::string Duration(double seconds) {
  if (seconds < 60) return std::to_string(std::lround(seconds)) + " s";
  const long minutes = std::lround(seconds / 60);
  if (minutes < 60) return std::to_string(minutes) + " min";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%ld h %02ld min", minutes / 60, minutes % 60);
  return buf;
}

// The smallest of 1, 2, 5 x 10^k (at least 1) that is >= `at_least`.
double RoundStep(double at_least) {
  for (double decade = 1;; decade *= 10) {
    for (double m : {1.0, 2.0, 5.0}) {
      if (m * decade >= at_least) return m * decade;
    }
  }
}

// The coverage curve (PlanResult::coverage_curve) as an inline SVG, then its milestones as a list:
// stations (x, from 0) against coverage of the coverable voxels (y, %). The curve's polyline holds
// the data itself, "k,percent" per point from "0,0", drawn through a transform from the plot's
// data units to pixels; each station count that reaches milestones is a <g class="milestone"
// data-levels="90 95" data-stations="6">.
std::string CoverageCurveSvg(const PlanResult& r) {
  const std::vector<CoveragePoint>& curve = r.coverage_curve;
  if (curve.empty()) return "<p id=\"coverage-curve\" class=\"note\">This plan carries no coverage curve.</p>\n";
  constexpr double kWidth = 380, kHeight = 220, kLeft = 46, kRight = 14, kTop = 10, kBottom = 40;
  const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  const double n = static_cast<double>(curve.back().stations);
  const double sx = plot_w / std::max(n, 1.0), sy = plot_h / 100.0;
  auto px = [&](double k) { return Fixed(kLeft + k * sx, 1); };
  auto py = [&](double percent) { return Fixed(kTop + plot_h - percent * sy, 1); };
  std::string svg = "<svg id=\"coverage-curve\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " +
                    Fixed(kWidth, 0) + " " + Fixed(kHeight, 0) + "\" role=\"img\" aria-label=\"coverage curve\">\n";
  for (int percent = 0; percent <= 100; percent += 20) {
    svg += "<line class=\"grid\" x1=\"" + px(0) + "\" x2=\"" + px(n) + "\" y1=\"" + py(percent) + "\" y2=\"" +
           py(percent) + "\"/><text class=\"tick\" x=\"" + Fixed(kLeft - 4, 1) + "\" y=\"" + py(percent) +
           "\" text-anchor=\"end\" dy=\"0.35em\">" + std::to_string(percent) + " %</text>\n";
  }
  const double step = RoundStep(n / 8);
  for (double k = 0; k <= n + 1e-9; k += step) {
    svg += "<text class=\"tick\" x=\"" + px(k) + "\" y=\"" + Fixed(kTop + plot_h + 14, 1) +
           "\" text-anchor=\"middle\">" + Fixed(k, 0) + "</text>\n";
  }
  svg += "<text class=\"axis\" x=\"" + Fixed(kLeft + plot_w / 2, 1) + "\" y=\"" + Fixed(kHeight - 6, 1) +
         "\" text-anchor=\"middle\">stations (plan order)</text>\n";
  svg += "<g transform=\"translate(" + Fixed(kLeft, 1) + " " + Fixed(kTop + plot_h, 1) + ") scale(" + Fixed(sx, 6) +
         " " + Fixed(-sy, 6) + ")\"><polyline id=\"coverage-points\" vector-effect=\"non-scaling-stroke\" points=\"0,0";
  for (const CoveragePoint& c : curve)
    svg += " " + std::to_string(c.stations) + "," + Fixed(100 * c.coverable_fraction, 3);
  svg += "\"/>";
  // The per-k bound, dashed: no k stations over these candidates cover more (absent: not computed).
  std::string bound;
  for (const CoveragePoint& c : curve) {
    if (c.best_voxels_upper_bound && r.coverable_voxels > 0)
      bound += " " + std::to_string(c.stations) + "," +
               Fixed(100.0 * static_cast<double>(*c.best_voxels_upper_bound) / r.coverable_voxels, 3);
  }
  if (!bound.empty())
    svg += "<polyline id=\"coverage-bound\" vector-effect=\"non-scaling-stroke\" points=\"" + bound.substr(1) + "\"/>";
  svg += "</g>\n";
  if (!bound.empty())
    svg += "<text class=\"legend\" x=\"" + px(n) + "\" y=\"" + py(8) +
           "\" text-anchor=\"end\">dashed: the most any plan of k stations can cover</text>\n";
  std::string list = "<ul id=\"milestones\">\n";
  const std::vector<double> levels(std::begin(kCoverageMilestones), std::end(kCoverageMilestones));
  // One mark per station count reached, naming every level it reaches (90, 95 and 99 % often fall
  // on the same station).
  std::vector<std::pair<CoveragePoint, std::vector<std::string>>> marks;
  for (const CoverageMilestone& m : CoverageMilestones(curve, r.coverable_voxels, levels)) {
    const std::string level = Fixed(100 * m.coverable_fraction, 0);
    if (!m.reached) {
      list += "<li>" + level + " % of what can be covered: not reached by this plan</li>\n";
      continue;
    }
    const CoveragePoint& c = *m.reached;
    if (marks.empty() || marks.back().first.stations != c.stations) marks.push_back({c, {}});
    marks.back().second.push_back(level);
    list += "<li>" + level + " % of what can be covered: " + std::to_string(c.stations) + " station" +
            (c.stations == 1 ? "" : "s") + " (" + Fixed(100 * c.scene_fraction, 1) +
            " % of the whole scene; setting up and scanning them about " + Duration(c.setup_scan_s) + ")" +
            (m.fewest_possible_stations ? "; no plan over these candidates reaches it with fewer than " +
                                              std::to_string(*m.fewest_possible_stations) + " stations"
                                        : "") +
            "</li>\n";
  }
  for (const auto& [c, marked_levels] : marks) {
    std::string data_levels, label;
    for (const std::string& level : marked_levels) {
      data_levels += (data_levels.empty() ? "" : " ") + level;
      label += (label.empty() ? "" : ", ") + level;
    }
    const std::string x = px(c.stations), y = py(100 * c.coverable_fraction);
    const bool right_half = c.stations > 0.6 * n;  // the label goes left of its mark there
    svg += "<g class=\"milestone\" data-levels=\"" + data_levels + "\" data-stations=\"" + std::to_string(c.stations) +
           "\"><line x1=\"" + px(0) + "\" x2=\"" + x + "\" y1=\"" + y + "\" y2=\"" + y + "\"/><line x1=\"" + x +
           "\" x2=\"" + x + "\" y1=\"" + y + "\" y2=\"" + py(0) + "\"/><circle cx=\"" + x + "\" cy=\"" + y +
           "\" r=\"3.5\"/><text x=\"" + x + "\" y=\"" + y + "\" dy=\"0.35em\" " +
           (right_half ? "dx=\"-6\" text-anchor=\"end\"" : "dx=\"6\"") + ">" + label + " %</text></g>\n";
  }
  return svg + "</svg>\n" + list + "</ul>\n";
}

// `j` as a JavaScript expression safe inside an HTML <script> element: ASCII only (ensure_ascii;
// invalid UTF-8 replaced), and '<', '>' and '&' (which then occur only inside strings) as \u
// escapes, so no "</script>" or "<!--" can appear.
std::string ScriptSafeJson(const Json& j) {
  const std::string text = j.dump(-1, ' ', true, Json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '<':
        out += "\\u003c";
        break;
      case '>':
        out += "\\u003e";
        break;
      case '&':
        out += "\\u0026";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string PlanToHtml(const PlanResult& result, const ReportHtmlOptions& options) {
  const std::string data = ScriptSafeJson(ReportData(result, options));
  std::string html;
  html.reserve(data.size() + 1000000);
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"vc (vc::PlanToHtml)\">\n<title>vc plan report</title>\n<style>\n";
  html += report_assets::ReportPageCss();
  html += "</style>\n<script>";
  html += kErrorCaptureJs;
  html += "</script>\n</head>\n<body data-ready=\"false\" data-errors=\"0\">\n";
  html += kViewHtml;
  html += kPanelHtml;
  html += CoverageCurveSvg(result);
  html += kGlossaryHtml;
  html += "<script>\n";
  html += report_assets::ThreeJs();
  html += "\n</script>\n<script>\n";
  html += report_assets::OrbitControlsJs();
  html += "\n</script>\n<script>\nwindow.VC_REPORT_DATA = ";
  html += data;
  html += ";\n</script>\n<script>\n";
  html += report_assets::ReportPageJs();
  html += "\n</script>\n</body>\n</html>\n";
  return html;
}

}  // namespace vc
