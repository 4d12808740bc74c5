// The files a plan produces: plan.json keys and values, stations.csv round trip, visibility.ply,
// PNG signature and size, evaluation.json, and ParseStationsCsv's errors.
#include "vc/report/plan_report.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "testing/test_paths.h"
#include "vc/plan/keep_out.h"
#include "vc/report/field_exports.h"

namespace vc {
namespace {

using nlohmann::json;

std::string ReadAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

uint32_t BigEndian32(const std::string& s, size_t at) {
  return (uint32_t(uint8_t(s[at])) << 24) | (uint32_t(uint8_t(s[at + 1])) << 16) | (uint32_t(uint8_t(s[at + 2])) << 8) |
         uint32_t(uint8_t(s[at + 3]));
}

// A small plan: 12 candidates on a 4 x 3 grid of 1 m, 3 stations (one removed by reduction).
PlanResult SamplePlan() {
  PlanResult r;
  r.resolution_m = 0.1;
  r.selection_test = SelectionTest::kSurfaceVisibility;
  r.stop_reason = StopReason::kExhausted;
  r.options.grid_spacing_m = 1.0;
  r.floor_levels_m = {0.1};
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) {
      r.heat_map.positions.emplace_back(0.5 + x, 0.5 + y, 1.6);
      r.heat_map.visible_voxels.push_back(static_cast<uint64_t>(100 + 10 * x + y));
    }
  }
  r.heat_map.grid_spacing_m = 1.0;
  r.candidate_count = 12;
  const WorldPoint s0(0.5, 0.5, 1.6), s1(3.5, 2.5, 1.6);
  r.stations.push_back({s0, 100, 100, 0.8, 0.41, 0});
  r.stations.push_back({s1, 132, 25, 1.0, 0.37, 11});
  r.reduction.size = 3;
  r.reduction.matrix = {0.2, 0.3, 0.25, 0.3, 0.1, 0.12, 0.25, 0.12, 0.0};
  r.reduction.removed = {2};
  r.reduction.positions = {s0, s1, WorldPoint(1.5, 1.5, 1.6)};
  r.reduction.global_visibility_before = 0.5;
  r.reduction.global_visibility_after = 0.5;
  r.occupied_voxels = 5;
  r.coverable_voxels = 4;
  r.covered_voxels = 4;
  r.evaluation.resolution_m = 0.1;
  r.evaluation.faces_total = 30;
  r.evaluation.faces_evaluated = 30;
  r.evaluation.overall = {0.5, 0.4, 0.8, 0.1};
  r.evaluation.per_viewpoint = {{0.41, 0.3, 0.7, 0.1}, {0.37, 0.2, 0.75, 0.05}};
  for (int i = 0; i < 5; ++i) {
    r.voxel_centers.emplace_back(0.05 + 0.1 * i, 0.05, 0.05);
    std::array<float, 6> v{};
    v[i % 6] = 0.2f * i;  // voxel 0 is seen by nobody
    r.evaluation.best_face_values.push_back(v);
  }
  r.timings = {{Stage::kVoxelize, 0.5, 300u << 20}, {Stage::kSelection, 0.01, 0}};
  r.total_seconds = 1.0;
  r.scan_graph.min_overlap = 0.3;
  r.scan_graph.connected = true;
  r.scan_graph.components = {{0, 1}};
  r.scan_graph.edges = {{0, 1, 0.45}};
  r.connecting_stations = 1;
  r.route.order = {1, 0};
  r.route.legs_m = {0.0, 3.6};
  r.route.polylines = {{}, {WorldPoint(3.5, 2.5, 0.1), WorldPoint(0.5, 2.5, 0.1), WorldPoint(0.5, 0.5, 0.1)}};
  r.route.length_m = 3.6;
  r.route.parts = 1;
  r.field_time = {240, 52, 3.6, 295.6, 26};
  r.warnings = {"20.0 % of occupied voxels (1) are visible from no candidate"};
  r.coverage_curve = CoverageCurve({3, 1}, 5, 4, 146);
  r.unseen_causes.hidden = 1;
  return r;
}

