// The proto <-> core conversions of vc/wire/convert.h: plan parameters both ways, and a plan's or
// an evaluation's result cut into chunks and reassembled (the scanner model's conversion:
// scanner_convert_test.cc).
#include "vc/wire/convert.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vc::wire {
namespace {

TEST(PlanParameters, RoundTripKeepsEveryField) {
  PlanOptions o;
  o.resolution_m = 0.07;
  o.memory_budget_bytes = 12345;
  o.selection_test = SelectionTest::kCompatibility;
  o.scanner.min_range_m = 0.3;
  o.scanner.max_range_m = 40;
  o.grid_spacing_m = 0.7;
  o.tripod_height_m = 1.2;
  o.clearance_m = 0.4;
  o.candidates = {{1, 2, 3}, {4, 5, 6}};
  o.max_stations = 9;
  o.min_marginal_gain_voxels = 17;
  o.target_coverage = 0.9;
  o.min_gain_voxels_per_minute = 12.5;
  o.min_gain_m2_per_minute = 0;
  o.refine = !PlanOptions{}.refine;
  o.refine_radius_m = 0.8;
  o.refine_step_m = 0.1;
  o.reduce = !PlanOptions{}.reduce;
  o.reduce_to = 3;
  o.threads = 5;
  o.consolidate = !PlanOptions{}.consolidate;
  o.min_overlap = 0.3;
  o.setup_seconds = 90;
  o.scan_seconds = 45;
  o.walk_speed_mps = 0.8;
  o.solver = SelectionSolver::kExact;
  o.solve_seconds = 7.5;
  o.local_candidates = !PlanOptions{}.local_candidates;
  o.local_candidates_radius_m = 0.75;
  o.local_candidates_step_m = 0.3;
  o.local_candidates_rounds = 2;
  o.coarse_above_candidates = 1234;
  o.route_start = WorldPoint(1, 2, std::nan(""));
  auto back = FromProto(ToProto(o));
  ASSERT_TRUE(back.ok());
  // Compare through the proto (every field), so a field added to one side only shows up here.
  EXPECT_EQ(ToProto(*back).SerializeAsString(), ToProto(o).SerializeAsString());
  EXPECT_EQ(back->selection_test, SelectionTest::kCompatibility);
  EXPECT_EQ(back->solver, SelectionSolver::kExact);
  EXPECT_EQ(back->solve_seconds, 7.5);
  EXPECT_EQ(back->min_gain_voxels_per_minute, 12.5);
  EXPECT_EQ(back->min_gain_m2_per_minute, 0.0);
  EXPECT_TRUE(back->local_candidates);
  EXPECT_EQ(back->local_candidates_radius_m, 0.75);
  EXPECT_EQ(back->local_candidates_step_m, 0.3);
  EXPECT_EQ(back->local_candidates_rounds, 2);
  EXPECT_EQ(back->coarse_above_candidates, 1234);
  EXPECT_EQ(back->candidates.size(), 2u);
  ASSERT_TRUE(back->route_start.has_value());
  EXPECT_TRUE(std::isnan(back->route_start->z()));
  EXPECT_FALSE(FromProto(ToProto(PlanOptions{}))->route_start.has_value());
}

TEST(PlanParameters, GroundModelsCrossTheWireAndAnUnknownOneIsRefused) {
  for (GroundModel g : {GroundModel::kAuto, GroundModel::kFloors, GroundModel::kTerrain}) {
    PlanOptions o;
    o.ground = g;
    Result<PlanOptions> back = FromProto(ToProto(o));
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->ground, g);
  }
  v1::PlanParameters p;
  p.set_ground(static_cast<v1::GroundModel>(9));
  Result<PlanOptions> bad = FromProto(p);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("unknown ground model value 9"), std::string::npos) << bad.status().ToString();
}

TEST(PlanParameters, UnsetFieldsTakeTheDefaults) {
  auto o = FromProto(v1::PlanParameters{});
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(ToProto(*o).SerializeAsString(), ToProto(PlanOptions{}).SerializeAsString());
}

// A request with the voxel gain rule and no area rule: the voxel rule takes the default area
// rule's place; with both fields set, both are kept (and PlanOptions::Validate refuses both > 0).
TEST(PlanParameters, VoxelGainRuleAloneReplacesTheAreaRule) {
  v1::PlanParameters p;
  p.set_min_gain_voxels_per_minute(50);
  auto o = FromProto(p);
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(o->min_gain_voxels_per_minute, 50);
  EXPECT_EQ(o->min_gain_m2_per_minute, 0.0);
  EXPECT_TRUE(o->Validate().ok());
  p.set_min_gain_m2_per_minute(0.25);
  o = FromProto(p);
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(o->min_gain_m2_per_minute, 0.25);
  EXPECT_EQ(o->Validate().code(), StatusCode::kInvalidArgument);
  p.clear_min_gain_voxels_per_minute();
  p.clear_min_gain_m2_per_minute();
  EXPECT_EQ(FromProto(p)->min_gain_m2_per_minute, PlanOptions{}.min_gain_m2_per_minute);
}

