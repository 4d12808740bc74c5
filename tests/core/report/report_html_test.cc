// report.html's writer: a self-contained page (no network references, three.js inlined), the
// plan's data as the page reads it (stations with their field-sheet names, floors and tripod
// heights, route order, sole voxels, the quantised voxels and their colours, floors, keep-out
// zones), the static parts (station table columns, coverage curve, glossary, print style),
// decimation, escaping of hostile strings, and WritePlanOutputs writing it.
// report_html_browser_test opens the page in a real browser.
#include "vc/report/report_html.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "testing/test_paths.h"
#include "vc/plan/coverage_curve.h"
#include "vc/plan/keep_out.h"
#include "vc/report/field_exports.h"
#include "vc/report/plan_report.h"

namespace vc {
namespace {

using nlohmann::json;

// Three stations over a 4 x 3 x 2 block of 0.2 m voxels: voxel i is seen by station i % 4 - 1
// alone (none for i % 4 == 0) and, for even i, by a second one too (V then 0.9).
PlanResult BlockPlan() {
  PlanResult r;
  r.resolution_m = 0.2;
  r.stations = {{WorldPoint(1.0, 0.5, 1.5), 900, 900, 0.6, 0.31, 4},
                {WorldPoint(-1.0, 0.5, 1.5), 700, 300, 0.9, 0.22, 7},
                {WorldPoint(0.3, 2.5, 1.5), 500, 100, 1.0, 0.12, -1, true}};
  r.occupied_voxels = 24;
  r.coverable_voxels = 20;
  r.covered_voxels = 18;
  r.evaluation.overall = {0.47, 0.3, 0.8, 0.2};
  r.route.order = {2, 0, 1};
  r.route.polylines = {
      {}, {WorldPoint(0.3, 2.5, 0), WorldPoint(1.0, 0.5, 0)}, {WorldPoint(1, 0.5, 0), WorldPoint(-1, 0.5, 0)}};
  r.route.length_m = 4.1;
  r.route.parts = 1;
  r.scan_graph.min_overlap = 0.3;
  r.scan_graph.edges = {{0, 1, 0.5}, {0, 2, 0.1}, {1, 2, 0.35}};
  r.field_time = {270, 90, 5, 365, 30};
  for (int z = 0; z < 2; ++z) {
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 4; ++x) {
        const int i = static_cast<int>(r.voxel_centers.size());
        r.voxel_centers.emplace_back(10.1 + 0.2 * x, -3.1 + 0.2 * y, 0.1 + 0.2 * z);
        std::array<float, 6> faces{};
        const int viewer = i % 4 - 1;
        if (viewer >= 0) faces[i % 6] = i % 2 == 0 ? 0.9f : 0.25f;
        r.evaluation.best_face_values.push_back(faces);
        r.evaluation.sole_viewer.push_back(viewer < 0 ? kNoViewer : (i % 2 == 0 ? kSeveralViewers : viewer));
      }
    }
  }
  r.warnings = {"a plain warning"};
  return r;
}

// The text between the first `begin` and the next `end` after it; "" if either is missing.
std::string Between(const std::string& text, const std::string& begin, const std::string& end) {
  const size_t at = text.find(begin);
  if (at == std::string::npos) return "";
  const size_t stop = text.find(end, at + begin.size());
  return stop == std::string::npos ? "" : text.substr(at + begin.size(), stop - at - begin.size());
}

// Every `<tag ...>text</tag>`'s text in `html`, in order (no nesting).
std::vector<std::string> Texts(const std::string& html, const std::string& tag) {
  std::vector<std::string> out;
  for (size_t at = html.find("<" + tag); at != std::string::npos; at = html.find("<" + tag, at + 1)) {
    const size_t open_end = html.find('>', at);
    const size_t close = html.find("</" + tag + ">", open_end);
    if (open_end == std::string::npos || close == std::string::npos) break;
    out.push_back(html.substr(open_end + 1, close - open_end - 1));
  }
  return out;
}

// The page's data object (window.VC_REPORT_DATA = {...};).
json PageData(const std::string& html) {
  const std::string start = "window.VC_REPORT_DATA = ";
  const size_t at = html.find(start);
  if (at == std::string::npos) return nullptr;
  const size_t end = html.find(";\n</script>", at);
  if (end == std::string::npos) return nullptr;
  return json::parse(html.substr(at + start.size(), end - at - start.size()));
}

