// vc/plan/evaluate_job.h: what an Evaluate job refuses, the options it runs with, and that
// RunEvaluation gives exactly vc::Evaluate on the scene voxelised at the job's resolution.
#include "vc/plan/evaluate_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "testing/scenes.h"

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

}  // namespace
}  // namespace vc