PlanResult BigResult(size_t voxels, size_t candidates) {
  PlanResult r;
  r.resolution_m = 0.1;
  r.selection_test = SelectionTest::kSurfaceVisibility;
  for (size_t i = 0; i < voxels; ++i) {
    r.voxel_centers.emplace_back(i * 0.1, -double(i), 0.5);
    std::array<float, kFacesPerVoxel> v{};
    for (int f = 0; f < kFacesPerVoxel; ++f) v[f] = float(i % 97) / 97.f + float(f);
    r.evaluation.best_face_values.push_back(v);
    r.evaluation.sole_viewer.push_back(int32_t(i % 4) - 2);  // several, none, station 0, station 1
  }
  for (size_t i = 0; i < candidates; ++i) {
    r.heat_map.positions.emplace_back(double(i), 0, 1.5);
    r.heat_map.visible_voxels.push_back(i * 3);
    r.heat_map.floor_z_m.push_back(i % 2 ? 0.25 : std::nan(""));
  }
  r.heat_map.grid_spacing_m = 1;
  r.stations.push_back({{1, 2, 3}, 10, 10, 0.5, 0.2, 4, false, 1.5});
  r.stations.push_back({{0, 0, 0}, 5, 5, 0.6, 0.1, -1, true});  // a fixed station, no floor below it
  r.reduction.size = 1;
  r.reduction.matrix = {0.25};
  r.occupied_voxels = voxels;
  r.evaluation.per_viewpoint.resize(1);
  r.evaluation.overall.global_visibility = 0.42;
  r.timings.push_back({Stage::kSelection, 1.5, uint64_t{3} << 30});
  r.total_seconds = 2.5;
  r.warnings.push_back("w");
  r.reduction.positions = {{1, 2, 3}};
  r.floor_levels_m = {0.0, 3.1};
  r.stop_reason = StopReason::kTargetReached;
  r.greedy_stations = 2;
  r.consolidated = 1;
  r.grid_cells = 11;
  r.cells_without_floor = 3;
  r.cells_failing_clearance = 2;
  r.scan_graph = {0.3, false, {{0}, {1}}, {{0, 1, 0.1}}};
  r.connecting_stations = 1;
  r.route.order = {1, 0};
  r.route.legs_m = {0.5, std::nan("")};
  r.route.polylines = {{{0, 0, 0}, {0.5, 0, 0}}, {}};
  r.route.length_m = 0.5;
  r.route.parts = 2;
  r.route.start = WorldPoint(0.5, 0, 0);
  r.field_time = {240, 90, 0.5, 330.5, 45};
  r.optimality.solver = "exact";
  r.optimality.status = planner::OptimalityStatus::kFeasible;
  r.optimality.stations = 2;
  r.optimality.lower_bound = 1;
  r.optimality.gap = 0.5;
  r.optimality.covered_bound = 9;
  r.optimality.seconds = 1.25;
  r.optimality.before = {7, 300, 301};
  r.optimality.model = {3, 12, 13};
  r.optimality.forced = 1;
  r.optimality.dominated = 2;
  r.optimality.note = "n";
  r.optimality.local_candidates = {2, 90, {4, 3, 3}, {26912, 26912, 26912}, "coarse then fine: why"};
  r.distribution = {3, 31, 2, 5000000000};
  r.coverage_curve = {{1, 5, 0.5, 0.25, 165}, {2, 9, 0.9, 0.45, 330, 10, 9, false}};
  r.unseen_causes = {1, 2, 3, 4, 5, 6, 7};
  return r;
}

// A station's figures between replicas (FaceValues.figures): every double bit for bit.
TEST(VisibilityFigures, RoundTripBitForBit) {
  const VisibilityFigures f{0.1 + 0.2, 1.0 / 3.0, std::nextafter(0.5, 1.0), 5e-324};
  const VisibilityFigures back = FromProto(ToProto(f));
  EXPECT_EQ(back.global_visibility, f.global_visibility);
  EXPECT_EQ(back.fully_visible_fraction, f.fully_visible_fraction);
  EXPECT_EQ(back.mean_full_visibility, f.mean_full_visibility);
  EXPECT_EQ(back.partially_visible_fraction, f.partially_visible_fraction);
}

TEST(PlanResultChunks, TheGroundChoiceRoundTrips) {
  PlanResult r = BigResult(3, 2);
  r.ground = {GroundModel::kTerrain, 0.37, "terrain: only 37%"};
  PlanResultAssembler a;
  for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) ASSERT_TRUE(a.AddHeatMap(c).ok());
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
    EXPECT_TRUE(a.AddVoxels(c).ok());
    return true;
  });
  auto back = std::move(a).Finish(ToProto(r));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->ground.model, GroundModel::kTerrain);
  EXPECT_EQ(back->ground.floor_share, 0.37);
  EXPECT_EQ(back->ground.reason, "terrain: only 37%");
}

