// Registration in whole plans (docs/PLANNING.md, "Registration"): with min_overlap the final
// stations' scan graph is connected, or the plan says which groups no candidate links; the
// reported overlaps are the brute-force intersections of the stations' own visibility sets;
// refinement and reduction never split the graph.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>

#include "testing/scenes.h"
#include "vc/plan/planner.h"
#include "vc/plan/scan_graph.h"
#include "vc/synth/synth.h"

namespace vc {
namespace {

using testing::Synthetic;

// Greedy selection: these tests are about how greedy selection, consolidation, refinement and
// reduction keep the scan graph; the connected integer program is tested in exact_selector_test
// (with the default auto it would spend its 20 s on every plan here for a bound).
PlanOptions Options(double min_overlap) {
  PlanOptions o;
  o.resolution_m = 0.1;
  o.min_overlap = min_overlap;
  o.solver = SelectionSolver::kGreedy;
  return o;
}

// Components of the plan's stations under `threshold`, from the reported edges.
int GroupsAt(const PlanResult& r, double threshold) {
  std::vector<int> parent(r.stations.size());
  for (size_t k = 0; k < parent.size(); ++k) parent[k] = static_cast<int>(k);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x];
    return x;
  };
  int groups = static_cast<int>(r.stations.size());
  for (const ScanGraph::Edge& e : r.scan_graph.edges) {
    if (e.overlap < threshold) continue;
    const int a = find(e.i), b = find(e.j);
    if (a != b) parent[b] = a, --groups;
  }
  return groups;
}

std::string Describe(const PlanResult& r) {
  std::string s = std::to_string(r.stations.size()) +
                  " stations, G = " + std::to_string(r.evaluation.overall.global_visibility) + ", " +
                  std::to_string(r.scan_graph.components.size()) + " groups, " + std::to_string(r.connecting_stations) +
                  " connecting";
  for (const auto& w : r.warnings) s += "\n  warning: " + w;
  return s;
}

TEST(Registration, RoomsOffACorridorSplitWithoutItAndAreLinkedWithIt) {
  const SceneInput in = Synthetic("rooms:3");
  Result<PlanResult> off = Plan(in, Options(0));
  ASSERT_TRUE(off.ok()) << off.status().ToString();
  std::cout << "[ rooms:3 off ] " << Describe(*off) << "\n";
  EXPECT_GT(GroupsAt(*off, 0.3), 1);       // each room's station shares little with the corridor's
  EXPECT_TRUE(off->scan_graph.connected);  // min_overlap 0: any shared voxel links

  Result<PlanResult> on = Plan(in, Options(0.3));
  ASSERT_TRUE(on.ok()) << on.status().ToString();
  std::cout << "[ rooms:3 0.3 ] " << Describe(*on) << "\n";
  EXPECT_TRUE(on->scan_graph.connected);
  EXPECT_EQ(on->scan_graph.components.size(), 1u);
  EXPECT_EQ(GroupsAt(*on, 0.3), 1);
  EXPECT_GT(on->stations.size(), off->stations.size());
  EXPECT_GE(double(on->covered_voxels), 0.99 * double(on->coverable_voxels));
  for (const std::string& w : on->warnings) EXPECT_EQ(w.find("groups"), std::string::npos) << w;
}

// tworooms (docs/SCENES.md): rooms A = [0, 5] and B = [5.25, 10.25] x [0, 4] m, the door at
// x [5, 5.25], y [0.3, 1.2] (design coordinates; the scene is shifted by kSceneOffsetM).
WorldPoint TwoRoomsPoint(double x, double y) { return WorldPoint(x, y, 1.5) + kSceneOffsetM; }

TEST(Registration, TwoRoomsGetAStationInTheDoorToLinkThem) {
  const SceneInput in = Synthetic("tworooms");
  PlanOptions off = Options(0);
  // Far in each room, in line with the door (so each sees the whole door opening: SCENES.md's
  // proof of the optimum), and the doorway itself.
  off.candidates = {TwoRoomsPoint(1.0, 0.75), TwoRoomsPoint(9.25, 0.75), TwoRoomsPoint(5.125, 0.75)};
  Result<PlanResult> plain = Plan(in, off);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  std::cout << "[ tworooms off ] " << Describe(*plain) << "\n";
  ASSERT_EQ(plain->stations.size(), 2u);  // one per room
  for (const PlannedStation& s : plain->stations) EXPECT_NE(s.candidate_index, 2);
  EXPECT_EQ(GroupsAt(*plain, 0.3), 2);

  PlanOptions on = off;
  on.min_overlap = 0.3;
  Result<PlanResult> linked = Plan(in, on);
  ASSERT_TRUE(linked.ok()) << linked.status().ToString();
  std::cout << "[ tworooms 0.3 ] " << Describe(*linked) << "\n";
  EXPECT_EQ(linked->stations.size(), 3u);
  EXPECT_TRUE(std::any_of(linked->stations.begin(), linked->stations.end(),
                          [](const PlannedStation& s) { return s.candidate_index == 2; }));
  EXPECT_TRUE(linked->scan_graph.connected);

  // Without the doorway nothing can link the rooms: the plan says so, with the groups.
  on.candidates.pop_back();
  Result<PlanResult> apart = Plan(in, on);
  ASSERT_TRUE(apart.ok()) << apart.status().ToString();
  EXPECT_FALSE(apart->scan_graph.connected);
  EXPECT_EQ(apart->scan_graph.components, (std::vector<std::vector<int>>{{0}, {1}}));
  EXPECT_TRUE(std::any_of(apart->warnings.begin(), apart->warnings.end(),
                          [](const std::string& w) { return w.find("2 groups ([1], [2]") != std::string::npos; }));
}

