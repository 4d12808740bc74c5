// The whole planner: known-optimum synthetic scenes, reduction against brute-force G(P - T) with
// vc::Evaluate, the real geb079 scan, option validation, cancellation, progress and callbacks.
#include "vc/plan/planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <set>

#include "testing/scenes.h"
#include "testing/test_paths.h"
#include "vc/plan/greedy.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/route.h"
#include "vc/plan/stages.h"
#include "vc/report/plan_report.h"
#include "vc/synth/synth.h"

namespace vc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using testing::Synthetic;

PlanOptions TestOptions() {
  PlanOptions o;
  o.resolution_m = 0.1;
  return o;
}

bool Inside(const WorldPoint& p, const AxisBox& b) {
  return (p.array() >= b.min.array()).all() && (p.array() <= b.max.array()).all();
}

std::string Describe(const PlanResult& r) {
  std::string s = std::to_string(r.stations.size()) + " stations, covered " + std::to_string(r.covered_voxels) + "/" +
                  std::to_string(r.coverable_voxels) + " coverable of " + std::to_string(r.occupied_voxels) +
                  " occupied, " + std::to_string(r.candidate_count) + " candidates, " +
                  std::to_string(r.greedy_stations) +
                  " greedy picks, G = " + std::to_string(r.evaluation.overall.global_visibility) + ", stop " +
                  std::string(StopReasonName(r.stop_reason));
  for (const auto& t : r.timings) s += ", " + std::string(StageName(t.stage)) + " " + std::to_string(t.seconds) + " s";
  for (const auto& w : r.warnings) s += "\n  warning: " + w;
  return s;
}

struct Known {
  const char* spec;
  int stations;
};

class KnownOptimumTest : public ::testing::TestWithParam<Known> {};

TEST_P(KnownOptimumTest, FindsTheOptimumAndAStationInEveryRoom) {
  const Known k = GetParam();
  Result<SceneInfo> info = DescribeScene(k.spec);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->optimum_stations, k.stations);
  // The optimum is the number of stations that see every coverable voxel: plan for all of them
  // (the gain rule would leave comb:5's last 94 voxels, under 1 m^2, to a sixth station).
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  o.min_gain_m2_per_minute = 0;
  Result<PlanResult> r = Plan(Synthetic(k.spec), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ " << k.spec << " ] " << Describe(*r) << "\n";
  EXPECT_EQ(static_cast<int>(r->stations.size()), k.stations);
  EXPECT_EQ(r->covered_voxels, r->coverable_voxels);
  EXPECT_GT(r->coverable_voxels, r->occupied_voxels * 9 / 10);
  for (size_t i = 0; i < info->rooms.size(); ++i) {
    const bool has = std::any_of(r->stations.begin(), r->stations.end(),
                                 [&](const PlannedStation& s) { return Inside(s.position, info->rooms[i]); });
    EXPECT_TRUE(has) << k.spec << ": no station in room " << i;
  }
  ASSERT_FALSE(r->stations.empty());
  EXPECT_DOUBLE_EQ(r->stations.back().cumulative_coverage, 1.0);
  EXPECT_EQ(r->selection_test, SelectionTest::kSurfaceVisibility);
}