TEST(PlanResultChunks, ReassembleExactlyAndStayUnderOneMebibyte) {
  const PlanResult r = BigResult(3 * kVoxelsPerChunk + 5, kCandidatesPerHeatMapChunk + 1);
  PlanResultAssembler a;
  for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) {
    EXPECT_LE(c.ByteSizeLong(), size_t{1} << 20);
    ASSERT_TRUE(a.AddHeatMap(c).ok());
  }
  int chunks = 0;
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
    EXPECT_LE(c.ByteSizeLong(), size_t{1} << 20);
    EXPECT_TRUE(a.AddVoxels(c).ok());
    ++chunks;
    return true;
  });
  EXPECT_EQ(chunks, 4);
  auto back = std::move(a).Finish(ToProto(r));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->voxel_centers, r.voxel_centers);
  EXPECT_EQ(back->evaluation.best_face_values, r.evaluation.best_face_values);
  EXPECT_EQ(back->evaluation.sole_viewer, r.evaluation.sole_viewer);
  EXPECT_EQ(back->heat_map.positions, r.heat_map.positions);
  EXPECT_EQ(back->heat_map.visible_voxels, r.heat_map.visible_voxels);
  ASSERT_EQ(back->heat_map.floor_z_m.size(), r.heat_map.floor_z_m.size());
  EXPECT_TRUE(std::isnan(back->heat_map.floor_z_m[0]));
  EXPECT_EQ(back->heat_map.floor_z_m[1], 0.25);
  EXPECT_EQ(back->stations[0].position, r.stations[0].position);
  EXPECT_EQ(back->stations[0].candidate_index, 4);
  EXPECT_FALSE(back->stations[0].fixed);
  EXPECT_TRUE(back->stations[1].fixed);
  EXPECT_EQ(back->stations[0].floor_z_m, 1.5);
  EXPECT_TRUE(std::isnan(back->stations[1].floor_z_m));
  EXPECT_EQ(back->reduction.matrix, r.reduction.matrix);
  EXPECT_DOUBLE_EQ(back->evaluation.overall.global_visibility, 0.42);
  EXPECT_EQ(back->timings[0].stage, Stage::kSelection);
  EXPECT_EQ(back->timings[0].peak_rss_bytes, uint64_t{3} << 30);
  EXPECT_EQ(back->total_seconds, 2.5);
  EXPECT_EQ(back->warnings, r.warnings);
  EXPECT_EQ(back->reduction.positions, r.reduction.positions);
  EXPECT_EQ(back->floor_levels_m, r.floor_levels_m);
  EXPECT_EQ(back->stop_reason, StopReason::kTargetReached);
  EXPECT_EQ(back->greedy_stations, 2);
  EXPECT_EQ(back->consolidated, 1);
  EXPECT_EQ(back->grid_cells, 11u);
  EXPECT_EQ(back->cells_without_floor, 3u);
  EXPECT_EQ(back->cells_failing_clearance, 2u);
  EXPECT_EQ(back->scan_graph.min_overlap, 0.3);
  EXPECT_FALSE(back->scan_graph.connected);
  EXPECT_EQ(back->scan_graph.components, r.scan_graph.components);
  ASSERT_EQ(back->scan_graph.edges.size(), 1u);
  EXPECT_EQ(back->scan_graph.edges[0].overlap, 0.1);
  EXPECT_EQ(back->connecting_stations, 1);
  EXPECT_EQ(back->route.order, r.route.order);
  EXPECT_EQ(back->route.legs_m[0], 0.5);
  EXPECT_TRUE(std::isnan(back->route.legs_m[1]));
  EXPECT_EQ(back->route.polylines, r.route.polylines);
  EXPECT_EQ(back->route.parts, 2);
  EXPECT_EQ(back->route.start, r.route.start);
  EXPECT_EQ(back->field_time.total_s, 330.5);
  EXPECT_EQ(back->field_time.scan_seconds_per_station, 45);
  const planner::Optimality& o = back->optimality;
  EXPECT_EQ(o.solver, "exact");
  EXPECT_EQ(o.status, planner::OptimalityStatus::kFeasible);
  EXPECT_EQ(o.stations, 2);
  EXPECT_EQ(o.lower_bound, 1);
  EXPECT_EQ(o.gap, 0.5);
  EXPECT_EQ(o.covered_bound, 9u);
  EXPECT_EQ(o.seconds, 1.25);
  EXPECT_EQ(o.before.candidates, 7);
  EXPECT_EQ(o.before.voxel_classes, 300);
  EXPECT_EQ(o.before.rows, 301);
  EXPECT_EQ(o.model.candidates, 3);
  EXPECT_EQ(o.model.voxel_classes, 12);
  EXPECT_EQ(o.model.rows, 13);
  EXPECT_EQ(o.forced, 1);
  EXPECT_EQ(o.dominated, 2);
  EXPECT_EQ(o.note, "n");
  EXPECT_EQ(o.local_candidates.rounds, 2);
  EXPECT_EQ(o.local_candidates.added, 90);
  EXPECT_EQ(o.local_candidates.stations_per_solve, (std::vector<int>{4, 3, 3}));
  EXPECT_EQ(o.local_candidates.covered_per_solve, (std::vector<uint64_t>{26912, 26912, 26912}));
  EXPECT_EQ(o.local_candidates.coarse_to_fine, "coarse then fine: why");
  EXPECT_EQ(back->distribution.replicas, 3);
  EXPECT_EQ(back->distribution.shards, 31);
  EXPECT_EQ(back->distribution.retried, 2);
  EXPECT_EQ(back->distribution.bytes_exchanged, 5000000000u);
  ASSERT_EQ(back->coverage_curve.size(), 2u);
  EXPECT_EQ(back->coverage_curve[1].stations, 2);
  EXPECT_EQ(back->coverage_curve[1].covered_voxels, 9u);
  EXPECT_EQ(back->coverage_curve[1].coverable_fraction, 0.9);
  EXPECT_EQ(back->coverage_curve[1].scene_fraction, 0.45);
  EXPECT_EQ(back->coverage_curve[1].setup_scan_s, 330);
  EXPECT_FALSE(back->coverage_curve[0].best_voxels_upper_bound);  // not computed stays absent
  EXPECT_FALSE(back->coverage_curve[0].best_voxels);
  EXPECT_EQ(back->coverage_curve[1].best_voxels_upper_bound, 10u);
  EXPECT_EQ(back->coverage_curve[1].best_voxels, 9u);
  EXPECT_FALSE(back->coverage_curve[1].best_voxels_optimal);
  EXPECT_EQ(back->unseen_causes.interior, 1u);
  EXPECT_EQ(back->unseen_causes.in_keep_out, 2u);
  EXPECT_EQ(back->unseen_causes.no_candidate_on_floor, 3u);
  EXPECT_EQ(back->unseen_causes.out_of_range, 4u);
  EXPECT_EQ(back->unseen_causes.outside_field_of_view, 5u);
  EXPECT_EQ(back->unseen_causes.faces_away, 6u);
  EXPECT_EQ(back->unseen_causes.hidden, 7u);
}

