// The parameter tables (vc/base/parameter.h) and every place derived from them: vc-client's flags
// (parameter_flags.h), the proto conversion (vc/wire/convert.h), validation and plan.json. For
// each row: a value other than the default goes through the flag, the proto and plan.json, and a
// value the row's check refuses is refused naming the row. And the other way round: every proto
// field and every plan.json parameter belongs to a row (or to the few non-row members).
#include "vc/client/parameter_flags.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "testing/e57_writer.h"
#include "vc/plan/keep_out.h"
#include "vc/report/plan_report.h"
#include "vc/visibility/scanner_presets.h"
#include "vc/wire/convert.h"

namespace vc {
namespace {

using nlohmann::json;

// A valid value of the row's type other than `v`.
double Other(double v, ParamCheck c) {
  switch (c) {
    case ParamCheck::kFraction:
    case ParamCheck::kElevationDeg:
    case ParamCheck::kIncidenceDeg:
    case ParamCheck::kAzimuthSpanDeg:
      return v / 2;
    case ParamCheck::kUnitInterval:
      return v == 0 ? 0.375 : v / 2;
    default:
      return v + 0.375;
  }
}
uint64_t Other(uint64_t v, ParamCheck) { return v + 3; }
int32_t Other(int32_t v, ParamCheck) { return v + 3; }
bool Other(bool v, ParamCheck) { return !v; }
SelectionTest Other(SelectionTest v, ParamCheck) {
  return v == SelectionTest::kCompatibility ? SelectionTest::kSurfaceVisibility : SelectionTest::kCompatibility;
}
SelectionSolver Other(SelectionSolver v, ParamCheck) {
  return v == SelectionSolver::kExact ? SelectionSolver::kAuto : SelectionSolver::kExact;
}
GroundModel Other(GroundModel v, ParamCheck) {
  return v == GroundModel::kTerrain ? GroundModel::kFloors : GroundModel::kTerrain;
}
FaceSet Other(FaceSet v, ParamCheck) { return v == FaceSet::kAll ? FaceSet::kExposed : FaceSet::kAll; }

// A value the row's check refuses, if there is one.
std::optional<double> Bad(double, ParamCheck c) {
  switch (c) {
    case ParamCheck::kAny:
      return std::numeric_limits<double>::quiet_NaN();
    case ParamCheck::kNonNegative:
      return -0.5;
    case ParamCheck::kPositive:
      return 0.0;
    case ParamCheck::kFraction:
    case ParamCheck::kUnitInterval:
      return 1.5;
    case ParamCheck::kElevationDeg:
      return -91.0;
    case ParamCheck::kIncidenceDeg:
    case ParamCheck::kAzimuthSpanDeg:
      return 0.0;
  }
  return std::nullopt;
}
std::optional<uint64_t> Bad(uint64_t, ParamCheck c) {
  if (c == ParamCheck::kPositive || c == ParamCheck::kFraction) return 0;
  return std::nullopt;
}
std::optional<int32_t> Bad(int32_t, ParamCheck c) {
  if (c == ParamCheck::kAny) return std::nullopt;
  return c == ParamCheck::kNonNegative ? -1 : 0;
}
template <UncheckedParameter T>
std::optional<T> Bad(T, ParamCheck) {
  return std::nullopt;
}

// The command-line words that set a flag to `v`.
std::string Args(std::string_view flag, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return "--" + std::string(flag) + " " + buf;
}
std::string Args(std::string_view flag, uint64_t v) { return "--" + std::string(flag) + " " + std::to_string(v); }
std::string Args(std::string_view flag, int32_t v) { return "--" + std::string(flag) + " " + std::to_string(v); }
std::string Args(std::string_view flag, bool v) { return (v ? "--" : "--no-") + std::string(flag); }
std::string Args(std::string_view flag, SelectionTest v) {
  return "--" + std::string(flag) + " " + std::string(SelectionTestName(v));
}
std::string Args(std::string_view flag, SelectionSolver v) {
  return "--" + std::string(flag) + " " + std::string(SelectionSolverName(v));
}
std::string Args(std::string_view flag, GroundModel v) {
  return "--" + std::string(flag) + " " + std::string(GroundModelName(v));
}
std::string Args(std::string_view flag, FaceSet v) {
  return "--" + std::string(flag) + (v == FaceSet::kExposed ? " exposed" : " all");
}

// How plan.json writes a value.
template <typename T>
json JsonValue(T v) {
  return json(v);
}
json JsonValue(SelectionTest v) { return std::string(SelectionTestName(v)); }
json JsonValue(SelectionSolver v) { return std::string(SelectionSolverName(v)); }
json JsonValue(GroundModel v) { return std::string(GroundModelName(v)); }

std::set<std::string> FieldNames(const google::protobuf::Descriptor* d) {
  std::set<std::string> names;
  for (int i = 0; i < d->field_count(); ++i) names.insert(d->field(i)->name());
  return names;
}

#define VC_ROW_NAME(type, name, ...) #name,

TEST(ParameterTablesTest, EveryPlanRowIsAFlagAProtoFieldAPlanJsonKeyAndChecked) {
  const PlanOptions defaults;
#define VC_PLAN_ROW(type, name, default_value, unit, flag, check, help)                  \
  {                                                                                      \
    SCOPED_TRACE(#name);                                                                 \
    const type other = Other(defaults.name, ParamCheck::check);                          \
    ASSERT_NE(other, defaults.name);                                                     \
    PlanOptions parsed;                                                                  \
    CLI::App app;                                                                        \
    client::AddPlanFlags(&app, &parsed);                                                 \
    app.parse(Args(flag, other), false);                                                 \
    EXPECT_EQ(parsed.name, other) << "flag --" << flag;                                  \
    PlanOptions o;                                                                       \
    o.name = other;                                                                      \
    Result<PlanOptions> back = wire::FromProto(wire::ToProto(o));                        \
    ASSERT_TRUE(back.ok()) << back.status().ToString();                                  \
    EXPECT_EQ(back->name, other) << "proto field " #name;                                \
    PlanResult r;                                                                        \
    r.options = o;                                                                       \
    EXPECT_EQ(json::parse(PlanToJson(r))["parameters"][#name], JsonValue(other));        \
    if (const auto bad = Bad(defaults.name, ParamCheck::check)) {                        \
      PlanOptions b;                                                                     \
      b.name = *bad;                                                                     \
      const Status s = b.Validate();                                                     \
      EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);                                 \
      EXPECT_NE(s.message().find(#name), std::string::npos) << s.message();              \
      const Status named = b.Validate(client::PlanFlagNamer());                          \
      EXPECT_EQ(named.message().rfind("--" flag " must be ", 0), 0u) << named.message(); \
    }                                                                                    \
  }
  VC_PLAN_PARAMETERS(VC_PLAN_ROW)
#undef VC_PLAN_ROW
}

TEST(ParameterTablesTest, EveryScannerRowIsAFlagOfBothCommandsAProtoFieldAndChecked) {
  const ScannerModel defaults;
#define VC_SCANNER_ROW(type, name, default_value, unit, flag, check, help)                   \
  {                                                                                          \
    SCOPED_TRACE(#name);                                                                     \
    const type other = Other(defaults.name, ParamCheck::check);                              \
    PlanOptions plan;                                                                        \
    CLI::App plan_app;                                                                       \
    client::AddPlanFlags(&plan_app, &plan);                                                  \
    plan_app.parse(Args(flag, other), false);                                                \
    EXPECT_EQ(plan.scanner.name, other);                                                     \
    EvaluateJobOptions eval;                                                                 \
    CLI::App eval_app;                                                                       \
    client::AddEvaluateFlags(&eval_app, &eval);                                              \
    eval_app.parse(Args(flag, other), false);                                                \
    EXPECT_EQ(eval.scanner.name, other);                                                     \
    EXPECT_EQ(wire::FromProto(wire::ToProto(plan))->scanner.name, other);                    \
    EXPECT_EQ(wire::FromProto(wire::ToProto(eval))->scanner.name, other);                    \
    PlanResult r;                                                                            \
    r.options = plan;                                                                        \
    EXPECT_EQ(json::parse(PlanToJson(r))["parameters"]["scanner"][#name], JsonValue(other)); \
    if (const auto bad = Bad(defaults.name, ParamCheck::check)) {                            \
      ScannerModel b;                                                                        \
      b.name = *bad;                                                                         \
      EXPECT_NE(b.Validate().message().find("scanner." #name), std::string::npos);           \
      PlanOptions p;                                                                         \
      p.scanner.name = *bad;                                                                 \
      const Status named = p.Validate(client::PlanFlagNamer());                              \
      EXPECT_EQ(named.message().rfind("--" flag " must be ", 0), 0u) << named.message();     \
      EvaluateJobOptions e;                                                                  \
      e.viewpoints = {{0, 0, 0}};                                                            \
      e.scanner.name = *bad;                                                                 \
      EXPECT_EQ(e.Validate(client::EvaluateFlagNamer()).message().rfind("--" flag, 0), 0u);  \
    }                                                                                        \
  }
  VC_SCANNER_PARAMETERS(VC_SCANNER_ROW)
#undef VC_SCANNER_ROW
}

TEST(ParameterTablesTest, EveryEvaluateRowIsAFlagAProtoFieldAndChecked) {
  EvaluateJobOptions defaults;
  defaults.viewpoints = {{0, 0, 0}};
#define VC_EVALUATE_ROW(type, name, default_value, unit, flag, check, help)              \
  {                                                                                      \
    SCOPED_TRACE(#name);                                                                 \
    const type other = Other(defaults.name, ParamCheck::check);                          \
    EvaluateJobOptions parsed;                                                           \
    CLI::App app;                                                                        \
    client::AddEvaluateFlags(&app, &parsed);                                             \
    app.parse(Args(flag, other), false);                                                 \
    EXPECT_EQ(parsed.name, other) << "flag --" << flag;                                  \
    EvaluateJobOptions o = defaults;                                                     \
    o.name = other;                                                                      \
    EXPECT_EQ(wire::FromProto(wire::ToProto(o))->name, other) << "proto field " #name;   \
    if (const auto bad = Bad(defaults.name, ParamCheck::check)) {                        \
      EvaluateJobOptions b = defaults;                                                   \
      b.name = *bad;                                                                     \
      const Status s = b.Validate();                                                     \
      EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);                                 \
      EXPECT_NE(s.message().find(#name), std::string::npos) << s.message();              \
      const Status named = b.Validate(client::EvaluateFlagNamer());                      \
      EXPECT_EQ(named.message().rfind("--" flag " must be ", 0), 0u) << named.message(); \
    }                                                                                    \
  }
  VC_EVALUATE_PARAMETERS(VC_EVALUATE_ROW)
#undef VC_EVALUATE_ROW
}

// The other direction: a proto field or a plan.json parameter that no row declares.
TEST(ParameterTablesTest, EveryProtoFieldAndPlanJsonParameterHasARow) {
  std::set<std::string> plan_rows = {VC_PLAN_PARAMETERS(VC_ROW_NAME)};
  std::set<std::string> scanner_rows = {VC_SCANNER_PARAMETERS(VC_ROW_NAME)};
  std::set<std::string> evaluate_rows = {VC_EVALUATE_PARAMETERS(VC_ROW_NAME)};

  std::set<std::string> want = plan_rows;
  want.insert({"scanner", "candidates", "tripod_heights_m", "keep_out", "fixed_stations", "route_start"});
  EXPECT_EQ(FieldNames(v1::PlanParameters::descriptor()), want);
  want = scanner_rows;
  want.insert("name");  // the preset, not a row (vc/visibility/scanner_presets.h)
  EXPECT_EQ(FieldNames(v1::ScannerModel::descriptor()), want);
  want = evaluate_rows;
  want.insert({"scanner", "viewpoints", "export_sets"});  // export_sets: --export-sets DIR, not a row
  EXPECT_EQ(FieldNames(v1::EvaluateParameters::descriptor()), want);

  std::set<std::string> keys;
  const json plan = json::parse(PlanToJson(PlanResult{}));
  for (const auto& [key, value] : plan["parameters"].items()) keys.insert(key);
  want = plan_rows;
  want.insert({"scanner", "user_candidates", "tripod_heights_m", "keep_out", "fixed_stations", "route_start"});
  EXPECT_EQ(keys, want);

  keys.clear();
  for (const auto& [key, value] : plan["parameters"]["scanner"].items()) keys.insert(key);
  want = scanner_rows;
  want.insert("name");
  EXPECT_EQ(keys, want);
}

#undef VC_ROW_NAME

// The list parameters that are not rows: --tripod-heights, and the files of --candidates,
// --fixed-stations and --keep-out, through the flags, the proto and plan.json.
std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  EXPECT_NE(f, nullptr) << path;
  if (f) {
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
  }
  return path;
}

TEST(ListParametersTest, FlagsFilesProtoAndPlanJson) {
  const std::string fixed = WriteTemp("fixed.csv", "x,y,z\n1,2,1.5\n-3.5,0.25,1.6\n");
  const std::string keep_out = WriteTemp("keep_out.csv", "# zones\nbox,0,0,0,1,1,3\npolygon,-1,4,5,5,7,5,6,7\n");
  const std::string candidates = WriteTemp("candidates.csv", "2,2,1.5\n");
  PlanOptions o;
  client::PlanFileFlags files;
  CLI::App app;
  client::AddPlanFlags(&app, &o);
  client::AddPlanFileFlags(&app, &files);
  app.parse("--tripod-heights 1.2,1.6,2.0 --fixed-stations " + fixed + " --keep-out " + keep_out + " --candidates " +
                candidates,
            false);
  EXPECT_EQ(o.tripod_heights_m, (std::vector<double>{1.2, 1.6, 2.0}));
  ASSERT_TRUE(client::LoadPlanFiles(files, &o).ok());
  ASSERT_EQ(o.fixed_stations.size(), 2u);
  EXPECT_EQ(o.fixed_stations[1], WorldPoint(-3.5, 0.25, 1.6));
  ASSERT_EQ(o.keep_out.size(), 2u);
  EXPECT_EQ(o.keep_out[1].shape, KeepOutShape::kPolygon);
  EXPECT_EQ(o.candidates.size(), 1u);
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().ToString();

  Result<PlanOptions> back = wire::FromProto(wire::ToProto(o));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->tripod_heights_m, o.tripod_heights_m);
  EXPECT_EQ(back->fixed_stations, o.fixed_stations);
  EXPECT_EQ(back->candidates, o.candidates);
  ASSERT_EQ(back->keep_out.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back->keep_out[i].shape, o.keep_out[i].shape);
    EXPECT_EQ(back->keep_out[i].min, o.keep_out[i].min);
    EXPECT_EQ(back->keep_out[i].max, o.keep_out[i].max);
    EXPECT_EQ(back->keep_out[i].polygon_xy_m, o.keep_out[i].polygon_xy_m);
  }

  PlanResult r;
  r.options = o;
  const json parameters = json::parse(PlanToJson(r))["parameters"];
  EXPECT_EQ(parameters["tripod_heights_m"], json({1.2, 1.6, 2.0}));
  EXPECT_EQ(parameters["fixed_stations"][1], json({-3.5, 0.25, 1.6}));
  EXPECT_EQ(parameters["keep_out"][0]["box"]["max"], json({1.0, 1.0, 3.0}));
  EXPECT_EQ(parameters["keep_out"][1]["polygon"]["xy_m"], json({5.0, 5.0, 7.0, 5.0, 6.0, 7.0}));
}

// --fixed-stations FILE.e57: "plan the next stations from what I already scanned", each scan's
// origin (its pose translation) a fixed station; a damaged file is refused naming it.
TEST(ListParametersTest, FixedStationsFromAnE57FilesScanOrigins) {
  testing::E57Spec spec;
  for (const Eigen::Vector3d& origin : {Eigen::Vector3d(1, 2, 1.5), Eigen::Vector3d(-4, 0.5, 1.7)}) {
    testing::E57ScanSpec scan;
    scan.points = {{1, 0, 0}, {0, 1, 0}};
    scan.translation_m = origin;
    scan.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
    spec.scans.push_back(scan);
  }
  std::string e57 = testing::WriteE57(spec);
  client::PlanFileFlags files;
  files.fixed_stations = WriteTemp("scanned.e57", e57);
  PlanOptions o;
  ASSERT_TRUE(client::LoadPlanFiles(files, &o).ok());
  ASSERT_EQ(o.fixed_stations.size(), 2u);
  EXPECT_EQ(o.fixed_stations[0], WorldPoint(1, 2, 1.5));
  EXPECT_EQ(o.fixed_stations[1], WorldPoint(-4, 0.5, 1.7));

  e57[1500] ^= 1;
  files.fixed_stations = WriteTemp("damaged.e57", e57);
  const Status s = client::LoadPlanFiles(files, &o).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("damaged.e57: E57 page 1"), std::string::npos) << s.message();
}

// --fixed-stations takes a pose table with a header and extra columns (3DTK-style), its rows in
// order; every other source is tested with vc::ParseStationFile (tests/core/scene/station_file_test.cc).
TEST(ListParametersTest, FixedStationsFromAPoseCsvWithAHeader) {
  client::PlanFileFlags files;
  files.fixed_stations = WriteTemp("poses.csv", "name,x,y,z,roll,pitch,yaw\ns1,1,2,1.5,0,0,90\ns2,-4,0.5,1.7,1,2,3\n");
  PlanOptions o;
  const Status s = client::LoadPlanFiles(files, &o).status();
  ASSERT_TRUE(s.ok()) << s.ToString();
  ASSERT_EQ(o.fixed_stations.size(), 2u);
  EXPECT_EQ(o.fixed_stations[0], WorldPoint(1, 2, 1.5));
  EXPECT_EQ(o.fixed_stations[1], WorldPoint(-4, 0.5, 1.7));
}

TEST(ListParametersTest, StationsCarryFixedAndTheHeatMapItsFloorsOverTheWire) {
  PlannedStation s;
  s.fixed = true;
  EXPECT_TRUE(wire::FromProto(wire::ToProto(s, WorldPoint::Zero())).fixed);
  s.fixed = false;
  EXPECT_FALSE(wire::FromProto(wire::ToProto(s, WorldPoint::Zero())).fixed);
  HeatMap h;
  h.positions = {{0, 0, 1.5}, {1, 0, 1.9}};
  h.visible_voxels = {1, 2};
  h.floor_z_m = {0, 0.3};
  const std::vector<v1::HeatMapChunk> chunks = wire::HeatMapChunks(h, WorldPoint::Zero());
  ASSERT_EQ(chunks.size(), 1u);
  ASSERT_EQ(chunks[0].floor_z_m_size(), 2);
  EXPECT_EQ(chunks[0].floor_z_m(1), 0.3);
}

TEST(ListParametersTest, BadFilesAndZonesAreRefusedNamingWhere) {
  PlanOptions o;
  client::PlanFileFlags files;
  files.keep_out = WriteTemp("bad_keep_out.csv", "box,0,0,0,1,1,1\nbox,0,0,0,1,1\n");
  Status s = client::LoadPlanFiles(files, &o).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("bad_keep_out.csv:2"), std::string::npos) << s.message();
  files.keep_out = ::testing::TempDir() + "/no_such_file.csv";
  EXPECT_EQ(client::LoadPlanFiles(files, &o).status().code(), StatusCode::kNotFound);
  files = {};
  files.fixed_stations = WriteTemp("bad_fixed.csv", "1,2,3\n1,2\n");
  s = client::LoadPlanFiles(files, &o).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("bad_fixed.csv:2"), std::string::npos) << s.message();
  // A zone without a shape on the wire, and bad values the server's Validate refuses.
  v1::PlanParameters p;
  p.add_keep_out();
  EXPECT_EQ(wire::FromProto(p).status().code(), StatusCode::kInvalidArgument);
  p.clear_keep_out();
  v1::KeepOutPolygon* poly = p.add_keep_out()->mutable_polygon();
  poly->set_z_min_m(0);
  poly->set_z_max_m(1);
  poly->add_xy_m(0);
  poly->add_xy_m(0);
  Result<PlanOptions> two = wire::FromProto(p);
  ASSERT_TRUE(two.ok());
  s = two->Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("keep_out[0]"), std::string::npos) << s.message();
  // A bad height names the entry.
  CLI::App app;
  PlanOptions h;
  client::AddPlanFlags(&app, &h);
  app.parse("--tripod-heights 1.5,0.1", false);
  s = h.Validate();
  EXPECT_NE(s.message().find("tripod_heights_m[1]"), std::string::npos) << s.message();
}

// What vc-client checks before it uploads, with the server's rules (PlanOptions::Validate), in
// the words of its command line: flags, units, the keep-out file's lines, a list's entries.
TEST(PlanFlagNamerTest, TheServersRulesInTheUsersWords) {
  PlanOptions o;
  CLI::App app;
  client::AddPlanFlags(&app, &o);
  app.parse("--max-range -5", false);
  EXPECT_EQ(o.Validate(client::PlanFlagNamer()), InvalidArgumentError("--max-range must be > 0 m, got -5"));
  EXPECT_EQ(o.Validate(), InvalidArgumentError("scanner.max_range_m must be > 0 m, got -5"));  // the server's

  PlanOptions c;
  c.clearance_m = 2;
  EXPECT_EQ(c.Validate(client::PlanFlagNamer()).message(),
            "--clearance (2 m) must be smaller than --tripod-height (1.5 m): the scanner would touch the floor");
  c = PlanOptions{};
  c.tripod_heights_m = {1.5, 0.1};
  EXPECT_EQ(c.Validate(client::PlanFlagNamer())
                .message()
                .rfind("--tripod-heights value 2 (0.1 m) must be larger than "
                       "--clearance (0.2 m)",
                       0),
            0u);
  c = PlanOptions{};
  c.scanner.min_range_m = 9;
  c.scanner.max_range_m = 8;
  EXPECT_EQ(c.Validate(client::PlanFlagNamer()).message(), "--max-range (8 m) must be greater than --min-range (9 m)");
  c = PlanOptions{};
  c.route_start = WorldPoint(std::nan(""), 0, 0);
  EXPECT_EQ(c.Validate(client::PlanFlagNamer()).message().rfind("--start needs finite x and y", 0), 0u);
}

TEST(PlanFlagNamerTest, AKeepOutConflictIsNamedByFlagAndLine) {
  client::PlanFileFlags files;
  files.keep_out =
      WriteTemp("conflict_zones.csv", "xmin,ymin,zmin,xmax,ymax,zmax\n# the crane\n0,0,0,1,1,3\n5,5,0,6,6,3\n");
  files.fixed_stations = WriteTemp("conflict_fixed.csv", "x,y,z\n10,10,1.5\n5.5,5.5,1.5\n");
  PlanOptions o;
  Result<client::PlanFileLines> lines = client::LoadPlanFiles(files, &o);
  ASSERT_TRUE(lines.ok()) << lines.status().ToString();
  EXPECT_EQ(lines->keep_out, (std::vector<size_t>{3, 4}));
  EXPECT_EQ(o.Validate(client::PlanFlagNamer(*lines)).message(),
            "--keep-out line 4: --fixed-stations " + files.fixed_stations + ":3 (5.5, 5.5, 1.5) lies inside this zone");
  EXPECT_EQ(o.Validate().message(), "keep_out[1]: fixed_stations[1] (5.5, 5.5, 1.5) lies inside this zone");
  o.keep_out[0].min.x() = 2;  // a zone the wire could carry: min above max
  EXPECT_EQ(o.Validate(client::PlanFlagNamer(*lines)).message(), "--keep-out line 3: box xmin (2) exceeds xmax (1)");
}

// The server checks fixed stations against the scene (outside its bounds, inside an occupied
// voxel) and names them by their place; vc-client names the file and line they came from.
TEST(PlanFlagNamerTest, TheServersMessagesAboutAFixedStationNameItsFileAndLine) {
  client::PlanFileFlags files;
  files.fixed_stations = WriteTemp("far_fixed.csv", "# scanned last week\nx,y,z\n1,1,1.5\n\n900,1,1.5\n");
  PlanOptions o;
  Result<client::PlanFileLines> lines = client::LoadPlanFiles(files, &o);
  ASSERT_TRUE(lines.ok()) << lines.status().ToString();
  EXPECT_EQ(lines->fixed_stations,
            (std::vector<std::string>{files.fixed_stations + ":3", files.fixed_stations + ":5"}));
  const std::string server =
      "fixed_stations[1] (station 2 of the file, at 900, 1, 1.5) lies outside the scene's bounds (x -2..30 m)";
  EXPECT_EQ(client::NameListEntries(server, client::PlanFlagNamer(*lines)),
            "--fixed-stations " + files.fixed_stations +
                ":5 (station 2 of the file, at 900, 1, 1.5) lies outside the scene's bounds (x -2..30 m)");
  // Brackets that are no list entry, and entries past the file's, stay as they are or by place.
  EXPECT_EQ(client::NameListEntries("voxel [3] of keep_out[0] and fixed_stations[7]", client::PlanFlagNamer(*lines)),
            "voxel [3] of --keep-out zone 1 and --fixed-stations station 8");
}

TEST(ListParametersTest, StartIsXYOrXYZAndAnythingElseIsRefused) {
  auto load = [](const std::string& start, PlanOptions* o) {
    client::PlanFileFlags files;
    CLI::App app;
    client::AddPlanFileFlags(&app, &files);
    app.parse("--start " + start, false);
    return client::LoadPlanFiles(files, o).status();
  };
  PlanOptions o;
  ASSERT_TRUE(load("1.5,-2", &o).ok());
  ASSERT_TRUE(o.route_start.has_value());
  EXPECT_EQ(o.route_start->x(), 1.5);
  EXPECT_EQ(o.route_start->y(), -2.0);
  EXPECT_TRUE(std::isnan(o.route_start->z()));  // the lowest floor
  EXPECT_TRUE(o.Validate().ok());
  ASSERT_TRUE(load("1,2,3.25", &o).ok());
  EXPECT_EQ(*o.route_start, WorldPoint(1, 2, 3.25));
  for (const char* bad : {"1", "1,2,3,4", "1,,2", "a,b", "1,nan", "1,2,inf"}) {
    PlanOptions b;
    const Status s = load(bad, &b);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(s.message().find("--start"), std::string::npos) << s.message();
  }
  // Over the wire and in plan.json (z NaN is null there).
  ASSERT_TRUE(load("1.5,-2", &o).ok());
  Result<PlanOptions> back = wire::FromProto(wire::ToProto(o));
  ASSERT_TRUE(back.ok());
  ASSERT_TRUE(back->route_start.has_value());
  EXPECT_TRUE(std::isnan(back->route_start->z()));
  PlanResult r;
  r.options = o;
  EXPECT_EQ(json::parse(PlanToJson(r))["parameters"]["route_start"], json::parse("[1.5, -2.0, null]"));
}

TEST(ParameterTablesTest, UnknownEnumNamesAreRefusedByTheFlag) {
  PlanOptions o;
  CLI::App app;
  client::AddPlanFlags(&app, &o);
  EXPECT_THROW(app.parse("--test visible", false), CLI::ValidationError);
  EXPECT_EQ(o.selection_test, SelectionTest::kSurfaceVisibility);
  EXPECT_THROW(app.parse("--solver cplex", false), CLI::ValidationError);
  EXPECT_EQ(o.solver, SelectionSolver::kAuto);
  EXPECT_THROW(app.parse("--ground hills", false), CLI::ValidationError);
  EXPECT_EQ(o.ground, GroundModel::kAuto);
}

TEST(ParameterTablesTest, TheGroundFlagTakesEachModelAndPlanJsonNamesIt) {
  for (const auto& [flag, model] :
       {std::pair{"floors", GroundModel::kFloors}, std::pair{"terrain", GroundModel::kTerrain},
        std::pair{"auto", GroundModel::kAuto}}) {
    PlanOptions o;
    CLI::App app;
    client::AddPlanFlags(&app, &o);
    app.parse(std::string("--ground ") + flag, false);
    EXPECT_EQ(o.ground, model) << flag;
    PlanResult r;
    r.options = o;
    EXPECT_EQ(json::parse(PlanToJson(r))["parameters"]["ground"], flag);
  }
}

// --scanner NAME: the preset fills every scanner row whose flag is not given; a given flag wins,
// even when it gives the row's default.
// --min-gain-voxels-per-minute alone takes the place of the default area rule; both > 0, in
// either order, is refused naming both flags.
TEST(GainRuleFlagsTest, TheVoxelRuleAloneReplacesTheAreaRuleAndBothAreRefused) {
  PlanOptions alone;
  CLI::App alone_app;
  client::AddPlanFlags(&alone_app, &alone);
  alone_app.parse("--min-gain-voxels-per-minute 50", false);
  EXPECT_EQ(alone.min_gain_voxels_per_minute, 50);
  EXPECT_EQ(alone.min_gain_m2_per_minute, 0.0);
  EXPECT_TRUE(alone.Validate(client::PlanFlagNamer()).ok());
  for (const std::string args : {"--min-gain-voxels-per-minute 50 --min-gain-m2-per-minute 0.5",
                                 "--min-gain-m2-per-minute 0.5 --min-gain-voxels-per-minute 50"}) {
    PlanOptions both;
    CLI::App both_app;
    client::AddPlanFlags(&both_app, &both);
    both_app.parse(args, false);
    EXPECT_EQ(both.min_gain_m2_per_minute, 0.5) << args;
    EXPECT_EQ(both.Validate(client::PlanFlagNamer())
                  .message()
                  .rfind("--min-gain-voxels-per-minute (50) and --min-gain-m2-per-minute (0.5) are both set", 0),
              0u)
        << both.Validate(client::PlanFlagNamer()).message();
  }
  PlanOptions area_off;
  CLI::App off_app;
  client::AddPlanFlags(&off_app, &area_off);
  off_app.parse("--min-gain-m2-per-minute 0 --min-gain-voxels-per-minute 50", false);
  EXPECT_TRUE(area_off.Validate(client::PlanFlagNamer()).ok());
}

TEST(ScannerPresetFlagTest, ThePresetFillsTheRowsAndExplicitFlagsOverrideIt) {
  ScannerModel want = *ScannerFromPreset("leica-rtc360");
  want.max_range_m = 40.0;
  PlanOptions plan;
  CLI::App plan_app;
  client::AddPlanFlags(&plan_app, &plan);
  plan_app.parse("--scanner leica-rtc360 --max-range 40", false);
  EvaluateJobOptions eval;
  CLI::App eval_app;  // as vc-client has it: a subcommand
  client::AddEvaluateFlags(eval_app.add_subcommand("evaluate"), &eval);
  eval_app.parse("evaluate --scanner leica-rtc360 --max-range 40", false);
  for (const ScannerModel* got : {&plan.scanner, &eval.scanner}) {
    EXPECT_EQ(got->name, "leica-rtc360");
#define VC_EXPECT_ROW_EQ(type, name, ...) EXPECT_EQ(got->name, want.name) << #name;
    VC_SCANNER_PARAMETERS(VC_EXPECT_ROW_EQ)
#undef VC_EXPECT_ROW_EQ
  }
}

TEST(ScannerPresetFlagTest, AFlagGivenAtItsDefaultStillOverridesThePreset) {
  const ScannerModel defaults;
  const ScannerModel preset = *ScannerFromPreset("zf-imager-5016");
  ASSERT_NE(preset.min_range_m, defaults.min_range_m);
  PlanOptions given;
  CLI::App app;
  client::AddPlanFlags(&app, &given);
  app.parse("--scanner zf-imager-5016 --min-range " + std::to_string(defaults.min_range_m), false);
  EXPECT_EQ(given.scanner.min_range_m, defaults.min_range_m);
  PlanOptions not_given;
  CLI::App app2;
  client::AddPlanFlags(&app2, &not_given);
  app2.parse("--scanner zf-imager-5016", false);
  EXPECT_EQ(not_given.scanner.min_range_m, preset.min_range_m);
  EXPECT_EQ(not_given.scanner.max_range_m, preset.max_range_m);
}

TEST(ScannerPresetFlagTest, WithoutScannerTheModelIsCustom) {
  PlanOptions o;
  CLI::App app;
  client::AddPlanFlags(&app, &o);
  app.parse("--max-range 40", false);
  EXPECT_TRUE(o.scanner.name.empty());
  EXPECT_EQ(o.scanner.max_range_m, 40.0);
  EXPECT_EQ(o.scanner.min_range_m, ScannerModel{}.min_range_m);
}

TEST(ScannerPresetFlagTest, AnUnknownPresetIsRefusedByTheFlag) {
  EvaluateJobOptions o;
  CLI::App app;
  client::AddEvaluateFlags(&app, &o);
  EXPECT_THROW(app.parse("--scanner leica-p50", false), CLI::ValidationError);
}

// What the client sends: the name and every field, which the server takes as they are.
TEST(ScannerPresetFlagTest, TheResolvedModelCrossesTheWireAsItIs) {
  PlanOptions o;
  CLI::App app;
  client::AddPlanFlags(&app, &o);
  app.parse("--scanner trimble-x7 --vfov-min -30", false);
  const v1::PlanParameters p = wire::ToProto(o);
  EXPECT_EQ(p.scanner().name(), "trimble-x7");
  EXPECT_TRUE(p.scanner().has_max_range_m());
  const Result<PlanOptions> back = wire::FromProto(p);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->scanner.name, "trimble-x7");
  EXPECT_EQ(back->scanner.vfov_min_deg, -30.0);
  EXPECT_EQ(back->scanner.max_range_m, FindScannerPreset("trimble-x7")->model.max_range_m);
}

TEST(ScannerPresetFlagTest, PlanJsonNamesThePresetOrNull) {
  PlanResult r;
  EXPECT_TRUE(json::parse(PlanToJson(r))["parameters"]["scanner"]["name"].is_null());
  r.options.scanner = *ScannerFromPreset("riegl-vz-400i");
  const json scanner = json::parse(PlanToJson(r))["parameters"]["scanner"];
  EXPECT_EQ(scanner["name"], "riegl-vz-400i");
  EXPECT_EQ(scanner["vfov_max_deg"], 60.0);
}

TEST(ScannerPresetFlagTest, TheScannersTableListsEveryPreset) {
  const std::string table = client::ScannerPresetsTable();
  size_t lines = 0;
  for (char c : table) lines += c == '\n';
  EXPECT_EQ(lines, ScannerPresets().size() + 1);  // a header line
  for (const ScannerPreset& p : ScannerPresets()) {
    EXPECT_NE(table.find(std::string(p.name) + " "), std::string::npos) << p.name;
    EXPECT_NE(table.find(p.display_name), std::string::npos) << p.display_name;
    EXPECT_NE(table.find(p.setting), std::string::npos) << p.setting;
  }
}

}  // namespace
}  // namespace vc
