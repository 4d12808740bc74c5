// The crew's files: the station table (walking order, names, floors, tripod heights), stations.csv
// read back by both station readers, plan.json's station fields, and stations.dxf opened by a real
// DXF reader (Debian's python3-ezdxf through tests/core/report/read_dxf.py), and stations.geojson
// checked by python's json and pyproj (Debian's python3-pyproj through
// tests/core/report/check_geojson.py). The tests fail, never skip, when a reader is missing:
// scripts/install-deps.sh --tests installs them.
#include "vc/report/field_exports.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "testing/test_paths.h"
#include "vc/plan/keep_out.h"
#include "vc/report/plan_report.h"
#include "vc/scene/station_file.h"

namespace vc {
namespace {

using nlohmann::json;

const WorldPoint kOrigin(512000, 5612000, 100);

// Two levels (floors 0 and 3 m, local), in a survey frame: a fixed station and two new ones
// walked 1 -> 0 -> 2 from a start, and station 3, without a floor, left out of the route.
PlanResult TwoFloorPlan() {
  PlanResult r;
  r.frame_origin_m = kOrigin;
  r.floor_levels_m = {0.0, 3.0};
  r.coverable_voxels = 100;
  r.stations = {{{1, 1, 1.5}, 50, 50, 0.5, 0.3, -1, true, 0.0},
                {{4, 1, 1.2}, 40, 30, 0.8, 0.2, 7, false, 0.0},
                {{4, 4, 4.6}, 25, 20, 1.0, 0.1, 9, false, 3.0},
                {{2, 4, 1.5}, 5, 0, 1.0, 0.0, -1, false, std::nan("")}};
  r.route.order = {1, 0, 2};
  r.route.start = WorldPoint(5, 0, 0);
  r.route.legs_m = {2.0, 3.0, std::nan("")};
  r.route.polylines = {{{5, 0, 0}, {4, 0, 0}, {4, 1, 0}}, {{4, 1, 0}, {1, 1, 0}}, {}};
  r.options.keep_out = {KeepOutBox({512002, 5612002, 100}, {512003, 5612003, 102}),
                        KeepOutPolygon(100, 103, {512000, 5612000, 512001, 5612000, 512000, 5612001})};
  return r;
}

TEST(FieldStationsTest, WalkingOrderNamesFloorsAndTripodHeights) {
  const std::vector<FieldStation> f = FieldStations(TwoFloorPlan(), {"BM 7"});
  ASSERT_EQ(f.size(), 4u);
  const std::vector<size_t> index = {1, 0, 2, 3};
  const std::vector<std::string> names = {"S01", "BM 7", "S02", "S03"};
  const std::vector<std::string> floors = {"L0", "L0", "L1", ""};
  const std::vector<int> route = {1, 2, 3, 0};
  for (size_t k = 0; k < f.size(); ++k) {
    EXPECT_EQ(f[k].number, static_cast<int>(k) + 1);
    EXPECT_EQ(f[k].index, index[k]);
    EXPECT_EQ(f[k].name, names[k]);
    EXPECT_EQ(f[k].floor, floors[k]);
    EXPECT_EQ(f[k].route_order, route[k]);
  }
  EXPECT_TRUE(f[1].fixed);
  EXPECT_FALSE(f[0].fixed);
  EXPECT_NEAR(f[0].tripod_height_m, 1.2, 1e-12);
  EXPECT_NEAR(f[2].tripod_height_m, 1.6, 1e-12);
  EXPECT_DOUBLE_EQ(f[2].floor_z_m, 103.0);  // the input's frame
  EXPECT_TRUE(std::isnan(f[3].floor_z_m));
  EXPECT_TRUE(std::isnan(f[3].tripod_height_m));
  EXPECT_EQ(f[0].position_m, WorldPoint(512004, 5612001, 101.2));
  EXPECT_EQ(f[0].gain_voxels, 30u);
  EXPECT_DOUBLE_EQ(f[0].cumulative_coverage, 0.8);
}

TEST(FieldStationsTest, GeneratedNamesSkipTheFixedStationsNamesAndWidenPastNinetyNine) {
  std::vector<std::string> names;
  for (const FieldStation& f : FieldStations(TwoFloorPlan(), {"S01"})) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"S02", "S01", "S03", "S04"}));
  // Unnamed or badly named fixed stations get generated names; separators become '_'.
  names.clear();
  for (const FieldStation& f : FieldStations(TwoFloorPlan(), {"a,b#c"})) names.push_back(f.name);
  EXPECT_EQ(names[1], "a_b_c");
  names.clear();
  for (const FieldStation& f : FieldStations(TwoFloorPlan())) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"S01", "S02", "S03", "S04"}));

  PlanResult many;
  for (int i = 0; i < 100; ++i) many.stations.push_back({{double(i), 0, 1.5}, 1, 1, 0.01 * (i + 1)});
  const std::vector<FieldStation> f = FieldStations(many);
  EXPECT_EQ(f.front().name, "S001");
  EXPECT_EQ(f.back().name, "S100");
}