TEST(PlanResultChunks, EveryStopReasonRoundTrips) {
  for (StopReason s : {StopReason::kExhausted, StopReason::kTargetReached, StopReason::kMaxStations,
                       StopReason::kMinGain, StopReason::kGainRule}) {
    Result<StopReason> back = FromProto(ToProto(s));
    ASSERT_TRUE(back.ok()) << StopReasonName(s);
    EXPECT_EQ(*back, s) << StopReasonName(s);
  }
}

TEST(PlanResultChunks, ARouteOrGraphNamingAMissingStationIsDataLoss) {
  for (int bad = 0; bad < 3; ++bad) {
    const PlanResult r = BigResult(1, 1);
    v1::PlanResult p = ToProto(r);
    if (bad == 0) p.mutable_route()->set_order(0, 7);
    if (bad == 1) p.mutable_scan_graph()->mutable_edges(0)->set_j(-1);
    if (bad == 2) p.mutable_route()->add_legs_m(1.0);  // one leg more than stations in the order
    PlanResultAssembler a;
    for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) ASSERT_TRUE(a.AddHeatMap(c).ok());
    ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) { return a.AddVoxels(c).ok(); });
    auto back = std::move(a).Finish(p);
    ASSERT_FALSE(back.ok()) << bad;
    EXPECT_EQ(back.status().code(), StatusCode::kDataLoss) << bad;
  }
}

TEST(PlanResultChunks, ASoleViewerNamingAMissingStationOrOnSomeChunksOnlyIsDataLoss) {
  for (int bad = 0; bad < 3; ++bad) {
    PlanResult r = BigResult(2 * kVoxelsPerChunk, 1);
    PlanResultAssembler a;
    for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) ASSERT_TRUE(a.AddHeatMap(c).ok());
    if (bad == 0) r.evaluation.sole_viewer[5] = 2;  // there are 2 stations
    if (bad == 1) r.evaluation.sole_viewer[5] = -3;
    bool ok = true;
    int chunk = 0;
    ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
      if (bad == 2 && chunk++ == 1) c.clear_sole_viewer();
      ok = ok && a.AddVoxels(c).ok();
      return ok;
    });
    if (!ok) continue;  // refused chunk by chunk (-3, or viewers missing from one chunk)
    EXPECT_NE(bad, 1);
    EXPECT_NE(bad, 2);
    auto back = std::move(a).Finish(ToProto(r));
    ASSERT_FALSE(back.ok()) << bad;
    EXPECT_EQ(back.status().code(), StatusCode::kDataLoss) << bad;
  }
}

// A tripwire: when a field is added to PlanResult or PlanOptions, its size changes; carry the new
// field in proto/vc/v1/planner.proto and proto/src/convert.cc (both ways), then update the sizes.
// (1440: Evaluation::per_viewpoint_sparse_values, which like per_viewpoint_face_values is the
// reduction's working data and never part of a result on the wire. 1448 and 416: the scanner's
// hfov_deg, a row carried as ScannerModel.hfov_deg. 1560: unseen_causes. 1568 and 432: walk_max_step_m, a
// row carried as PlanParameters.walk_max_step_m; PlanResult holds the options. 1616: ground, carried as
// PlanResult.ground; PlanOptions' ground row, PlanParameters.ground, fits its padding. 1624 and 440:
// min_gain_m2_per_minute, a row carried as PlanParameters.min_gain_m2_per_minute. 1672:
// Evaluation::best_values and best_perceptions, the reduction's join state, cleared once its batches
// are joined and never part of a result on the wire. 1712 and 448: coarse_above_candidates, a row
// carried as PlanParameters.coarse_above_candidates, and LocalCandidatesReport::coarse_to_fine,
// carried as LocalCandidates.coarse_to_fine.)
TEST(PlanResultChunks, EveryCoreFieldIsCarried) {
  EXPECT_EQ(sizeof(PlanResult), 1712u) << "PlanResult changed: update the vc.v1 PlanResult and vc::wire";
  EXPECT_EQ(sizeof(PlanOptions), 448u) << "PlanOptions changed: update vc.v1 PlanParameters and vc::wire";
}