std::vector<uint8_t> FromBase64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<uint8_t> out;
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | static_cast<uint32_t>(alphabet.find(c));
    count += 6;
    if (count >= 8) {
      count -= 8;
      out.push_back(static_cast<uint8_t>((bits >> count) & 0xff));
    }
  }
  return out;
}

std::vector<uint16_t> Uint16s(const std::string& base64) {
  const std::vector<uint8_t> b = FromBase64(base64);
  std::vector<uint16_t> out;
  for (size_t i = 0; i + 1 < b.size(); i += 2) out.push_back(static_cast<uint16_t>(b[i] | (b[i + 1] << 8)));
  return out;
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The first `src=` or `href=` (any case, optional quotes and spaces) whose value starts with
// http:, https: or //, with what follows it; "" if none.
std::string RemoteReference(const std::string& html) {
  std::string lower = html;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const std::string attribute : {"src", "href"}) {
    for (size_t at = lower.find(attribute); at != std::string::npos; at = lower.find(attribute, at + 1)) {
      size_t k = at + attribute.size();
      while (k < lower.size() && std::isspace(static_cast<unsigned char>(lower[k]))) ++k;
      if (k >= lower.size() || lower[k] != '=') continue;
      ++k;
      while (k < lower.size() &&
             (std::isspace(static_cast<unsigned char>(lower[k])) || lower[k] == '"' || lower[k] == '\''))
        ++k;
      const std::string value = lower.substr(k, 8);
      if (value.rfind("http:", 0) == 0 || value.rfind("https:", 0) == 0 || value.rfind("//", 0) == 0) {
        return html.substr(at, 60);
      }
    }
  }
  return "";
}

TEST(ReportHtmlTest, IsSelfContainedWithThreeJsInlined) {
  const std::string html = PlanToHtml(BlockPlan());
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  // No reference that would load anything: no src/href to a URL, no <link>, no external script.
  EXPECT_EQ(RemoteReference(html), "");
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_NE(html.find("REVISION=\"111\""), std::string::npos) << "three.js r111 is not inlined";
  EXPECT_NE(html.find("exports.OrbitControls = OrbitControls"), std::string::npos) << "OrbitControls is not inlined";
  EXPECT_NE(html.find("window.vcReport"), std::string::npos);
  // Five inline scripts (error capture, three.js, OrbitControls, data, page), each closed once.
  EXPECT_EQ(Count(html, "<script>"), 5u);
  EXPECT_EQ(Count(html, "</script>"), 5u);
  EXPECT_LT(html.size(), 1500000u);
}

TEST(ReportHtmlTest, DataHoldsTheStationsRouteOrderAndFigures) {
  const json d = PageData(PlanToHtml(BlockPlan()));
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["schema"], "vc.report/1");
  ASSERT_EQ(d["stations"].size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(d["stations"][k]["number"].get<int>(), k + 1);
  // The route visits 2, 0, 1: stations.csv's route_order 2, 3, 1.
  EXPECT_EQ(d["stations"][0]["route_order"].get<int>(), 2);
  EXPECT_EQ(d["stations"][1]["route_order"].get<int>(), 3);
  EXPECT_EQ(d["stations"][2]["route_order"].get<int>(), 1);
  EXPECT_TRUE(d["stations"][2]["fixed"].get<bool>());
  EXPECT_DOUBLE_EQ(d["stations"][1]["position"][0].get<double>(), -1.0);
  // Voxels 1, 5, 9, ... (i % 4 == 1, odd) are station 0's alone; 3, 7, 11, ... station 2's.
  EXPECT_EQ(d["stations"][0]["sole_voxels"].get<int>(), 6);
  EXPECT_EQ(d["stations"][1]["sole_voxels"].get<int>(), 0);
  EXPECT_EQ(d["stations"][2]["sole_voxels"].get<int>(), 6);
  EXPECT_DOUBLE_EQ(d["figures"]["global_visibility"].get<double>(), 0.47);
  EXPECT_DOUBLE_EQ(d["figures"]["covered_fraction_of_coverable"].get<double>(), 0.9);
  EXPECT_DOUBLE_EQ(d["figures"]["field_time_s"]["total"].get<double>(), 365);
  EXPECT_EQ(d["figures"]["fixed_stations"].get<int>(), 1);
  // Edges at min_overlap 0.3: (0, 1) and (1, 2), not (0, 2).
  EXPECT_EQ(d["edges"], json::parse("[[0, 1, 0.5], [1, 2, 0.35]]"));
  ASSERT_EQ(d["route"].size(), 2u);  // the empty first leg is left out
  EXPECT_EQ(d["route"][0].size(), 6u);
}