TEST(Registration, ReportedOverlapsAreTheIntersectionsOfTheStationsSets) {
  const SceneInput in = Synthetic("rooms:3");
  const PlanOptions options = Options(0.3);
  Result<PlanResult> r = Plan(in, options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  Result<VoxelScene> scene = Voxelize(in, {options.resolution_m, options.memory_budget_bytes});
  ASSERT_TRUE(scene.ok());
  std::vector<WorldPoint> positions;
  for (const PlannedStation& s : r->stations) positions.push_back(s.position);
  VisibilitySetsOptions set_options{options.selection_test, 0};
  set_options.scanner = options.scanner;
  Result<std::vector<VoxelSet>> sets = ComputeVisibilitySets(*scene, positions, set_options);
  ASSERT_TRUE(sets.ok());
  size_t pairs = 0;
  for (size_t i = 0; i < positions.size(); ++i) {
    for (size_t j = i + 1; j < positions.size(); ++j) {
      uint64_t common = 0, ni = 0, nj = 0;
      for (size_t v = 0; v < (*sets)[i].size(); ++v) {
        ni += (*sets)[i].test(v);
        nj += (*sets)[j].test(v);
        common += (*sets)[i].test(v) && (*sets)[j].test(v);
      }
      if (common == 0) continue;
      ++pairs;
      const auto it = std::find_if(r->scan_graph.edges.begin(), r->scan_graph.edges.end(), [&](const auto& e) {
        return e.i == static_cast<int>(i) && e.j == static_cast<int>(j);
      });
      ASSERT_NE(it, r->scan_graph.edges.end()) << i << "-" << j;
      EXPECT_DOUBLE_EQ(it->overlap, double(common) / double(std::min(ni, nj))) << i << "-" << j;
    }
  }
  EXPECT_EQ(pairs, r->scan_graph.edges.size());
}

TEST(Registration, StoreysNoCandidateLinksAreReportedAsGroups) {
  PlanOptions o = Options(0.3);
  // The 99 % target alone: below it (the default gain rule stops greedy at 1 m^2 a station) the
  // exact solver finds a connected plan through the stair opening for what greedy covered.
  o.min_gain_m2_per_minute = 0;
  Result<PlanResult> r = Plan(Synthetic("twofloor"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ twofloor 0.3 ] " << Describe(*r) << "\n";
  ASSERT_FALSE(r->scan_graph.connected);
  EXPECT_EQ(r->scan_graph.components.size(), 2u);
  const bool warned = std::any_of(r->warnings.begin(), r->warnings.end(), [](const std::string& w) {
    return w.find("2 groups") != std::string::npos && w.find("min_overlap = 0.3") != std::string::npos;
  });
  EXPECT_TRUE(warned);
}

TEST(Registration, RefinementAndReductionKeepTheGraphConnected) {
  PlanOptions o = Options(0.3);
  o.refine = true;
  o.reduce_to = 3;  // removals down to 3 stations, each allowed only if the graph stays connected
  Result<PlanResult> r = Plan(Synthetic("rooms:3"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ rooms:3 0.3 refine reduce_to 3 ] " << Describe(*r) << "\n";
  EXPECT_TRUE(r->scan_graph.connected);
  EXPECT_EQ(GroupsAt(*r, 0.3), 1);
}

TEST(Route, StairsAreClimbedAndTheFieldTimeAddsUp) {
  PlanOptions o = Options(0);
  o.scanner.name = "leica-rtc360";  // scan time 26 s (scanner_presets.cc)
  o.setup_seconds = 90;
  o.walk_speed_mps = 0.5;
  o.route_start = WorldPoint(7.5, 5.5, std::numeric_limits<double>::quiet_NaN()) + kSceneOffsetM;
  Result<PlanResult> r = Plan(Synthetic("stairs"), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ stairs route ] " << Describe(*r) << ", route " << r->route.length_m << " m\n";
  const size_t n = r->stations.size();
  ASSERT_EQ(r->route.order.size(), n);
  EXPECT_EQ(r->route.parts, 1);  // the flight links the storeys
  for (double leg : r->route.legs_m) EXPECT_TRUE(std::isfinite(leg));
  EXPECT_GT(r->route.legs_m[0], 0.0);  // from the start
  // Some leg climbs from the lower floor (z ~0) to the upper one (z ~3.3).
  bool climbs = false;
  for (const auto& line : r->route.polylines) {
    if (line.size() < 2) continue;
    climbs |= std::abs(line.back().z() - line.front().z()) > 3.0;
  }
  EXPECT_TRUE(climbs);
  EXPECT_DOUBLE_EQ(r->field_time.scan_seconds_per_station, 26.0);
  EXPECT_DOUBLE_EQ(r->field_time.setup_s, 90.0 * n);
  EXPECT_DOUBLE_EQ(r->field_time.scan_s, 26.0 * n);
  EXPECT_DOUBLE_EQ(r->field_time.walk_s, r->route.length_m / 0.5);
  EXPECT_DOUBLE_EQ(r->field_time.total_s, r->field_time.setup_s + r->field_time.scan_s + r->field_time.walk_s);
  // scan_seconds overrides the preset.
  o.scan_seconds = 60;
  EXPECT_DOUBLE_EQ(ComputeFieldTime(4, 100, o).total_s, 4 * 90 + 4 * 60 + 100 / 0.5);
  o.scan_seconds = 0;
  o.scanner.name.clear();  // no preset, no scan time
  EXPECT_DOUBLE_EQ(ComputeFieldTime(4, 100, o).scan_s, 0.0);
}

TEST(Registration, BadMinOverlapIsRefused) {
  PlanOptions o = Options(1.5);
  Result<PlanResult> r = Plan(Synthetic("box"), o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("min_overlap"), std::string::npos) << r.status().ToString();
}

}  // namespace
}  // namespace vc