// A georeferenced plan: local positions, the frame's origin at UTM-like coordinates (and once
// with a z offset, for the heights).
TEST(PlanResultChunks, TheWireIsInTheInputsFrameAndTheResultComesBackLocal) {
  for (const WorldPoint origin : {WorldPoint(512000, 5612000, 0), WorldPoint(512000, 5612000, 2000)}) {
    PlanResult r = BigResult(kVoxelsPerChunk + 3, 5);
    r.frame_origin_m = origin;
    r.stations[0].position = WorldPoint(345.457, 330.123, 1.6);
    std::vector<v1::HeatMapChunk> heat = HeatMapChunks(r.heat_map, r.frame_origin_m);
    ASSERT_EQ(heat.size(), 1u);
    EXPECT_EQ(heat[0].positions(3).x_m(), 512003.0);
    EXPECT_EQ(heat[0].positions(3).z_m(), 1.5 + origin.z());
    EXPECT_EQ(heat[0].floor_z_m(1), 0.25 + origin.z());
    const v1::PlanResult summary = ToProto(r);
    EXPECT_EQ(FromProto(summary.frame_origin()), origin);
    EXPECT_NEAR(summary.stations(0).position().y_m(), 5612330.123, 1e-6);
    EXPECT_EQ(summary.stations(1).position().x_m(), 512000.0);
    EXPECT_EQ(summary.reduction().positions(0).y_m(), 5612002.0);
    EXPECT_EQ(summary.floor_levels_m(1), 3.1 + origin.z());
    EXPECT_EQ(summary.stations(0).floor_z_m(), 1.5 + origin.z());
    EXPECT_FALSE(summary.stations(1).has_floor_z_m());  // NaN: absent
    EXPECT_EQ(summary.route().start().x_m(), 512000.5);
    EXPECT_EQ(summary.route().polylines(0).points(1).x_m(), 512000.5);
    EXPECT_EQ(summary.options().SerializeAsString(), ToProto(r.options).SerializeAsString());  // as given
    PlanResultAssembler a;
    ASSERT_TRUE(a.AddHeatMap(heat[0]).ok());
    EXPECT_EQ(a.heat_map().positions[3].y(), 5612000.0);  // what a client shows while the plan runs
    std::vector<v1::VoxelChunk> voxels;
    ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
      voxels.push_back(c);
      return true;
    });
    ASSERT_EQ(voxels.size(), 2u);
    EXPECT_EQ(voxels[0].centers_xyz_m(3 * 7), 512000.0 + 7 * 0.1);
    EXPECT_EQ(voxels[0].centers_xyz_m(3 * 7 + 1), 5612000.0 - 7);
    for (const v1::VoxelChunk& c : voxels) ASSERT_TRUE(a.AddVoxels(c).ok());
    auto back = std::move(a).Finish(summary);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->frame_origin_m, origin);
    // Local again, to a nanometre; and in the input's frame, which is what the writers use, exact.
    auto same_place = [&](const WorldPoint& got, const WorldPoint& sent) {
      EXPECT_LT((got - sent).norm(), 1e-9) << got.transpose() << " vs " << sent.transpose();
      EXPECT_EQ(got + origin, sent + origin);
    };
    for (size_t k = 0; k < r.stations.size(); ++k) same_place(back->stations[k].position, r.stations[k].position);
    for (size_t i = 0; i < r.heat_map.positions.size(); ++i)
      same_place(back->heat_map.positions[i], r.heat_map.positions[i]);
    for (size_t i = 0; i < r.voxel_centers.size(); ++i) same_place(back->voxel_centers[i], r.voxel_centers[i]);
    same_place(back->reduction.positions[0], r.reduction.positions[0]);
    same_place(back->route.polylines[0][1], r.route.polylines[0][1]);
    same_place(*back->route.start, *r.route.start);
    ASSERT_EQ(back->floor_levels_m.size(), r.floor_levels_m.size());
    for (size_t i = 0; i < r.floor_levels_m.size(); ++i) {
      EXPECT_EQ(back->floor_levels_m[i] + origin.z(), r.floor_levels_m[i] + origin.z());
    }
    EXPECT_EQ(back->heat_map.floor_z_m[1] + origin.z(), 0.25 + origin.z());
    EXPECT_EQ(back->stations[0].floor_z_m + origin.z(), 1.5 + origin.z());
    EXPECT_TRUE(std::isnan(back->stations[1].floor_z_m));
    EXPECT_TRUE(std::isnan(back->heat_map.floor_z_m[0]));
  }
}

TEST(PlanResultChunks, AZeroOriginCarriesEveryBitAsBefore) {
  PlannedStation s;
  s.position = WorldPoint(-0.0, 1, 2);
  EXPECT_TRUE(std::signbit(ToProto(s, WorldPoint::Zero()).position().x_m()));
}

