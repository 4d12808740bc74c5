#include "vc/report/report_html.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string_view>
#include <vector>

#include "raster.h"
#include "report_assets.h"

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

// The page's fixed markup; report_page.js fills it.
constexpr std::string_view kBodyHtml =
    R"html(<div id="view"><div id="hint">drag: rotate &middot; right-drag: pan &middot; wheel: zoom &middot; click a station: the voxels only it sees</div></div>
<aside id="panel">
<h1>vc plan report</h1>
<table id="figures"></table>
<h2>View</h2>
<div id="legend"></div>
<div id="controls"></div>
<p id="points-note" class="note"></p>
<h2>Stations</h2>
<p class="note">Numbered in plan order (as heatmap.png and the rows of stations.csv); &ldquo;walk&rdquo; is the place in the walking route; &ldquo;sole&rdquo; counts the voxels no other station sees.</p>
<p id="selection" class="note"></p>
<table id="stations"><thead><tr><th>#</th><th>walk</th><th>x (m)</th><th>y (m)</th><th>z (m)</th><th>G alone</th><th>gain</th><th>sole</th></tr></thead><tbody></tbody></table>
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

Json ReportData(const PlanResult& r, const ReportHtmlOptions& options) {
  const size_t voxels = std::min(r.voxel_centers.size(), r.evaluation.best_face_values.size());
  const bool with_sole = voxels > 0 && r.evaluation.sole_viewer.size() == r.voxel_centers.size();
  std::vector<uint64_t> sole_counts(r.stations.size(), 0);
  Json points = PointsJson(r, options.max_points, with_sole, &sole_counts);

  std::vector<int> route_order(r.stations.size(), 0);  // as stations.csv: 1 = visited first, 0 = left out
  for (size_t k = 0; k < r.route.order.size(); ++k) {
    const int s = r.route.order[k];
    if (s >= 0 && static_cast<size_t>(s) < route_order.size()) route_order[s] = static_cast<int>(k) + 1;
  }
  Json stations = Json::array();
  int fixed = 0;
  for (size_t k = 0; k < r.stations.size(); ++k) {
    const PlannedStation& s = r.stations[k];
    fixed += s.fixed ? 1 : 0;
    stations.push_back({{"number", k + 1},
                        {"route_order", route_order[k]},
                        {"position", PointJson(s.position)},
                        {"global_visibility", s.global_visibility},
                        {"marginal_gain", s.marginal_gain},
                        {"cumulative_coverage", s.cumulative_coverage},
                        {"fixed", s.fixed},
                        {"sole_voxels", with_sole ? Json(sole_counts[k]) : Json(nullptr)}});
  }
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
  return Json{{"schema", "vc.report/1"},        {"frame_origin_m", PointJson(r.frame_origin_m)},
              {"resolution_m", r.resolution_m}, {"selection_test", std::string(SelectionTestName(r.selection_test))},
              {"figures", std::move(figures)},  {"stations", std::move(stations)},
              {"edge_min_overlap", edge_min},   {"edges", std::move(edges)},
              {"route", std::move(route)},      {"points", std::move(points)},
              {"palette", PaletteBase64()},     {"warnings", r.warnings}};
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
  html += kBodyHtml;
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