// The sloping site (docs/SCENES.md, "slope"): auto picks terrain; every station stands 1.5 m over
// the terrace under it, none on a roof or the van; the route walks the slope in one part.
TEST(PlannerTest, SlopingSitePlansOnTheTerrainWithOneRoute) {
  PlanOptions o = TestOptions();
  o.grid_spacing_m = 2.0;
  o.solver = SelectionSolver::kGreedy;
  Result<PlanResult> r = Plan(Synthetic("slope"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ slope ] " << Describe(*r) << "; " << r->ground.reason << "; route " << r->route.length_m << " m in "
            << r->route.parts << " part(s)\n";
  EXPECT_EQ(r->ground.model, GroundModel::kTerrain) << r->ground.reason;
  EXPECT_TRUE(r->floor_levels_m.empty());
  ASSERT_GE(r->stations.size(), 2u);
  for (const PlannedStation& s : r->stations) {
    const double x = s.position.x() - kSceneOffsetM.x(), y = s.position.y() - kSceneOffsetM.y();
    const bool on_roof = (x > 8 && x < 16 && y > 6 && y < 14) || (x > 24 && x < 32 && y > 16 && y < 24) ||
                         (x > 34 && x < 38.5 && y > 5 && y < 7);
    EXPECT_FALSE(on_roof) << s.position.transpose();
    EXPECT_NEAR(s.floor_z_m, 0.1 * std::floor(x) + kSceneOffsetM.z(), 0.11) << s.position.transpose();
    EXPECT_NEAR(s.position.z() - s.floor_z_m, 1.5, 1e-9);
  }
  EXPECT_EQ(r->route.parts, 1);
  // The roofs are seen from no candidate (14.7 %): the warning names what reaches them on terrain,
  // not "other floor levels", which the terrain does not have (issue 35).
  int uncoverable = 0;
  for (const std::string& w : r->warnings) {
    std::cout << "  warning: " << w << "\n";
    if (w.find("cannot be covered") == std::string::npos) continue;
    ++uncoverable;
    EXPECT_NE(w.find("terrain's walkable ground"), std::string::npos) << w;
    EXPECT_NE(w.find("roofs"), std::string::npos) << w;
    EXPECT_EQ(w.find("floor levels"), std::string::npos) << w;
  }
  EXPECT_EQ(uncoverable, 1);
}

// hillside (docs/SCENES.md): a house cut into a 1:5 slope, its door opening onto it. On terrain
// with doorway candidates, refinement and local candidates over 1-1.5 m (rises of 0.2-0.3 m, more
// than the floor level's band): every station stands at tripod height over the ground of its own
// voxel column (the terrace, or the room's floor through the door), and the route is one walk.
TEST(PlannerTest, HillsideStationsStayOnTheGroundThroughRefinementAndLocalCandidates) {
  PlanOptions o = TestOptions();
  o.solver = SelectionSolver::kGreedy;
  o.refine = true;
  o.refine_radius_m = 1.5;
  o.refine_step_m = 0.5;
  o.local_candidates = true;
  o.local_candidates_radius_m = 1.0;
  o.local_candidates_step_m = 0.5;
  const SceneInput input = Synthetic("hillside");
  Result<PlanResult> r = Plan(input, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ hillside ] " << Describe(*r) << "; " << r->ground.reason << "; route " << r->route.length_m
            << " m in " << r->route.parts << " part(s)\n";
  EXPECT_EQ(r->ground.model, GroundModel::kTerrain) << r->ground.reason;
  const Result<VoxelScene> scene = Voxelize(input, VoxelizeOptions{0.1});
  ASSERT_TRUE(scene.ok());
  ASSERT_GE(r->stations.size(), 2u);
  int moved = 0;
  for (const PlannedStation& s : r->stations) {
    const double x = s.position.x() - kSceneOffsetM.x(), y = s.position.y() - kSceneOffsetM.y();
    const bool in_house = x > 8 && x < 14.3 && y > 4.3 && y < 9.7;  // the room and its door
    const double ground = in_house ? 1.5 : 0.1 * std::floor(x / 0.5);
    std::cout << "  " << (s.position - kSceneOffsetM).transpose() << " floor " << s.floor_z_m - kSceneOffsetM.z()
              << (s.candidate_index < 0 ? " (moved or added)" : "") << "\n";
    EXPECT_NEAR(s.floor_z_m, planner::FloorBelow(scene->grid, s.position), 1e-9) << s.position.transpose();
    EXPECT_NEAR(s.floor_z_m - kSceneOffsetM.z(), ground, 0.11) << s.position.transpose();
    EXPECT_NEAR(s.position.z() - s.floor_z_m, 1.5, 1e-9) << s.position.transpose();
    moved += s.candidate_index < 0;
  }
  EXPECT_GT(moved, 0);
  EXPECT_EQ(r->route.parts, 1);
}

INSTANTIATE_TEST_SUITE_P(Scenes, KnownOptimumTest,
                         ::testing::Values(Known{"box", 1}, Known{"lroom", 1}, Known{"comb:3", 3}, Known{"comb:5", 5}),
                         [](const auto& info) {
                           std::string n = info.param.spec;
                           std::replace(n.begin(), n.end(), ':', '_');
                           return n;
                         });

// --solver exact: the selection is proven optimal on each known-optimum scene, with the optimum's
// station count, and the plan reports it (optimality) with the model sizes before and after.
TEST_P(KnownOptimumTest, ExactSolverProvesTheOptimum) {
  const Known k = GetParam();
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;  // every coverable voxel, as above
  o.min_gain_m2_per_minute = 0;
  o.solver = SelectionSolver::kExact;
  Result<PlanResult> r = Plan(Synthetic(k.spec), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(static_cast<int>(r->stations.size()), k.stations);
  EXPECT_EQ(r->covered_voxels, r->coverable_voxels);
  const planner::Optimality& opt = r->optimality;
  EXPECT_EQ(opt.solver, "exact");
  EXPECT_EQ(opt.status, planner::OptimalityStatus::kOptimal);
  EXPECT_EQ(opt.stations, k.stations);
  EXPECT_EQ(opt.lower_bound, k.stations);
  EXPECT_EQ(opt.gap, 0.0);
  EXPECT_EQ(opt.before.candidates, static_cast<int>(r->candidate_count));
  EXPECT_LE(opt.model.candidates, opt.before.candidates);
  EXPECT_LT(opt.model.voxel_classes, opt.before.voxel_classes);
}

// hub:K (docs/SCENES.md): the optimum 2K needs a station just inside every door, where the 1 m
// grid has none. The exact selector over the grid and the doorway candidates proves it.
TEST(PlannerTest, HubsReachTheirOptimumWithDoorwayCandidatesAndTheExactSolver) {
  for (const char* spec : {"hub:1", "hub:2"}) {
    Result<SceneInfo> info = DescribeScene(spec);
    ASSERT_TRUE(info.ok());
    PlanOptions o = TestOptions();
    o.solver = SelectionSolver::kExact;
    o.doorway_candidates = false;
    Result<PlanResult> grid = Plan(Synthetic(spec), o);
    o.doorway_candidates = true;
    Result<PlanResult> doors = Plan(Synthetic(spec), o);
    ASSERT_TRUE(grid.ok() && doors.ok());
    std::cout << "[ " << spec << ", exact ] " << Describe(*grid) << "\n[ " << spec << ", exact, doorway candidates ] "
              << Describe(*doors) << " (optimum " << info->optimum_stations << ")\n";
    // On the grid alone even the optimum over its candidates is one station over.
    EXPECT_EQ(grid->optimality.status, planner::OptimalityStatus::kOptimal);
    EXPECT_EQ(static_cast<int>(grid->stations.size()), info->optimum_stations + 1);
    EXPECT_EQ(doors->optimality.status, planner::OptimalityStatus::kOptimal);
    EXPECT_EQ(static_cast<int>(doors->stations.size()), info->optimum_stations);
    EXPECT_GE(double(doors->covered_voxels), o.target_coverage * double(doors->coverable_voxels));
  }
}

// Rooms around a hall at the defaults (doorway candidates, --solver auto, the 0.99 target and the
// gain rule; issue 36): hub:K, court:K (doors off-centre and crossed along both axes, rooms at the
// hall's ends), tee (rooms on three sides of a square hall) and the held-out star:K (arms behind
// doors at different positions) and atrium:K (rooms on four sides of an atrium with a pier;
// docs/SCENES.md) reach their optimum, a station in every room and none in the hall, proven
// optimal over the candidates. The plans go to `plans` when given.
void ExpectOptimumAtTheDefaults(std::initializer_list<const char*> specs, std::vector<PlanResult>* plans = nullptr) {
  for (const char* spec : specs) {
    Result<SceneInfo> info = DescribeScene(spec);
    ASSERT_TRUE(info.ok());
    const PlanOptions o = TestOptions();
    ASSERT_TRUE(o.doorway_candidates);
    Result<PlanResult> r = Plan(Synthetic(spec), o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    std::cout << "[ " << spec << ", defaults ] " << Describe(*r) << " (optimum " << info->optimum_stations << ")\n";
    EXPECT_EQ(static_cast<int>(r->stations.size()), info->optimum_stations) << spec;
    EXPECT_EQ(r->optimality.status, planner::OptimalityStatus::kOptimal) << spec;
    EXPECT_EQ(r->optimality.lower_bound, info->optimum_stations) << spec;
    EXPECT_GE(double(r->covered_voxels), o.target_coverage * double(r->coverable_voxels)) << spec;
    for (size_t i = 0; i < info->rooms.size(); ++i) {
      EXPECT_TRUE(std::any_of(r->stations.begin(), r->stations.end(),
                              [&](const PlannedStation& s) { return Inside(s.position, info->rooms[i]); }))
          << spec << ": no station in room " << i;
    }
    if (plans != nullptr) plans->push_back(std::move(*r));
  }
}

TEST(PlannerTest, RoomsAroundAHallReachTheirOptimumAtTheDefaults) {
  ExpectOptimumAtTheDefaults({"hub:1", "court:1", "tee", "star:3", "star:4"});
}

// The same on larger ones (hub:2, hub:3, court:2, atrium:2, atrium:3: 0.2-3 s of selection each in
// release under load; label heavy).
TEST(PlannerTest, LargerRoomsAroundAHallReachTheirOptimumAtTheDefaults) {
  ExpectOptimumAtTheDefaults({"hub:2", "hub:3", "court:2", "atrium:2", "atrium:3"});
}

// hub:6 (issue 36): greedy plans 13 (a hall station first) and no exchange from there reaches 12,
// while CBC's root LP outlasts the 20 s limit under load; the Lagrangian heuristic's plan of 12 is
// proven by the bound, no integer program solved (about 1 s of selection in release; label heavy).
TEST(PlannerTest, LargeHubReachesItsOptimumByTheLagrangianHeuristicAtTheDefaults) {
  std::vector<PlanResult> plans;
  ExpectOptimumAtTheDefaults({"hub:6"}, &plans);
  ASSERT_EQ(plans.size(), 1u);
  const PlanResult* r = &plans[0];
  EXPECT_EQ(r->greedy_stations, 13);
  EXPECT_NE(r->optimality.note.find("Lagrangian heuristic"), std::string::npos) << r->optimality.note;
  EXPECT_NE(r->optimality.note.find("no integer program solved"), std::string::npos) << r->optimality.note;
}

// --local-candidates (docs/PLANNING.md, "Local candidates"): on a 2 m grid the comb's bays are
// seen from no grid position that also sees the neighbouring bay's back wall, so even the optimum
// over the grid (proven by auto) is one station over; solving again over sub-grids around the
// chosen stations reaches the scene's optimum, with the coverage problem unchanged.
TEST(PlannerTest, LocalCandidatesReachTheCombsOptimumWhereA2mGridCannot) {
  for (const char* spec : {"comb:3", "comb:5"}) {
    Result<SceneInfo> info = DescribeScene(spec);
    ASSERT_TRUE(info.ok());
    PlanOptions o = TestOptions();
    o.grid_spacing_m = 2.0;
    o.doorway_candidates = false;  // the bays are passages of a 2 m grid: they would reach the optimum
    Result<PlanResult> grid = Plan(Synthetic(spec), o);
    o.local_candidates = true;
    Result<PlanResult> local = Plan(Synthetic(spec), o);
    ASSERT_TRUE(grid.ok() && local.ok()) << grid.status().ToString() << local.status().ToString();
    std::cout << "[ " << spec << ", 2 m grid ] " << Describe(*grid) << "\n[ " << spec
              << ", 2 m grid, local candidates ] " << Describe(*local) << " (optimum " << info->optimum_stations
              << ")\n";
    EXPECT_EQ(grid->optimality.status, planner::OptimalityStatus::kOptimal);
    EXPECT_EQ(static_cast<int>(grid->stations.size()), info->optimum_stations + 1);
    EXPECT_TRUE(grid->optimality.local_candidates.stations_per_solve.empty());
    EXPECT_EQ(static_cast<int>(local->stations.size()), info->optimum_stations);
    const planner::LocalCandidatesReport& l = local->optimality.local_candidates;
    ASSERT_GE(l.stations_per_solve.size(), 2u);
    EXPECT_EQ(l.stations_per_solve.front(), info->optimum_stations + 1);  // the first solve is the grid's
    EXPECT_EQ(static_cast<int>(l.stations_per_solve.size()), l.rounds + 1);
    EXPECT_GT(l.added, 0);
    // The coverage problem is the grid's: same coverable voxels, the target reached.
    EXPECT_EQ(local->coverable_voxels, grid->coverable_voxels);
    EXPECT_GE(double(local->covered_voxels), o.target_coverage * double(local->coverable_voxels));
    EXPECT_EQ(local->candidate_count, grid->candidate_count);  // the grid's; added positions are not counted
    int off_grid = 0;
    for (const PlannedStation& ps : local->stations) off_grid += ps.candidate_index < 0;
    EXPECT_GT(off_grid, 0) << "no station at an added position";
  }
}

// Coarse then fine (docs/PLANNING.md, "Coarse then fine candidates"): above
// coarse_above_candidates the plan selects over the grid of twice the spacing, then once more with
// the grid's positions around its picks; at the threshold the plan is the full grid's, the same as
// with the rule off.
TEST(PlannerTest, CoarseThenFineAboveTheThresholdAndTheFullGridAtIt) {
  PlanOptions o = TestOptions();
  o.solver = SelectionSolver::kGreedy;
  o.coarse_above_candidates = 0;
  const SceneInput input = Synthetic("hub:3");
  Result<PlanResult> full = Plan(input, o);
  ASSERT_TRUE(full.ok()) << full.status().ToString();
  const int n = static_cast<int>(full->candidate_count);
  ASSERT_GT(n, 40);

  o.coarse_above_candidates = n;
  Result<PlanResult> at = Plan(input, o);
  ASSERT_TRUE(at.ok()) << at.status().ToString();
  EXPECT_EQ(static_cast<int>(at->candidate_count), n);
  EXPECT_TRUE(at->optimality.local_candidates.coarse_to_fine.empty());
  EXPECT_TRUE(at->optimality.local_candidates.stations_per_solve.empty());
  ASSERT_EQ(at->stations.size(), full->stations.size());
  for (size_t k = 0; k < at->stations.size(); ++k) {
    EXPECT_EQ(at->stations[k].position, full->stations[k].position) << k;
  }
  EXPECT_EQ(at->covered_voxels, full->covered_voxels);
  EXPECT_EQ(at->evaluation.overall.global_visibility, full->evaluation.overall.global_visibility);

  o.coarse_above_candidates = n - 1;
  Result<PlanResult> coarse = Plan(input, o);
  PlanOptions two_m = o;
  two_m.coarse_above_candidates = 0;
  two_m.grid_spacing_m = 2.0;
  Result<PlanResult> grid2 = Plan(input, two_m);
  ASSERT_TRUE(coarse.ok() && grid2.ok()) << coarse.status().ToString() << grid2.status().ToString();
  std::cout << "[ hub:3, 1 m grid ] " << Describe(*full) << "\n[ hub:3, 2 m grid ] " << Describe(*grid2)
            << "\n[ hub:3, coarse then fine ] " << Describe(*coarse) << "\n";
  EXPECT_EQ(coarse->candidate_count, grid2->candidate_count);  // the coarse grid's
  EXPECT_LT(static_cast<int>(coarse->candidate_count), n);
  const planner::LocalCandidatesReport& l = coarse->optimality.local_candidates;
  EXPECT_NE(l.coarse_to_fine.find("the 1 m grid gives " + std::to_string(n) +
                                  " candidates, more than coarse_above_candidates = " + std::to_string(n - 1)),
            std::string::npos)
      << l.coarse_to_fine;
  EXPECT_NE(l.coarse_to_fine.find("the 2 m grid's " + std::to_string(coarse->candidate_count)), std::string::npos)
      << l.coarse_to_fine;
  EXPECT_NE(PlanToJson(*coarse).find("\"coarse_to_fine\""), std::string::npos);
  // One fine round: the 1 m positions around the first solve's picks (8 per pick at most).
  ASSERT_EQ(l.stations_per_solve.size(), 2u);
  EXPECT_EQ(l.rounds, 1);
  EXPECT_GT(l.added, 0);
  EXPECT_LE(l.added, 8 * l.stations_per_solve.front());
  // The fine positions' sets are whole: the coverable set is the coarse grid's and what they add.
  EXPECT_GE(coarse->coverable_voxels, grid2->coverable_voxels);
  EXPECT_GE(double(coarse->covered_voxels), o.target_coverage * double(grid2->coverable_voxels));
}

// The fine round's sets go through PlanCallbacks::visibility_sets as the visibility stage's do
// (vc-server fans both out over its peers): the same plan as computed here, the fine round's shards
// counted in the plan's distribution, and their progress reported as the selection stage's.
TEST(PlannerTest, CoarseThenFineFansOutTheFineRoundsSets) {
  PlanOptions o = TestOptions();
  o.solver = SelectionSolver::kGreedy;
  const SceneInput input = Synthetic("hub:3");
  o.coarse_above_candidates = 0;
  Result<PlanResult> full = Plan(input, o);
  ASSERT_TRUE(full.ok()) << full.status().ToString();
  o.coarse_above_candidates = static_cast<int>(full->candidate_count) - 1;
  Result<PlanResult> here = Plan(input, o);
  ASSERT_TRUE(here.ok()) << here.status().ToString();
  ASSERT_GT(here->optimality.local_candidates.added, 0);

  std::vector<size_t> asked;  // positions per call
  std::vector<std::string> named;
  PlanCallbacks callbacks;
  callbacks.visibility_sets = [&](const VoxelScene& scene, const std::vector<WorldPoint>& positions,
                                  const VisibilitySetsOptions& set_options, const JobContext& ctx,
                                  const char* what) -> Result<DistributedSets> {
    asked.push_back(positions.size());
    named.push_back(what);
    DistributedSets d;
    for (size_t b = 0; b < positions.size(); b += 5) {  // shards of 5, as a fan-out would split them
      const std::vector<WorldPoint> shard(positions.begin() + b, positions.begin() + std::min(b + 5, positions.size()));
      VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> sets, ComputeVisibilitySets(scene, shard, set_options, {}));
      for (VoxelSet& s : sets) d.sets.push_back(std::move(s));
      ++d.distribution.shards;
      // (vc-server's fan-out counts shards done; this one, positions done)
      ctx.ReportCount(Stage::kVisibility, d.sets.size(), positions.size(), "positions");
    }
    d.distribution.replicas = 2;
    return d;
  };
  std::vector<ProgressEvent> events;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
  Result<PlanResult> spread = Plan(input, o, ctx, callbacks);
  ASSERT_TRUE(spread.ok()) << spread.status().ToString();

  ASSERT_EQ(asked.size(), 2u) << "the visibility stage's call, then the fine round's";
  EXPECT_EQ(named, (std::vector<std::string>{"the visibility stage", "the fine round's sets"}));
  EXPECT_EQ(asked[0], here->candidate_count);
  EXPECT_EQ(asked[1], static_cast<size_t>(here->optimality.local_candidates.added));
  EXPECT_EQ(spread->distribution.shards, int((asked[0] + 4) / 5 + (asked[1] + 4) / 5));
  ASSERT_EQ(spread->stations.size(), here->stations.size());
  for (size_t k = 0; k < here->stations.size(); ++k) {
    EXPECT_EQ(spread->stations[k].position, here->stations[k].position) << k;
  }
  EXPECT_EQ(spread->covered_voxels, here->covered_voxels);
  EXPECT_EQ(spread->coverable_voxels, here->coverable_voxels);
  EXPECT_EQ(spread->evaluation.overall.global_visibility, here->evaluation.overall.global_visibility);
  const std::string fine = "local candidates: visibility of " + std::to_string(asked[1]) + " positions";
  const int fine_counts = int(std::count_if(events.begin(), events.end(), [&](const ProgressEvent& e) {
    return e.stage == Stage::kSelection && e.message == fine && e.total == asked[1];
  }));
  EXPECT_EQ(fine_counts, int((asked[1] + 4) / 5)) << "the fine round's shards, counted as the selection stage's";
}

// Coarse then fine short of the target (target_coverage 1: the gain rule stops greedy first): the
// fine round's neighbourhood rule decides which fine positions get a set, and plan.json says how
// many it passed over (docs/PLANNING.md, "Coarse then fine candidates"). At the default target the
// coarse solve of hub:3 reaches it and the rule decides nothing (the test above: no such note).
TEST(PlannerTest, CoarseThenFineShortOfTheTargetPassesOverFinePositionsWithNothingNearToGain) {
  PlanOptions o = TestOptions();
  o.solver = SelectionSolver::kGreedy;
  o.coarse_above_candidates = 10;
  o.target_coverage = 1.0;
  const SceneInput input = Synthetic("hub:3");
  Result<PlanResult> r = Plan(input, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ hub:3, coarse then fine, target 1 ] " << Describe(*r) << "\n";
  const planner::LocalCandidatesReport& l = r->optimality.local_candidates;
  ASSERT_FALSE(l.coarse_to_fine.empty());
  ASSERT_LT(r->covered_voxels, r->coverable_voxels);  // short of the target: the rule applies
  const std::string mark = " fine positions passed over (the candidates within 1 m of each see fewer than ";
  const size_t at = l.coarse_to_fine.find(mark);
  ASSERT_NE(at, std::string::npos) << l.coarse_to_fine;
  // "; N of M fine positions passed over ...": M is what the round considered, N of them got no set.
  const size_t semi = l.coarse_to_fine.rfind("; ", at);
  ASSERT_NE(semi, std::string::npos);
  int passed = -1, considered = -1;
  ASSERT_EQ(std::sscanf(l.coarse_to_fine.c_str() + semi, "; %d of %d", &passed, &considered), 2) << l.coarse_to_fine;
  EXPECT_GT(passed, 0) << l.coarse_to_fine;  // hub:3's rooms are covered: most positions have nothing near to gain
  EXPECT_LE(passed, considered) << l.coarse_to_fine;
  // The gate is the selector's own smallest pick: greedy's gain rule at this resolution.
  int min_gain = 0;
  ASSERT_EQ(std::sscanf(l.coarse_to_fine.c_str() + at + mark.size(), "%d", &min_gain), 1);
  EXPECT_EQ(uint64_t(min_gain), planner::SmallestGainPickedVoxels(planner::SelectorOptionsFor(o, r->resolution_m)));
  EXPECT_GT(min_gain, 1);  // the default gain rule, not the floor of 1
  // The fine round never loses what the coarse solve covered (the loop keeps the better solve).
  ASSERT_FALSE(l.covered_per_solve.empty());
  EXPECT_GE(r->covered_voxels, l.covered_per_solve.front());
}

// Sparse visibility sets (vc/visibility/voxel_set.h) change memory and time, never the plan: with
// every set sparse, each stage that takes sets (greedy and consolidation, the exact solver, local
// candidates, refinement, registration) gives the plan of dense sets.
TEST(PlannerTest, SparseSetsGiveTheSamePlanAsDenseOnes) {
  struct Case {
    const char* spec;
    SelectionSolver solver;
    double min_overlap;
    bool local_candidates, refine;
  };
  // Greedy wherever the solver is not the point: a time-limited solve may differ between two runs.
  for (const Case& c : {Case{"comb:5", SelectionSolver::kGreedy, 0.0, false, true},
                        Case{"comb:3", SelectionSolver::kExact, 0.0, false, false},
                        Case{"comb:3", SelectionSolver::kGreedy, 0.0, true, false},
                        Case{"rooms:3", SelectionSolver::kGreedy, 0.3, false, false}}) {
    PlanOptions o = TestOptions();
    o.solver = c.solver;
    o.min_overlap = c.min_overlap;
    o.local_candidates = c.local_candidates;
    o.refine = c.refine;
    if (c.local_candidates) o.grid_spacing_m = 2.0;
    o.sparse_set_gain = 0;
    Result<PlanResult> dense = Plan(Synthetic(c.spec), o);
    o.sparse_set_gain = 1e-9;  // every set sparse
    Result<PlanResult> sparse = Plan(Synthetic(c.spec), o);
    ASSERT_TRUE(dense.ok() && sparse.ok()) << c.spec << ": " << dense.status().ToString() << sparse.status().ToString();
    SCOPED_TRACE(c.spec);
    ASSERT_EQ(dense->stations.size(), sparse->stations.size());
    for (size_t k = 0; k < dense->stations.size(); ++k) {
      EXPECT_EQ(dense->stations[k].position, sparse->stations[k].position);
      EXPECT_EQ(dense->stations[k].marginal_gain, sparse->stations[k].marginal_gain);
    }
    EXPECT_EQ(dense->covered_voxels, sparse->covered_voxels);
    EXPECT_EQ(dense->coverable_voxels, sparse->coverable_voxels);
    EXPECT_EQ(dense->heat_map.visible_voxels, sparse->heat_map.visible_voxels);
    EXPECT_EQ(dense->evaluation.overall.global_visibility, sparse->evaluation.overall.global_visibility);
    EXPECT_EQ(dense->scan_graph.edges.size(), sparse->scan_graph.edges.size());
    EXPECT_EQ(dense->optimality.status, sparse->optimality.status);
    EXPECT_EQ(dense->optimality.lower_bound, sparse->optimality.lower_bound);
  }
}

// Sparse sets are held to the memory budget as they are computed: a budget they cannot fit in is
// RESOURCE_EXHAUSTED naming what to change, not an allocation failure.
TEST(PlannerTest, SparseSetsOverTheBudgetAreRefusedAsTheyAreKept) {
  const VoxelScene scene = *Voxelize(Synthetic("rooms:3"), {});
  std::vector<WorldPoint> positions;
  for (double x = 1; x < 10; x += 1) positions.emplace_back(x, 2, 1.5);
  VisibilitySetsOptions so;
  so.compact_gain = 1e-9;
  so.batch_bytes = 1;  // one position per batch
  so.max_set_bytes = 1;
  const auto r = ComputeVisibilitySets(scene, positions, so);
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(r.status().message().find("raise grid_spacing_m"), std::string::npos) << r.status().message();
  so.max_set_bytes = 0;
  const auto ok = ComputeVisibilitySets(scene, positions, so);
  ASSERT_TRUE(ok.ok());
  ASSERT_EQ(ok->size(), positions.size());
  const auto dense = ComputeVisibilitySets(scene, positions, VisibilitySetsOptions{});
  ASSERT_TRUE(dense.ok());
  for (size_t k = 0; k < positions.size(); ++k) {
    EXPECT_TRUE((*ok)[k].sparse());
    EXPECT_EQ((*ok)[k].count(), (*dense)[k].count());
    EXPECT_EQ((*ok)[k].CountAnd((*dense)[k]), (*dense)[k].count());
  }
}

// A fixed station with local candidates: it stays first and fixed, the added positions are told
// apart from the grid's candidates (candidate index -1) and from the fixed station.
TEST(PlannerTest, LocalCandidatesWithAFixedStationKeepItFirst) {
  PlanOptions o = TestOptions();
  o.grid_spacing_m = 2.0;
  o.doorway_candidates = false;  // as above: the loop, not the passages, is what is tested
  o.local_candidates = true;
  Result<PlanResult> free = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(free.ok()) << free.status().ToString();
  o.fixed_stations = {free->stations.back().position};  // a station of the free plan, placed first
  Result<PlanResult> r = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ comb:5, 2 m grid, local candidates, 1 fixed ] " << Describe(*r) << "\n";
  ASSERT_FALSE(r->stations.empty());
  EXPECT_TRUE(r->stations[0].fixed);
  EXPECT_EQ(r->stations[0].position, o.fixed_stations[0]);
  EXPECT_EQ(r->stations[0].candidate_index, -1);
  int added = 0;
  for (size_t k = 1; k < r->stations.size(); ++k) {
    const PlannedStation& ps = r->stations[k];
    EXPECT_FALSE(ps.fixed) << k;
    EXPECT_NE(ps.position, o.fixed_stations[0]) << k;
    if (ps.candidate_index >= 0) {
      ASSERT_LT(static_cast<size_t>(ps.candidate_index), r->heat_map.positions.size());
      EXPECT_EQ(ps.position, r->heat_map.positions[ps.candidate_index]) << k;
    } else {
      ++added;
    }
  }
  EXPECT_GT(added, 0);
  EXPECT_LE(r->stations.size(), free->stations.size() + 1);
  EXPECT_GE(double(r->covered_voxels), o.target_coverage * double(r->coverable_voxels));
}

// Without an improvement the loop keeps the first selection: the plan is the one without the loop.
TEST(PlannerTest, LocalCandidatesKeepThePlanWhenNothingImproves) {
  PlanOptions o = TestOptions();
  Result<PlanResult> plain = Plan(Synthetic("rooms:3"), o);
  o.local_candidates = true;
  Result<PlanResult> local = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(plain.ok() && local.ok());
  ASSERT_EQ(local->stations.size(), plain->stations.size());
  for (size_t k = 0; k < plain->stations.size(); ++k) {
    EXPECT_EQ(local->stations[k].position, plain->stations[k].position) << "station " << k;
  }
  EXPECT_EQ(local->evaluation.overall.global_visibility, plain->evaluation.overall.global_visibility);
  EXPECT_EQ(local->optimality.local_candidates.stations_per_solve.front(), static_cast<int>(plain->stations.size()));
  o.local_candidates_step_m = 0.75;  // more than the radius
  EXPECT_EQ(Plan(Synthetic("rooms:3"), o).status().code(), StatusCode::kInvalidArgument);
}

// ALGORITHM.md s.3: a voxel is compatible only within ~45 degrees of its normal, so the paper's
// test needs more stations than the optimum under surface visibility. The counts go to PLANNING.md.
TEST(PlannerTest, CompatibilityNeedsMoreStationsThanSurfaceVisibility) {
  for (const char* spec : {"box", "lroom", "comb:3"}) {
    PlanOptions o = TestOptions();
    o.selection_test = SelectionTest::kCompatibility;
    o.target_coverage = 1.0;       // compare station counts at full coverage,
    o.min_gain_m2_per_minute = 0;  // which the gain rule would stop short of
    Result<PlanResult> r = Plan(Synthetic(spec), o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    std::cout << "[ " << spec << ", compatibility ] " << Describe(*r) << "\n";
    EXPECT_EQ(r->selection_test, SelectionTest::kCompatibility);
    EXPECT_GT(static_cast<int>(r->stations.size()), DescribeScene(spec)->optimum_stations);
    EXPECT_EQ(r->covered_voxels, r->coverable_voxels);
  }
}

TEST(PlannerTest, EveryRoomOfARowOfRoomsGetsAStation) {
  for (int n : {2, 3, 4}) {
    const std::string spec = "rooms:" + std::to_string(n);
    Result<SceneInfo> info = DescribeScene(spec);
    ASSERT_TRUE(info.ok());
    Result<PlanResult> r = Plan(Synthetic(spec), TestOptions());
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    std::cout << "[ " << spec << " ] " << Describe(*r) << " (optimum " << info->optimum_stations << ")\n";
    ASSERT_EQ(static_cast<int>(info->rooms.size()), n + 1);  // the rooms, then the corridor
    for (size_t i = 0; i < info->rooms.size(); ++i) {
      const bool has = std::any_of(r->stations.begin(), r->stations.end(),
                                   [&](const PlannedStation& s) { return Inside(s.position, info->rooms[i]); });
      EXPECT_TRUE(has) << spec << ": no station in room " << i;
    }
    // The plan stops at the target coverage (99 %); the scanner's minimum range leaves a few
    // voxels near walls coverable only from candidates the optimum does not need.
    EXPECT_GE(double(r->covered_voxels), TestOptions().target_coverage * double(r->coverable_voxels));
    EXPECT_EQ(static_cast<int>(r->stations.size()), info->optimum_stations);
  }
}

TEST(PlannerTest, TwoFloorsGetCandidatesAndStationsOnBothStoreys) {
  Result<SceneInfo> info = DescribeScene("twofloor");
  ASSERT_TRUE(info.ok());
  ASSERT_EQ(info->floor_heights_m.size(), 2u);
  Result<PlanResult> r = Plan(Synthetic("twofloor"), TestOptions());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ twofloor ] " << Describe(*r) << " (optimum " << info->optimum_stations << ")\n";
  ASSERT_EQ(r->floor_levels_m.size(), 2u);
  for (int f = 0; f < 2; ++f) {
    EXPECT_NEAR(r->floor_levels_m[f], info->floor_heights_m[f], 0.1);
    const double z = info->floor_heights_m[f] + 1.5;
    const auto near = [&](const WorldPoint& p) { return std::fabs(p.z() - z) < 0.15; };
    EXPECT_TRUE(std::any_of(r->heat_map.positions.begin(), r->heat_map.positions.end(), near)) << "floor " << f;
    EXPECT_TRUE(
        std::any_of(r->stations.begin(), r->stations.end(), [&](const PlannedStation& s) { return near(s.position); }))
        << "no station on floor " << f;
  }
  // Each station knows the floor it stands over: one of the two levels, 1.5 m below it.
  for (const PlannedStation& s : r->stations) {
    EXPECT_NEAR(s.position.z() - s.floor_z_m, 1.5, 1e-9);
    const double level = std::fabs(s.floor_z_m - r->floor_levels_m[0]) < std::fabs(s.floor_z_m - r->floor_levels_m[1])
                             ? r->floor_levels_m[0]
                             : r->floor_levels_m[1];
    EXPECT_NEAR(s.floor_z_m, level, 0.1);
  }
  EXPECT_EQ(r->covered_voxels, r->coverable_voxels);
}

// hub:K (optimum 2K): doorway candidates reach the plan (candidates just inside each door), but
// greedy selection still plans 2K + 1 (docs/PLANNING.md, "Doorway candidates"); every room gets a
// station and coverage is full either way.
TEST(PlannerTest, HubDoorwayCandidatesReachThePlanAndEveryRoomGetsAStation) {
  Result<SceneInfo> info = DescribeScene("hub:1");
  ASSERT_TRUE(info.ok());
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  o.doorway_candidates = false;
  Result<PlanResult> off = Plan(Synthetic("hub:1"), o);
  o.doorway_candidates = true;
  Result<PlanResult> on = Plan(Synthetic("hub:1"), o);
  ASSERT_TRUE(off.ok() && on.ok());
  std::cout << "[ hub:1 ] " << Describe(*off) << "\n[ hub:1, doorway candidates ] " << Describe(*on) << " (optimum "
            << info->optimum_stations << ")\n";
  EXPECT_GT(on->candidate_count, off->candidate_count);
  // Two of the new candidates stand within 0.1 m of the optimum's stations, 0.125 m inside each door.
  const WorldPoint offset = kSceneOffsetM - WorldPoint(0, 0, kSceneOffsetM.z());
  for (const WorldPoint& optimum :
       std::vector<WorldPoint>{WorldPoint(2.5, 4.875, 0) + offset, WorldPoint(2.5, -0.375, 0) + offset}) {
    EXPECT_TRUE(std::any_of(on->heat_map.positions.begin(), on->heat_map.positions.end(), [&](const WorldPoint& p) {
      return (p - optimum).head<2>().norm() < 0.1;
    })) << optimum.transpose();
  }
  for (const Result<PlanResult>* r : {&off, &on}) {
    EXPECT_EQ((*r)->covered_voxels, (*r)->coverable_voxels);
    EXPECT_GE(static_cast<int>((*r)->stations.size()), info->optimum_stations);
    for (size_t i = 0; i < info->rooms.size(); ++i) {
      EXPECT_TRUE(std::any_of((*r)->stations.begin(), (*r)->stations.end(),
                              [&](const PlannedStation& s) { return Inside(s.position, info->rooms[i]); }))
          << "no station in room " << i;
    }
  }
}

// Loss of removing T, by evaluating P - T from scratch.
TEST(PlannerTest, ReductionMatrixMatchesBruteForceEvaluation) {
  const SceneInput in = Synthetic("comb:3");
  Result<PlanResult> r = Plan(in, TestOptions());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const int n = r->reduction.size;
  ASSERT_EQ(n, static_cast<int>(r->stations.size()));
  ASSERT_GE(n, 2);
  Result<VoxelScene> scene = Voxelize(in, {0.1, kDefaultMemoryBudgetBytes});
  ASSERT_TRUE(scene.ok());
  const std::vector<WorldPoint>& p = r->reduction.positions;
  const auto g = [&](const std::vector<WorldPoint>& s) {
    if (s.empty()) return 0.0;
    Result<Evaluation> e = Evaluate(*scene, s, {});
    EXPECT_TRUE(e.ok());
    return e->overall.global_visibility;
  };
  const double g_all = g(p);
  EXPECT_NEAR(r->reduction.global_visibility_before, g_all, 1e-6);
  EXPECT_NEAR(r->evaluation.overall.global_visibility, g_all, 1e-12);
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) {
      std::vector<WorldPoint> rest;
      for (int k = 0; k < n; ++k) {
        if (k != i && k != j) rest.push_back(p[k]);
      }
      EXPECT_NEAR(r->reduction.matrix[i * n + j], g_all - g(rest), 1e-6) << i << "," << j;
      EXPECT_EQ(r->reduction.matrix[i * n + j], r->reduction.matrix[j * n + i]);
    }
    EXPECT_GT(r->reduction.matrix[i * n + i], 0.0);  // nothing obsolete -> nothing removed
  }
  EXPECT_TRUE(r->reduction.removed.empty());
}

