// vc/plan/evaluate_job.h: what an Evaluate job refuses, the options it runs with, and that
// RunEvaluation gives exactly vc::Evaluate on the scene voxelised at the job's resolution.
#include "vc/plan/evaluate_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "testing/scenes.h"
#include "testing/subvoxel_reference.h"
#include "vc/plan/stages.h"
#include "vc/scene/surface_patches.h"

namespace vc {
namespace {

using ::testing::HasSubstr;

EvaluateJobOptions InsideTheBox(const SceneInput& box) {
  EvaluateJobOptions o;
  o.resolution_m = 0.2;
  const VoxelScene scene = *Voxelize(box, o.voxelize_options());
  o.viewpoints = {(scene.BoundsMin() + scene.BoundsMax()) / 2};
  return o;
}

TEST(EvaluateJobOptionsTest, ValidateNamesWhatIsWrong) {
  EvaluateJobOptions o;
  Status s = o.Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("no viewpoint to evaluate"));
  o.viewpoints = {{1, 2, 1.5}, {1, std::nan(""), 1.5}};
  EXPECT_THAT(o.Validate().message(), HasSubstr("viewpoint 1 has a non-finite coordinate"));
  o.viewpoints = {{1, 2, 1.5}};
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().ToString();
  o.resolution_m = -0.1;
  EXPECT_THAT(o.Validate().message(), HasSubstr("resolution_m must be"));
  o.resolution_m = 0;
  o.threads = -1;
  EXPECT_THAT(o.Validate().message(), HasSubstr("threads must be"));
  o.threads = 0;
  o.scanner.max_range_m = -5;
  EXPECT_THAT(o.Validate().message(), HasSubstr("scanner.max_range_m"));
  o.scanner = ScannerModel();
  o.scanner.hfov_deg = 90;  // evaluated viewpoints carry no heading
  EXPECT_THAT(o.Validate().message(), HasSubstr("scanner.hfov_deg"));
}

TEST(EvaluateJobOptionsTest, TheOptionsItRunsWithCarryEveryRow) {
  EvaluateJobOptions o;
  o.resolution_m = 0.05;
  o.memory_budget_bytes = 12345;
  o.faces = FaceSet::kExposed;
  o.sample_faces = 500;
  o.seed = 9;
  o.threads = 3;
  o.scanner.max_range_m = 12;
  const VoxelizeOptions v = o.voxelize_options();
  EXPECT_EQ(v.resolution_m, 0.05);
  EXPECT_EQ(v.memory_budget_bytes, 12345u);
  const EvaluateOptions e = o.evaluate_options();
  EXPECT_EQ(e.faces, FaceSet::kExposed);
  EXPECT_EQ(e.sample_faces, 500u);
  EXPECT_EQ(e.seed, 9u);
  EXPECT_EQ(e.threads, 3);
  EXPECT_EQ(e.scanner.max_range_m, 12);
  EXPECT_FALSE(e.keep_face_values);  // sampling keeps none
  o.sample_faces = 0;
  EXPECT_TRUE(o.evaluate_options().keep_face_values);
  EXPECT_FALSE(e.keep_per_viewpoint_values);
  EXPECT_FALSE(e.keep_sparse_per_viewpoint_values);
}

TEST(RunEvaluationTest, GivesEvaluateOnTheSceneAtTheJobsResolution) {
  const SceneInput box = testing::Synthetic("box");
  for (const FaceSet faces : {FaceSet::kAll, FaceSet::kExposed}) {
    EvaluateJobOptions o = InsideTheBox(box);
    o.faces = faces;
    const Result<EvaluateJobResult> job = RunEvaluation(box, o);
    ASSERT_TRUE(job.ok()) << job.status().ToString();
    const Result<Evaluation> direct = Evaluate(*Voxelize(box, {0.2}), o.viewpoints, o.evaluate_options());
    ASSERT_TRUE(direct.ok());
    EXPECT_EQ(job->evaluation.resolution_m, 0.2);
    EXPECT_EQ(job->evaluation.faces_total, direct->faces_total);
    ASSERT_EQ(job->evaluation.per_viewpoint.size(), 1u);
    EXPECT_EQ(job->evaluation.overall.global_visibility, direct->overall.global_visibility);
    EXPECT_GT(job->evaluation.overall.global_visibility, 0.0);
    EXPECT_EQ(job->evaluation.best_face_values, direct->best_face_values);
    EXPECT_EQ(job->evaluation.sole_viewer, direct->sole_viewer);
  }
}

TEST(RunEvaluationTest, ExactModeKeepsEveryVoxelsCentreBestFaceValuesAndSoleViewer) {
  const SceneInput box = testing::Synthetic("box");
  const EvaluateJobOptions o = InsideTheBox(box);
  const Result<EvaluateJobResult> job = RunEvaluation(box, o);
  ASSERT_TRUE(job.ok()) << job.status().ToString();
  const VoxelScene scene = *Voxelize(box, {0.2});
  ASSERT_EQ(job->voxel_centers.size(), scene.occupied.size());
  for (size_t id : {size_t{0}, scene.occupied.size() - 1}) EXPECT_EQ(job->voxel_centers[id], scene.Center(id));
  EXPECT_EQ(job->evaluation.best_face_values.size(), scene.occupied.size());
  EXPECT_EQ(job->evaluation.sole_viewer.size(), scene.occupied.size());
  EXPECT_EQ(job->viewpoints, o.viewpoints);
  EXPECT_EQ(job->frame_origin_m, WorldPoint::Zero());
}

TEST(RunEvaluationTest, ViewpointsInTheInputsFrameAreEvaluatedAtTheirLocalPlace) {
  SceneInput georeferenced = testing::Synthetic("box");
  const WorldPoint origin(512000, 5612000, 0);
  georeferenced.frame_origin_m = origin;
  EvaluateJobOptions given = InsideTheBox(georeferenced);
  for (WorldPoint& p : given.viewpoints) p += origin;  // in the input's frame, as a user gives them
  std::vector<WorldPoint> local = given.viewpoints;
  for (WorldPoint& p : local) p -= origin;
  const Result<Evaluation> direct =
      Evaluate(*Voxelize(testing::Synthetic("box"), {0.2}), local, given.evaluate_options());
  ASSERT_TRUE(direct.ok());
  const Result<EvaluateJobResult> job = RunEvaluation(georeferenced, given);
  ASSERT_TRUE(job.ok()) << job.status().ToString();
  EXPECT_GT(job->evaluation.overall.global_visibility, 0.0);
  EXPECT_EQ(job->evaluation.overall.global_visibility, direct->overall.global_visibility);
  EXPECT_EQ(job->frame_origin_m, origin);
  EXPECT_EQ(job->viewpoints, given.viewpoints);
}

TEST(RunEvaluationTest, SamplesWhenAskedTo) {
  const SceneInput box = testing::Synthetic("box");
  EvaluateJobOptions o = InsideTheBox(box);
  o.sample_faces = 300;
  const Result<EvaluateJobResult> r = RunEvaluation(box, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->evaluation.sampled);
  EXPECT_EQ(r->evaluation.faces_evaluated, 300u);
  EXPECT_GT(r->evaluation.global_visibility_ci95, 0.0);
  EXPECT_TRUE(r->evaluation.best_face_values.empty());
  EXPECT_FALSE(r->voxel_centers.empty());
}

TEST(RunEvaluationTest, RefusesBadOptionsAndAnOverBudgetScene) {
  const SceneInput box = testing::Synthetic("box");
  EvaluateJobOptions o;
  EXPECT_THAT(RunEvaluation(box, o).status().message(), HasSubstr("no viewpoint to evaluate"));
  o = InsideTheBox(box);
  o.memory_budget_bytes = 1024;
  EXPECT_EQ(RunEvaluation(box, o).status().code(), StatusCode::kResourceExhausted);
}

// A little room for the seen sets: a floor, a wall, a tilted board and a post, noisy points.
SceneInput LittleRoom() {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  std::normal_distribution<float> noise(0, 0.004f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 5000; ++i) {
    const float x = 2 * u(rng), y = 2 * u(rng);
    points.emplace_back(x, y, 0.02f + noise(rng));
    if (x > 0.5f && x < 1.3f && y > 0.5f && y < 1.1f) points.emplace_back(x, y, 0.3f + 0.6f * (x - 0.5f) + noise(rng));
    points.emplace_back(1.9f + noise(rng), y, 1.2f * u(rng));
  }
  for (int i = 0; i < 600; ++i) {
    const float a = 6.2832f * u(rng);
    points.emplace_back(0.4f + 0.06f * std::cos(a), 1.5f + 0.06f * std::sin(a), 1.0f * u(rng));
  }
  return testing::Cloud(std::move(points));
}

EvaluateJobOptions ExportFromTwoPlaces(SelectionTest test) {
  EvaluateJobOptions o;
  o.resolution_m = 0.1;
  o.test = test;
  o.export_sets = true;
  o.threads = 2;
  o.scanner.min_range_m = 0;  // the references apply no range
  o.viewpoints = {{0.25, 0.3, 1.05}, {1.45, 1.75, 0.55}};
  return o;
}

TEST(RunEvaluationTest, ExportedSetsAreWhatTheTestsPerRayReferenceSees) {
  const SceneInput room = LittleRoom();
  const VoxelScene scene = *Voxelize(room, {0.1});
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, room.points);
  const testing::SubvoxelReference subvoxel{scene, patches};
  for (const SelectionTest test :
       {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility, SelectionTest::kSubvoxel}) {
    const EvaluateJobOptions o = ExportFromTwoPlaces(test);
    const Result<EvaluateJobResult> job = RunEvaluation(room, o);
    ASSERT_TRUE(job.ok()) << job.status().ToString();
    EXPECT_EQ(job->selection_test, test);
    EXPECT_TRUE(job->warnings.empty());
    ASSERT_EQ(job->seen_sets.size(), 2u);
    for (size_t k = 0; k < 2; ++k) {
      const WorldPoint& o_m = o.viewpoints[k];
      size_t expected_count = 0;
      for (size_t id = 0; id < scene.occupied.size(); ++id) {
        const VoxelIndex v = KeyToIndex(scene.occupied[id]);
        const bool expected = test == SelectionTest::kSubvoxel        ? subvoxel.Seen(o_m / 0.1, id)
                              : test == SelectionTest::kCompatibility ? IsCompatible(scene.grid, o_m, v, o.scanner)
                                                                      : IsSurfaceVisible(scene.grid, o_m, v, o.scanner);
        ASSERT_EQ(job->seen_sets[k].test(id), expected)
            << SelectionTestName(test) << " viewpoint " << k << " voxel " << id;
        expected_count += expected;
      }
      EXPECT_EQ(job->seen_sets[k].count(), expected_count);
      EXPECT_GT(expected_count, 50u) << SelectionTestName(test);  // something is seen
      // And something hidden (the subvoxel test, whose blockers are its points' boxes, sees all but
      // a few dozen of the room's 946 voxels from one of the places).
      EXPECT_LT(expected_count, scene.occupied.size() - 20) << SelectionTestName(test);
    }
  }
}