TEST(PlanReportTest, PlanJsonHasEveryDocumentedKey) {
  const json j = json::parse(PlanToJson(SamplePlan()));
  for (const char* key :
       {"schema",         "resolution_m",        "selection_test", "stop_reason",  "viewpoints", "coverage",
        "reduction",      "candidates",          "timings_s",      "parameters",   "warnings",   "scan_graph",
        "route",          "field_time_s",        "optimality",     "distribution", "frame",      "crs",
        "coverage_curve", "coverage_milestones", "peak_rss_bytes", "gain_rule"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  const json& by_cause = j["coverage"]["uncoverable_by_cause"];
  EXPECT_EQ(by_cause["hidden"].get<int>(), 1);
  for (const char* cause :
       {"interior", "in_keep_out", "no_candidate_on_floor", "out_of_range", "outside_field_of_view", "faces_away"}) {
    EXPECT_EQ(by_cause[cause].get<int>(), 0) << cause;
  }
  EXPECT_EQ(j["scan_graph"]["min_overlap"].get<double>(), 0.3);
  EXPECT_TRUE(j["scan_graph"]["connected"].get<bool>());
  EXPECT_EQ(j["scan_graph"]["components"], json::parse("[[0, 1]]"));
  EXPECT_EQ(j["scan_graph"]["edges"], json::parse("[[0, 1, 0.45]]"));
  EXPECT_EQ(j["scan_graph"]["connecting_stations"].get<int>(), 1);
  EXPECT_EQ(j["route"]["order"], json::parse("[1, 0]"));
  EXPECT_EQ(j["route"]["legs_m"], json::parse("[0.0, 3.6]"));
  EXPECT_EQ(j["route"]["length_m"].get<double>(), 3.6);
  EXPECT_EQ(j["route"]["parts"].get<int>(), 1);
  ASSERT_EQ(j["route"]["polyline"].size(), 2u);
  EXPECT_EQ(j["route"]["polyline"][1].size(), 3u);
  EXPECT_TRUE(j["route"]["start"].is_null());
  for (const char* key : {"setup", "scan", "walk", "total", "scan_per_station"}) {
    EXPECT_TRUE(j["field_time_s"].contains(key)) << key;
  }
  EXPECT_DOUBLE_EQ(j["field_time_s"]["total"].get<double>(), 295.6);
  for (const char* key : {"solver", "status", "stations", "lower_bound", "gap", "seconds", "model"}) {
    EXPECT_TRUE(j["optimality"].contains(key)) << key;
  }
  for (const char* key : {"candidates", "voxel_classes", "rows"}) EXPECT_TRUE(j["optimality"]["model"].contains(key));
  EXPECT_EQ(j["optimality"]["solver"], "greedy");
  EXPECT_EQ(j["optimality"]["status"], "heuristic");
  EXPECT_FALSE(j["optimality"].contains("local_candidates"));  // the loop did not run
  PlanResult local = SamplePlan();
  local.optimality.local_candidates = {1, 24, {2, 2}, {5, 5}};
  const json l = json::parse(PlanToJson(local))["optimality"]["local_candidates"];
  EXPECT_EQ(l, json::parse(R"({"rounds": 1, "added": 24, "stations_per_solve": [2, 2], "covered_per_solve": [5, 5]})"));
  EXPECT_TRUE(j["distribution"].is_null());  // planned by one replica
  PlanResult fanned = SamplePlan();
  fanned.distribution = {3, 12, 2, 123456};
  EXPECT_EQ(json::parse(PlanToJson(fanned))["distribution"],
            json::parse(R"({"replicas": 3, "shards": 12, "retried": 2, "bytes_exchanged": 123456})"));
  EXPECT_EQ(j["viewpoints"][0]["route_order"].get<int>(), 2);
  EXPECT_EQ(j["viewpoints"][1]["route_order"].get<int>(), 1);
  ASSERT_EQ(j["viewpoints"].size(), 2u);
  for (const char* key :
       {"index", "x", "y", "z", "compatible_voxels", "marginal_gain", "cumulative_coverage", "global_visibility",
        "candidate_index", "fully_visible_fraction", "partially_visible_fraction"}) {
    EXPECT_TRUE(j["viewpoints"][1].contains(key)) << key;
  }
  EXPECT_DOUBLE_EQ(j["viewpoints"][1]["x"].get<double>(), 3.5);
  EXPECT_EQ(j["viewpoints"][1]["compatible_voxels"].get<int>(), 132);
  EXPECT_EQ(j["viewpoints"][1]["marginal_gain"].get<int>(), 25);
  EXPECT_DOUBLE_EQ(j["viewpoints"][0]["cumulative_coverage"].get<double>(), 0.8);
  EXPECT_DOUBLE_EQ(j["viewpoints"][1]["global_visibility"].get<double>(), 0.37);
  for (const char* key :
       {"occupied_voxels", "coverable_voxels", "covered_voxels", "uncovered_voxels", "uncoverable_voxels",
        "covered_fraction_of_coverable", "covered_fraction_of_occupied", "global_visibility", "fully_visible_fraction",
        "mean_full_visibility", "partially_visible_fraction", "faces_total"}) {
    EXPECT_TRUE(j["coverage"].contains(key)) << key;
  }
  EXPECT_EQ(j["coverage"]["uncovered_voxels"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(j["coverage"]["covered_fraction_of_coverable"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["coverage"]["global_visibility"].get<double>(), 0.5);
  for (const char* key :
       {"size", "stations", "matrix", "removed", "global_visibility_before", "global_visibility_after"}) {
    EXPECT_TRUE(j["reduction"].contains(key)) << key;
  }
  ASSERT_EQ(j["reduction"]["matrix"].size(), 3u);
  EXPECT_DOUBLE_EQ(j["reduction"]["matrix"][1][2].get<double>(), 0.12);
  EXPECT_EQ(j["reduction"]["removed"], json::array({2}));
  EXPECT_EQ(j["candidates"]["count"].get<int>(), 12);
  for (const char* key : {"grid_spacing_m", "floor_levels_m", "grid_cells", "cells_without_floor",
                          "cells_failing_clearance", "visible_voxels"}) {
    EXPECT_TRUE(j["candidates"].contains(key)) << key;
  }
  for (const char* key : {"greedy_stations", "consolidated"}) EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["candidates"]["visible_voxels"].size(), 12u);
  EXPECT_EQ(j["candidates"]["visible_voxels"][11][3].get<int>(), 132);
  EXPECT_DOUBLE_EQ(j["timings_s"]["voxelize"].get<double>(), 0.5);
  EXPECT_EQ(j["peak_rss_bytes"]["voxelize"].get<uint64_t>(), uint64_t{300} << 20);
  EXPECT_TRUE(j["peak_rss_bytes"]["selection"].is_null());  // not measured
  EXPECT_EQ(j["peak_rss_bytes"]["plan"].get<uint64_t>(), uint64_t{300} << 20);
  EXPECT_DOUBLE_EQ(j["parameters"]["grid_spacing_m"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["parameters"]["tripod_height_m"].get<double>(), 1.5);
  EXPECT_EQ(j["parameters"]["selection_test"], "surface");
  EXPECT_EQ(j["warnings"].size(), 1u);
  EXPECT_DOUBLE_EQ(j["resolution_m"].get<double>(), 0.1);
}

// The coverage curve, one point per station, and the stations needed for 80 / 90 / 95 / 99 % of
// the coverable voxels with the scene's share there (null where the plan never gets there).
TEST(PlanReportTest, PlanJsonHasTheCoverageCurveAndItsMilestones) {
  PlanResult r = SamplePlan();
  r.coverage_curve = CoverageCurve({3, 1}, 5, 4, 146);
  json j = json::parse(PlanToJson(r));
  EXPECT_EQ(j["coverage_curve"], json::parse(R"([
      {"stations": 1, "covered_voxels": 3, "coverable_fraction": 0.75, "scene_fraction": 0.6, "setup_scan_s": 146.0},
      {"stations": 2, "covered_voxels": 4, "coverable_fraction": 1.0, "scene_fraction": 0.8, "setup_scan_s": 292.0}])"));
  ASSERT_EQ(j["coverage_milestones"].size(), 4u);
  for (const json& m : j["coverage_milestones"]) EXPECT_EQ(m["stations"].get<int>(), 2) << m;
  EXPECT_DOUBLE_EQ(j["coverage_milestones"][0]["coverable_fraction"].get<double>(), 0.8);
  EXPECT_DOUBLE_EQ(j["coverage_milestones"][3]["scene_fraction"].get<double>(), 0.8);
  r.coverage_curve.resize(1);  // 75 %: no level reached
  j = json::parse(PlanToJson(r));
  EXPECT_TRUE(j["coverage_milestones"][0]["stations"].is_null());
  EXPECT_TRUE(j["coverage_milestones"][0]["scene_fraction"].is_null());
  EXPECT_TRUE(j["coverage_milestones"][0]["fewest_possible_stations"].is_null());
  EXPECT_FALSE(j["coverage_curve"][0].contains("best_voxels_upper_bound"));  // not computed: absent
}

// The per-k bound and the best found in each point, and the fewest stations any plan needs per level.
TEST(PlanReportTest, PlanJsonHasTheBestKStationCoverageAndItsBound) {
  PlanResult r = SamplePlan();
  r.coverage_curve = CoverageCurve({3, 1}, 5, 4, 146);
  AddBestCoverage(r.coverage_curve, {BestCoverage{4, 3}, BestCoverage{4, 4}});
  const json j = json::parse(PlanToJson(r));
  EXPECT_EQ(j["coverage_curve"][0]["best_voxels_upper_bound"], 4);
  EXPECT_EQ(j["coverage_curve"][0]["best_voxels"], 3);
  EXPECT_EQ(j["coverage_curve"][0]["best_voxels_optimal"], false);
  EXPECT_EQ(j["coverage_curve"][1]["best_voxels_optimal"], true);
  // The bound of 1 station (4 of 4) reaches every level; the plan needs 2.
  for (const json& m : j["coverage_milestones"]) {
    EXPECT_EQ(m["fewest_possible_stations"], 1) << m;
    EXPECT_EQ(m["stations"], 2) << m;
  }
}

// The gain rule that ran: its parameter and value, and one station's threshold in voxels
// (0.5 m2/min at 0.1 m and 2 min a station: 1 m2, 100 voxels); null when off.
TEST(PlanReportTest, PlanJsonSaysTheGainRuleAndItsValue) {
  PlanResult r = SamplePlan();
  r.options.min_gain_voxels_per_minute = 0;
  r.options.min_gain_m2_per_minute = 0.5;
  r.options.setup_seconds = 120;
  r.field_time.scan_seconds_per_station = 0;
  json j = json::parse(PlanToJson(r));
  EXPECT_EQ(j["gain_rule"]["parameter"], "min_gain_m2_per_minute");
  EXPECT_DOUBLE_EQ(j["gain_rule"]["value"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["gain_rule"]["station_minutes"].get<double>(), 2.0);
  EXPECT_NEAR(j["gain_rule"]["threshold_voxels"].get<double>(), 100.0, 1e-9);
  r.options.min_gain_m2_per_minute = 0;
  r.options.min_gain_voxels_per_minute = 30;
  j = json::parse(PlanToJson(r));
  EXPECT_EQ(j["gain_rule"]["parameter"], "min_gain_voxels_per_minute");
  EXPECT_DOUBLE_EQ(j["gain_rule"]["threshold_voxels"].get<double>(), 60.0);
  r.options.min_gain_voxels_per_minute = 0;
  EXPECT_TRUE(json::parse(PlanToJson(r))["gain_rule"].is_null());
}

TEST(PlanReportTest, WritesAllFilesWithPngsOfTheExpectedSize) {
  const PlanResult plan = SamplePlan();
  const std::string dir = testing::MakeTempDir() + "/out";  // created by the writer
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  const ImageSize heat = HeatmapImageSize(plan);
  const ImageSize red = ReductionImageSize(3);
  // Layout (docs/PLANNING.md): footprint 4 x 3 m -> 180 px/m, plot 720 x 540; one panel.
  EXPECT_EQ(heat.width, 64 + 720 + 24 + 110);
  EXPECT_EQ(heat.height, 40 + 540 + 60);
  for (const auto& [name, size] : {std::pair{"heatmap.png", heat}, std::pair{"reduction.png", red}}) {
    const std::string png = ReadAll(dir + "/" + name);
    ASSERT_GT(png.size(), 33u) << name;
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
    EXPECT_EQ(png.substr(12, 4), "IHDR");
    EXPECT_EQ(BigEndian32(png, 16), static_cast<uint32_t>(size.width)) << name;
    EXPECT_EQ(BigEndian32(png, 20), static_cast<uint32_t>(size.height)) << name;
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/plan.json"));
  EXPECT_EQ(json::parse(ReadAll(dir + "/plan.json"))["viewpoints"].size(), 2u);
}

// A decoded RGB picture.
struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  std::array<int, 3> at(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

Picture DecodePng(const std::string& png) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_memory(&image, png.data(), png.size()));
  image.format = PNG_FORMAT_RGB;
  Picture p{int(image.width), int(image.height), std::vector<uint8_t>(PNG_IMAGE_SIZE(image))};
  EXPECT_TRUE(png_image_finish_read(&image, nullptr, p.rgb.data(), 0, nullptr));
  return p;
}

// The heat map reads as a floor plan: a wall (a column of voxels from the floor to the tripod
// height) is drawn dark over the cells, a low box light grey; the floor's own voxels and a ceiling
// above the tripod are not drawn. Pixels (docs/PLANNING.md layout): 180 px/m, plot at (64, 40),
// world (x, y) at (64 + 180 x, 40 + 180 (3 - y)).
TEST(PlanReportTest, HeatmapDrawsTheWallsAndObjectsOfTheLevelUnderTheStations) {
  const PlanResult bare = SamplePlan();  // floor top 0.1 m, tripod 1.5 m; its voxels lie in the floor
  PlanResult plan = bare;
  auto add = [&](double x, double y, double z) {
    plan.voxel_centers.emplace_back(x, y, z);
    plan.evaluation.best_face_values.push_back({});
  };
  for (double y = 0.05; y < 3; y += 0.1)
    for (double z = 0.15; z < 1.6; z += 0.1) add(2.05, y, z);             // a wall at x = 2 m, up to 1.55 m
  add(0.55, 2.45, 0.15);                                                  // a box 0.1 m high
  add(3.05, 1.05, 2.8);                                                   // the ceiling, over the tripod
  add(3.05, 1.35, 0.05);                                                  // the floor itself
  EXPECT_EQ(HeatmapImageSize(plan).width, HeatmapImageSize(bare).width);  // all inside the footprint
  const Result<std::string> with = HeatmapPng(plan), without = HeatmapPng(bare);
  ASSERT_TRUE(with.ok() && without.ok());
  const Picture a = DecodePng(*with), b = DecodePng(*without);
  ASSERT_EQ(a.width, 64 + 720 + 24 + 110);
  auto at = [](double x, double y) { return std::pair{int(64 + 180 * x), int(40 + 180 * (3 - y))}; };
  auto grey = [](std::array<int, 3> c) { return c[0] == c[1] && c[1] == c[2] ? c[0] : -1; };
  const auto [wx, wy] = at(2.05, 1.0);
  EXPECT_LE(grey(a.at(wx, wy)), 60) << "the wall is dark";
  EXPECT_GE(grey(a.at(wx, wy)), 0);
  EXPECT_EQ(grey(b.at(wx, wy)), -1) << "a viridis cell without the wall";
  const auto [bx, by] = at(0.55, 2.43);
  EXPECT_GE(grey(a.at(bx, by)), 150) << "the box is light";
  EXPECT_LE(grey(a.at(bx, by)), 180);
  for (const auto& [x, y] : {at(3.05, 1.05), at(3.05, 1.35), at(1.0, 1.0)}) {
    EXPECT_EQ(a.at(x, y), b.at(x, y)) << "no floor plan at pixel " << x << "," << y;
  }
  // Stations stay on top: station 1's marker centre (white disc) at (0.5, 0.5).
  const auto [sx, sy] = at(0.5, 0.5);
  EXPECT_EQ(a.at(sx + 4, sy - 5), (std::array<int, 3>{255, 255, 255}));
}

// Voxels of the level beyond the candidates (the building's outer walls) widen the picture.
TEST(PlanReportTest, HeatmapFootprintTakesInTheWallsAroundTheCandidates) {
  PlanResult plan = SamplePlan();
  const ImageSize before = HeatmapImageSize(plan);
  plan.voxel_centers.emplace_back(1.0, -0.95, 1.0);  // a wall 1 m south of the candidates
  plan.evaluation.best_face_values.push_back({});
  const ImageSize after = HeatmapImageSize(plan);
  EXPECT_EQ(after.width, before.width);
  EXPECT_EQ(before.height, 40 + 540 + 60);
  EXPECT_EQ(after.height, 40 + 720 + 60);  // 4 x 4 m now, still 180 px/m
}

// A keep-out zone whose height range meets the floor's slice is hatched and outlined on the
// floor's panel, and said in the legend; one above the tripod is not drawn at all. The zone
// (1.2..1.8 m in x and y) lies at pixels 280..388 x 256..364.
TEST(PlanReportTest, HeatmapHatchesAndOutlinesTheKeepOutZonesOfTheFloor) {
  PlanResult bare = SamplePlan();
  bare.scan_graph.edges.clear();  // its white line would cross the zone
  PlanResult zoned = bare, above = bare;
  zoned.options.keep_out = {KeepOutBox(WorldPoint(1.2, 1.2, 0.0), WorldPoint(1.8, 1.8, 2.5))};
  above.options.keep_out = {KeepOutBox(WorldPoint(1.2, 1.2, 5.0), WorldPoint(1.8, 1.8, 6.0))};
  const Picture a = DecodePng(*HeatmapPng(zoned)), b = DecodePng(*HeatmapPng(bare)), c = DecodePng(*HeatmapPng(above));
  const std::array<int, 3> black{0, 0, 0};
  int hatched = 0, between = 0;
  for (int y = 266; y < 355; ++y)
    for (int x = 290; x < 379; ++x) (a.at(x, y) == black ? hatched : between) += 1;
  EXPECT_GT(hatched, 89 * 89 / 8) << "diagonals every 6 pixels";
  EXPECT_GT(between, 89 * 89 / 2) << "the cells show between them";
  for (int y = 262; y < 358; y += 5) {
    EXPECT_EQ(a.at(281, y), black) << "the west edge at row " << y;
    EXPECT_EQ(a.at(387, y), black) << "the east edge at row " << y;
  }
  for (const auto& [x, y] : {std::pair{275, 310}, std::pair{393, 310}, std::pair{330, 251}, std::pair{330, 369}}) {
    EXPECT_EQ(a.at(x, y), b.at(x, y)) << "outside the zone at " << x << "," << y;
  }
  int legend_ink = 0;
  for (int y = 40 + 540 + 52; y < 40 + 540 + 59; ++y)
    for (int x = 64; x < 400; ++x) legend_ink += a.at(x, y) != b.at(x, y) ? 1 : 0;
  EXPECT_GT(legend_ink, 50) << "the legend names the hatching";
  EXPECT_EQ(c.rgb, b.rgb) << "a zone above the tripod is not on this floor";
}

// The colour bar reads in per cent of the scene: with 1,000 occupied voxels and 132 seen at best
// the bar's top is 13.2 % and its ticks 0, 5 and 10 %; with 2,000, 6.6 % and 0, 2, 4, 6 %. Bar:
// x 828..843, y 54..579 (h = 526); a tick mark is 4 pixels right of it, its label beyond.
TEST(PlanReportTest, HeatmapColourBarIsInPerCentOfTheScene) {
  PlanResult plan = SamplePlan();
  const int bar_x = 64 + 720 + 24 + 110 - 110 + 20, bar_y = 54, h = 540 - 14;
  for (const auto& [occupied, ticks] :
       {std::pair{1000, std::vector<double>{0, 5, 10}}, std::pair{2000, std::vector<double>{0, 2, 4, 6}}}) {
    plan.occupied_voxels = static_cast<uint64_t>(occupied);
    const double top_pct = 100.0 * 132 / occupied;
    const Picture p = DecodePng(*HeatmapPng(plan));
    std::vector<int> marks;
    for (int y = bar_y - 2; y < bar_y + h + 2; ++y) {
      if (p.at(bar_x + 18, y) == std::array<int, 3>{0, 0, 0}) marks.push_back(y);
    }
    std::vector<int> expected;
    for (double t : ticks) expected.push_back(bar_y + h - 1 - static_cast<int>(std::lround((h - 1) * t / top_pct)));
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(marks, expected) << occupied << " occupied voxels";
    for (int y : expected) {
      int ink = 0;
      for (int v = y - 3; v <= y + 3; ++v)
        for (int u = bar_x + 22; u < bar_x + 22 + 30; ++u) ink += p.at(u, v)[0] < 128 ? 1 : 0;
      EXPECT_GT(ink, 15) << "a label beside the tick at row " << y;
    }
    int under = 0, over = 0;
    for (int u = bar_x - 2; u < bar_x + 80; ++u) {
      for (int v = bar_y + h + 8; v < bar_y + h + 27; ++v) under += p.at(u, v)[0] < 128 ? 1 : 0;
      for (int v = bar_y - 26; v < bar_y - 7; ++v) over += p.at(u, v)[0] < 128 ? 1 : 0;
    }
    EXPECT_GT(under, 100) << "the top's value and its voxel count under the bar";
    EXPECT_GT(over, 100) << "two title lines over the bar";
  }
}

// Every character heatmap.png and reduction.png draw has a glyph: nowhere is the font's unknown
// box (a 5 x 7 outline, hollow) drawn, with zones, moved numbers and the scan graph's "≥" in the
// legend.
TEST(PlanReportTest, HeatmapAndReductionDrawNoCharacterAsTheUnknownBox) {
  PlanResult plan = SamplePlan();
  plan.occupied_voxels = 1000;
  plan.options.keep_out = {KeepOutBox(WorldPoint(1.2, 1.2, 0.0), WorldPoint(1.8, 1.8, 2.5))};
  plan.stations.push_back({WorldPoint(0.55, 0.55, 1.6), 10, 10, 0.9, 0.4, 1});
  const std::string dir = testing::MakeTempDir() + "/out";
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  for (const char* name : {"heatmap.png", "reduction.png"}) {
    const Picture p = DecodePng(ReadAll(dir + "/" + name));
    const std::array<int, 3> black{0, 0, 0}, white{255, 255, 255};
    int boxes = 0;
    for (int y = 0; y + 7 <= p.height; ++y)
      for (int x = 0; x + 5 <= p.width; ++x) {
        bool box = true;
        for (int v = 0; v < 7 && box; ++v)
          for (int u = 0; u < 5 && box; ++u) {
            const bool rim = u == 0 || u == 4 || v == 0 || v == 6;
            box = p.at(x + u, y + v) == (rim ? black : white);
          }
        boxes += box ? 1 : 0;
      }
    EXPECT_EQ(boxes, 0) << name;
  }
}

// 30 stations 0.1 m (18 pixels) apart in a row at y = 1.5 m: centred, their 23-pixel discs would
// cover each other. Each disc is drawn whole (its red ring on all four sides), none covers
// another or another station's pixel, and a moved one has a red dot at its station and a black
// leader line from the dot towards the disc.
TEST(PlanReportTest, HeatmapMovesNumbersAsideOnADensePlanWithoutOverlaps) {
  PlanResult plan = SamplePlan();
  plan.scan_graph.edges.clear();
  plan.route.polylines.clear();
  for (int i = 0; i < 30; ++i) plan.stations.push_back({WorldPoint(0.3 + 0.1 * i, 1.5, 1.6), 10, 10, 0.9, 0.4, 1});
  const std::vector<HeatmapStationPlace> places = HeatmapStationPlaces(plan);
  ASSERT_EQ(places.size(), plan.stations.size());
  const Picture p = DecodePng(*HeatmapPng(plan));
  const std::array<int, 3> red{215, 40, 40}, black{0, 0, 0};
  int moved = 0;
  for (size_t i = 0; i < places.size(); ++i) {
    const LabelBox& d = places[i].disc.box;
    EXPECT_FALSE(places[i].disc.overlaps) << "station " << i + 1;
    for (size_t j = 0; j < places.size(); ++j) {
      if (j == i) continue;
      EXPECT_FALSE(d.Overlaps(places[j].disc.box)) << "discs " << i + 1 << " and " << j + 1;
      const LabelPoint s = places[j].station_px;
      EXPECT_FALSE(s.x > d.x0 && s.x < d.x1 && s.y > d.y0 && s.y < d.y1) << i + 1 << " covers station " << j + 1;
    }
    const int cx = static_cast<int>(std::lround(0.5 * (d.x0 + d.x1)));
    const int cy = static_cast<int>(std::lround(0.5 * (d.y0 + d.y1)));
    for (const auto& [dx, dy] : {std::pair{10, 0}, std::pair{-10, 0}, std::pair{0, 10}, std::pair{0, -10}}) {
      EXPECT_EQ(p.at(cx + dx, cy + dy), red) << "station " << i + 1 << "'s ring at " << dx << "," << dy;
    }
    if (!places[i].disc.leader) continue;
    ++moved;
    const int sx = static_cast<int>(places[i].station_px.x), sy = static_cast<int>(places[i].station_px.y);
    EXPECT_EQ(p.at(sx, sy), red) << "station " << i + 1 << "'s dot";
    // Just beyond the dot's white rim on the way to the disc: the leader line.
    const double len = std::hypot(cx - sx, cy - sy);
    const int lx = static_cast<int>(std::lround(sx + 6 * (cx - sx) / len));
    const int ly = static_cast<int>(std::lround(sy + 6 * (cy - sy) / len));
    const bool under_a_disc = std::any_of(places.begin(), places.end(), [&](const HeatmapStationPlace& q) {
      return lx + 1 >= q.disc.box.x0 && lx - 1 <= q.disc.box.x1 && ly + 1 >= q.disc.box.y0 && ly - 1 <= q.disc.box.y1;
    });
    int ink = 0;
    for (int v = ly - 1; v <= ly + 1; ++v)
      for (int u = lx - 1; u <= lx + 1; ++u) ink += p.at(u, v) == black ? 1 : 0;
    EXPECT_TRUE(under_a_disc || ink > 0) << "station " << i + 1 << "'s leader near " << lx << "," << ly;
  }
  EXPECT_GE(moved, 15) << "at most every other one fits centred";
  EXPECT_FALSE(places[0].disc.leader) << "station 1 stands alone and keeps its disc";
}

TEST(PlanReportTest, ReductionImageGrowsWithTheMatrix) {
  const ImageSize a = ReductionImageSize(2), b = ReductionImageSize(20), c = ReductionImageSize(0);
  EXPECT_GT(b.height, a.height - 1);
  EXPECT_GT(b.width, 0);
  EXPECT_GT(c.width, 0);
  EXPECT_EQ(ReductionImageSize(10).height, 52 + 10 * 48 + 48);    // cells of 48 px up to 10 stations
  EXPECT_EQ(ReductionImageSize(146).height, 52 + 146 * 14 + 48);  // 14 px while that fits in 2,048
  EXPECT_EQ(ReductionImageSize(905).height, 52 + 905 * 2 + 48);   // a campus plan: 2 px cells
  EXPECT_EQ(ReductionImageSize(5000).height, 52 + 5000 + 48);     // never below 1 px
}

TEST(PlanReportTest, StationsCsvRoundTrips) {
  const PlanResult plan = SamplePlan();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  const std::string csv = ReadAll(dir + "/stations.csv");
  EXPECT_EQ(csv.substr(0, 16), "# vc stations: l");
  EXPECT_NE(csv.find("\nstation,name,x_m,y_m,z_m,"), std::string::npos) << csv;
  // The route visits station 1 first, then station 0: rows in that order.
  EXPECT_LT(csv.find("\n1,S01,3.500000,2.500000,1.600000,"), csv.find("\n2,S02,0.500000,0.500000,1.600000,")) << csv;
  Result<std::vector<WorldPoint>> parsed = ParseStationsCsv(csv, "stations.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  ASSERT_EQ(parsed->size(), plan.stations.size());
  for (size_t i = 0; i < parsed->size(); ++i) {
    EXPECT_NEAR(((*parsed)[i] - plan.stations[plan.route.order[i]].position).norm(), 0.0, 1e-6);
  }
}

TEST(PlanReportTest, VisibilityPlyHoldsOneColouredVertexPerVoxel) {
  const PlanResult plan = SamplePlan();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  const std::string ply = ReadAll(dir + "/visibility.ply");
  const size_t end = ply.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = ply.substr(0, end);
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex 5"), std::string::npos);
  EXPECT_NE(header.find("property float visibility"), std::string::npos);
  EXPECT_NE(header.find("property uchar red"), std::string::npos);
  const size_t body = end + std::strlen("end_header\n");
  ASSERT_EQ(ply.size() - body, 5u * 19u);
  // Vertex 4: best V = 0.8; vertex 0: seen by nobody -> grey.
  float v4;
  std::memcpy(&v4, ply.data() + body + 4 * 19 + 15, 4);
  EXPECT_FLOAT_EQ(v4, 0.8f);
  EXPECT_EQ(uint8_t(ply[body + 12]), 128);
  EXPECT_EQ(uint8_t(ply[body + 13]), 128);
  float x1;
  std::memcpy(&x1, ply.data() + body + 19, 4);
  EXPECT_FLOAT_EQ(x1, 0.15f);
}

// SamplePlan as a georeferenced scan's plan: the same local positions, the local frame at a
// UTM-like origin, and a station 330.123 m north of it (5,612,330.123 in the input's frame).
constexpr double kOriginX = 512000, kOriginY = 5612000;
PlanResult GeoreferencedPlan() {
  PlanResult r = SamplePlan();
  r.frame_origin_m = WorldPoint(kOriginX, kOriginY, 0);
  r.stations[1].position = WorldPoint(345.457, 330.123, 1.6);
  r.route.start = WorldPoint(0.5, 0.5, 0.1);
  return r;
}

TEST(PlanReportTest, PlanJsonWritesTheInputsFrameToTheMillimetre) {
  const PlanResult plan = GeoreferencedPlan();
  const json j = json::parse(PlanToJson(plan));
  EXPECT_EQ(j["frame"]["origin_m"], json::parse("[512000.0, 5612000.0, 0.0]"));
  EXPECT_TRUE(j["frame"]["units"].is_null());  // unknown without the upload's summary
  UploadSummary upload;
  upload.units = "mm";
  EXPECT_EQ(json::parse(PlanToJson(plan, &upload))["frame"]["units"], "mm");
  upload.units.clear();
  EXPECT_EQ(json::parse(PlanToJson(plan, &upload))["frame"]["units"], "m");
  EXPECT_NEAR(j["viewpoints"][1]["x"].get<double>(), 512345.457, 1e-4);
  EXPECT_NEAR(j["viewpoints"][1]["y"].get<double>(), 5612330.123, 1e-4);
  EXPECT_NEAR(j["viewpoints"][0]["y"].get<double>(), 5612000.5, 1e-4);
  EXPECT_NEAR(j["reduction"]["stations"][2][1].get<double>(), 5612001.5, 1e-4);
  EXPECT_NEAR(j["candidates"]["visible_voxels"][11][1].get<double>(), 5612002.5, 1e-4);
  EXPECT_NEAR(j["route"]["polyline"][1][0][0].get<double>(), 512003.5, 1e-4);
  EXPECT_NEAR(j["route"]["start"][1].get<double>(), 5612000.5, 1e-4);
  EXPECT_NEAR(j["candidates"]["floor_levels_m"][0].get<double>(), 0.1, 1e-9);  // origin z = 0
  // The text itself carries the millimetres (not 5.61233e+06).
  EXPECT_NE(PlanToJson(plan).find("5612330.123"), std::string::npos);
  // A plan near its origin says so.
  EXPECT_EQ(json::parse(PlanToJson(SamplePlan()))["frame"]["origin_m"], json::parse("[0.0, 0.0, 0.0]"));
}

TEST(PlanReportTest, StationsCsvAndVisibilityPlyAreInTheInputsFrame) {
  const PlanResult plan = GeoreferencedPlan();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  const std::string csv = ReadAll(dir + "/stations.csv");
  EXPECT_NE(csv.find("\n1,S01,512345.457000,5612330.123000,1.600000,"), std::string::npos) << csv;
  Result<std::vector<WorldPoint>> parsed = ParseStationsCsv(csv, "stations.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  ASSERT_EQ(parsed->size(), 2u);
  EXPECT_LT(((*parsed)[1] - WorldPoint(512000.5, 5612000.5, 1.6)).norm(), 1e-6);

  const std::string ply = ReadAll(dir + "/visibility.ply");
  const size_t end = ply.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = ply.substr(0, end);
  EXPECT_NE(header.find("property double x\nproperty double y\nproperty double z\n"), std::string::npos) << header;
  EXPECT_NE(header.find("comment frame_origin_m 512000.000 5612000.000 0.000"), std::string::npos) << header;
  const size_t body = end + std::strlen("end_header\n");
  constexpr size_t kVertex = 3 * 8 + 3 + 4;
  ASSERT_EQ(ply.size() - body, 5u * kVertex);
  double xyz[3];
  std::memcpy(xyz, ply.data() + body + kVertex, sizeof(xyz));  // vertex 1: (0.15, 0.05, 0.05) local
  EXPECT_NEAR(xyz[0], 512000.15, 1e-6);
  EXPECT_NEAR(xyz[1], 5612000.05, 1e-6);
  EXPECT_NEAR(xyz[2], 0.05, 1e-9);
  float v4;
  std::memcpy(&v4, ply.data() + body + 4 * kVertex + 3 * 8 + 3, 4);
  EXPECT_FLOAT_EQ(v4, 0.8f);
}

TEST(PlanReportTest, APlanNearItsOriginWritesFloatCoordinatesAsBefore) {
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(SamplePlan(), dir).ok());
  const std::string ply = ReadAll(dir + "/visibility.ply");
  EXPECT_EQ(ply.find("frame_origin_m"), std::string::npos);
  EXPECT_EQ(ply.find("property double"), std::string::npos);
  const std::string csv = ReadAll(dir + "/stations.csv");
  const std::string rows = csv.substr(csv.find("\n1,"));
  EXPECT_EQ(rows,
            "\n1,S01,3.500000,2.500000,1.600000,,,,new,1,2,25,1.000000\n"
            "2,S02,0.500000,0.500000,1.600000,,,,new,2,1,100,0.800000\n");
  PlanResult negative_zero = SamplePlan();
  negative_zero.stations[0].position.x() = -0.0;  // adding a zero origin would print it as 0.000000
  ASSERT_TRUE(WritePlanOutputs(negative_zero, dir).ok());
  EXPECT_NE(ReadAll(dir + "/stations.csv").find("\n2,S02,-0.000000,"), std::string::npos);
}

TEST(PlanReportTest, ColouredPointsPlyWithoutAValueHoldsPositionAndColourOnly) {
  const std::string ply = ColouredPointsPly({"first line", "colour: red = missed"},
                                            {{{1.5, -2, 0.25}, {230, 40, 40}, 7.0f}, {{0, 0, 3}, {1, 2, 3}, 0.0f}});
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment first line\ncomment colour: red = missed\n"
      "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  ASSERT_EQ(ply.substr(0, header.size()), header);
  ASSERT_EQ(ply.size(), header.size() + 2 * 15);
  float y0, z1;
  std::memcpy(&y0, ply.data() + header.size() + 4, 4);
  std::memcpy(&z1, ply.data() + header.size() + 15 + 8, 4);
  EXPECT_FLOAT_EQ(y0, -2.0f);
  EXPECT_FLOAT_EQ(z1, 3.0f);
  EXPECT_EQ(uint8_t(ply[header.size() + 12]), 230);
  EXPECT_EQ(uint8_t(ply[header.size() + 15 + 14]), 3);
}

TEST(PlanReportTest, RefusesMissingFaceValues) {
  PlanResult plan = SamplePlan();
  plan.evaluation.best_face_values.pop_back();
  const Status s = WritePlanOutputs(plan, testing::MakeTempDir());
  EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition);
}

TEST(PlanReportTest, UnwritableDirectoryNamesThePath) {
  const std::string dir = testing::MakeTempDir();
  std::ofstream(dir + "/file") << "x";
  const Status s = WritePlanOutputs(SamplePlan(), dir + "/file/sub");
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(dir + "/file/sub"), std::string::npos) << s.message();
}

TEST(PlanReportTest, EvaluationJsonHasItsKeys) {
  const PlanResult plan = SamplePlan();
  const std::vector<WorldPoint> vps = {plan.stations[0].position, plan.stations[1].position};
  const json j = json::parse(EvaluationToJson(plan.evaluation, vps));
  for (const char* key :
       {"resolution_m", "faces_total", "faces_evaluated", "sampled", "global_visibility", "global_visibility_ci95",
        "fully_visible_fraction", "mean_full_visibility", "partially_visible_fraction", "per_viewpoint"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  ASSERT_EQ(j["per_viewpoint"].size(), 2u);
  for (const char* key : {"global_visibility", "fully_visible_fraction", "mean_full_visibility",
                          "partially_visible_fraction", "x", "y", "z"}) {
    EXPECT_TRUE(j["per_viewpoint"][0].contains(key)) << key;
  }
  EXPECT_DOUBLE_EQ(j["per_viewpoint"][1]["global_visibility"].get<double>(), 0.37);
  EXPECT_DOUBLE_EQ(j["per_viewpoint"][1]["x"].get<double>(), 3.5);
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WriteEvaluationOutputs(
                  {.evaluation = plan.evaluation, .viewpoints = vps, .voxel_centers = plan.voxel_centers}, dir)
                  .ok());
  EXPECT_EQ(json::parse(ReadAll(dir + "/evaluation.json"))["faces_total"].get<int>(), 30);
}

TEST(PlanReportTest, EvaluationJsonNamesTheCrsOfItsFrameWhenGivenOne) {
  const PlanResult plan = SamplePlan();
  const std::vector<WorldPoint> vps = {plan.stations[0].position};
  EXPECT_TRUE(json::parse(EvaluationToJson(plan.evaluation, vps))["crs"].is_null());
  CrsInfo crs;
  crs.definition = "EPSG:2263";
  crs.name = "NAD83 / New York Long Island (ftUS)";
  crs.epsg = 2263;
  crs.axis_unit = "US survey foot";
  crs.metres_per_unit = 1200.0 / 3937.0;
  const json j = json::parse(EvaluationToJson(plan.evaluation, vps, &crs))["crs"];
  EXPECT_EQ(j["definition"], "EPSG:2263");
  EXPECT_EQ(j["name"], "NAD83 / New York Long Island (ftUS)");
  EXPECT_EQ(j["epsg"], 2263);
  EXPECT_EQ(j["axis_unit"], "US survey foot");
  EXPECT_DOUBLE_EQ(j["metres_per_unit"].get<double>(), 1200.0 / 3937.0);
}

// An evaluation of `viewpoints` (resolution 0.1 m) over `voxels`, each seen (best V 0.5 on one
// face) or not.
EvaluateJobResult SampleEvaluation(const std::vector<WorldPoint>& viewpoints,
                                   const std::vector<std::pair<WorldPoint, bool>>& voxels) {
  EvaluateJobResult r;
  r.evaluation.resolution_m = 0.1;
  r.evaluation.per_viewpoint.resize(viewpoints.size());
  for (size_t i = 0; i < viewpoints.size(); ++i) r.evaluation.per_viewpoint[i].global_visibility = 0.1 * double(i + 1);
  r.viewpoints = viewpoints;
  for (const auto& [centre, seen] : voxels) {
    r.voxel_centers.push_back(centre);
    std::array<float, kFacesPerVoxel> v{};
    v[5] = seen ? 0.5f : 0.f;
    r.evaluation.best_face_values.push_back(v);
    r.evaluation.sole_viewer.push_back(seen ? 0 : kNoViewer);
  }
  return r;
}

// Stations on two levels (1.6 m: floor 0.1 m; 4.6 m: floor 3.1 m at the default 1.5 m tripod);
// voxels missed and seen, below the lowest floor, on the upper level, and a solid block whose
// centre no face of which is exposed.
EvaluateJobResult TwoLevelEvaluation() {
  std::vector<std::pair<WorldPoint, bool>> voxels = {
      {{2.05, 0.05, 0.55}, false},  {{2.05, 0.05, 0.65}, false},  // missed, level 0, column (2, 0)
      {{2.05, 0.05, 0.75}, true},                                 // seen
      {{2.05, 0.05, -0.45}, false},                               // below the lowest floor: the ground
      {{0.55, 1.55, 3.55}, false},                                // missed, level 1, column (0, 1)
      {{7.05, 0.05, 0.55}, true},                                 // seen: a cell counting 0
      {{3.05, 1.05, 0.05}, true},    // the floor under station 1 (top 0.1 m, the level's floor): a cell counting 0
      {{3.05, 1.05, -0.05}, false},  // under the floor's top layer: the ground
  };
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      for (int z = 0; z < 3; ++z) voxels.push_back({{5.05 + 0.1 * x, 5.05 + 0.1 * y, 1.05 + 0.1 * z}, false});
  return SampleEvaluation({{1, 1, 1.6}, {3, 1, 1.6}, {1, 1, 4.6}}, voxels);
}

TEST(MissedVoxelsHeatMapTest, CountsTheExposedVoxelsNoStationSeesPerColumnAndLevel) {
  const PlanResult plan = EvaluationAsPlan(TwoLevelEvaluation());
  const HeatMap map = MissedVoxelsHeatMap(plan, 1.0);
  EXPECT_EQ(map.grid_spacing_m, 1.0);
  std::map<std::array<double, 3>, uint64_t> cells;
  ASSERT_EQ(map.positions.size(), map.visible_voxels.size());
  for (size_t i = 0; i < map.positions.size(); ++i) {
    cells[{map.positions[i].x(), map.positions[i].y(), map.positions[i].z()}] = map.visible_voxels[i];
  }
  const std::map<std::array<double, 3>, uint64_t> expected = {
      {{2.5, 0.5, 1.6}, 2},   // the two missed voxels; not the seen one, not the ground's
      {{0.5, 1.5, 4.6}, 1},   // the upper level's, at its stations' height
      {{5.5, 5.5, 1.6}, 26},  // the block less its hidden centre
      {{7.5, 0.5, 1.6}, 0},   // nothing missed there
      {{3.5, 1.5, 1.6}, 0},   // the floor seen
  };
  EXPECT_EQ(cells, expected);
  ASSERT_EQ(map.floor_z_m.size(), map.positions.size());
  for (size_t i = 0; i < map.positions.size(); ++i) EXPECT_NEAR(map.floor_z_m[i], map.positions[i].z() - 1.5, 1e-12);
}

TEST(MissedVoxelsHeatMapTest, EmptyWithoutFaceValues) {
  EvaluateJobResult sampled = TwoLevelEvaluation();
  sampled.evaluation.best_face_values.clear();
  EXPECT_TRUE(MissedVoxelsHeatMap(EvaluationAsPlan(sampled), 1.0).positions.empty());
}

TEST(EvaluationAsPlanTest, TheViewpointsAreItsStationsLocalWithTheirG) {
  EvaluateJobResult r = TwoLevelEvaluation();
  const WorldPoint origin(512000, 5612000, 100);
  r.frame_origin_m = origin;
  for (WorldPoint& v : r.viewpoints) v += origin;  // given in the input's frame
  const PlanResult plan = EvaluationAsPlan(r);
  ASSERT_EQ(plan.stations.size(), 3u);
  EXPECT_LT((plan.stations[2].position - WorldPoint(1, 1, 4.6)).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(plan.stations[1].global_visibility, 0.2);
  EXPECT_FALSE(plan.stations[0].fixed);
  EXPECT_EQ(plan.frame_origin_m, origin);
  EXPECT_EQ(plan.resolution_m, 0.1);
  EXPECT_EQ(plan.occupied_voxels, r.voxel_centers.size());
  EXPECT_EQ(plan.covered_voxels, 3u);  // the three seen voxels
  EXPECT_EQ(plan.heat_map.positions.size(), 5u);
  EXPECT_NEAR(plan.stations[1].floor_z_m, 0.1, 1e-9);   // the voxel under it, 1.5 m below
  EXPECT_TRUE(std::isnan(plan.stations[0].floor_z_m));  // nothing under it
  EXPECT_TRUE(std::isnan(plan.stations[2].floor_z_m));  // nothing under it either
  EXPECT_EQ(plan.evaluation.best_face_values, r.evaluation.best_face_values);
}

TEST(WriteEvaluationOutputsTest, WritesSubmitsFilesWithTheCrewsStationsCsv) {
  const EvaluateJobResult r = TwoLevelEvaluation();
  const std::string dir = testing::MakeTempDir() + "/out";
  ASSERT_TRUE(WriteEvaluationOutputs(r, dir).ok());
  for (const char* name : {"evaluation.json", "stations.csv", "stations.dxf", "fieldsheet.pdf", "visibility.ply",
                           "heatmap.png", "report.html"}) {
    EXPECT_TRUE(std::filesystem::file_size(dir + "/" + name) > 0) << name;
  }
  for (const char* name : {"plan.json", "reduction.png", "stations.geojson"}) {
    EXPECT_FALSE(std::filesystem::exists(dir + "/" + name)) << name;
  }
  const PlanResult plan = EvaluationAsPlan(r);
  EXPECT_EQ(ReadAll(dir + "/stations.csv"), FieldStationsCsv(FieldStations(plan)));
  EXPECT_NE(ReadAll(dir + "/stations.csv").find("\nstation,name,x_m,y_m,z_m,"), std::string::npos);
  // The stations were given, not selected: no gain or cumulative coverage (empty cells, not zeros).
  std::istringstream rows(ReadAll(dir + "/stations.csv"));
  int data_rows = 0;
  for (std::string row; std::getline(rows, row);) {
    if (row.empty() || row[0] == '#' || row.rfind("station,", 0) == 0) continue;
    ++data_rows;
    EXPECT_EQ(row.substr(row.size() - 2), ",,") << row;
  }
  EXPECT_EQ(data_rows, static_cast<int>(r.viewpoints.size()));
  EXPECT_EQ(ReadAll(dir + "/heatmap.png"), *HeatmapPng(plan, HeatmapMeaning::kMissedByStations));
}

// With the job's scanner, the field sheet knows the scan time: set-up and scans of every station
// (no walk: an evaluation has no route).
TEST(WriteEvaluationOutputsTest, TheJobsScannerGivesTheFieldTime) {
  const EvaluateJobResult r = TwoLevelEvaluation();
  EXPECT_EQ(EvaluationAsPlan(r).field_time.scan_seconds_per_station, 0.0);
  ScannerModel rtc360;
  rtc360.name = "leica-rtc360";
  const PlanResult plan = EvaluationAsPlan(r, rtc360);
  ASSERT_GT(plan.field_time.scan_seconds_per_station, 0.0);
  EXPECT_EQ(plan.options.scanner.name, "leica-rtc360");
  EXPECT_DOUBLE_EQ(plan.field_time.scan_s, plan.field_time.scan_seconds_per_station * double(r.viewpoints.size()));
  EXPECT_DOUBLE_EQ(plan.field_time.setup_s, plan.options.setup_seconds * double(r.viewpoints.size()));
  EXPECT_EQ(plan.field_time.walk_s, 0.0);
}

// An evaluation's heat map counts what is missed: only its title and colour bar's words differ
// from the same cells drawn as a plan's.
TEST(WriteEvaluationOutputsTest, TheMissedVoxelsHeatMapSaysWhatItCountsInItsTitleAndColourBar) {
  const PlanResult plan = EvaluationAsPlan(TwoLevelEvaluation());
  const Picture missed = DecodePng(*HeatmapPng(plan, HeatmapMeaning::kMissedByStations));
  const Picture seen = DecodePng(*HeatmapPng(plan));
  ASSERT_EQ(missed.width, seen.width);
  ASSERT_EQ(missed.height, seen.height);
  int title_rows_differing = 0, plot_pixels_differing = 0;
  for (int y = 0; y < missed.height; ++y) {
    for (int x = 0; x < missed.width; ++x) {
      if (missed.at(x, y) == seen.at(x, y)) continue;
      if (y < 40) {
        ++title_rows_differing;
      } else if (x < missed.width - 110) {
        ++plot_pixels_differing;
      }
    }
  }
  EXPECT_GT(title_rows_differing, 50);
  EXPECT_EQ(plot_pixels_differing, 0);
}

TEST(WriteEvaluationOutputsTest, ASampledEvaluationWritesTheStationFilesOnly) {
  EvaluateJobResult r = TwoLevelEvaluation();
  r.evaluation.best_face_values.clear();
  r.evaluation.sole_viewer.clear();
  r.evaluation.sampled = true;
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WriteEvaluationOutputs(r, dir).ok());
  for (const char* name : {"evaluation.json", "stations.csv", "stations.dxf", "fieldsheet.pdf"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + name)) << name;
  }
  for (const char* name : {"visibility.ply", "heatmap.png", "report.html"}) {
    EXPECT_FALSE(std::filesystem::exists(dir + "/" + name)) << name;
  }
}

TEST(WriteEvaluationOutputsTest, WithACrsWritesStationsGeoJsonAndNamesItInEvaluationJson) {
  Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok()) << crs.status().ToString();
  EvaluateJobResult r = TwoLevelEvaluation();
  const WorldPoint origin(512000, 5612000, 0);
  r.frame_origin_m = origin;
  for (WorldPoint& v : r.viewpoints) v += origin;
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WriteEvaluationOutputs(r, dir, &*crs).ok());
  const json geo = json::parse(ReadAll(dir + "/stations.geojson"));
  EXPECT_EQ(geo["type"], "FeatureCollection");
  int stations = 0;
  for (const json& f : geo["features"]) stations += f["properties"]["kind"] == "station";
  EXPECT_EQ(stations, 3);
  EXPECT_EQ(json::parse(ReadAll(dir + "/evaluation.json"))["crs"]["definition"], "EPSG:25832");
  EXPECT_NE(ReadAll(dir + "/stations.csv").find("512001.000000,5612001.000000"), std::string::npos);
}

TEST(ParseStationsCsvTest, AcceptsHeaderCommentsBlankLinesAndSpaces) {
  const std::string text = "# stations\nx, y, z\n\n1, 2, 3\n  4.5,-5,6e-1  # trailing comment\n7 8 9\r\n";
  Result<std::vector<WorldPoint>> r = ParseStationsCsv(text, "my.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 3u);
  EXPECT_EQ((*r)[1], WorldPoint(4.5, -5, 0.6));
  EXPECT_EQ((*r)[2], WorldPoint(7, 8, 9));
}

TEST(ParseStationsCsvTest, RejectsBadRowsNamingTheLine) {
  struct Case {
    std::string text;
    std::string line;
  };
  for (const Case& c :
       {Case{"x,y,z\n1,2,3\n1,2\n", "my.csv:3:"}, Case{"1,2,3\n1,2,abc\n", "my.csv:2:"},
        Case{"1,2,3\n1,2,3,4,5\n", "my.csv:2:"}, Case{"1,2,3,x\n", "my.csv:1:"}, Case{"1,2,nan\n", "my.csv:1:"},
        Case{"1,2,3\n1,inf,3\n", "my.csv:2:"}, Case{"1,2,3\nx,y,z\n", "my.csv:2:"}, Case{"1,,3\n", "my.csv:1:"}}) {
    Result<std::vector<WorldPoint>> r = ParseStationsCsv(c.text, "my.csv");
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find(c.line), std::string::npos) << r.status().message();
  }
}

TEST(ParseStationsCsvTest, RejectsAFileWithoutStations) {
  for (const std::string text : {"", "x,y,z\n", "# nothing\n\n"}) {
    Result<std::vector<WorldPoint>> r = ParseStationsCsv(text, "empty.csv");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("empty.csv"), std::string::npos);
  }
}

}  // namespace
}  // namespace vc