TEST(PlannerTest, ReduceToKeepsTheRequestedNumberOfStations) {
  PlanOptions o = TestOptions();
  o.reduce_to = 1;
  Result<PlanResult> r = Plan(Synthetic("comb:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->stations.size(), 1u);
  EXPECT_EQ(r->reduction.size, 3);
  EXPECT_EQ(r->reduction.removed.size(), 2u);
  EXPECT_LT(r->reduction.global_visibility_after, r->reduction.global_visibility_before);
  EXPECT_LT(r->covered_voxels, r->coverable_voxels);
  EXPECT_NEAR(r->evaluation.overall.global_visibility, r->reduction.global_visibility_after, 1e-6);
}

// With a memory budget too small to keep every station's face values, reduction evaluates each
// station alone, as often as it needs; the plan is the one the batch evaluation gives.
TEST(PlannerTest, ReductionOneStationAtATimeMatchesTheBatch) {
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  o.reduce_to = 3;
  Result<PlanResult> batch = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(batch.ok()) << batch.status().ToString();
  // The smallest budget that holds the reduction's table (16.9 MB): cache budget 4.2 MB < 5
  // stations x 1.15 MB of face values.
  o.memory_budget_bytes = planner::ReductionTableBudgetBytes(batch->occupied_voxels);
  Result<PlanResult> single = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(single.ok()) << single.status().ToString();
  ASSERT_GE(single->reduction.size, 5);
  EXPECT_GT(single->reduction.size * single->occupied_voxels * kFacesPerVoxel * sizeof(float),
            o.memory_budget_bytes / 4);
  EXPECT_EQ(single->stations.size(), 3u);
  ASSERT_EQ(single->stations.size(), batch->stations.size());
  for (size_t k = 0; k < single->stations.size(); ++k) {
    EXPECT_EQ(single->stations[k].position, batch->stations[k].position) << k;
  }
  EXPECT_EQ(single->reduction.removed, batch->reduction.removed);
  EXPECT_DOUBLE_EQ(single->reduction.global_visibility_after, batch->reduction.global_visibility_after);
  EXPECT_DOUBLE_EQ(single->evaluation.overall.global_visibility, batch->evaluation.overall.global_visibility);
}

// With a memory budget that splits the reduction's stations into batches, the batches' evaluations,
// joined, are the final evaluation (the evaluation stage evaluates nothing again: it reports no
// stations), and it is the one evaluation of the final stations gives and the one-batch plan has.
TEST(PlannerTest, ReductionBatchesJoinedAreTheFinalEvaluation) {
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  Result<PlanResult> one = Plan(Synthetic("comb:5"), o);
  Result<VoxelScene> scene = Voxelize(Synthetic("comb:5"), {0.1, kDefaultMemoryBudgetBytes});
  ASSERT_TRUE(scene.ok());
  // The smallest budget that keeps the joined evaluation (beside the table, in three quarters of
  // it); the cache gets a quarter, 143 bytes per voxel: room for two stations at the worst case (48
  // per voxel each), so two per batch.
  o.memory_budget_bytes = planner::ReductionJoinBudgetBytes(scene->occupied.size());
  const planner::ReductionMemory memory = planner::ReductionMemoryFor(scene->occupied.size(), o.memory_budget_bytes);
  ASSERT_TRUE(memory.keep_join);
  const uint64_t worst_station_bytes = scene->occupied.size() * kFacesPerVoxel * 8;
  bool evaluation_counted = false;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { evaluation_counted |= e.stage == Stage::kEvaluation && e.total > 0; };
  Result<PlanResult> batched = Plan(Synthetic("comb:5"), o, ctx);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  ASSERT_TRUE(batched.ok()) << batched.status().ToString();
  // More stations than the first batch holds: at least two batches were joined.
  ASSERT_GT(batched->stations.size() * worst_station_bytes, memory.cache_bytes);
  EXPECT_TRUE(batched->reduction.removed.empty());
  EXPECT_FALSE(evaluation_counted);
  for (const std::string& w : batched->warnings) EXPECT_EQ(w.find("joined evaluation"), std::string::npos) << w;
  std::vector<WorldPoint> positions;
  for (const PlannedStation& st : batched->stations) positions.push_back(st.position);
  Result<Evaluation> fresh = Evaluate(*scene, positions, planner::StationEvaluateOptions(o));
  ASSERT_TRUE(fresh.ok()) << fresh.status().ToString();
  for (const Evaluation* e : {&*fresh, &one->evaluation}) {
    EXPECT_EQ(batched->evaluation.overall.global_visibility, e->overall.global_visibility);
    EXPECT_EQ(batched->evaluation.overall.fully_visible_fraction, e->overall.fully_visible_fraction);
    EXPECT_EQ(batched->evaluation.overall.partially_visible_fraction, e->overall.partially_visible_fraction);
    EXPECT_EQ(batched->evaluation.best_face_values, e->best_face_values);
    EXPECT_EQ(batched->evaluation.sole_viewer, e->sole_viewer);
    ASSERT_EQ(batched->evaluation.per_viewpoint.size(), e->per_viewpoint.size());
    for (size_t k = 0; k < e->per_viewpoint.size(); ++k) {
      EXPECT_EQ(batched->evaluation.per_viewpoint[k].global_visibility, e->per_viewpoint[k].global_visibility) << k;
    }
  }
  EXPECT_TRUE(batched->evaluation.best_values.empty());  // the join state is dropped once every station is in
}

// Across replicas (PlanCallbacks::face_values, as vc-server's peers answer: shards of three
// stations) the batches' values come with their join state and are joined into the final
// evaluation as one replica joins its own: the same evaluation, bit for bit, and the evaluation
// stage evaluates nothing. Replicas too old to give the join state, or a budget without room for it
// in flight, cost one more evaluation, with a note, and the same result.
TEST(PlannerTest, ReductionJoinsTheReplicasValuesIntoTheFinalEvaluation) {
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  Result<PlanResult> one = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  Result<VoxelScene> scene = Voxelize(Synthetic("comb:5"), {0.1, kDefaultMemoryBudgetBytes});
  ASSERT_TRUE(scene.ok());
  const uint64_t voxels = scene->occupied.size();
  // The table, the join and 9/8 of the cache (the join state in flight) in three quarters of the
  // budget: 15/32 of it for the table and the join; the cache's quarter then holds four stations at
  // the worst case, so more than one batch.
  const uint64_t with_room =
      (planner::ReductionTableBytes(voxels) + planner::ReductionJoinBytes(voxels)) * 32 / 15 + 64;
  const uint64_t worst_station_bytes = voxels * kFacesPerVoxel * 8;
  int calls = 0;
  auto replicas = [&](bool old) {
    return [&, old](const VoxelScene& sc, const std::vector<WorldPoint>& stations, const EvaluateOptions& options,
                    const JobContext& ctx) -> Result<DistributedFaceValues> {
      ++calls;
      DistributedFaceValues d;
      EvaluateOptions asked = options;
      if (old) asked.keep_sparse_join_state = false;  // an older replica ignores the request
      for (size_t b = 0; b < stations.size(); b += 3) {
        const std::vector<WorldPoint> shard(stations.begin() + b, stations.begin() + std::min(b + 3, stations.size()));
        VC_ASSIGN_OR_RETURN(Evaluation e, Evaluate(sc, shard, asked, ctx));
        for (size_t k = 0; k < shard.size(); ++k) {
          d.values.push_back(std::move(e.per_viewpoint_sparse_values[k]));
          if (asked.keep_sparse_join_state) d.figures.push_back(e.per_viewpoint[k]);
        }
      }
      d.distribution.shards = int((stations.size() + 2) / 3);
      d.distribution.replicas = 2;
      return d;
    };
  };
  auto plan = [&](bool old, uint64_t budget, bool& evaluation_counted) {
    PlanOptions with = o;
    with.memory_budget_bytes = budget;
    PlanCallbacks callbacks;
    callbacks.face_values = replicas(old);
    JobContext ctx;
    evaluation_counted = false;
    ctx.progress = [&](const ProgressEvent& e) { evaluation_counted |= e.stage == Stage::kEvaluation && e.total > 0; };
    return Plan(Synthetic("comb:5"), with, ctx, callbacks);
  };
  auto expect_same_evaluation = [&](const PlanResult& r, const std::string& what) {
    EXPECT_EQ(r.evaluation.overall.global_visibility, one->evaluation.overall.global_visibility) << what;
    EXPECT_EQ(r.evaluation.overall.fully_visible_fraction, one->evaluation.overall.fully_visible_fraction) << what;
    EXPECT_EQ(r.evaluation.overall.mean_full_visibility, one->evaluation.overall.mean_full_visibility) << what;
    EXPECT_EQ(r.evaluation.overall.partially_visible_fraction, one->evaluation.overall.partially_visible_fraction)
        << what;
    EXPECT_EQ(r.evaluation.best_face_values, one->evaluation.best_face_values) << what;
    EXPECT_EQ(r.evaluation.sole_viewer, one->evaluation.sole_viewer) << what;
    ASSERT_EQ(r.evaluation.per_viewpoint.size(), one->evaluation.per_viewpoint.size()) << what;
    for (size_t k = 0; k < r.evaluation.per_viewpoint.size(); ++k) {
      EXPECT_EQ(r.evaluation.per_viewpoint[k].global_visibility, one->evaluation.per_viewpoint[k].global_visibility)
          << what << k;
      EXPECT_EQ(r.evaluation.per_viewpoint[k].fully_visible_fraction,
                one->evaluation.per_viewpoint[k].fully_visible_fraction)
          << what << k;
    }
    EXPECT_EQ(r.evaluation.faces_total, one->evaluation.faces_total) << what;
    EXPECT_TRUE(r.evaluation.best_values.empty()) << what;  // the join state is dropped at the end
  };
  auto has = [](const PlanResult& r, const std::string& part) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [&](const std::string& w) { return w.find(part) != std::string::npos; });
  };
  bool counted = false;
  Result<PlanResult> joined = plan(false, with_room, counted);
  ASSERT_TRUE(joined.ok()) << joined.status().ToString();
  ASSERT_GT(joined->stations.size() * worst_station_bytes, with_room / 4);  // more than one batch
  EXPECT_GE(calls, 2);
  EXPECT_TRUE(joined->reduction.removed.empty());
  EXPECT_FALSE(counted) << "the evaluation stage evaluated the stations again";
  EXPECT_FALSE(has(*joined, "reduction:"));  // (at this budget the solver warns that it went greedy)
  expect_same_evaluation(*joined, "joined");

  Result<PlanResult> older = plan(true, with_room, counted);
  ASSERT_TRUE(older.ok()) << older.status().ToString();
  EXPECT_TRUE(counted);
  EXPECT_TRUE(has(*older, "older than this one")) << older->warnings.size();
  expect_same_evaluation(*older, "older replicas");

  // The smallest budget that joins on one replica has no room for the join state in flight.
  Result<PlanResult> tight = plan(false, planner::ReductionJoinBudgetBytes(voxels), counted);
  ASSERT_TRUE(tight.ok()) << tight.status().ToString();
  EXPECT_TRUE(counted);
  EXPECT_TRUE(has(*tight, "join state in flight")) << tight->warnings.size();
  expect_same_evaluation(*tight, "tight budget");
}