TEST(RunEvaluationTest, TheSubvoxelTestSeesMoreOfTheRoomThanTheSurfaceTest) {
  const SceneInput room = LittleRoom();
  const Result<EvaluateJobResult> surface = RunEvaluation(room, ExportFromTwoPlaces(SelectionTest::kSurfaceVisibility));
  const Result<EvaluateJobResult> subvoxel = RunEvaluation(room, ExportFromTwoPlaces(SelectionTest::kSubvoxel));
  ASSERT_TRUE(surface.ok() && subvoxel.ok());
  EXPECT_GT(subvoxel->seen_sets[0].count(), surface->seen_sets[0].count());
  // The evaluation itself does not depend on the test of the seen sets.
  EXPECT_EQ(subvoxel->evaluation.overall.global_visibility, surface->evaluation.overall.global_visibility);
}

TEST(RunEvaluationTest, ExportedSetsDoNotDependOnTheInputsFrame) {
  const SceneInput near = LittleRoom();
  SceneInput far = near;
  const WorldPoint origin(512000, 5612000, 100);
  far.frame_origin_m = origin;
  EvaluateJobOptions near_options = ExportFromTwoPlaces(SelectionTest::kSubvoxel);
  EvaluateJobOptions far_options = near_options;
  for (WorldPoint& p : far_options.viewpoints) p += origin;
  const Result<EvaluateJobResult> a = RunEvaluation(near, near_options);
  const Result<EvaluateJobResult> b = RunEvaluation(far, far_options);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(b->frame_origin_m, origin);
  ASSERT_EQ(a->seen_sets.size(), b->seen_sets.size());
  for (size_t k = 0; k < a->seen_sets.size(); ++k) EXPECT_EQ(a->seen_sets[k].words(), b->seen_sets[k].words());
}

