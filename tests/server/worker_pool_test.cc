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
        std::move(*t), [&](uint32_t p) { positions.push_back(p); }, std::move(task));
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

}  // namespace
}  // namespace vc::server