// The reduction's table (the top-3 table, 144 bytes a voxel, and an evaluation's working set, 134)
// and the joined evaluation are charged to three quarters of the budget; the cache keeps its quarter
// (at most 1 GiB) either way.
TEST(PlannerTest, ReductionMemoryChargesTheTableAndTheJoinToThreeQuartersOfTheBudget) {
  EXPECT_EQ(planner::ReductionJoinBytes(1000), 2 * 1000 * (6 * (8 + 1 + 4) + 4));
  EXPECT_EQ(planner::EvaluateWorkingBytes(1000), 1000 * (12 + 32 + 24 + 12 + 6 * 9));
  EXPECT_EQ(planner::ReductionTableBytes(1000), 1000 * (6 * 24 + 134));
  const uint64_t table = planner::ReductionTableBytes(1000), join = planner::ReductionJoinBytes(1000);
  const uint64_t with_join = planner::ReductionJoinBudgetBytes(1000);
  EXPECT_GE(with_join / 4 * 3, table + join);
  planner::ReductionMemory m = planner::ReductionMemoryFor(1000, with_join);
  EXPECT_TRUE(m.table_fits);
  EXPECT_TRUE(m.keep_join);
  EXPECT_EQ(m.table_bytes, table);
  EXPECT_EQ(m.join_bytes, join);
  EXPECT_EQ(m.cache_bytes, with_join / 4);
  m = planner::ReductionMemoryFor(1000, with_join - 4);
  EXPECT_TRUE(m.table_fits);
  EXPECT_FALSE(m.keep_join);
  EXPECT_EQ(m.cache_bytes, (with_join - 4) / 4);
  const uint64_t table_only = planner::ReductionTableBudgetBytes(1000);
  EXPECT_TRUE(planner::ReductionMemoryFor(1000, table_only).table_fits);
  EXPECT_FALSE(planner::ReductionMemoryFor(1000, table_only - 4).table_fits);
  m = planner::ReductionMemoryFor(1000, kDefaultMemoryBudgetBytes);
  EXPECT_TRUE(m.keep_join);
  EXPECT_EQ(m.cache_bytes, uint64_t{1} << 30);
  // The default budget keeps the join up to 7.28 M voxels (3 GiB / 442 bytes), the 4 x 4 tiled
  // hall's 6.78 M among them, and holds the table up to 11.58 M (3 GiB / 278 bytes).
  EXPECT_TRUE(planner::ReductionMemoryFor(6'780'000, kDefaultMemoryBudgetBytes).keep_join);
  EXPECT_TRUE(planner::ReductionMemoryFor(7'280'000, kDefaultMemoryBudgetBytes).keep_join);
  EXPECT_FALSE(planner::ReductionMemoryFor(7'290'000, kDefaultMemoryBudgetBytes).keep_join);
  EXPECT_TRUE(planner::ReductionMemoryFor(11'580'000, kDefaultMemoryBudgetBytes).table_fits);
  EXPECT_FALSE(planner::ReductionMemoryFor(11'590'000, kDefaultMemoryBudgetBytes).table_fits);
}