TEST(ReportHtmlTest, DrawsInTheLocalFrameAndGivesThePageTheFramesOrigin) {
  PlanResult plan = BlockPlan();
  const json near_origin = PageData(PlanToHtml(plan));
  EXPECT_EQ(near_origin["frame_origin_m"], json::parse("[0.0, 0.0, 0.0]"));
  plan.frame_origin_m = WorldPoint(512000, 5612000, 0);
  const json d = PageData(PlanToHtml(plan));
  EXPECT_EQ(d["frame_origin_m"], json::parse("[512000.0, 5612000.0, 0.0]"));
  // Positions and voxels stay local (float32 in WebGL); the page adds the origin where it shows them.
  EXPECT_EQ(d["stations"], near_origin["stations"]);
  EXPECT_EQ(d["points"], near_origin["points"]);
}

TEST(ReportHtmlTest, VoxelsAreQuantisedWithVisibilityBytesAndSoleViewers) {
  const PlanResult plan = BlockPlan();
  const json p = PageData(PlanToHtml(plan))["points"];
  ASSERT_EQ(p["total"].get<int>(), 24);
  ASSERT_EQ(p["drawn"].get<int>(), 24);
  EXPECT_EQ(p["unseen_total"].get<int>(), 6);  // i % 4 == 0
  EXPECT_DOUBLE_EQ(p["step_m"].get<double>(), 0.2);
  const std::vector<uint16_t> cells = Uint16s(p["xyz"]);
  const std::vector<uint8_t> v = FromBase64(p["v"]);
  const std::vector<uint16_t> sole = Uint16s(p["sole"]);
  ASSERT_EQ(cells.size(), 72u);
  ASSERT_EQ(v.size(), 24u);
  ASSERT_EQ(sole.size(), 24u);
  for (size_t i = 0; i < 24; ++i) {
    for (int a = 0; a < 3; ++a) {
      const double decoded = p["origin"][a].get<double>() + cells[3 * i + a] * p["step_m"].get<double>();
      EXPECT_NEAR(decoded, plan.voxel_centers[i][a], 1e-9) << "voxel " << i << " axis " << a;
    }
    const int viewer = static_cast<int>(i % 4) - 1;
    EXPECT_EQ(v[i], viewer < 0 ? 0 : (i % 2 == 0 ? 229 : 64)) << i;  // round(V * 255), 0 only for V = 0
    EXPECT_EQ(sole[i], viewer < 0 || i % 2 == 0 ? 0 : viewer + 1) << i;
  }
  // The palette: grey for V = 0, then viridis (dark purple at the low end, yellow at the top).
  const std::vector<uint8_t> palette = FromBase64(PageData(PlanToHtml(plan))["palette"]);
  ASSERT_EQ(palette.size(), 768u);
  EXPECT_EQ(palette[0], 128);
  EXPECT_GT(palette[3 * 255], 200);   // yellow: red high
  EXPECT_LT(palette[3 * 1 + 1], 40);  // purple: green low
}

TEST(ReportHtmlTest, ManyVoxelsAreDecimatedDeterministically) {
  PlanResult plan = BlockPlan();
  ReportHtmlOptions options;
  options.max_points = 10;
  const std::string html = PlanToHtml(plan, options);
  EXPECT_EQ(html, PlanToHtml(plan, options));
  const json p = PageData(html)["points"];
  EXPECT_EQ(p["total"].get<int>(), 24);
  EXPECT_EQ(p["drawn"].get<int>(), 10);
  EXPECT_EQ(p["cap"].get<int>(), 10);
  const std::vector<uint16_t> cells = Uint16s(p["xyz"]);
  ASSERT_EQ(cells.size(), 30u);
  std::set<std::array<uint16_t, 3>> distinct;
  for (size_t i = 0; i < 10; ++i) distinct.insert({cells[3 * i], cells[3 * i + 1], cells[3 * i + 2]});
  EXPECT_EQ(distinct.size(), 10u);
  EXPECT_EQ(FromBase64(p["v"]).size(), 10u);
  // Sole voxel counts stay over all voxels.
  EXPECT_EQ(PageData(html)["stations"][0]["sole_voxels"].get<int>(), 6);
}