TEST(PlanResultChunks, ANonFiniteFrameOriginIsDataLoss) {
  PlanResult r = BigResult(2, 1);
  PlanResultAssembler a;
  for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) ASSERT_TRUE(a.AddHeatMap(c).ok());
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) { return a.AddVoxels(c).ok(); });
  v1::PlanResult summary = ToProto(r);
  summary.mutable_frame_origin()->set_x_m(std::nan(""));
  EXPECT_EQ(std::move(a).Finish(summary).status().code(), StatusCode::kDataLoss);
}

TEST(PlanResultChunks, MissingChunkIsDataLoss) {
  const PlanResult r = BigResult(2 * kVoxelsPerChunk, 3);
  PlanResultAssembler a;
  for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) ASSERT_TRUE(a.AddHeatMap(c).ok());
  bool first = true;
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
    if (!first) return true;  // drop the second chunk
    first = false;
    return a.AddVoxels(c).ok();
  });
  auto back = std::move(a).Finish(ToProto(r));
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), StatusCode::kDataLoss);
}

TEST(PlanResultChunks, SecondHeatMapIsDataLoss) {
  const PlanResult r = BigResult(1, 3);
  PlanResultAssembler a;
  for (const auto& c : HeatMapChunks(r.heat_map, r.frame_origin_m)) ASSERT_TRUE(a.AddHeatMap(c).ok());
  EXPECT_EQ(a.AddHeatMap(HeatMapChunks(r.heat_map, r.frame_origin_m).front()).code(), StatusCode::kDataLoss);
}

TEST(PlanResultChunks, MissingHeatMapIsDataLoss) {
  const PlanResult r = BigResult(1, 3);
  PlanResultAssembler a;
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) { return a.AddVoxels(c).ok(); });
  auto back = std::move(a).Finish(ToProto(r));
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), StatusCode::kDataLoss);
}

TEST(PlanResultChunks, OutOfOrderChunkIsDataLoss) {
  const PlanResult r = BigResult(2 * kVoxelsPerChunk, 0);
  std::vector<v1::VoxelChunk> chunks;
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
    chunks.push_back(std::move(c));
    return true;
  });
  ASSERT_EQ(chunks.size(), 2u);
  PlanResultAssembler a;
  EXPECT_EQ(a.AddVoxels(chunks[1]).code(), StatusCode::kDataLoss);
}

// An evaluation of two viewpoints with `voxels` voxels (BigResult's), its frame at `origin`.
EvaluateJobResult BigEvaluation(size_t voxels, const WorldPoint& origin = WorldPoint::Zero()) {
  const PlanResult plan = BigResult(voxels, 0);
  EvaluateJobResult r;
  r.evaluation = plan.evaluation;
  r.evaluation.per_viewpoint.resize(2);
  r.evaluation.per_viewpoint[1].global_visibility = 0.37;
  r.voxel_centers = plan.voxel_centers;
  r.frame_origin_m = origin;
  r.viewpoints = {origin + WorldPoint(1, 2, 1.5), origin + WorldPoint(3, 2, 1.5)};
  return r;
}

std::vector<v1::VoxelChunk> EvaluationChunks(const EvaluateJobResult& r) {
  std::vector<v1::VoxelChunk> chunks;
  ForEachVoxelChunk(r, [&](v1::VoxelChunk&& c) {
    chunks.push_back(std::move(c));
    return true;
  });
  return chunks;
}

TEST(EvaluateResultChunks, ReassembleExactlyWithTheVoxelsLocalAndTheViewpointsAsGiven) {
  for (const WorldPoint origin : {WorldPoint(0, 0, 0), WorldPoint(512000, 5612000, 100)}) {
    const EvaluateJobResult r = BigEvaluation(2 * kVoxelsPerChunk + 5, origin);
    const std::vector<v1::VoxelChunk> chunks = EvaluationChunks(r);
    ASSERT_EQ(chunks.size(), 3u);
    EXPECT_EQ(chunks[0].centers_xyz_m(3 * 7), origin.x() + 7 * 0.1);  // the input's frame on the wire
    const v1::EvaluateResult summary = ToProto(r);
    EXPECT_EQ(summary.voxel_count(), r.voxel_centers.size());
    EXPECT_EQ(summary.evaluation().face_value_voxels(), r.voxel_centers.size());
    EXPECT_EQ(FromProto(summary.frame_origin()), origin);
    EvaluateResultAssembler a;
    for (const v1::VoxelChunk& c : chunks) {
      EXPECT_LE(c.ByteSizeLong(), size_t{1} << 20);
      ASSERT_TRUE(a.AddVoxels(c).ok());
    }
    auto back = std::move(a).Finish(summary);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->viewpoints, r.viewpoints);
    EXPECT_EQ(back->frame_origin_m, origin);
    ASSERT_EQ(back->voxel_centers.size(), r.voxel_centers.size());
    for (size_t i = 0; i < r.voxel_centers.size(); i += 997) {
      EXPECT_LT((back->voxel_centers[i] - r.voxel_centers[i]).norm(), 1e-9) << i;
    }
    EXPECT_EQ(back->evaluation.best_face_values, r.evaluation.best_face_values);
    EXPECT_EQ(back->evaluation.sole_viewer, r.evaluation.sole_viewer);
    EXPECT_EQ(back->evaluation.per_viewpoint[1].global_visibility, 0.37);
  }
}

