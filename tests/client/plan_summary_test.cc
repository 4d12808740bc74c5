// What vc-client prints after a plan: durations, the station table's route column, the scan graph,
// the route (parts marked "//"), the field time, and the optimality line for each status (none for
// a greedy plan without a bound) with the local-candidates line before it.
#include "vc/client/plan_summary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace vc::client {
namespace {

TEST(PlanSummaryTest, DurationsReadAsACrewReadsThem) {
  EXPECT_EQ(FormatDuration(0), "0 s");
  EXPECT_EQ(FormatDuration(44.6), "45 s");
  EXPECT_EQ(FormatDuration(90), "2 min");
  EXPECT_EQ(FormatDuration(59 * 60), "59 min");
  EXPECT_EQ(FormatDuration(3600 + 5 * 60), "1 h 05 min");
  EXPECT_EQ(FormatDuration(std::numeric_limits<double>::quiet_NaN()), "?");
}

PlanResult ThreeStations() {
  PlanResult r;
  for (int k = 0; k < 3; ++k) r.stations.push_back({WorldPoint(k, 0, 1.5), 10, 5, 0.5 + 0.2 * k, 0.1, k});
  r.coverable_voxels = 20;
  r.covered_voxels = 20;
  r.scan_graph.min_overlap = 0.3;
  r.scan_graph.connected = false;
  r.scan_graph.components = {{0, 2}, {1}};
  r.scan_graph.edges = {{0, 2, 0.5}, {0, 1, 0.1}};
  r.route.order = {2, 0, 1};
  r.route.legs_m = {0, 2.0, std::numeric_limits<double>::quiet_NaN()};
  r.route.polylines = {{}, {WorldPoint(2, 0, 0), WorldPoint(0, 0, 0)}, {}};
  r.route.length_m = 2.0;
  r.route.parts = 2;
  r.field_time = {360, 78, 2, 440, 26};
  r.warnings = {"w1"};
  return r;
}

TEST(PlanSummaryTest, StationsScanGraphRouteAndFieldTime) {
  const std::string s = PlanSummary(ThreeStations());
  EXPECT_NE(s.find("3 station(s), coverage 100.0% of 20 coverable voxels"), std::string::npos) << s;
  EXPECT_NE(s.find("walk"), std::string::npos);
  // Station 3 (index 2) is walked first.
  EXPECT_NE(s.find("90.0%      1\n"), std::string::npos) << s;
  EXPECT_NE(s.find("scan graph: 1 pairs overlap by 30% or more, 2 groups no chain links: [1 3] [2]"), std::string::npos)
      << s;
  EXPECT_NE(s.find("route: 3 -> 1 // 2"), std::string::npos) << s;
  EXPECT_NE(s.find("walking 2.0 m in 2 parts"), std::string::npos) << s;
  EXPECT_NE(s.find("field time: 7 min (set-up 6 min, scans 1 min, walking 2 s)"), std::string::npos) << s;
  EXPECT_EQ(s.find("no scan time known"), std::string::npos);
  EXPECT_NE(s.find("warning: w1\n"), std::string::npos);
}

// The ground model's line says which the candidates used and why; none for user candidates.
TEST(PlanSummaryTest, TheGroundLineSaysWhichModelAndWhy) {
  PlanResult r = ThreeStations();
  EXPECT_EQ(PlanSummary(r).find("ground:"), std::string::npos);
  r.ground.model = GroundModel::kTerrain;
  r.ground.reason = "terrain: only 15% of the walkable ground's surfaces lie within 0.2 m of 3 floor levels";
  EXPECT_NE(PlanSummary(r).find("\nground: terrain: only 15% of the walkable ground's surfaces lie within 0.2 m of 3 "
                                "floor levels (--ground)\n"),
            std::string::npos)
      << PlanSummary(r);
}

// A crew reads the first figure: the share of the whole scene, then that of what any candidate can
// see, and how much no candidate sees.
TEST(PlanSummaryTest, TheHeadlineIsTheShareOfTheWholeScene) {
  PlanResult r = ThreeStations();
  r.occupied_voxels = 80;
  r.coverable_voxels = 20;
  r.covered_voxels = 19;
  const std::string s = PlanSummary(r);
  EXPECT_EQ(s.substr(0, s.find('\n')),
            "3 station(s) see 23.8% of the scene (19 of 80 occupied voxels), global visibility G = 0.000")
      << s;
  EXPECT_NE(
      s.find("\n  95.0% of the 20 voxels some candidate can see; 60 (75.0% of the scene) no candidate sees at all"),
      std::string::npos)
      << s;
  EXPECT_EQ(s.find("unseen:"), std::string::npos) << s;  // no breakdown sent
  r.unseen_causes.hidden = 40;
  r.unseen_causes.interior = 15;
  r.unseen_causes.outside_field_of_view = 5;
  r.unseen_causes.faces_away = 15;
  EXPECT_NE(PlanSummary(r).find("\n  unseen: 40 hidden behind other surfaces from every candidate (a finer grid or "
                                "your own candidates); 15 facing away from every candidate (undersides, outer walls: "
                                "a station on that side); 15 inside solid matter, seen from nowhere; 5 outside the "
                                "vertical field of view (another tripod height)\n"),
            std::string::npos)
      << PlanSummary(r);
  r.occupied_voxels = 20;  // everything occupied is coverable: no third figure
  r.unseen_causes = {};
  EXPECT_EQ(PlanSummary(r).find("no candidate sees"), std::string::npos);
}

TEST(PlanSummaryTest, StationsAndTheRouteStartAreInTheInputsFrame) {
  PlanResult r = ThreeStations();
  r.frame_origin_m = WorldPoint(512000, 5612000, 0);
  r.stations[1].position = WorldPoint(345.457, 330.123, 1.6);
  r.route.start = WorldPoint(1, 2, 0);
  const std::string s = PlanSummary(r);
  EXPECT_NE(s.find("512345.457 5612330.123      1.600"), std::string::npos) << s;
  EXPECT_NE(s.find("route: start (512001.00, 5612002.00) -> 3"), std::string::npos) << s;
}

TEST(PlanSummaryTest, WithoutAScanTimeTheFieldTimeLineSaysSo) {
  PlanResult r = ThreeStations();
  r.field_time.scan_seconds_per_station = 0;
  r.route.start = WorldPoint(1, 1, 0);
  const std::string s = PlanSummary(r);
  EXPECT_NE(s.find("no scan time known: pass --scan-seconds or --scanner"), std::string::npos) << s;
  EXPECT_NE(s.find("route: start (1.00, 1.00) -> 3"), std::string::npos) << s;
}

// A known plan: gains 50, 30, 12, 4, 3 of 100 coverable voxels in a scene of 200, 150 s of set-up
// and scan a station.
PlanResult KnownCurve() {
  PlanResult r = ThreeStations();
  r.occupied_voxels = 200;
  r.coverable_voxels = 100;
  r.covered_voxels = 99;
  r.coverage_curve = CoverageCurve({50, 30, 12, 4, 3}, 200, 100, 150);
  return r;
}

TEST(CoverageTableTest, StationsSceneShareAndFieldTimeAtEachLevel) {
  EXPECT_EQ(CoverageTable(KnownCurve()),
            "  coverage   scene  stations  field time (set-up and scans)\n"
            "      80 %   40.0%         2  5 min\n"
            "      90 %   46.0%         3  8 min\n"
            "      95 %   48.0%         4  10 min\n"
            "      99 %   49.5%         5  13 min\n");
  PlanResult shorter = KnownCurve();
  shorter.coverage_curve.resize(2);
  const std::string s = CoverageTable(shorter);
  EXPECT_NE(s.find("      90 %       -         -  not reached by this plan\n"), std::string::npos) << s;
  EXPECT_EQ(CoverageTable(ThreeStations()), "");  // an older server sends no curve
  EXPECT_NE(PlanSummary(KnownCurve()).find("      99 %   49.5%         5  13 min\n"), std::string::npos);
}

// With the per-k bound: the fewest stations any plan over the candidates needs for each level (one
// station's bound, 82, already reaches 80 %; "-" where no bound reaches a level).
TEST(CoverageTableTest, AnyPlanColumnFromThePerKBound) {
  PlanResult r = KnownCurve();
  AddBestCoverage(r.coverage_curve, {BestCoverage{82, 50}, BestCoverage{85, 80}, BestCoverage{93, 92},
                                     BestCoverage{97, 96}, BestCoverage{99, 99}});
  EXPECT_EQ(CoverageTable(r),
            "  coverage   scene  stations   any plan  field time (set-up and scans)\n"
            "      80 %   40.0%         2       >= 1  5 min\n"
            "      90 %   46.0%         3       >= 3  8 min\n"
            "      95 %   48.0%         4       >= 4  10 min\n"
            "      99 %   49.5%         5       >= 5  13 min\n"
            "  (any plan: no plan over these candidates reaches the level with fewer stations)\n");
  r.coverage_curve.resize(4);  // the bound reaches 97 at most: 99 % gets "-"
  EXPECT_NE(CoverageTable(r).find("      99 %       -         -          -  not reached by this plan\n"),
            std::string::npos)
      << CoverageTable(r);
}

// Two fixed stations: no bound for k = 1 (fewer than the fixed ones), the column is still there.
TEST(CoverageTableTest, AnyPlanColumnWhenTheBoundStartsAtTheFixedStations) {
  PlanResult r = KnownCurve();
  AddBestCoverage(r.coverage_curve, {std::nullopt, BestCoverage{85, 80}, BestCoverage{93, 92}, BestCoverage{97, 96},
                                     BestCoverage{99, 99}});
  const std::string s = CoverageTable(r);
  EXPECT_NE(s.find("   any plan  "), std::string::npos) << s;
  EXPECT_NE(s.find("      80 %   40.0%         2       >= 2  5 min\n"), std::string::npos) << s;
}

TEST(StopLineTest, NamesTheRuleThatStoppedTheSelection) {
  PlanResult r = ThreeStations();
  r.stop_reason = StopReason::kTargetReached;
  EXPECT_EQ(StopLine(r), "stopped: target coverage 99 % reached (--target-coverage)\n");
  r.stop_reason = StopReason::kGainRule;
  r.options.min_gain_voxels_per_minute = 10;
  r.options.setup_seconds = 120;
  r.field_time.scan_seconds_per_station = 60;
  EXPECT_EQ(StopLine(r),
            "stopped: gain rule, the next station adds under 30 voxels for its 3 min of set-up and scan "
            "(--min-gain-voxels-per-minute 10)\n");
  r.options.min_gain_voxels_per_minute = 0;
  r.options.min_gain_m2_per_minute = 0.5;
  r.resolution_m = 0.1;
  EXPECT_EQ(StopLine(r),
            "stopped: gain rule, the next station adds under 1.5 m2 of surface (150 voxels at 0.1 m) for its 3 min "
            "of set-up and scan (--min-gain-m2-per-minute 0.5)\n");
  r.stop_reason = StopReason::kMinGain;
  EXPECT_NE(StopLine(r).find("candidates exhausted"), std::string::npos);
  r.stop_reason = StopReason::kExhausted;
  EXPECT_NE(StopLine(r).find("every voxel some candidate sees is covered"), std::string::npos);
  r.stop_reason = StopReason::kMaxStations;
  r.options.max_stations = 4;
  EXPECT_EQ(StopLine(r), "stopped: 4 stations (--max-stations)\n");
  EXPECT_NE(PlanSummary(r).find("stopped: 4 stations"), std::string::npos);
}

TEST(OptimalityLineTest, SaysProvenOptimalOrHowFarFromTheBound) {
  PlanResult r;
  EXPECT_EQ(OptimalityLine(r), "") << "a greedy plan without a bound prints no line";
  r.optimality.solver = "exact";
  r.optimality.status = planner::OptimalityStatus::kOptimal;
  r.optimality.stations = 37;
  r.optimality.lower_bound = 37;
  EXPECT_EQ(OptimalityLine(r), "optimal: 37 stations, proven\n");
  r.optimality.status = planner::OptimalityStatus::kFeasible;
  r.optimality.lower_bound = 32.2;  // a fractional bound rounds up: 33 stations at least
  EXPECT_EQ(OptimalityLine(r), "37 stations, at most 4 more than the optimum (bound 33)\n");
  r.optimality.solver = "greedy+swap";
  r.optimality.status = planner::OptimalityStatus::kHeuristic;
  EXPECT_EQ(OptimalityLine(r), "37 stations (greedy+swap), no bound on the optimum\n");
  EXPECT_NE(PlanSummary(r).find("37 stations (greedy+swap)"), std::string::npos);
}

TEST(OptimalityLineTest, TheLocalCandidatesLoopGetsALineBeforeTheBound) {
  PlanResult r;
  r.optimality.solver = "exact";
  r.optimality.status = planner::OptimalityStatus::kOptimal;
  r.optimality.stations = 3;
  r.optimality.lower_bound = 3;
  r.optimality.local_candidates = {2, 90, {4, 3, 3}, {26912, 26912, 26912}};
  EXPECT_EQ(OptimalityLine(r),
            "local candidates: 90 position(s) in 2 round(s); stations per selection 4 -> 3 -> 3\n"
            "optimal: 3 stations, proven\n");
}

TEST(DistributionLineTest, OnlyAFannedOutPlanGetsOne) {
  PlanResult r;
  EXPECT_EQ(DistributionLine(r), "");
  r.distribution = {3, 31, 2, 3 * 1048576 + 524288};
  EXPECT_EQ(DistributionLine(r), "fanned out: 31 shard(s) on 3 replica(s), 2 retried, 3.5 MiB exchanged\n");
  EXPECT_NE(PlanSummary(r).find("fanned out: 31 shard(s)"), std::string::npos);
}

TEST(TimingLineTest, EachStagesTimeAndPeakMemoryWhereMeasured) {
  PlanResult r;
  EXPECT_EQ(TimingLine(r), "");
  r.timings = {{Stage::kVisibility, 12.345, uint64_t{1536} << 20}, {Stage::kRoute, 0.5, 0}};
  r.total_seconds = 13;
  EXPECT_EQ(TimingLine(r), "stages: visibility 12.35 s (peak 1536 MiB), route 0.50 s; total 13.00 s\n");
  EXPECT_NE(PlanSummary(r).find("stages: visibility 12.35 s"), std::string::npos);
}

}  // namespace
}  // namespace vc::client