TEST(ReportHtmlTest, WithoutSoleViewersThePageIsToldSo) {
  PlanResult plan = BlockPlan();
  plan.evaluation.sole_viewer.clear();
  const json d = PageData(PlanToHtml(plan));
  EXPECT_TRUE(d["points"]["sole"].is_null());
  for (const json& s : d["stations"]) EXPECT_TRUE(s["sole_voxels"].is_null());
}

TEST(ReportHtmlTest, HostileWarningCannotEscapeTheScript) {
  PlanResult plan = BlockPlan();
  const std::string hostile = "</script><script>alert('x')</script><!-- <b onmouseover=\"x()\">&amp; \u2028 é";
  plan.warnings = {hostile, std::string("bad UTF-8: \xff\xfe end")};
  const std::string html = PlanToHtml(plan);
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_EQ(html.find("<b onmouseover"), std::string::npos);
  EXPECT_EQ(Count(html, "</script>"), 5u);
  EXPECT_EQ(Count(html, "<!--"), 0u);
  const json d = PageData(html);
  ASSERT_EQ(d["warnings"].size(), 2u);
  EXPECT_EQ(d["warnings"][0].get<std::string>(), hostile);  // the page shows it as text, unchanged
  EXPECT_EQ(d["warnings"][1].get<std::string>(), "bad UTF-8: \ufffd\ufffd end");
}

TEST(ReportHtmlTest, NoVoxelsGiveAnEmptyButValidPage) {
  PlanResult plan = BlockPlan();
  plan.voxel_centers.clear();
  plan.evaluation.best_face_values.clear();
  const json d = PageData(PlanToHtml(plan));
  EXPECT_EQ(d["points"]["drawn"].get<int>(), 0);
  EXPECT_TRUE(d["points"]["sole"].is_null());
  EXPECT_EQ(d["stations"].size(), 3u);
}

TEST(ReportHtmlTest, StationTableNamesTheFieldSheetsColumns) {
  const std::string head = Between(PlanToHtml(BlockPlan()), "<table id=\"stations\"><thead>", "</thead>");
  EXPECT_EQ(Texts(head, "th"),
            (std::vector<std::string>{"#", "name", "floor", "tripod height (m)", "walking order", "x (m)", "y (m)",
                                      "z (m)", "score alone", "new voxels", "seen only here"}));
}

TEST(ReportHtmlTest, StationsCarryTheirFieldSheetNameFloorAndTripodHeight) {
  PlanResult plan = BlockPlan();
  plan.stations[0].floor_z_m = 0.0;  // 1.5 m above it
  plan.stations[1].floor_z_m = 0.1;  // 1.4 m
  ReportHtmlOptions options;
  options.fixed_station_names = {"PILLAR 7"};  // station 2, the only fixed one
  const json d = PageData(PlanToHtml(plan, options));
  const std::vector<FieldStation> field = FieldStations(plan, options.fixed_station_names);
  ASSERT_EQ(field.size(), 3u);
  for (const FieldStation& f : field) {
    const json& s = d["stations"][f.index];
    EXPECT_EQ(s["name"].get<std::string>(), f.name);
    EXPECT_EQ(s["walk_number"].get<int>(), f.number);
    EXPECT_EQ(s["page_floor"].get<int>(), 0);
  }
  EXPECT_EQ(d["stations"][2]["name"], "PILLAR 7");
  EXPECT_EQ(d["stations"][2]["walk_number"], 1);  // the route starts there
  EXPECT_EQ(d["stations"][0]["floor"], "L0");
  EXPECT_NEAR(d["stations"][0]["tripod_height_m"].get<double>(), 1.5, 1e-12);
  EXPECT_NEAR(d["stations"][1]["tripod_height_m"].get<double>(), 1.4, 1e-12);
  EXPECT_TRUE(d["stations"][2]["floor"].is_null()) << "no floor below it";
  EXPECT_TRUE(d["stations"][2]["tripod_height_m"].is_null());
}