TEST(FieldStationsTest, WithoutPlannerLevelsTheStationsFloorsAreGrouped) {
  PlanResult r;
  r.stations = {{{0, 0, 1.5}, 1, 1, 0.1, 0, -1, false, 0.0},
                {{1, 0, 1.6}, 1, 1, 0.2, 0, -1, false, 0.1},
                {{2, 0, 4.5}, 1, 1, 0.3, 0, -1, false, 3.0}};
  const std::vector<FieldStation> f = FieldStations(r);
  EXPECT_EQ(f[0].floor, "L0");
  EXPECT_EQ(f[1].floor, "L0");
  EXPECT_EQ(f[2].floor, "L1");
}

TEST(FieldStationsCsvTest, RowsInWalkingOrderWithUnitsAndEmptyCellsWithoutAFloor) {
  const std::string csv = FieldStationsCsv(FieldStations(TwoFloorPlan(), {"BM 7"}));
  const size_t header = csv.find('\n') + 1;
  EXPECT_EQ(csv.substr(0, 2), "# ");
  EXPECT_NE(csv.substr(0, header).find("metres"), std::string::npos);
  EXPECT_NE(csv.substr(0, header).find("selection order"), std::string::npos);
  EXPECT_EQ(csv.substr(header),
            "station,name,x_m,y_m,z_m,floor,floor_z_m,tripod_height_m,fixed,route_order,selection_order,gain_voxels,"
            "cumulative_coverage\n"
            "1,S01,512004.000000,5612001.000000,101.200000,L0,100.000,1.200,new,1,2,30,0.800000\n"
            "2,BM 7,512001.000000,5612001.000000,101.500000,L0,100.000,1.500,existing,2,1,50,0.500000\n"
            "3,S02,512004.000000,5612004.000000,104.600000,L1,103.000,1.600,new,3,3,20,1.000000\n"
            "4,S03,512002.000000,5612004.000000,101.500000,,,,new,0,4,0,1.000000\n");
}

TEST(FieldStationsCsvTest, BothStationReadersReadItBackWithTheNames) {
  const PlanResult plan = TwoFloorPlan();
  const std::vector<FieldStation> f = FieldStations(plan, {"BM 7"});
  const std::string csv = FieldStationsCsv(f);
  Result<std::vector<WorldPoint>> points = ParseStationsCsv(csv, "stations.csv");
  ASSERT_TRUE(points.ok()) << points.status().ToString();
  Result<std::vector<KnownStation>> known = ParseStationFile(csv, "stations.csv");
  ASSERT_TRUE(known.ok()) << known.status().ToString();
  ASSERT_EQ(points->size(), f.size());
  ASSERT_EQ(known->size(), f.size());
  for (size_t k = 0; k < f.size(); ++k) {
    EXPECT_LT(((*points)[k] - f[k].position_m).norm(), 1e-6);
    EXPECT_LT(((*known)[k].position_m - f[k].position_m).norm(), 1e-6);
    EXPECT_EQ((*known)[k].name, f[k].name);
  }
  // Given back as fixed stations, the names stay: the next plan's existing stations keep them.
  std::vector<std::string> names;
  for (const KnownStation& s : *known) names.push_back(s.name);
  PlanResult next = TwoFloorPlan();
  for (PlannedStation& s : next.stations) s.fixed = true;
  next.route.order = {0, 1, 2, 3};
  std::vector<std::string> again;
  for (const FieldStation& s : FieldStations(next, names)) again.push_back(s.name);
  EXPECT_EQ(again, names);
}

TEST(ParseStationsCsvTest, ReadsTheColumnsAHeaderNames) {
  Result<std::vector<WorldPoint>> r = ParseStationsCsv("name;z_m;Y;x\nA;3;2;1\nB;6;5;4\n", "named.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[1], WorldPoint(4, 5, 6));
  Result<std::vector<WorldPoint>> bad = ParseStationsCsv("name,x_m,y_m,z_m\nA,1,2\n", "named.csv");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("named.csv:2:"), std::string::npos) << bad.status().message();
}

