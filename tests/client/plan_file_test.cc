// evaluate --plan: plan.json read for its stations, scanner, resolution and CRS; each malformed file refused
// naming the field.
#include "vc/client/plan_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "vc/client/parameter_flags.h"

namespace vc::client {
namespace {

// A plan.json as PlanToJson writes it, cut to what an evaluation reads.
constexpr const char* kPlan = R"({
  "schema": "vc.plan/1",
  "crs": {"definition": "EPSG:25832", "name": "ETRS89 / UTM zone 32N"},
  "resolution_m": 0.1,
  "viewpoints": [{"x": 1.5, "y": 2.0, "z": 1.6}, {"x": -3.0, "y": 4.25, "z": 2.1}],
  "parameters": {"scanner": {"min_range_m": 0.6, "max_range_m": 10.0, "vfov_min_deg": null, "vfov_max_deg": null,
    "max_incidence_deg": 80.0, "angular_step_deg": null, "max_spacing_m": null, "hfov_deg": null, "name": null}}
})";

Status ParseError(const std::string& text) { return ParsePlanForEvaluation(text, "p/plan.json").status(); }

TEST(PlanFile, ReadsStationsScannerAndCrs) {
  Result<PlanForEvaluation> plan = ParsePlanForEvaluation(kPlan, "plan.json");
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  ASSERT_EQ(plan->stations.size(), 2u);
  EXPECT_EQ(plan->stations[1], WorldPoint(-3.0, 4.25, 2.1));
  EXPECT_EQ(plan->scanner.min_range_m, 0.6);
  EXPECT_EQ(plan->scanner.max_range_m, 10.0);
  EXPECT_EQ(plan->scanner.max_incidence_deg, 80.0);
  EXPECT_EQ(plan->scanner.vfov_min_deg, -90.0);  // null: the limit is off
  EXPECT_EQ(plan->scanner.hfov_deg, 360.0);
  EXPECT_EQ(plan->scanner.name, "");
  EXPECT_EQ(plan->crs_definition, "EPSG:25832");
  EXPECT_EQ(plan->resolution_m, 0.1);
}

TEST(PlanFile, MissingOrNonPositiveResolutionIsNamed) {
  std::string text = kPlan;
  const std::string row = "\"resolution_m\": 0.1,";
  const size_t at = text.find(row);
  ASSERT_NE(at, std::string::npos);
  std::string without = text;
  without.erase(at, row.size());
  EXPECT_NE(ParseError(without).message().find("p/plan.json: no resolution_m"), std::string::npos)
      << ParseError(without).message();
  std::string zero = text;
  zero.replace(at, row.size(), "\"resolution_m\": 0,");
  EXPECT_NE(ParseError(zero).message().find("resolution_m is not positive"), std::string::npos)
      << ParseError(zero).message();
}

TEST(PlanFile, NotJsonIsRefusedNamingTheFile) {
  const Status s = ParseError("x,y,z\n1,2,3\n");
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("p/plan.json: not JSON"), std::string::npos) << s.message();
}

TEST(PlanFile, OtherSchemaIsRefused) {
  const Status s = ParseError(R"({"schema": "vc.evaluation/1"})");
  EXPECT_NE(s.message().find("schema is not \"vc.plan/1\""), std::string::npos) << s.message();
}

TEST(PlanFile, MissingCoordinateIsNamed) {
  std::string text = kPlan;
  text.replace(text.find("\"z\": 2.1"), 8, "\"q\": 2.1");
  const Status s = ParseError(text);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("p/plan.json: no viewpoints[1].z"), std::string::npos) << s.message();
}

TEST(PlanFile, NonNumericScannerRowIsNamed) {
  std::string text = kPlan;
  text.replace(text.find("10.0"), 4, "\"ten\"");
  const Status s = ParseError(text);
  EXPECT_NE(s.message().find("parameters.scanner.max_range_m is not a number"), std::string::npos) << s.message();
}

TEST(PlanFile, MissingScannerRowIsNamed) {
  std::string text = kPlan;
  text.replace(text.find("\"min_range_m\""), 13, "\"min_range\"");
  const Status s = ParseError(text);
  EXPECT_NE(s.message().find("no parameters.scanner.min_range_m"), std::string::npos) << s.message();
}

TEST(PlanFile, PlanWithoutStationsIsRefused) {
  const Status s = ParseError(R"({"schema": "vc.plan/1", "viewpoints": []})");
  EXPECT_NE(s.message().find("viewpoints is empty"), std::string::npos) << s.message();
}

TEST(PlanFile, UnreadableFileIsNotFound) {
  const Result<PlanForEvaluation> plan = LoadPlanForEvaluation("/nonexistent/plan.json");
  EXPECT_EQ(plan.status().code(), StatusCode::kNotFound);
  EXPECT_NE(plan.status().message().find("/nonexistent/plan.json"), std::string::npos);
}

// The evaluate command's flags, parsed from `args`, with the plan's scanner taken.
struct Taken {
  EvaluateJobOptions options;
  std::vector<std::string> differ;
};
Taken TakeWith(std::vector<std::string> args) {
  CLI::App app;
  Taken t;
  AddEvaluateFlags(&app, &t.options);
  std::reverse(args.begin(), args.end());
  app.parse(args);
  const PlanForEvaluation plan = *ParsePlanForEvaluation(kPlan, "plan.json");
  t.differ = TakeScannerFromPlan(app, plan.scanner, &t.options.scanner);
  for (std::string& line : TakeResolutionFromPlan(app, plan.resolution_m, &t.options.resolution_m)) {
    t.differ.push_back(std::move(line));
  }
  return t;
}

TEST(PlanFile, ScannerComesFromThePlanWithoutFlags) {
  const Taken t = TakeWith({});
  EXPECT_EQ(t.options.scanner.max_range_m, 10.0);
  EXPECT_EQ(t.options.scanner.min_range_m, 0.6);
  EXPECT_EQ(t.options.scanner.max_incidence_deg, 80.0);
  EXPECT_TRUE(t.differ.empty());
}

TEST(PlanFile, GivenFlagOverridesThePlanAndIsNoted) {
  const Taken t = TakeWith({"--max-range", "30", "--min-range", "0.6"});
  EXPECT_EQ(t.options.scanner.max_range_m, 30.0);
  EXPECT_EQ(t.options.scanner.max_incidence_deg, 80.0);
  ASSERT_EQ(t.differ.size(), 1u);  // --min-range equals the plan's
  EXPECT_EQ(t.differ[0], "--max-range 30 m (the plan: 10 m)");
}

TEST(PlanFile, ResolutionComesFromThePlanUnlessTheFlagOverridesIt) {
  EXPECT_EQ(TakeWith({}).options.resolution_m, 0.1);
  const Taken same = TakeWith({"--resolution", "0.1"});
  EXPECT_EQ(same.options.resolution_m, 0.1);
  EXPECT_TRUE(same.differ.empty());
  const Taken t = TakeWith({"--resolution", "0.25"});
  EXPECT_EQ(t.options.resolution_m, 0.25);
  ASSERT_EQ(t.differ.size(), 1u);
  EXPECT_EQ(t.differ[0], "--resolution 0.25 m (the plan: 0.1 m)");
}

}  // namespace
}  // namespace vc::client