// Below the budget that holds the reduction's table the stage refuses before allocating it, naming
// itself, the figure and the budget that plans the scene; at that budget the plan is the same.
TEST(PlannerTest, ReductionRefusesWhenItsTableDoesNotFitTheBudget) {
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  Result<PlanResult> one = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  const uint64_t table_budget = planner::ReductionTableBudgetBytes(one->occupied_voxels);
  o.memory_budget_bytes = table_budget - 4;
  bool reduction_started = false;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { reduction_started |= e.stage == Stage::kReduction; };
  Result<PlanResult> refused = Plan(Synthetic("comb:5"), o, ctx);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(reduction_started);  // the stages before it ran within the budget
  const std::string m = refused.status().message();
  EXPECT_EQ(m.rfind("reduction: its table of the stations' best face values (", 0), 0u) << m;
  EXPECT_NE(m.find("--memory-budget-bytes " + std::to_string(table_budget) + ")"), std::string::npos) << m;
  EXPECT_NE(m.find("--no-reduce"), std::string::npos) << m;
  o.memory_budget_bytes = table_budget;
  Result<PlanResult> fits = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(fits.ok()) << fits.status().ToString();
  ASSERT_EQ(fits->stations.size(), one->stations.size());
  for (size_t k = 0; k < one->stations.size(); ++k) {
    EXPECT_EQ(fits->stations[k].position, one->stations[k].position) << k;
  }
  EXPECT_EQ(fits->evaluation.overall.global_visibility, one->evaluation.overall.global_visibility);
}

// The evaluation stage charges what it holds (EvaluationStageBytes) before it evaluates: below it,
// RESOURCE_EXHAUSTED names the stage and the budget that plans the scene.
TEST(PlannerTest, EvaluationRefusesWhenItsEvaluationDoesNotFitTheBudget) {
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  o.reduce = false;  // the evaluation stage evaluates the stations itself
  Result<PlanResult> one = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  const uint64_t need = planner::EvaluationStageBytes(one->occupied_voxels, one->stations.size(), o.threads);
  EXPECT_GE(need, one->occupied_voxels * (134 + 4 + 24 + 24));
  o.memory_budget_bytes = need - 1;
  Result<PlanResult> refused = Plan(Synthetic("comb:5"), o);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
  const std::string m = refused.status().message();
  EXPECT_EQ(m.rfind("evaluation: evaluating the " + std::to_string(one->stations.size()) + " final stations on ", 0),
            0u)
      << m;
  EXPECT_NE(m.find("--memory-budget-bytes " + std::to_string(need) + ")"), std::string::npos) << m;
  o.memory_budget_bytes = need;
  Result<PlanResult> fits = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(fits.ok()) << fits.status().ToString();
  EXPECT_EQ(fits->evaluation.overall.global_visibility, one->evaluation.overall.global_visibility);
}

// A budget too small for the joined evaluation: the reduction keeps none, says so, and the
// evaluation stage evaluates the final stations, with the same result as the joined one.
TEST(PlannerTest, ReductionWithoutRoomForTheJoinEvaluatesAgain) {
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  Result<PlanResult> one = Plan(Synthetic("comb:5"), o);
  Result<VoxelScene> scene = Voxelize(Synthetic("comb:5"), {0.1, kDefaultMemoryBudgetBytes});
  ASSERT_TRUE(scene.ok());
  // Just too small for the join beside the table; the cache (a quarter, 143 bytes per voxel) too
  // small for every station at the worst case (48 bytes per voxel each): none joined.
  o.memory_budget_bytes = planner::ReductionJoinBudgetBytes(scene->occupied.size()) - 8;
  const planner::ReductionMemory memory = planner::ReductionMemoryFor(scene->occupied.size(), o.memory_budget_bytes);
  ASSERT_FALSE(memory.keep_join);
  ASSERT_GT(one->stations.size() * scene->occupied.size() * kFacesPerVoxel * 8, memory.cache_bytes);
  bool evaluation_counted = false;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { evaluation_counted |= e.stage == Stage::kEvaluation && e.total > 0; };
  Result<PlanResult> again = Plan(Synthetic("comb:5"), o, ctx);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  ASSERT_TRUE(again->reduction.removed.empty());
  EXPECT_TRUE(evaluation_counted);
  const auto warning = std::find_if(again->warnings.begin(), again->warnings.end(), [](const std::string& w) {
    return w.rfind("reduction: the joined evaluation of the stations (", 0) == 0;
  });
  ASSERT_NE(warning, again->warnings.end());
  EXPECT_NE(warning->find("the evaluation stage evaluates the final stations again; a memory budget of"),
            std::string::npos)
      << *warning;
  ASSERT_EQ(again->stations.size(), one->stations.size());
  for (size_t k = 0; k < one->stations.size(); ++k) {
    EXPECT_EQ(again->stations[k].position, one->stations[k].position) << k;
  }
  EXPECT_EQ(again->evaluation.overall.global_visibility, one->evaluation.overall.global_visibility);
  EXPECT_EQ(again->evaluation.best_face_values, one->evaluation.best_face_values);
  EXPECT_EQ(again->evaluation.sole_viewer, one->evaluation.sole_viewer);
}