TEST(PlanJsonStationFieldsTest, EachViewpointCarriesItsCrewFieldsInSelectionOrder) {
  const json j = json::parse(PlanToJson(TwoFloorPlan(), nullptr, {"BM 7"}));
  const json& v = j["viewpoints"];
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[0]["index"], 0);  // the array keeps selection order
  EXPECT_EQ(v[0]["name"], "BM 7");
  EXPECT_EQ(v[0]["station"], 2);
  EXPECT_EQ(v[1]["name"], "S01");
  EXPECT_EQ(v[1]["station"], 1);
  EXPECT_EQ(v[2]["floor"], "L1");
  EXPECT_NEAR(v[2]["tripod_height_m"].get<double>(), 1.6, 1e-9);
  EXPECT_DOUBLE_EQ(v[2]["floor_z_m"].get<double>(), 103.0);
  EXPECT_TRUE(v[3]["floor"].is_null());
  EXPECT_TRUE(v[3]["floor_z_m"].is_null());
  EXPECT_TRUE(v[3]["tripod_height_m"].is_null());
}

// What read_dxf.py reports for `dxf`; fails the test when the reader does not run or read it.
json ReadWithEzdxf(const std::string& dxf) {
  const std::string dir = testing::MakeTempDir();
  const std::string path = dir + "/stations.dxf";
  {
    std::ofstream f(path, std::ios::binary);
    f << dxf;
  }
  const std::string command = "'" + std::string(VC_DXF_PYTHON) + "' '" + VC_READ_DXF_SCRIPT + "' '" + path + "' >'" +
                              dir + "/out.json' 2>'" + dir + "/err.txt'";
  const int rc = std::system(command.c_str());
  EXPECT_EQ(rc, 0) << "ezdxf could not read stations.dxf (install python3-ezdxf with scripts/install-deps.sh "
                      "--tests): "
                   << testing::ReadFileBytes(dir + "/err.txt");
  if (rc != 0) return json();
  return json::parse(testing::ReadFileBytes(dir + "/out.json"));
}

void ExpectPoint(const json& xyz, const WorldPoint& p) {
  ASSERT_EQ(xyz.size(), 3u);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(xyz[size_t(a)].get<double>(), p[a], 1e-6) << xyz.dump();
}

TEST(StationsDxfTest, EzdxfReadsTheLayersStationsRouteAndKeepOutZones) {
  const PlanResult plan = TwoFloorPlan();
  const std::vector<FieldStation> f = FieldStations(plan, {"BM 7"});
  const json d = ReadWithEzdxf(StationsDxf(plan, f));
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["dxfversion"], "AC1009");
  ExpectPoint(d["extents"][0], {512000, 5612000, 100});    // a keep-out polygon's corner
  ExpectPoint(d["extents"][1], {512005, 5612004, 104.6});  // the route's start, station 2
  EXPECT_TRUE(d["audit_errors"].empty()) << d["audit_errors"].dump();
  for (const char* layer : {"STATIONS", "LABELS", "ROUTE", "KEEP_OUT"}) {
    EXPECT_NE(std::find(d["layers"].begin(), d["layers"].end(), layer), d["layers"].end()) << layer;
  }
  EXPECT_NE(std::find(d["styles"].begin(), d["styles"].end(), "STANDARD"), d["styles"].end()) << d["styles"].dump();
  EXPECT_FALSE(d.contains("other")) << d["other"].dump();
  ASSERT_EQ(d["points"].size(), f.size());
  ASSERT_EQ(d["texts"].size(), f.size());
  for (size_t k = 0; k < f.size(); ++k) {
    EXPECT_EQ(d["points"][k]["layer"], "STATIONS");
    ExpectPoint(d["points"][k]["xyz"], f[k].position_m);
    EXPECT_EQ(d["texts"][k]["layer"], "LABELS");
  }
  EXPECT_EQ(d["texts"][0]["text"], "S01 h=1.20");
  EXPECT_EQ(d["texts"][1]["text"], "BM 7 h=1.50");
  EXPECT_EQ(d["texts"][3]["text"], "S03");

  std::vector<json> route, zones;
  for (const json& p : d["polylines"]) (p["layer"] == "ROUTE" ? route : zones).push_back(p);
  // One walkable part: start, (4, 0), station 1's floor, station 0's floor; station 2 is not linked.
  ASSERT_EQ(route.size(), 1u);
  const std::vector<WorldPoint> walk = {{5, 0, 0}, {4, 0, 0}, {4, 1, 0}, {1, 1, 0}};
  ASSERT_EQ(route[0]["vertices"].size(), walk.size());
  for (size_t i = 0; i < walk.size(); ++i) ExpectPoint(route[0]["vertices"][i], walk[i] + kOrigin);
  EXPECT_FALSE(route[0]["closed"].get<bool>());
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_EQ(zones[0]["layer"], "KEEP_OUT");
  EXPECT_TRUE(zones[0]["closed"].get<bool>());
  ASSERT_EQ(zones[0]["vertices"].size(), 4u);
  ExpectPoint(zones[0]["vertices"][0], {512002, 5612002, 100});
  ExpectPoint(zones[0]["vertices"][2], {512003, 5612003, 100});
  ASSERT_EQ(zones[1]["vertices"].size(), 3u);
  ExpectPoint(zones[1]["vertices"][1], {512001, 5612000, 100});
}

