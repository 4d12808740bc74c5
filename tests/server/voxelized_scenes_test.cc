// vc/server/voxelized_scenes.h: a scene is made once per key and shared, also by callers asking at
// the same time; the least recently used go first; a failure is not kept; and SceneFingerprint
// tells apart every change a peer's voxelization could have.
#include "vc/server/voxelized_scenes.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <new>
#include <stdexcept>
#include <thread>
#include <vector>

namespace vc::server {
namespace {

VoxelScene Scene(double r, std::vector<VoxelKey> keys) {
  VoxelScene s;
  s.resolution_m = r;
  s.occupied = std::move(keys);
  return s;
}

VoxelizedScenes::MakeFn Counting(std::atomic<int>* made, double r = 0.1) {
  return [made, r]() -> Result<VoxelScene> {
    made->fetch_add(1);
    return Scene(r, {{1, 2, 3}});
  };
}

TEST(VoxelizedScenesTest, MakesEachSceneOnceAndSharesIt) {
  VoxelizedScenes scenes(2);
  std::atomic<int> made{0};
  Result<VoxelizedScenes::Scene> a = scenes.Get("a", Counting(&made));
  Result<VoxelizedScenes::Scene> again = scenes.Get("a", Counting(&made));
  ASSERT_TRUE(a.ok() && again.ok());
  EXPECT_EQ(made.load(), 1);
  EXPECT_EQ(a->get(), again->get());
  EXPECT_EQ(scenes.size(), 1u);
}

TEST(VoxelizedScenesTest, KeepsTheMostRecentlyUsedUpToItsCapacity) {
  VoxelizedScenes scenes(2);
  std::atomic<int> made{0};
  ASSERT_TRUE(scenes.Get("a", Counting(&made)).ok());
  ASSERT_TRUE(scenes.Get("b", Counting(&made)).ok());
  ASSERT_TRUE(scenes.Get("a", Counting(&made)).ok());  // a is now the most recently used
  ASSERT_TRUE(scenes.Get("c", Counting(&made)).ok());  // so b goes
  EXPECT_EQ(scenes.size(), 2u);
  EXPECT_EQ(made.load(), 3);
  ASSERT_TRUE(scenes.Get("a", Counting(&made)).ok());
  EXPECT_EQ(made.load(), 3);
  ASSERT_TRUE(scenes.Get("b", Counting(&made)).ok());
  EXPECT_EQ(made.load(), 4);
}

TEST(VoxelizedScenesTest, AFailureIsReturnedButNotKept) {
  VoxelizedScenes scenes(4);
  Result<VoxelizedScenes::Scene> r =
      scenes.Get("a", []() -> Result<VoxelScene> { return ResourceExhaustedError("too big"); });
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(scenes.size(), 0u);
  r = scenes.Get("b", []() -> Result<VoxelScene> { throw std::bad_alloc(); });
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(r.status().message(), "this replica ran out of memory voxelizing the scene");
  r = scenes.Get("c", []() -> Result<VoxelScene> { throw std::runtime_error("disk on fire"); });
  EXPECT_EQ(r.status().code(), StatusCode::kInternal);
  EXPECT_EQ(r.status().message(), "voxelizing the scene failed: disk on fire");
  EXPECT_EQ(scenes.size(), 0u);
  std::atomic<int> made{0};
  ASSERT_TRUE(scenes.Get("a", Counting(&made)).ok());  // a retry makes it again
  EXPECT_EQ(made.load(), 1);
}

TEST(VoxelizedScenesTest, CallersAskingAtOnceShareOneVoxelization) {
  VoxelizedScenes scenes(2);
  std::atomic<int> made{0};
  const VoxelizedScenes::MakeFn slow = [&]() -> Result<VoxelScene> {
    made.fetch_add(1);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return Scene(0.1, {{1, 2, 3}});
  };
  std::vector<const VoxelScene*> got(8, nullptr);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < got.size(); ++i) {
    threads.emplace_back([&, i] {
      Result<VoxelizedScenes::Scene> r = scenes.Get("same", slow);
      if (r.ok()) got[i] = r->get();
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(made.load(), 1);
  for (const VoxelScene* s : got) EXPECT_EQ(s, got[0]);
  EXPECT_NE(got[0], nullptr);
}

TEST(SceneFingerprintTest, ChangesWithTheResolutionAndEveryKey) {
  const VoxelScene base = Scene(0.1, {{1, 2, 3}, {4, 5, 6}});
  const uint32_t f = SceneFingerprint(base);
  EXPECT_EQ(SceneFingerprint(Scene(0.1, {{1, 2, 3}, {4, 5, 6}})), f);
  EXPECT_NE(SceneFingerprint(Scene(0.1000001, {{1, 2, 3}, {4, 5, 6}})), f);
  EXPECT_NE(SceneFingerprint(Scene(0.1, {{1, 2, 3}})), f);
  EXPECT_NE(SceneFingerprint(Scene(0.1, {{4, 5, 6}, {1, 2, 3}})), f);  // order counts
  EXPECT_NE(SceneFingerprint(Scene(0.1, {{1, 2, 3}, {4, 5, 7}})), f);
  EXPECT_NE(SceneFingerprint(Scene(0.1, {{1, 2, 3}, {4 + 256, 5, 6}})), f);  // a key's high byte
  VoxelScene shifted = Scene(0.1, {{1, 2, 3}, {4, 5, 6}});
  shifted.frame_origin_m = WorldPoint(512000, 5612000, 0);
  EXPECT_NE(SceneFingerprint(shifted), f);  // the same keys in another frame
}

TEST(VoxelizedSceneKeyTest, TellsUnitsAndResolutionsApart) {
  const std::string sha(64, 'a');
  const std::string metres = VoxelizedSceneKey(sha, 0.1, "");
  EXPECT_EQ(VoxelizedSceneKey(sha, 0.1, "m"), metres);  // empty is metres
  EXPECT_NE(VoxelizedSceneKey(sha, 0.1, "mm"), metres);
  EXPECT_NE(VoxelizedSceneKey(sha, 0.1, "mm"), VoxelizedSceneKey(sha, 0.1, "cm"));
  EXPECT_NE(VoxelizedSceneKey(sha, 0.2, ""), metres);
  EXPECT_NE(VoxelizedSceneKey(std::string(64, 'b'), 0.1, ""), metres);
}

}  // namespace
}  // namespace vc::server
