// SceneCache: scenes by hash, least recently used out first, bounded by bytes; safe from threads.
#include "vc/server/scene_cache.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace vc::server {
namespace {

SceneCache::Bytes Of(size_t n, char c = 'x') { return std::make_shared<const std::string>(n, c); }

TEST(SceneCache, KeepsScenesUntilTheBytesRunOutThenDropsTheLeastRecentlyUsed) {
  SceneCache cache(100);
  EXPECT_TRUE(cache.Put("a", Of(40, 'a')));
  EXPECT_TRUE(cache.Put("b", Of(40, 'b')));
  ASSERT_TRUE(cache.Get("a"));               // a is now the most recently used
  EXPECT_TRUE(cache.Put("c", Of(40, 'c')));  // 120 > 100: b goes
  EXPECT_EQ(cache.Get("b"), nullptr);
  ASSERT_TRUE(cache.Get("a"));
  EXPECT_EQ(*cache.Get("c"), std::string(40, 'c'));
  EXPECT_EQ(cache.bytes(), 80u);
  EXPECT_EQ(cache.scenes(), 2u);
}

TEST(SceneCache, ASceneOverTheCapacityIsNotKeptAndEvictsNothing) {
  SceneCache cache(100);
  ASSERT_TRUE(cache.Put("a", Of(60)));
  EXPECT_FALSE(cache.Put("big", Of(101)));
  EXPECT_TRUE(cache.Get("a"));
  EXPECT_EQ(cache.Get("big"), nullptr);
  SceneCache off(0);
  EXPECT_FALSE(off.Put("a", Of(1)));
  EXPECT_EQ(off.Get("a"), nullptr);
}

TEST(SceneCache, PuttingAKnownSceneAgainKeepsOneCopy) {
  SceneCache cache(100);
  ASSERT_TRUE(cache.Put("a", Of(60)));
  ASSERT_TRUE(cache.Put("a", Of(60)));
  EXPECT_EQ(cache.bytes(), 60u);
  EXPECT_EQ(cache.scenes(), 1u);
}

TEST(SceneCache, ManyThreadsPutAndGetWithinTheCapacity) {
  SceneCache cache(1000);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&cache, t] {
      for (int i = 0; i < 500; ++i) {
        const std::string key = std::to_string((t * 7 + i) % 40);
        if (i % 3 == 0) {
          cache.Put(key, Of(50));
        } else if (auto b = cache.Get(key)) {
          EXPECT_EQ(b->size(), 50u);
        }
      }
    });
  }
  for (auto& th : threads) th.join();
  EXPECT_LE(cache.bytes(), 1000u);
  EXPECT_EQ(cache.bytes(), 50u * cache.scenes());
}

}  // namespace
}  // namespace vc::server