TEST(StationsDxfTest, WritePlanOutputsWritesItNextToStationsCsv) {
  PlanResult plan = TwoFloorPlan();
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir, nullptr, {"BM 7"}).ok());
  const std::string dxf = testing::ReadFileBytes(dir + "/stations.dxf");
  EXPECT_EQ(dxf, StationsDxf(plan, FieldStations(plan, {"BM 7"})));
  EXPECT_NE(testing::ReadFileBytes(dir + "/stations.csv").find("\n2,BM 7,"), std::string::npos);
  EXPECT_FALSE(std::ifstream(dir + "/stations.geojson").good()) << "no CRS, no GeoJSON";
  EXPECT_TRUE(json::parse(testing::ReadFileBytes(dir + "/plan.json"))["crs"].is_null());
}

// What check_geojson.py says of `geojson` against the input-frame points of `expected`; fails the
// test when pyproj disagrees with a coordinate or the structure is wrong.
json CheckWithPyproj(const std::string& geojson, const json& expected) {
  const std::string dir = testing::MakeTempDir();
  std::ofstream(dir + "/stations.geojson", std::ios::binary) << geojson;
  std::ofstream(dir + "/expected.json", std::ios::binary) << expected.dump();
  // Appended piece by piece: GCC 12's -Wstringop-overflow misreads "literal" + std::string (GCC PR 105651).
  std::string command;
  for (const std::string_view part : {"'", VC_DXF_PYTHON, "' '", VC_CHECK_GEOJSON_SCRIPT, "' '"}) command += part;
  command += dir;
  command += "/stations.geojson' '";
  command += dir;
  command += "/expected.json' >'";
  command += dir;
  command += "/out.json' 2>'";
  command += dir;
  command += "/err.txt'";
  const int rc = std::system(command.c_str());
  EXPECT_EQ(rc, 0) << "check_geojson.py (python3-pyproj: scripts/install-deps.sh --tests): "
                   << testing::ReadFileBytes(dir + "/err.txt");
  if (rc != 0) return json();
  return json::parse(testing::ReadFileBytes(dir + "/out.json"));
}

json Xy(const WorldPoint& p) { return json::array({p.x(), p.y()}); }