TEST(RunEvaluationTest, NoSeenSetsUnlessAsked) {
  const SceneInput room = LittleRoom();
  EvaluateJobOptions o = ExportFromTwoPlaces(SelectionTest::kSubvoxel);
  o.export_sets = false;
  const Result<EvaluateJobResult> job = RunEvaluation(room, o);
  ASSERT_TRUE(job.ok());
  EXPECT_TRUE(job->seen_sets.empty());
}

TEST(RunEvaluationTest, TheSubvoxelTestWithoutPointsFallsBackToSurfaceAndSaysSo) {
  // A compact upload of the room: its voxels' centres, not its points.
  const VoxelScene scene = *Voxelize(LittleRoom(), {0.1});
  SceneInput voxels;
  voxels.format = InputFormat::kVoxelStream;
  voxels.voxel_resolution_m = 0.1;
  for (size_t id = 0; id < scene.occupied.size(); ++id) voxels.points.push_back(scene.Center(id).cast<float>());
  const Result<EvaluateJobResult> job = RunEvaluation(voxels, ExportFromTwoPlaces(SelectionTest::kSubvoxel));
  ASSERT_TRUE(job.ok()) << job.status().ToString();
  EXPECT_EQ(job->selection_test, SelectionTest::kSurfaceVisibility);
  ASSERT_EQ(job->warnings.size(), 1u);
  EXPECT_THAT(job->warnings[0], HasSubstr("the subvoxel test needs the input's points"));
  const Result<EvaluateJobResult> surface =
      RunEvaluation(LittleRoom(), ExportFromTwoPlaces(SelectionTest::kSurfaceVisibility));
  ASSERT_TRUE(surface.ok());
  EXPECT_EQ(job->seen_sets[0].words(), surface->seen_sets[0].words());
}

TEST(RunEvaluationTest, SeenSetsOverHalfTheBudgetAreRefused) {
  const SceneInput room = LittleRoom();
  EvaluateJobOptions o = ExportFromTwoPlaces(SelectionTest::kSurfaceVisibility);
  const size_t voxels = Voxelize(room, {0.1})->occupied.size();
  o.memory_budget_bytes = 4 << 20;
  // Enough viewpoints that their dense sets need more than 2 MiB.
  o.viewpoints.assign((2 << 20) / ((voxels + 63) / 64 * 8) + 1, WorldPoint(0.25, 0.3, 1.05));
  const Result<EvaluateJobResult> job = RunEvaluation(room, o);
  EXPECT_EQ(job.status().code(), StatusCode::kResourceExhausted) << job.status().ToString();
  EXPECT_THAT(job.status().message(), HasSubstr("the seen sets (--export-sets)"));
  o.viewpoints.resize(o.viewpoints.size() / 2);  // half as many fit
  EXPECT_TRUE(planner::CheckVisibilitySetBudget(o.viewpoints.size(), voxels, o.memory_budget_bytes, "").ok());
}

}  // namespace
}  // namespace vc
