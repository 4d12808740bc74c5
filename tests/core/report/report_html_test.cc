// report.html's writer: a self-contained page (no network references, three.js inlined), the
// plan's data as the page reads it (stations, route order, sole voxels, the quantised voxels and
// their colours), decimation, escaping of hostile strings, and WritePlanOutputs writing it.
// report_html_browser_test opens the page in a real browser.
#include "vc/report/report_html.h"

#include <gtest/gtest.h>

#include <cctype>
#include <nlohmann/json.hpp>
#include <set>

#include "testing/test_paths.h"
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

TEST(ReportHtmlTest, WritePlanOutputsWritesReportHtml) {
  const PlanResult plan = BlockPlan();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  EXPECT_EQ(testing::ReadFileBytes(dir + "/report.html"), PlanToHtml(plan));
}

}  // namespace
}  // namespace vc