TEST(StationsGeoJsonTest, PyprojAgreesWithEveryCoordinateAndRingsAreClosedCounterClockwise) {
  const PlanResult plan = TwoFloorPlan();  // at 512 km east, 5,612 km north: EPSG:25832 in Germany
  const Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok()) << crs.status().message();
  const std::vector<FieldStation> stations = FieldStations(plan, {"BM 7"});
  const Result<std::string> geojson = StationsGeoJson(plan, stations, *crs);
  ASSERT_TRUE(geojson.ok()) << geojson.status().message();

  json expected{{"crs", "EPSG:25832"}, {"stations", json::array()}};
  for (const FieldStation& f : stations) expected["stations"].push_back(Xy(f.position_m));
  // The route's paths joined in walking order: start (5, 0), (4, 0), station 1 at (4, 1), station 0 at (1, 1).
  expected["route"] = json::array({json::array()});
  for (const WorldPoint& local : {WorldPoint(5, 0, 0), WorldPoint(4, 0, 0), WorldPoint(4, 1, 0), WorldPoint(1, 1, 0)}) {
    expected["route"][0].push_back(Xy(local + kOrigin));
  }
  expected["zones"] = json::array(
      {json::array({json::array({512002, 5612002}), json::array({512003, 5612002}), json::array({512003, 5612003}),
                    json::array({512002, 5612003})}),
       json::array({json::array({512000, 5612000}), json::array({512001, 5612000}), json::array({512000, 5612001})})});
  const json summary = CheckWithPyproj(*geojson, expected);
  EXPECT_EQ(summary["Point"], 4);
  EXPECT_EQ(summary["LineString"], 1);
  EXPECT_EQ(summary["Polygon"], 2);

  const json doc = json::parse(*geojson);
  const json& first = doc["features"][0]["properties"];  // walking order: S01 first, then the fixed BM 7
  EXPECT_EQ(first["kind"], "station");
  EXPECT_EQ(first["station"], 1);
  EXPECT_EQ(first["name"], "S01");
  EXPECT_EQ(first["fixed"], false);
  EXPECT_EQ(first["route_order"], 1);
  EXPECT_EQ(first["floor"], "L0");
  EXPECT_NEAR(first["tripod_height_m"].get<double>(), 1.2, 1e-9);
  EXPECT_EQ(doc["features"][1]["properties"]["name"], "BM 7");
  EXPECT_EQ(doc["features"][1]["properties"]["fixed"], true);
  EXPECT_TRUE(doc["features"][3]["properties"]["tripod_height_m"].is_null());  // no floor below it
  EXPECT_EQ(doc["features"][4]["properties"]["kind"], "route");
  EXPECT_EQ(doc["features"][5]["properties"]["kind"], "keep_out");
  EXPECT_EQ(doc["features"][5]["properties"]["z_max_m"], 102);
  // Nine decimals of a degree (0.1 mm): "9.1234567..,"
  const std::string lon = doc["features"][0]["geometry"]["coordinates"][0].dump();
  EXPECT_GE(lon.size() - lon.find('.') - 1, 7u) << lon;
}

TEST(StationsGeoJsonTest, AFootCrsTakesTheMetresOfTheOutputs) {
  PlanResult plan = TwoFloorPlan();
  plan.frame_origin_m = WorldPoint(300000, 60000, 10);  // NAD83 / New York Long Island, in metres
  plan.options.keep_out.clear();
  const Result<Crs> crs = Crs::Create("EPSG:2263");
  ASSERT_TRUE(crs.ok()) << crs.status().message();
  const std::vector<FieldStation> stations = FieldStations(plan);
  const Result<std::string> geojson = StationsGeoJson(plan, stations, *crs);
  ASSERT_TRUE(geojson.ok()) << geojson.status().message();
  json expected{{"crs", "EPSG:2263"},
                {"metres_per_unit", 1200.0 / 3937.0},
                {"stations", json::array()},
                {"route", json::array({json::array()})},
                {"zones", json::array()}};
  for (const FieldStation& f : stations) expected["stations"].push_back(Xy(f.position_m));
  for (const WorldPoint& local : {WorldPoint(5, 0, 0), WorldPoint(4, 0, 0), WorldPoint(4, 1, 0), WorldPoint(1, 1, 0)}) {
    expected["route"][0].push_back(Xy(local + plan.frame_origin_m));
  }
  EXPECT_EQ(CheckWithPyproj(*geojson, expected)["Point"], 4);
}

TEST(StationsGeoJsonTest, WithACrsWritePlanOutputsWritesItAndNamesTheCrs) {
  const PlanResult plan = TwoFloorPlan();
  const Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok());
  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(plan, dir, nullptr, {"BM 7"}, &*crs).ok());
  EXPECT_EQ(testing::ReadFileBytes(dir + "/stations.geojson"),
            *StationsGeoJson(plan, FieldStations(plan, {"BM 7"}), *crs));
  const json j = json::parse(testing::ReadFileBytes(dir + "/plan.json"));
  EXPECT_EQ(j["crs"]["definition"], "EPSG:25832");
  EXPECT_EQ(j["crs"]["name"], "ETRS89 / UTM zone 32N");
  EXPECT_EQ(j["crs"]["epsg"], 25832);
  EXPECT_EQ(j["crs"]["axis_unit"], "metre");
  EXPECT_EQ(testing::ReadFileBytes(dir + "/stations.csv")
                .rfind("# vc stations: lengths in metres in the input's frame, CRS EPSG:25832 (ETRS89 / UTM zone 32N) "
                       "(x_m",
                       0),
            0u);
}

}  // namespace
}  // namespace vc