TEST(EvaluateResultChunks, WithoutFaceValuesOnlyTheCentresTravel) {
  EvaluateJobResult r = BigEvaluation(kVoxelsPerChunk + 1);
  r.evaluation.best_face_values.clear();  // a sampled evaluation
  r.evaluation.sole_viewer.clear();
  EvaluateResultAssembler a;
  for (const v1::VoxelChunk& c : EvaluationChunks(r)) {
    EXPECT_EQ(c.best_face_values_size(), 0);
    ASSERT_TRUE(a.AddVoxels(c).ok());
  }
  const v1::EvaluateResult summary = ToProto(r);
  EXPECT_EQ(summary.evaluation().face_value_voxels(), 0u);
  auto back = std::move(a).Finish(summary);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->voxel_centers.size(), r.voxel_centers.size());
  EXPECT_TRUE(back->evaluation.best_face_values.empty());
}

TEST(EvaluateResultChunks, MissingOrOutOfOrderChunkIsDataLoss) {
  const EvaluateJobResult r = BigEvaluation(2 * kVoxelsPerChunk + 5);
  const std::vector<v1::VoxelChunk> chunks = EvaluationChunks(r);
  ASSERT_EQ(chunks.size(), 3u);
  {
    EvaluateResultAssembler a;
    EXPECT_EQ(a.AddVoxels(chunks[1]).code(), StatusCode::kDataLoss);
  }
  {
    EvaluateResultAssembler a;
    ASSERT_TRUE(a.AddVoxels(chunks[0]).ok());
    EXPECT_EQ(a.AddVoxels(chunks[2]).code(), StatusCode::kDataLoss);
  }
  {
    EvaluateResultAssembler a;  // the last chunk never came
    ASSERT_TRUE(a.AddVoxels(chunks[0]).ok());
    ASSERT_TRUE(a.AddVoxels(chunks[1]).ok());
    auto back = std::move(a).Finish(ToProto(r));
    EXPECT_EQ(back.status().code(), StatusCode::kDataLoss);
    EXPECT_NE(back.status().message().find("received 32768 voxels of 32773"), std::string::npos)
        << back.status().message();
  }
}

TEST(EvaluateResultChunks, ASoleViewerNamingAMissingViewpointOrANonFiniteOriginIsDataLoss) {
  for (int bad = 0; bad < 2; ++bad) {
    EvaluateJobResult r = BigEvaluation(100);
    v1::EvaluateResult summary = ToProto(r);
    if (bad == 0) summary.mutable_viewpoints()->RemoveLast();  // sole viewers name viewpoint 1
    if (bad == 1) summary.mutable_frame_origin()->set_y_m(std::nan(""));
    EvaluateResultAssembler a;
    for (const v1::VoxelChunk& c : EvaluationChunks(r)) ASSERT_TRUE(a.AddVoxels(c).ok());
    auto back = std::move(a).Finish(summary);
    EXPECT_EQ(back.status().code(), StatusCode::kDataLoss) << bad;
  }
}

// BigEvaluation's with seen sets: viewpoint 0 sees every third voxel, viewpoint 1 nothing.
EvaluateJobResult WithSeenSets(size_t voxels) {
  EvaluateJobResult r = BigEvaluation(voxels);
  r.selection_test = SelectionTest::kSubvoxel;
  r.seen_sets.assign(2, VoxelSet(voxels));
  for (size_t id = 0; id < voxels; id += 3) r.seen_sets[0].set(id);
  r.warnings = {"a note"};
  return r;
}

std::vector<v1::SeenSetChunk> SeenSetChunks(const EvaluateJobResult& r) {
  std::vector<v1::SeenSetChunk> chunks;
  ForEachSeenSetChunk(r, [&](v1::SeenSetChunk&& c) {
    chunks.push_back(std::move(c));
    return true;
  });
  return chunks;
}

TEST(EvaluateResultChunks, SeenSetsReassembleExactlyInChunksUnderOneMebibyte) {
  const size_t voxels = 3 * kSeenIdsPerChunk + 10;
  const EvaluateJobResult r = WithSeenSets(voxels);
  const std::vector<v1::SeenSetChunk> chunks = SeenSetChunks(r);
  ASSERT_EQ(chunks.size(), 3u);  // 393,220 / 3 ids: two chunks, then one empty chunk for viewpoint 1
  EXPECT_EQ(chunks[1].viewpoint(), 0u);
  EXPECT_EQ(chunks[1].first_index(), kSeenIdsPerChunk);
  EXPECT_EQ(chunks[2].viewpoint(), 1u);
  EXPECT_EQ(chunks[2].voxel_ids_size(), 0);
  const v1::EvaluateResult summary = ToProto(r);
  EXPECT_EQ(summary.selection_test(), v1::SELECTION_TEST_SUBVOXEL);
  ASSERT_EQ(summary.seen_voxels_size(), 2);
  EXPECT_EQ(summary.seen_voxels(0), r.seen_sets[0].count());
  EvaluateResultAssembler a;
  for (const v1::VoxelChunk& c : EvaluationChunks(r)) ASSERT_TRUE(a.AddVoxels(c).ok());
  for (const v1::SeenSetChunk& c : chunks) {
    EXPECT_LE(c.ByteSizeLong(), size_t{1} << 20);
    ASSERT_TRUE(a.AddSeenSet(c).ok());
  }
  auto back = std::move(a).Finish(summary);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->selection_test, SelectionTest::kSubvoxel);
  EXPECT_EQ(back->warnings, r.warnings);
  ASSERT_EQ(back->seen_sets.size(), 2u);
  EXPECT_EQ(back->seen_sets[0].words(), r.seen_sets[0].words());
  EXPECT_EQ(back->seen_sets[1].count(), 0u);
}