TEST(PlannerTest, UserCandidatesWithADuplicateAreReducedToDistinctStations) {
  // Greedy never picks a duplicate (it adds nothing), so every plan it makes has no zero-loss
  // station; with max_stations and the candidates given, it still cannot pick one twice.
  Result<SceneInfo> info = DescribeScene("comb:3");
  ASSERT_TRUE(info.ok());
  PlanOptions o = TestOptions();
  for (const AxisBox& room : info->rooms) {
    const WorldPoint c = 0.5 * (room.min + room.max);
    o.candidates.push_back(WorldPoint(c.x(), c.y(), info->floor_heights_m[0] + 1.5));
  }
  o.candidates.push_back(o.candidates[0]);
  Result<PlanResult> r = Plan(Synthetic("comb:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->candidate_count, 4u);
  std::set<int> picked;
  for (const PlannedStation& s : r->stations) picked.insert(s.candidate_index);
  EXPECT_EQ(picked.size(), r->stations.size());
  EXPECT_FALSE(picked.count(3)) << "the duplicate of candidate 0 was picked";
  EXPECT_TRUE(r->floor_levels_m.empty());
}

TEST(PlannerTest, RefinementNeverLowersCoverage) {
  PlanOptions o = TestOptions();
  o.grid_spacing_m = 1.5;
  Result<PlanResult> plain = Plan(Synthetic("rooms:3"), o);
  o.refine = true;
  Result<PlanResult> refined = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(plain.ok() && refined.ok());
  EXPECT_GE(refined->covered_voxels, plain->covered_voxels);
  EXPECT_GE(refined->coverable_voxels, plain->coverable_voxels);
  EXPECT_LE(refined->stations.size(), plain->stations.size());
  EXPECT_TRUE(std::any_of(refined->timings.begin(), refined->timings.end(),
                          [](const StageTiming& t) { return t.stage == Stage::kRefine; }));
}

TEST(PlannerTest, ProgressCallbacksAndTimings) {
  std::vector<Stage> stages;
  std::map<Stage, ProgressEvent> last_count;  // the last counted event of each stage
  ProgressEvent last_stations;                // selection's last count of stations picked
  std::atomic<bool> bad_fraction{false};
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) {
    if (!(e.fraction >= 0 && e.fraction <= 1)) bad_fraction = true;
    if (stages.empty() || stages.back() != e.stage) stages.push_back(e.stage);
    if (!e.unit.empty()) last_count[e.stage] = e;
    if (e.unit == "stations" && e.stage == Stage::kSelection) last_stations = e;
  };
  int heat_maps = 0;
  std::vector<int> station_indices;
  PlanCallbacks cb;
  cb.on_heat_map = [&](const HeatMap& h) {
    ++heat_maps;
    EXPECT_FALSE(h.positions.empty());
    EXPECT_EQ(h.positions.size(), h.visible_voxels.size());
  };
  cb.on_station = [&](const PlannedStation& s, int index) {
    station_indices.push_back(index);
    EXPECT_GT(s.marginal_gain, 0u);
  };
  std::vector<std::vector<PlannedStation>> finals;
  cb.on_final_stations = [&](const std::vector<PlannedStation>& s) { finals.push_back(s); };
  Result<PlanResult> r = Plan(Synthetic("comb:3"), TestOptions(), ctx, cb);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(finals.size(), 1u);
  ASSERT_EQ(finals[0].size(), r->stations.size());
  for (size_t k = 0; k < r->stations.size(); ++k) {
    EXPECT_EQ(finals[0][k].position, r->stations[k].position);
    EXPECT_EQ(finals[0][k].marginal_gain, r->stations[k].marginal_gain);
  }
  EXPECT_FALSE(bad_fraction);
  EXPECT_EQ(heat_maps, 1);
  EXPECT_EQ(station_indices, std::vector<int>({0, 1, 2}));
  // Stages in pipeline order (each may report several times, but not go back).
  const std::vector<Stage> order = {Stage::kVoxelize,  Stage::kCandidates, Stage::kVisibility, Stage::kSelection,
                                    Stage::kReduction, Stage::kEvaluation, Stage::kRoute};
  std::vector<Stage> seen;
  for (const auto& s : stages) {
    if (std::find(seen.begin(), seen.end(), s) == seen.end()) seen.push_back(s);
  }
  EXPECT_EQ(seen, order);
  std::vector<Stage> timed;
  for (const auto& t : r->timings) timed.push_back(t.stage);
  EXPECT_EQ(timed, order);
  EXPECT_GT(r->total_seconds, 0.0);
  EXPECT_EQ(r->voxel_centers.size(), r->occupied_voxels);
  EXPECT_EQ(r->evaluation.best_face_values.size(), r->occupied_voxels);
  // Counted progress ends at its total: every candidate's visibility; greedy selection counts the
  // stations it picked (its total is not known in advance), consolidation and the exact model
  // their own steps after it. (The evaluation stage reuses the reduction's evaluation here;
  // EvaluateTest counts stations.)
  ASSERT_EQ(last_count.count(Stage::kVisibility), 1u);
  EXPECT_EQ(last_count[Stage::kVisibility].unit, "candidates");
  EXPECT_EQ(last_count[Stage::kVisibility].total, r->candidate_count);
  EXPECT_EQ(last_count[Stage::kVisibility].done, r->candidate_count);
  EXPECT_EQ(last_count.count(Stage::kSelection), 1u);
  EXPECT_EQ(last_stations.total, 0u);
  EXPECT_GE(last_stations.done, 1u);
  EXPECT_NE(last_stations.message.find("coverage"), std::string::npos);
  // Each voxel's sole viewer: none exactly where no face has V > 0, else a station or several.
  ASSERT_EQ(r->evaluation.sole_viewer.size(), r->occupied_voxels);
  for (size_t i = 0; i < r->occupied_voxels; ++i) {
    const auto& v = r->evaluation.best_face_values[i];
    const bool seen = *std::max_element(v.begin(), v.end()) > 0;
    const int32_t sole = r->evaluation.sole_viewer[i];
    ASSERT_EQ(sole != kNoViewer, seen) << "voxel " << i;
    ASSERT_TRUE(sole == kNoViewer || sole == kSeveralViewers || (sole >= 0 && size_t(sole) < r->stations.size()));
  }
  EXPECT_EQ(r->heat_map.positions.size(), r->candidate_count);
}

TEST(PlannerTest, CancelledBeforeAndDuringEveryStage) {
  const SceneInput in = Synthetic("comb:3");
  {
    CancelToken token;
    token.Cancel();
    JobContext ctx;
    ctx.cancel = &token;
    EXPECT_EQ(Plan(in, TestOptions(), ctx).status().code(), StatusCode::kCancelled);
  }
  for (const Stage stage : {Stage::kCandidates, Stage::kVisibility, Stage::kSelection, Stage::kReduction,
                            Stage::kEvaluation, Stage::kRoute}) {
    CancelToken token;
    JobContext ctx;
    ctx.cancel = &token;
    ctx.progress = [&](const ProgressEvent& e) {
      if (e.stage == stage) token.Cancel();
    };
    Result<PlanResult> r = Plan(in, TestOptions(), ctx);
    ASSERT_FALSE(r.ok()) << "not cancelled in " << StageName(stage);
    EXPECT_EQ(r.status().code(), StatusCode::kCancelled) << StageName(stage) << ": " << r.status().ToString();
  }
}

TEST(PlannerTest, ValidateRejectsBadParametersClearly) {
  struct Case {
    void (*set)(PlanOptions&);
    const char* names;
  };
  const Case cases[] = {
      {[](PlanOptions& o) { o.grid_spacing_m = 0; }, "grid_spacing_m"},
      {[](PlanOptions& o) { o.grid_spacing_m = -1; }, "grid_spacing_m"},
      {[](PlanOptions& o) { o.grid_spacing_m = kNaN; }, "grid_spacing_m"},
      {[](PlanOptions& o) { o.tripod_height_m = kNaN; }, "tripod_height_m"},
      {[](PlanOptions& o) { o.tripod_height_m = 0; }, "tripod_height_m"},
      {[](PlanOptions& o) { o.clearance_m = -0.1; }, "clearance_m"},
      {[](PlanOptions& o) { o.clearance_m = 2.0; }, "clearance_m"},
      {[](PlanOptions& o) { o.resolution_m = -0.1; }, "resolution_m"},
      {[](PlanOptions& o) { o.resolution_m = kNaN; }, "resolution_m"},
      {[](PlanOptions& o) { o.target_coverage = 0; }, "target_coverage"},
      {[](PlanOptions& o) { o.target_coverage = 1.5; }, "target_coverage"},
      {[](PlanOptions& o) { o.max_stations = -2; }, "max_stations"},
      {[](PlanOptions& o) { o.reduce_to = -1; }, "reduce_to"},
      {[](PlanOptions& o) { o.threads = -1; }, "threads"},
      {[](PlanOptions& o) { o.coarse_above_candidates = -1; }, "coarse_above_candidates"},
      {[](PlanOptions& o) { o.scanner.max_range_m = 0.1; }, "max_range_m"},
      {[](PlanOptions& o) { o.scanner.hfov_deg = 0; }, "scanner.hfov_deg"},
      // Stations have no heading, so a partial field of view cannot be planned.
      {[](PlanOptions& o) { o.scanner.hfov_deg = 182; }, "scanner.hfov_deg is 182 deg"},
      {[](PlanOptions& o) { o.candidates = {WorldPoint(0, kNaN, 0)}; }, "candidates[0]"},
      {[](PlanOptions& o) { o.refine = true, o.refine_step_m = 1.0, o.refine_radius_m = 0.5; }, "refine_step_m"},
  };
  EXPECT_TRUE(PlanOptions{}.Validate().ok());
  for (const Case& c : cases) {
    PlanOptions o;
    c.set(o);
    const Status s = o.Validate();
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << c.names;
    EXPECT_NE(s.message().find(c.names), std::string::npos) << s.message();
    // Plan reports the same error before touching the input.
    EXPECT_EQ(Plan(SceneInput{}, o).status(), s);
  }
}

TEST(PlannerTest, ClearanceWiderThanTheCorridorIsAClearError) {
  PlanOptions o = TestOptions();
  o.clearance_m = 1.4;  // the bays and the corridor are narrower than 2.8 m
  Result<PlanResult> r = Plan(Synthetic("comb:3"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("clearance_m"), std::string::npos) << r.status().message();
}

TEST(PlannerTest, UserCandidateInsideAnOccupiedVoxelIsRejected) {
  Result<SceneInfo> info = DescribeScene("box");
  ASSERT_TRUE(info.ok());
  PlanOptions o = TestOptions();
  // A point on the floor surface lies in a floor voxel.
  const WorldPoint centre = 0.5 * (info->rooms[0].min + info->rooms[0].max);
  o.candidates = {WorldPoint(centre.x(), centre.y(), info->floor_heights_m[0] + 1.5),
                  WorldPoint(centre.x(), centre.y(), info->floor_heights_m[0] + 0.01)};
  Result<PlanResult> r = Plan(Synthetic("box"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("candidates[1]"), std::string::npos) << r.status().message();
  // A candidate absurdly far away is refused too, before any ray is cast.
  o.candidates = {WorldPoint(centre.x(), centre.y(), info->floor_heights_m[0] + 1.5), WorldPoint(3e9, 0, 0)};
  r = Plan(Synthetic("box"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("from the origin"), std::string::npos) << r.status().message();
}

// --- Several tripod heights, keep-out zones, fixed stations (issue #20) ---

TEST(PlannerTest, SeveralTripodHeightsGiveCandidatesAtEachHeightAndOneHeatMapPanel) {
  Result<SceneInfo> info = DescribeScene("lroom");
  ASSERT_TRUE(info.ok());
  PlanOptions one = TestOptions();
  Result<PlanResult> single = Plan(Synthetic("lroom"), one);
  ASSERT_TRUE(single.ok()) << single.status().ToString();
  PlanOptions o = TestOptions();
  o.tripod_heights_m = {1.2, 1.6, 2.0};
  Result<PlanResult> r = Plan(Synthetic("lroom"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ lroom, heights 1.2/1.6/2.0 ] " << Describe(*r) << "\n";
  // The room is 3 m high: every cell with floor takes all three heights.
  EXPECT_EQ(r->candidate_count, 3 * single->candidate_count);
  ASSERT_EQ(r->heat_map.floor_z_m.size(), r->heat_map.positions.size());
  std::set<long> heights;
  for (size_t i = 0; i < r->heat_map.positions.size(); ++i) {
    heights.insert(std::lround(10 * (r->heat_map.positions[i].z() - r->heat_map.floor_z_m[i])));
  }
  EXPECT_EQ(heights, (std::set<long>{12, 16, 20}));
  EXPECT_GE(static_cast<double>(r->covered_voxels), 0.99 * static_cast<double>(r->coverable_voxels));
  // Each station's floor lies one of the tripod heights below it.
  for (const PlannedStation& s : r->stations) {
    const long height = std::lround(10 * (s.position.z() - s.floor_z_m));
    EXPECT_TRUE(height == 12 || height == 16 || height == 20) << s.position.transpose() << " floor " << s.floor_z_m;
  }
  // The heat map keeps one panel for the one floor.
  const ImageSize one_panel = HeatmapImageSize(*single);
  EXPECT_EQ(HeatmapImageSize(*r).width, one_panel.width);
  // A height at or below the clearance is refused, naming the entry.
  o.tripod_heights_m = {1.2, 0.1};
  const Status s = o.Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("tripod_heights_m[1]"), std::string::npos) << s.message();
  o.tripod_heights_m = {kNaN};
  EXPECT_NE(o.Validate().message().find("tripod_heights_m[0]"), std::string::npos);
  o.tripod_heights_m = {1.2, 1.6, 1.2};
  EXPECT_NE(o.Validate().message().find("tripod_heights_m[2] (1.2 m) repeats tripod_heights_m[0]"), std::string::npos)
      << o.Validate().message();
}

TEST(PlannerTest, NoStationOrCandidateLiesInAKeepOutZone) {
  Result<SceneInfo> info = DescribeScene("comb:3");
  ASSERT_TRUE(info.ok());
  Result<PlanResult> free = Plan(Synthetic("comb:3"), TestOptions());
  ASSERT_TRUE(free.ok()) << free.status().ToString();
  ASSERT_GE(free->stations.size(), 2u);
  // A 1.5 m box around the first station and a triangle around the second, over all heights.
  PlanOptions o = TestOptions();
  o.refine = true;  // refined positions must stay out too
  const WorldPoint a = free->stations[0].position, b = free->stations[1].position;
  o.keep_out = {KeepOutBox(a - WorldPoint(0.75, 0.75, 10), a + WorldPoint(0.75, 0.75, 10)),
                KeepOutPolygon(-10, 10, {b.x() - 1, b.y() - 1, b.x() + 1, b.y() - 1, b.x(), b.y() + 1})};
  Result<PlanResult> r = Plan(Synthetic("comb:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ comb:3 with 2 keep-out zones ] " << Describe(*r) << "\n";
  EXPECT_LT(r->candidate_count, free->candidate_count);
  for (const PlannedStation& s : r->stations) {
    EXPECT_EQ(KeepOutZoneContaining(o.keep_out, s.position), -1) << s.position.transpose();
  }
  for (const WorldPoint& p : r->heat_map.positions) EXPECT_EQ(KeepOutZoneContaining(o.keep_out, p), -1);
  // Every bay still gets a station.
  for (const AxisBox& room : info->rooms) {
    EXPECT_TRUE(std::any_of(r->stations.begin(), r->stations.end(),
                            [&](const PlannedStation& s) { return Inside(s.position, room); }));
  }
  // User candidates in a zone are dropped with a warning; all of them in zones is an error.
  o.refine = false;
  o.candidates = {a, b, r->stations[0].position};
  r = Plan(Synthetic("comb:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->candidate_count, 1u);
  EXPECT_TRUE(std::any_of(r->warnings.begin(), r->warnings.end(),
                          [](const std::string& w) { return w.find("keep-out") != std::string::npos; }));
  o.candidates = {a, b};
  r = Plan(Synthetic("comb:3"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
}

TEST(PlannerTest, PositionsGivenInTheInputsFrameApplyAtTheirLocalPlace) {
  // The same scene twice: at its frame's origin, and as a georeferenced scan whose local frame
  // lies at a UTM-like origin. Fixed stations, keep-out zones and the route start given in the
  // input's frame must plan exactly as their local equivalents do at the origin. (Input
  // coordinates less a whole-kilometre origin are exact in double, so "exactly" holds.)
  Result<SceneInfo> info = DescribeScene("comb:3");
  ASSERT_TRUE(info.ok());
  Result<PlanResult> free = Plan(Synthetic("comb:3"), TestOptions());
  ASSERT_TRUE(free.ok()) << free.status().ToString();
  ASSERT_GE(free->stations.size(), 3u);
  const WorldPoint origin(512000, 5612000, 0);
  PlanOptions around = TestOptions();
  const WorldPoint a = free->stations[0].position, b = free->stations[1].position;
  around.keep_out = {KeepOutBox(a - WorldPoint(0.75, 0.75, 10), a + WorldPoint(0.75, 0.75, 10)),
                     KeepOutPolygon(-10, 10, {b.x() - 1, b.y() - 1, b.x() + 1, b.y() - 1, b.x(), b.y() + 1})};
  around.fixed_stations = {free->stations[2].position + WorldPoint(0.13, 0.07, 0)};
  around.route_start = free->stations[2].position;
  const PlanOptions given = InLocalFrame(around, -origin);  // in the input's frame, as a user gives them
  ASSERT_NEAR(given.fixed_stations[0].y() - around.fixed_stations[0].y(), 5612000, 1e-6);
  const PlanOptions local = InLocalFrame(given, origin);
  Result<PlanResult> at_origin = Plan(Synthetic("comb:3"), local);
  ASSERT_TRUE(at_origin.ok()) << at_origin.status().ToString();
  EXPECT_EQ(at_origin->frame_origin_m, WorldPoint::Zero());

  SceneInput georeferenced = Synthetic("comb:3");
  georeferenced.frame_origin_m = origin;
  Result<PlanResult> shifted = Plan(georeferenced, given);
  ASSERT_TRUE(shifted.ok()) << shifted.status().ToString();
  EXPECT_EQ(shifted->frame_origin_m, origin);
  EXPECT_EQ(shifted->options.fixed_stations, given.fixed_stations);  // options stay as given
  ASSERT_EQ(shifted->stations.size(), at_origin->stations.size());
  ASSERT_TRUE(shifted->stations[0].fixed);
  EXPECT_EQ(shifted->stations[0].position, local.fixed_stations[0]);
  for (size_t k = 0; k < shifted->stations.size(); ++k) {
    EXPECT_EQ(shifted->stations[k].position, at_origin->stations[k].position) << k;
    EXPECT_EQ(KeepOutZoneContaining(local.keep_out, shifted->stations[k].position), -1) << k;
  }
  EXPECT_EQ(shifted->candidate_count, at_origin->candidate_count);
  EXPECT_LT(shifted->candidate_count, free->candidate_count);
  EXPECT_EQ(shifted->heat_map.positions, at_origin->heat_map.positions);
  ASSERT_TRUE(shifted->route.start.has_value());
  EXPECT_EQ(*shifted->route.start, *local.route_start);
  EXPECT_EQ(shifted->covered_voxels, at_origin->covered_voxels);
}

TEST(PlannerTest, FixedStationsArePlacedFirstKeptAndThePlanAddsToThem) {
  Result<SceneInfo> info = DescribeScene("comb:3");
  ASSERT_TRUE(info.ok());
  ASSERT_EQ(info->rooms.size(), 3u);
  PlanOptions o = TestOptions();
  o.target_coverage = 1.0;
  o.refine = true;
  // A station already placed in the middle bay, off the candidate grid, twice (a duplicate that
  // reduction would remove as obsolete were it not fixed).
  const AxisBox& bay = info->rooms[1];
  const WorldPoint fixed(0.5 * (bay.min.x() + bay.max.x()) + 0.13, 0.5 * (bay.min.y() + bay.max.y()) + 0.07,
                         info->floor_heights_m[0] + 1.5);
  o.fixed_stations = {fixed, fixed};
  std::vector<PlannedStation> picked, final_stations;
  PlanCallbacks callbacks;
  callbacks.on_station = [&](const PlannedStation& s, int) { picked.push_back(s); };
  callbacks.on_final_stations = [&](const std::vector<PlannedStation>& s) { final_stations = s; };
  Result<PlanResult> r = Plan(Synthetic("comb:3"), o, {}, callbacks);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ comb:3 with a fixed station ] " << Describe(*r) << "\n";
  ASSERT_GE(r->stations.size(), 4u);
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(r->stations[k].fixed);
    EXPECT_EQ(r->stations[k].position, fixed);  // not refined
    EXPECT_EQ(r->stations[k].candidate_index, -1);
    // A fixed station has no candidate's floor: the floor below it in the scene, 1.5 m down.
    EXPECT_NEAR(r->stations[k].floor_z_m, info->floor_heights_m[0], r->resolution_m) << k;
  }
  EXPECT_GT(r->stations[0].marginal_gain, 0u);  // its coverage counts first
  EXPECT_EQ(r->stations[1].marginal_gain, 0u);
  for (size_t k = 2; k < r->stations.size(); ++k) {
    EXPECT_FALSE(r->stations[k].fixed);
    EXPECT_FALSE(Inside(r->stations[k].position, bay)) << "the middle bay is seen already";
  }
  EXPECT_EQ(r->covered_voxels, r->coverable_voxels);
  EXPECT_EQ(r->reduction.size, static_cast<int>(r->stations.size()));
  ASSERT_GE(picked.size(), 2u);
  EXPECT_TRUE(picked[0].fixed && picked[1].fixed);
  ASSERT_EQ(final_stations.size(), r->stations.size());
  EXPECT_TRUE(final_stations[0].fixed);
  EXPECT_FALSE(final_stations.back().fixed);
  const std::string json = PlanToJson(*r);
  EXPECT_NE(json.find("\"fixed\": true"), std::string::npos);
  EXPECT_NE(json.find("\"fixed\": false"), std::string::npos);
}

TEST(PlannerTest, FixedStationsThatReachTheTargetGetNoneAdded) {
  Result<SceneInfo> info = DescribeScene("box");
  ASSERT_TRUE(info.ok());
  Result<PlanResult> free = Plan(Synthetic("box"), TestOptions());
  ASSERT_TRUE(free.ok()) << free.status().ToString();
  ASSERT_EQ(free->stations.size(), 1u);
  PlanOptions o = TestOptions();
  o.fixed_stations = {free->stations[0].position};  // where the plan would put its one station
  Result<PlanResult> r = Plan(Synthetic("box"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->stations.size(), 1u);
  EXPECT_TRUE(r->stations[0].fixed);
  EXPECT_EQ(r->greedy_stations, 0);
  EXPECT_EQ(r->covered_voxels, free->covered_voxels);
  EXPECT_DOUBLE_EQ(r->evaluation.overall.global_visibility, free->evaluation.overall.global_visibility);
}

TEST(PlannerTest, FixedStationInAKeepOutZoneOrAWallIsRefused) {
  Result<SceneInfo> info = DescribeScene("box");
  ASSERT_TRUE(info.ok());
  const WorldPoint centre = 0.5 * (info->rooms[0].min + info->rooms[0].max);
  const WorldPoint station(centre.x(), centre.y(), info->floor_heights_m[0] + 1.5);
  PlanOptions o = TestOptions();
  o.keep_out = {KeepOutBox(station - WorldPoint(1, 1, 1), station + WorldPoint(1, 1, 1))};
  o.fixed_stations = {station};
  Result<PlanResult> r = Plan(Synthetic("box"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("fixed_stations[0]"), std::string::npos) << r.status().message();
  EXPECT_NE(r.status().message().find("keep_out[0]"), std::string::npos) << r.status().message();
  o.keep_out.clear();
  o.fixed_stations = {station, WorldPoint(centre.x(), centre.y(), info->floor_heights_m[0] + 0.01)};
  r = Plan(Synthetic("box"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("fixed_stations[1]"), std::string::npos) << r.status().message();
  o.fixed_stations = {WorldPoint(kNaN, 0, 0)};
  EXPECT_EQ(Plan(Synthetic("box"), o).status().code(), StatusCode::kInvalidArgument);
}

TEST(PlannerTest, MaxStationsStopsEarlyWithAWarning) {
  PlanOptions o = TestOptions();
  o.max_stations = 2;
  Result<PlanResult> r = Plan(Synthetic("comb:5"), o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->stations.size(), 2u);
  EXPECT_EQ(r->stop_reason, StopReason::kMaxStations);
  EXPECT_LT(r->covered_voxels, r->coverable_voxels);
  EXPECT_TRUE(std::any_of(r->warnings.begin(), r->warnings.end(),
                          [](const std::string& w) { return w.find("max_stations") != std::string::npos; }));
}

// One row of stations.csv by its header's column names.
std::map<std::string, std::string> CsvRow(const std::vector<std::string>& header, const std::string& line) {
  std::map<std::string, std::string> row;
  size_t start = 0;
  for (const std::string& name : header) {
    const size_t end = std::min(line.find(',', start), line.size());
    row[name] = line.substr(start, end - start);
    start = end + 1;
  }
  return row;
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= line.size()) {
    const size_t end = std::min(line.find(',', start), line.size());
    out.push_back(line.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// The coverage curve: each step is a station's gain as PlanResult and stations.csv give it, the
// curve never falls, its last point is the plan's coverage (of the coverable voxels and of the
// whole scene) and plan.json carries it with the 80 / 90 / 95 / 99 % milestones.
TEST(PlannerTest, CoverageCurveAgreesWithTheStationsAndStationsCsv) {
  PlanOptions o = TestOptions();
  o.scan_seconds = 30;
  Result<PlanResult> r = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const std::vector<CoveragePoint>& curve = r->coverage_curve;
  ASSERT_EQ(curve.size(), r->stations.size());
  ASSERT_GE(curve.size(), 3u);
  uint64_t before = 0;
  for (size_t k = 0; k < curve.size(); ++k) {
    EXPECT_EQ(curve[k].stations, static_cast<int>(k) + 1);
    EXPECT_GE(curve[k].covered_voxels, before) << "the curve falls at " << k;
    EXPECT_EQ(curve[k].covered_voxels - before, r->stations[k].marginal_gain) << k;
    EXPECT_DOUBLE_EQ(curve[k].coverable_fraction, r->stations[k].cumulative_coverage) << k;
    EXPECT_DOUBLE_EQ(curve[k].setup_scan_s, (k + 1) * (o.setup_seconds + 30.0)) << k;
    before = curve[k].covered_voxels;
  }
  EXPECT_EQ(curve.back().covered_voxels, r->covered_voxels);
  EXPECT_DOUBLE_EQ(curve.back().coverable_fraction, double(r->covered_voxels) / double(r->coverable_voxels));
  EXPECT_DOUBLE_EQ(curve.back().scene_fraction, double(r->covered_voxels) / double(r->occupied_voxels));
  EXPECT_DOUBLE_EQ(curve.back().setup_scan_s, r->field_time.setup_s + r->field_time.scan_s);

  const std::string dir = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(*r, dir).ok());
  std::ifstream csv(dir + "/stations.csv");
  std::string line;
  std::vector<std::string> header;
  size_t rows = 0;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty()) {
      header = SplitCsv(line);
      continue;
    }
    std::map<std::string, std::string> row = CsvRow(header, line);
    const size_t k = std::stoul(row.at("selection_order")) - 1;
    ASSERT_LT(k, curve.size()) << line;
    const uint64_t step = curve[k].covered_voxels - (k ? curve[k - 1].covered_voxels : 0);
    EXPECT_EQ(std::stoull(row.at("gain_voxels")), step) << line;
    EXPECT_NEAR(std::stod(row.at("cumulative_coverage")), curve[k].coverable_fraction, 1e-6) << line;
    ++rows;
  }
  EXPECT_EQ(rows, curve.size());
  std::ifstream plan_json(dir + "/plan.json");
  const std::string text((std::istreambuf_iterator<char>(plan_json)), std::istreambuf_iterator<char>());
  for (const std::string key : {"\"coverage_curve\"", "\"coverage_milestones\"", "\"setup_scan_s\""}) {
    EXPECT_NE(text.find(key), std::string::npos) << key;
  }
}

// The per-k bound on the curve (vc/plan/k_coverage_bound.h): every point carries it, the plan's
// prefix <= the best found <= the bound <= the coverable voxels, both monotone in k; a fixed
// station counts as given (one station: exactly its own voxels, proven); refinement moves stations
// off the candidates the bound is over, so a refined plan carries none.
void ExpectValidBestCoverage(const PlanResult& r) {
  uint64_t bound_before = 0, best_before = 0;
  for (const CoveragePoint& c : r.coverage_curve) {
    ASSERT_TRUE(c.best_voxels_upper_bound && c.best_voxels) << c.stations;
    EXPECT_LE(c.covered_voxels, *c.best_voxels) << c.stations;
    EXPECT_LE(*c.best_voxels, *c.best_voxels_upper_bound) << c.stations;
    EXPECT_LE(*c.best_voxels_upper_bound, r.coverable_voxels) << c.stations;
    EXPECT_GE(*c.best_voxels_upper_bound, bound_before) << c.stations;
    EXPECT_GE(*c.best_voxels, best_before) << c.stations;
    EXPECT_EQ(c.best_voxels_optimal, *c.best_voxels == *c.best_voxels_upper_bound) << c.stations;
    bound_before = *c.best_voxels_upper_bound, best_before = *c.best_voxels;
  }
}

TEST(PlannerTest, CoverageCurveCarriesTheBestKStationBound) {
  PlanOptions o = TestOptions();
  o.grid_spacing_m = 2.0;
  Result<PlanResult> r = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_GE(r->coverage_curve.size(), 2u);
  ExpectValidBestCoverage(*r);
  // The plan reaches the coverable voxels, so the bound does by then at the latest.
  EXPECT_EQ(*r->coverage_curve.back().best_voxels_upper_bound, r->coverable_voxels);

  o.fixed_stations = {r->stations.back().position};
  Result<PlanResult> fixed = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(fixed.ok()) << fixed.status().ToString();
  ASSERT_TRUE(fixed->stations[0].fixed);
  ExpectValidBestCoverage(*fixed);
  EXPECT_EQ(*fixed->coverage_curve[0].best_voxels_upper_bound, fixed->coverage_curve[0].covered_voxels);
  EXPECT_TRUE(fixed->coverage_curve[0].best_voxels_optimal);

  o.fixed_stations.clear();
  o.refine = true;
  Result<PlanResult> refined = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(refined.ok()) << refined.status().ToString();
  for (const CoveragePoint& c : refined->coverage_curve) EXPECT_FALSE(c.best_voxels_upper_bound) << c.stations;
}

// The selector's proven bound at the target caps the per-k bound below it (CapBelowTheSelectorsBound):
// on hub:3 auto proves 6 stations optimal, so no 5 stations reach the target and the 99 % level
// (the default target) needs 6 by the curve's bound too, where the per-k bound alone, in its 0.1 s,
// allowed 4 (docs/PLANNING.md, "The coverage curve"). About 1 s in release.
TEST(PlannerTest, CoverageCurveBoundBelowTheTargetTakesTheSelectorsBound) {
  const PlanOptions o = TestOptions();
  ASSERT_EQ(o.target_coverage, 0.99);
  Result<PlanResult> r = Plan(Synthetic("hub:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->optimality.status, planner::OptimalityStatus::kOptimal);
  ASSERT_EQ(r->optimality.lower_bound, 6);
  ASSERT_EQ(r->coverage_curve.size(), 6u);
  ExpectValidBestCoverage(*r);
  const double need = o.target_coverage * double(r->coverable_voxels);
  for (int k = 1; k <= 5; ++k) EXPECT_LT(double(*r->coverage_curve[k - 1].best_voxels_upper_bound), need) << k;
  EXPECT_GE(double(*r->coverage_curve[5].best_voxels_upper_bound), need);
  const std::vector<CoverageMilestone> m = CoverageMilestones(r->coverage_curve, r->coverable_voxels, {0.99});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].fewest_possible_stations, 6);
  ASSERT_TRUE(m[0].reached);
  EXPECT_EQ(m[0].reached->stations, 6);
}

// Greedy's own gains to every last voxel (no consolidation, no reduction), 3 minutes a station,
// no gain rule yet: the gain-rule tests below set one.
PlanOptions GainRuleTestOptions() {
  PlanOptions o = TestOptions();
  o.solver = SelectionSolver::kGreedy;
  o.consolidate = false;
  o.reduce = false;
  o.target_coverage = 1.0;
  o.setup_seconds = 120;
  o.scan_seconds = 60;
  o.min_gain_m2_per_minute = 0;
  return o;
}

// The gain rule in voxels: with greedy's own gains (no consolidation, no reduction) the plan keeps
// exactly the stations whose gain is worth their minutes; the exact solver (auto) then needs no
// more stations for at least as much. The default is the area rule (the test below), not this one.
TEST(PlannerTest, GainRuleKeepsTheStationsWorthTheirMinutes) {
  PlanOptions o = GainRuleTestOptions();
  const SceneInput scene = Synthetic("rooms:3");
  Result<PlanResult> all = Plan(scene, o);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  ASSERT_GE(all->stations.size(), 4u);
  const double threshold = static_cast<double>(all->stations[all->stations.size() / 2].marginal_gain) + 0.5;
  const size_t worth =
      static_cast<size_t>(std::count_if(all->stations.begin(), all->stations.end(), [&](const auto& s) {
        return static_cast<double>(s.marginal_gain) >= threshold;
      }));
  ASSERT_GE(worth, 1u);
  ASSERT_LT(worth, all->stations.size());
  o.min_gain_voxels_per_minute = threshold / 3.0;
  Result<PlanResult> ruled = Plan(scene, o);
  ASSERT_TRUE(ruled.ok()) << ruled.status().ToString();
  EXPECT_EQ(ruled->stations.size(), worth);
  EXPECT_EQ(ruled->stop_reason, StopReason::kGainRule);
  EXPECT_EQ(ruled->covered_voxels, all->coverage_curve[worth - 1].covered_voxels);
  o.solver = SelectionSolver::kAuto;
  Result<PlanResult> exact = Plan(scene, o);
  ASSERT_TRUE(exact.ok()) << exact.status().ToString();
  EXPECT_LE(exact->stations.size(), worth);
  EXPECT_GE(exact->covered_voxels, ruled->covered_voxels);
  EXPECT_EQ(exact->stop_reason, StopReason::kGainRule);
  EXPECT_EQ(PlanOptions{}.min_gain_voxels_per_minute, 0.0);
}

// The area rule is the voxel rule at 1 / resolution^2 voxels per m^2: the same threshold in m^2
// keeps the same stations; both > 0 is refused, naming both.
TEST(PlannerTest, AreaGainRuleIsTheVoxelRuleInSquareMetres) {
  PlanOptions o = GainRuleTestOptions();
  const SceneInput scene = Synthetic("rooms:3");
  Result<PlanResult> all = Plan(scene, o);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  ASSERT_GE(all->stations.size(), 4u);
  const double threshold = static_cast<double>(all->stations[all->stations.size() / 2].marginal_gain) + 0.5;
  o.min_gain_voxels_per_minute = threshold / 3.0;
  Result<PlanResult> voxels = Plan(scene, o);
  ASSERT_TRUE(voxels.ok()) << voxels.status().ToString();
  o.min_gain_voxels_per_minute = 0;
  const double res = all->resolution_m;
  o.min_gain_m2_per_minute = threshold * res * res / 3.0;
  Result<PlanResult> area = Plan(scene, o);
  ASSERT_TRUE(area.ok()) << area.status().ToString();
  EXPECT_LT(area->stations.size(), all->stations.size());
  EXPECT_EQ(area->stations.size(), voxels->stations.size());
  EXPECT_EQ(area->stop_reason, StopReason::kGainRule);
  const std::optional<GainRule> rule = GainRuleOf(o, res);
  ASSERT_TRUE(rule.has_value());
  EXPECT_EQ(rule->parameter, "min_gain_m2_per_minute");
  EXPECT_NEAR(rule->voxels_per_minute, threshold / 3.0, 1e-9);
  EXPECT_FALSE(GainRuleOf(o, 0).has_value());
  o.min_gain_voxels_per_minute = 10;
  EXPECT_EQ(GainRuleOf(o, res)->parameter, "min_gain_voxels_per_minute");
  const Status both = o.Validate();
  EXPECT_EQ(both.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(both.message().find("min_gain_voxels_per_minute (10) and min_gain_m2_per_minute"), std::string::npos)
      << both.message();
  o.min_gain_m2_per_minute = 0;
  o.min_gain_voxels_per_minute = 0;
  EXPECT_FALSE(GainRuleOf(o, res).has_value());
}

TEST(PlannerTest, RealScanGeb079) {
  Result<SceneInput> in = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  PlanOptions o;        // defaults: the octree's own 0.08 m, 1 m grid, --solver auto
  o.solve_seconds = 3;  // the bound, not its tightness, is tested here (the default 20 s: PLANNING.md)
  Result<PlanResult> r = Plan(*in, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ geb079 ] " << Describe(*r) << "\n";
  ASSERT_FALSE(r->stations.empty());
  // auto: fewer stations than greedy's plan (the Lagrangian heuristic's 49 against greedy's 51 as
  // CBC's warm start, which CBC does not improve on within the limit), for what greedy covered when
  // the gain rule stopped it, with the integer program's bound beside it.
  PlanOptions g = o;
  g.solver = SelectionSolver::kGreedy;
  Result<PlanResult> greedy = Plan(*in, g);
  ASSERT_TRUE(greedy.ok()) << greedy.status().ToString();
  EXPECT_LT(r->stations.size(), greedy->stations.size());
  EXPECT_EQ(r->optimality.stations, static_cast<int>(r->stations.size()));
  EXPECT_EQ(r->optimality.solver, "exact");
  EXPECT_NE(r->optimality.status, planner::OptimalityStatus::kHeuristic);
  EXPECT_GT(r->optimality.lower_bound, 0);
  EXPECT_LE(r->optimality.lower_bound, static_cast<double>(r->optimality.stations));
  EXPECT_EQ(greedy->optimality.status, planner::OptimalityStatus::kHeuristic);
  EXPECT_GE(static_cast<double>(r->covered_voxels), 0.95 * r->coverable_voxels);
  Result<VoxelScene> scene = Voxelize(*in, {});
  ASSERT_TRUE(scene.ok());
  const WorldPoint lo = scene->BoundsMin(), hi = scene->BoundsMax();
  for (size_t k = 0; k < r->stations.size(); ++k) {
    const WorldPoint& p = r->stations[k].position;
    EXPECT_TRUE((p.array() > lo.array()).all() && (p.array() < hi.array()).all()) << "station " << k << " outside";
    // The floor: an occupied voxel 1.5 m (+- 0.25 m) under the station, in its 3 x 3 columns.
    const VoxelIndex c = scene->grid.WorldToIndex(p);
    const int drop = static_cast<int>(std::lround(1.5 / scene->resolution_m));
    bool floor = false;
    for (int dz = drop - 4; dz <= drop + 4 && !floor; ++dz) {
      for (int dy = -1; dy <= 1 && !floor; ++dy) {
        for (int dx = -1; dx <= 1 && !floor; ++dx) floor = scene->grid.Occupied(c.x + dx, c.y + dy, c.z - dz);
      }
    }
    EXPECT_TRUE(floor) << "station " << k << " at (" << p.transpose() << ") has no floor under it";
  }
  const std::string out = testing::MakeTempDir();
  ASSERT_TRUE(WritePlanOutputs(*r, out).ok());
  for (const char* f : {"plan.json", "stations.csv", "visibility.ply", "heatmap.png", "reduction.png"}) {
    EXPECT_GT(std::filesystem::file_size(out + "/" + f), 100u) << f;
  }
}

// The worked example of docs/PLANNING.md: writes every output file for geb079 with
// target_coverage 0.95 into $VC_PLANNING_EXAMPLE_DIR (skipped when it is not set).
TEST(PlannerTest, Geb079WorkedExample) {
  const char* dir = std::getenv("VC_PLANNING_EXAMPLE_DIR");
  if (dir == nullptr) GTEST_SKIP() << "set VC_PLANNING_EXAMPLE_DIR to write the example";
  Result<SceneInput> in = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  PlanOptions o;
  o.target_coverage = 0.95;
  Result<PlanResult> r = Plan(*in, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ geb079, target 0.95 ] " << Describe(*r) << "\n";
  ASSERT_TRUE(WritePlanOutputs(*r, dir).ok());
  EXPECT_TRUE(std::filesystem::exists(std::string(dir) + "/heatmap.png"));
  // The same with all defaults, into $VC_PLANNING_EXAMPLE_DIR/defaults.
  Result<PlanResult> d = Plan(*in, PlanOptions{});
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  std::cout << "[ geb079, defaults ] " << Describe(*d) << "\n";
  ASSERT_TRUE(WritePlanOutputs(*d, std::string(dir) + "/defaults").ok());
}

TEST(PlannerTest, TheSubvoxelTestRunsOnPointsAndSaysSoWhereThereAreNone) {
  PlanOptions o = TestOptions();
  o.selection_test = SelectionTest::kSubvoxel;
  const SceneInput cloud = Synthetic("rooms:2");
  const Result<PlanResult> subvoxel = Plan(cloud, o);
  ASSERT_TRUE(subvoxel.ok()) << subvoxel.status().ToString();
  EXPECT_EQ(subvoxel->selection_test, SelectionTest::kSubvoxel) << Describe(*subvoxel);
  EXPECT_GT(subvoxel->stations.size(), 0u);
  for (const std::string& w : subvoxel->warnings) EXPECT_EQ(w.find("subvoxel"), std::string::npos) << w;

  // The same rooms as a compact upload (the voxels' centres): no points, so the surface test runs.
  const VoxelScene scene = *Voxelize(cloud, {0.1});
  SceneInput voxels;
  voxels.format = InputFormat::kVoxelStream;
  voxels.voxel_resolution_m = 0.1;
  for (size_t id = 0; id < scene.occupied.size(); ++id) voxels.points.push_back(scene.Center(id).cast<float>());
  const Result<PlanResult> fallback = Plan(voxels, o);
  ASSERT_TRUE(fallback.ok()) << fallback.status().ToString();
  EXPECT_EQ(fallback->selection_test, SelectionTest::kSurfaceVisibility);
  EXPECT_EQ(fallback->options.selection_test, SelectionTest::kSubvoxel);  // as asked
  ASSERT_FALSE(fallback->warnings.empty());
  EXPECT_NE(fallback->warnings[0].find("the subvoxel test needs the input's points"), std::string::npos)
      << fallback->warnings[0];
  o.selection_test = SelectionTest::kSurfaceVisibility;
  const Result<PlanResult> surface = Plan(voxels, o);
  ASSERT_TRUE(surface.ok());
  ASSERT_EQ(fallback->stations.size(), surface->stations.size());
  for (size_t k = 0; k < surface->stations.size(); ++k) {
    EXPECT_EQ(fallback->stations[k].position, surface->stations[k].position);
  }
}

}  // namespace
}  // namespace vc
