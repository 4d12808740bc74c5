#include "vc/server/worker_pool.h"

#include <gtest/gtest.h>

#include <future>

namespace vc::server {
namespace {

TEST(WorkerPool, AdmitsWorkersPlusQueueThenRefuses) {
  WorkerPool pool(2, 1);
  std::vector<WorkerPool::Ticket> tickets;
  for (int i = 0; i < 3; ++i) {
    auto t = pool.TryAdmit();
    ASSERT_TRUE(t.has_value()) << i;
    tickets.push_back(std::move(*t));
  }
  EXPECT_FALSE(pool.TryAdmit().has_value());
  tickets.pop_back();  // an unused ticket gives its place back
  EXPECT_TRUE(pool.TryAdmit().has_value());
}

TEST(WorkerPool, QueuePositionsAndRelease) {
  WorkerPool pool(1, 2);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_running;
  std::vector<uint32_t> positions;
  std::atomic<int> done{0};
  auto submit = [&](std::function<void()> task) {
    auto t = pool.TryAdmit();
    ASSERT_TRUE(t.has_value());
    pool.Submit(
        std::move(*t), [&](uint32_t p) { positions.push_back(p); },
        [task = std::move(task)](WorkerPool::Ticket) { task(); });
  };
  submit([&] {
    first_running.set_value();
    released.wait();
    ++done;
  });
  first_running.get_future().wait();
  submit([&] { ++done; });
  submit([&] { ++done; });
  EXPECT_EQ(positions, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_FALSE(pool.TryAdmit().has_value());
  EXPECT_EQ(pool.running(), 1);
  release.set_value();
  while (pool.admitted() != 0) std::this_thread::yield();
  EXPECT_EQ(done.load(), 3);
}

// A job answers its client from inside its task; it gives its place back first, so a client that
// submits again the moment it hears the answer is admitted (the CI run of 2026-12-03 found a
// service test refused as busy in that window).
TEST(WorkerPool, ATaskThatReleasesItsPlaceLetsTheNextJobInWhileItFinishes) {
  std::promise<void> place_released;
  std::promise<void> finish;
  std::shared_future<void> may_finish = finish.get_future().share();
  WorkerPool pool(1, 0);  // declared last: destroyed (its worker joined) before what the task uses
  auto t = pool.TryAdmit();
  ASSERT_TRUE(t.has_value());
  EXPECT_FALSE(pool.TryAdmit().has_value());
  pool.Submit(
      std::move(*t), [](uint32_t) {},
      [&](WorkerPool::Ticket place) {
        place.Release();
        place.Release();  // idempotent
        place_released.set_value();
        may_finish.wait();
      });
  place_released.get_future().wait();
  EXPECT_EQ(pool.admitted(), 0);
  EXPECT_EQ(pool.running(), 0);
  EXPECT_TRUE(pool.TryAdmit().has_value());
  finish.set_value();
}

TEST(WorkerPool, ATaskThatKeepsItsPlaceGivesItBackOnReturn) {
  std::promise<void> started;
  std::promise<void> finish;
  std::shared_future<void> may_finish = finish.get_future().share();
  WorkerPool pool(1, 0);  // declared last: destroyed (its worker joined) before what the task uses
  auto t = pool.TryAdmit();
  ASSERT_TRUE(t.has_value());
  pool.Submit(
      std::move(*t), [](uint32_t) {},
      [&](WorkerPool::Ticket) {
        started.set_value();
        may_finish.wait();
      });
  started.get_future().wait();
  EXPECT_FALSE(pool.TryAdmit().has_value());
  EXPECT_EQ(pool.running(), 1);
  finish.set_value();
  while (pool.admitted() != 0) std::this_thread::yield();
  EXPECT_EQ(pool.running(), 0);
  EXPECT_TRUE(pool.TryAdmit().has_value());
}

}  // namespace
}  // namespace vc::server