TEST(EvaluateResultChunks, NoSeenSetsTravelUnlessComputed) {
  const EvaluateJobResult r = BigEvaluation(100);
  EXPECT_TRUE(SeenSetChunks(r).empty());
  EvaluateResultAssembler a;
  for (const v1::VoxelChunk& c : EvaluationChunks(r)) ASSERT_TRUE(a.AddVoxels(c).ok());
  auto back = std::move(a).Finish(ToProto(r));
  ASSERT_TRUE(back.ok());
  EXPECT_TRUE(back->seen_sets.empty());
}

TEST(EvaluateResultChunks, AMissingOutOfOrderOrForeignSeenSetIsDataLoss) {
  const EvaluateJobResult r = WithSeenSets(300);
  const std::vector<v1::SeenSetChunk> chunks = SeenSetChunks(r);
  ASSERT_EQ(chunks.size(), 2u);
  {
    EvaluateResultAssembler a;
    EXPECT_EQ(a.AddSeenSet(chunks[1]).code(), StatusCode::kDataLoss);  // viewpoint 1 before viewpoint 0
  }
  {
    EvaluateResultAssembler a;
    v1::SeenSetChunk descending = chunks[0];
    descending.set_voxel_ids(1, 0);
    EXPECT_EQ(a.AddSeenSet(descending).code(), StatusCode::kDataLoss);
  }
  for (int bad = 0; bad < 3; ++bad) {
    EvaluateResultAssembler a;
    for (const v1::VoxelChunk& c : EvaluationChunks(r)) ASSERT_TRUE(a.AddVoxels(c).ok());
    v1::EvaluateResult summary = ToProto(r);
    ASSERT_TRUE(a.AddSeenSet(chunks[0]).ok());
    if (bad == 0) summary.set_seen_voxels(0, summary.seen_voxels(0) + 1);  // declares more than came
    if (bad == 1) summary.clear_seen_voxels();                             // the sets came undeclared
    if (bad != 2) ASSERT_TRUE(a.AddSeenSet(chunks[1]).ok());               // bad == 2: viewpoint 1 never came
    auto back = std::move(a).Finish(summary);
    EXPECT_EQ(back.status().code(), StatusCode::kDataLoss) << bad;
  }
  {
    EvaluateJobResult small = BigEvaluation(10);
    EvaluateResultAssembler a;
    for (const v1::VoxelChunk& c : EvaluationChunks(small)) ASSERT_TRUE(a.AddVoxels(c).ok());
    v1::SeenSetChunk foreign;
    foreign.set_total_voxels(1);
    foreign.add_voxel_ids(10);  // not a voxel of the 10
    v1::SeenSetChunk empty;
    empty.set_viewpoint(1);
    ASSERT_TRUE(a.AddSeenSet(foreign).ok());
    ASSERT_TRUE(a.AddSeenSet(empty).ok());
    v1::EvaluateResult summary = ToProto(small);
    summary.add_seen_voxels(1);
    summary.add_seen_voxels(0);
    auto back = std::move(a).Finish(summary);
    EXPECT_EQ(back.status().code(), StatusCode::kDataLoss);
    EXPECT_NE(back.status().message().find("names voxel 10 of 10"), std::string::npos) << back.status().message();
  }
}

TEST(EvaluateParameters, TheTestAndExportSetsRoundTrip) {
  EvaluateJobOptions o;
  o.viewpoints = {{1, 2, 3}};
  o.test = SelectionTest::kSubvoxel;
  o.export_sets = true;
  const v1::EvaluateParameters p = ToProto(o);
  EXPECT_EQ(p.test(), v1::SELECTION_TEST_SUBVOXEL);
  EXPECT_TRUE(p.export_sets());
  auto back = FromProto(p);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->test, SelectionTest::kSubvoxel);
  EXPECT_TRUE(back->export_sets);
  auto unset = FromProto(v1::EvaluateParameters());
  ASSERT_TRUE(unset.ok());
  EXPECT_EQ(unset->test, SelectionTest::kSurfaceVisibility);
  EXPECT_FALSE(unset->export_sets);
}

TEST(PlanParameters, EverySelectionTestRoundTrips) {
  for (const SelectionTest t :
       {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility, SelectionTest::kSubvoxel}) {
    auto back = FromProto(ToProto(t));
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(*back, t);
  }
}

}  // namespace
}  // namespace vc::wire