TEST(ReportHtmlTest, FloorsAreTheFieldSheetsWithTheirBandsOfVoxels) {
  PlanResult plan = BlockPlan();
  // Candidates on two floors (tops at z 0 and 3.3) under 1.5 m tripods; station 1 upstairs.
  plan.heat_map.grid_spacing_m = 1.0;
  plan.heat_map.positions = {WorldPoint(0, 0, 1.5), WorldPoint(1, 0, 1.5), WorldPoint(0, 0, 4.8)};
  plan.heat_map.floor_z_m = {0.0, 0.0, 3.3};
  plan.heat_map.visible_voxels = {5, 5, 5};
  plan.stations[0].floor_z_m = plan.stations[2].floor_z_m = 0.0;
  plan.stations[1].position.z() = 4.8;
  plan.stations[1].floor_z_m = 3.3;
  plan.floor_levels_m = {0.0, 3.3};
  const json d = PageData(PlanToHtml(plan));
  ASSERT_EQ(d["floors"].size(), 2u);
  EXPECT_EQ(d["floors"][0]["name"], "L0");
  EXPECT_EQ(d["floors"][1]["name"], "L1");
  EXPECT_NEAR(d["floors"][0]["floor_z"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(d["floors"][1]["floor_z"].get<double>(), 3.3, 1e-9);
  // The lower floor ends, and the upper begins, half a metre below the upper floor's top.
  EXPECT_TRUE(d["floors"][0]["from_z"].is_null());
  EXPECT_NEAR(d["floors"][0]["to_z"].get<double>(), 2.8, 1e-9);
  EXPECT_NEAR(d["floors"][1]["from_z"].get<double>(), 2.8, 1e-9);
  EXPECT_TRUE(d["floors"][1]["to_z"].is_null());
  EXPECT_EQ(d["stations"][0]["page_floor"], 0);
  EXPECT_EQ(d["stations"][1]["page_floor"], 1);
  EXPECT_EQ(d["stations"][1]["floor"], "L1");
  EXPECT_EQ(d["stations"][2]["page_floor"], 0);
}

TEST(ReportHtmlTest, KeepOutZonesAreGivenInTheLocalFrame) {
  PlanResult plan = BlockPlan();
  plan.frame_origin_m = WorldPoint(512000, 5612000, 100);
  plan.options.keep_out = {KeepOutBox(WorldPoint(512001, 5612002, 100), WorldPoint(512003, 5612004, 102)),
                           KeepOutPolygon(99, 101, {512000, 5612000, 512002, 5612000, 512001, 5612001})};
  const json z = PageData(PlanToHtml(plan))["keep_out"];
  ASSERT_EQ(z.size(), 2u);
  EXPECT_EQ(z[0]["number"], 1);
  EXPECT_EQ(z[0]["shape"], "box");
  EXPECT_EQ(z[0]["outline"], json::parse("[1.0, 2.0, 3.0, 2.0, 3.0, 4.0, 1.0, 4.0]"));
  EXPECT_EQ(z[0]["min"], json::parse("[1.0, 2.0, 0.0]"));
  EXPECT_EQ(z[0]["max"], json::parse("[3.0, 4.0, 2.0]"));
  EXPECT_EQ(z[1]["shape"], "polygon");
  EXPECT_EQ(z[1]["outline"], json::parse("[0.0, 0.0, 2.0, 0.0, 1.0, 1.0]"));
  EXPECT_EQ(z[1]["min"], json::parse("[0.0, 0.0, -1.0]"));
  EXPECT_EQ(z[1]["max"], json::parse("[2.0, 1.0, 1.0]"));
  EXPECT_EQ(PageData(PlanToHtml(BlockPlan()))["keep_out"], json::array());
}

TEST(ReportHtmlTest, CoverageCurveHoldsEveryPointAndMarksTheMilestones) {
  PlanResult plan = BlockPlan();
  plan.coverage_curve = CoverageCurve({10, 6, 2}, 24, 20, 30);  // 50, 80, 90 % of the coverable voxels
  const std::string html = PlanToHtml(plan);
  const std::string svg = Between(html, "<svg id=\"coverage-curve\"", "</svg>");
  ASSERT_FALSE(svg.empty());
  EXPECT_EQ(Between(svg, "<polyline id=\"coverage-points\" vector-effect=\"non-scaling-stroke\" points=\"", "\""),
            "0,0 1,50.000 2,80.000 3,90.000");
  // 80 % after 2 stations, 90 % after 3; 95 and 99 % never.
  EXPECT_NE(svg.find("<g class=\"milestone\" data-levels=\"80\" data-stations=\"2\">"), std::string::npos);
  EXPECT_NE(svg.find("<g class=\"milestone\" data-levels=\"90\" data-stations=\"3\">"), std::string::npos);
  EXPECT_EQ(Count(svg, "class=\"milestone\""), 2u);
  // Levels reached by the same station share its mark: 80 and 90 % both after 2 stations here.
  plan.coverage_curve = CoverageCurve({10, 8, 2}, 24, 20, 30);  // 50, 90, 100 %
  const std::string shared = Between(PlanToHtml(plan), "<svg id=\"coverage-curve\"", "</svg>");
  EXPECT_NE(shared.find("<g class=\"milestone\" data-levels=\"80 90\" data-stations=\"2\">"), std::string::npos);
  EXPECT_NE(shared.find(">80, 90 %</text>"), std::string::npos);
  EXPECT_NE(shared.find("<g class=\"milestone\" data-levels=\"95 99\" data-stations=\"3\">"), std::string::npos);
  const std::vector<std::string> items = Texts(Between(html, "<ul id=\"milestones\">", "</ul>"), "li");
  ASSERT_EQ(items.size(), 4u);
  EXPECT_EQ(items[0],
            "80 % of what can be covered: 2 stations (66.7 % of the whole scene; setting up and scanning "
            "them about 1 min)");
  EXPECT_EQ(items[2], "95 % of what can be covered: not reached by this plan");
  EXPECT_EQ(items[3], "99 % of what can be covered: not reached by this plan");
}

// The per-k bound as a second, dashed line and, per milestone, the fewest stations any plan needs.
TEST(ReportHtmlTest, CoverageCurveDrawsThePerKBound) {
  PlanResult plan = BlockPlan();
  plan.coverage_curve = CoverageCurve({10, 6, 2}, 24, 20, 30);  // 50, 80, 90 %
  const std::string without = PlanToHtml(plan);
  EXPECT_EQ(without.find("coverage-bound\""), std::string::npos);
  AddBestCoverage(plan.coverage_curve, {BestCoverage{12, 10}, BestCoverage{17, 16}, BestCoverage{19, 18}});
  const std::string html = PlanToHtml(plan);
  const std::string svg = Between(html, "<svg id=\"coverage-curve\"", "</svg>");
  EXPECT_EQ(Between(svg, "<polyline id=\"coverage-bound\" vector-effect=\"non-scaling-stroke\" points=\"", "\""),
            "1,60.000 2,85.000 3,95.000");
  const std::vector<std::string> items = Texts(Between(html, "<ul id=\"milestones\">", "</ul>"), "li");
  ASSERT_EQ(items.size(), 4u);
  EXPECT_NE(items[0].find("no plan over these candidates reaches it with fewer than 2 stations"), std::string::npos)
      << items[0];
}

TEST(ReportHtmlTest, WithoutACoverageCurveThePageSaysSo) {
  const std::string html = PlanToHtml(BlockPlan());
  EXPECT_EQ(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("This plan carries no coverage curve."), std::string::npos);
}

TEST(ReportHtmlTest, GlossaryExplainsTheWordsAndColoursInPlainLanguage) {
  const std::vector<std::string> terms = Texts(Between(PlanToHtml(BlockPlan()), "<dl id=\"glossary\">", "</dl>"), "dt");
  for (const std::string term : {"Visibility score", "Coverable", "Coverage", "Field time", "Tripod height", "Floor",
                                 "Walking order", "Colours"}) {
    EXPECT_NE(std::find(terms.begin(), terms.end(), term), terms.end()) << term;
  }
  const std::string colours = Between(PlanToHtml(BlockPlan()), "<dt>Colours</dt><dd>", "</dd>");
  for (const std::string colour : {"dark purple to yellow", "grey", "magenta", "orange", "light blue", "red ring",
                                   "black ring", "translucent red: keep-out zones", "metre grid"}) {
    EXPECT_NE(colours.find(colour), std::string::npos) << colour;
  }
}

TEST(ReportHtmlTest, PrintStyleDropsTheControlsAndShowsASnapshot) {
  const std::string html = PlanToHtml(BlockPlan());
  const std::string print = Between(html, "@media print {", "\n}\n");
  ASSERT_FALSE(print.empty());
  EXPECT_NE(print.find("#controls"), std::string::npos);
  EXPECT_NE(print.find("#snapshot { display: block;"), std::string::npos);
  EXPECT_NE(html.find("<img id=\"snapshot\""), std::string::npos);
}

TEST(ReportHtmlTest, WritePlanOutputsWritesReportHtml) {
  const PlanResult plan = BlockPlan();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  EXPECT_EQ(testing::ReadFileBytes(dir + "/report.html"), PlanToHtml(plan));
}

}  // namespace
}  // namespace vc
