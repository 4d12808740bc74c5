// Outbox without gRPC: a fake stream records the writes the outbox starts and completes them when
// the test (or a writer thread, standing in for gRPC's completion queue) says so.
#include "vc/server/outbox.h"

#include <gtest/gtest.h>

#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/test_messages.h"
#include "vc/v1/planner.pb.h"

namespace vc::server {
namespace {

using Message = v1::PlanResponse;

Message Accepted(const std::string& id) { return testing::AcceptedMessage(id); }
Message Progress(double fraction) { return testing::ProgressMessage(fraction); }
Message Bulk(size_t bytes) { return testing::BulkMessage(bytes); }

// Records the writes; the test completes them one at a time with Ack.
struct FakeStream {
  std::mutex mu;
  std::vector<Message> written;  // copies of what start_write was given, in order
  int in_flight = 0;
  std::optional<Status> finished;
  int finishes = 0;

  Outbox<Message>::StartWriteFn StartWrite() {
    return [this](const Message* m) {
      std::lock_guard lock(mu);
      written.push_back(*m);
      ++in_flight;
    };
  }
  Outbox<Message>::FinishFn Finish() {
    return [this](const Status& s) {
      std::lock_guard lock(mu);
      finished = s;
      ++finishes;
    };
  }
  void Ack(Outbox<Message>& box, bool ok = true) {
    {
      std::lock_guard lock(mu);
      ASSERT_EQ(in_flight, 1) << "exactly one write may be in flight";
      --in_flight;
    }
    box.OnWriteDone(ok);
  }
};

// An outbox over a FakeStream, with the default byte limit.
class OutboxTest : public ::testing::Test {
 protected:
  CancelToken token_;
  FakeStream stream_;
  Outbox<Message> box_{stream_.StartWrite(), stream_.Finish(), &token_};
};

TEST_F(OutboxTest, OneWriteAtATimeInOrder) {
  EXPECT_TRUE(box_.Post(Accepted("a")));
  EXPECT_TRUE(box_.Post(Accepted("b")));
  EXPECT_EQ(stream_.written.size(), 1u) << "the second waits for the first write";
  stream_.Ack(box_);
  ASSERT_EQ(stream_.written.size(), 2u);
  EXPECT_EQ(stream_.written[1].accepted().job_id(), "b");
  stream_.Ack(box_);
  EXPECT_EQ(box_.queued_bytes(), 0u);
}

TEST_F(OutboxTest, CompleteFinishesOnlyOnceTheQueueIsWritten) {
  ASSERT_TRUE(box_.Post(Accepted("a")));
  ASSERT_TRUE(box_.Post(Accepted("b")));
  box_.Complete(Status::Ok());
  EXPECT_FALSE(stream_.finished) << "finished with writes pending";
  stream_.Ack(box_);
  EXPECT_FALSE(stream_.finished);
  stream_.Ack(box_);
  ASSERT_TRUE(stream_.finished);
  EXPECT_TRUE(stream_.finished->ok());
  box_.Complete(InternalError("late"));
  EXPECT_EQ(stream_.finishes, 1) << "only the first Complete counts";
}

TEST_F(OutboxTest, CompleteWhenIdleFinishesAtOnce) {
  box_.Complete(UnauthenticatedError("no token"));
  ASSERT_TRUE(stream_.finished);
  EXPECT_EQ(stream_.finished->code(), StatusCode::kUnauthenticated);
  EXPECT_TRUE(stream_.written.empty());
}

TEST_F(OutboxTest, ErrorReplacesWhatHasNotStartedWriting) {
  ASSERT_TRUE(box_.Post(Accepted("a")));
  ASSERT_TRUE(box_.Post(Accepted("b")));
  ASSERT_TRUE(box_.Post(Accepted("c")));
  box_.Complete(InternalError("boom"));
  stream_.Ack(box_);
  EXPECT_EQ(stream_.written.size(), 1u) << "b and c were dropped";
  ASSERT_TRUE(stream_.finished);
  EXPECT_EQ(stream_.finished->code(), StatusCode::kInternal);
  EXPECT_EQ(box_.queued_bytes(), 0u);
}

TEST_F(OutboxTest, WaitingProgressIsReplacedByTheNewer) {
  ASSERT_TRUE(box_.Post(Accepted("a")));
  box_.PostProgress(Progress(0.1));
  box_.PostProgress(Progress(0.2));
  box_.PostProgress(Progress(0.3));
  stream_.Ack(box_);
  stream_.Ack(box_);
  ASSERT_EQ(stream_.written.size(), 2u);
  EXPECT_DOUBLE_EQ(stream_.written[1].progress().fraction(), 0.3);
}

TEST_F(OutboxTest, ProgressBeingWrittenIsNotReplaced) {
  box_.PostProgress(Progress(0.1));
  box_.PostProgress(Progress(0.2));
  stream_.Ack(box_);
  stream_.Ack(box_);
  ASSERT_EQ(stream_.written.size(), 2u);
  EXPECT_DOUBLE_EQ(stream_.written[0].progress().fraction(), 0.1);
  EXPECT_DOUBLE_EQ(stream_.written[1].progress().fraction(), 0.2);
}

TEST_F(OutboxTest, ProgressDoesNotReplaceOtherMessages) {
  ASSERT_TRUE(box_.Post(Accepted("a")));
  ASSERT_TRUE(box_.Post(Accepted("b")));
  box_.PostProgress(Progress(0.5));
  stream_.Ack(box_);
  stream_.Ack(box_);
  stream_.Ack(box_);
  ASSERT_EQ(stream_.written.size(), 3u);
  EXPECT_EQ(stream_.written[1].accepted().job_id(), "b");
}

TEST_F(OutboxTest, FailedWriteDropsTheQueueAndStopsProducers) {
  ASSERT_TRUE(box_.Post(Accepted("a")));
  ASSERT_TRUE(box_.Post(Accepted("b")));
  stream_.Ack(box_, /*ok=*/false);
  EXPECT_EQ(stream_.written.size(), 1u);
  EXPECT_FALSE(box_.Post(Accepted("c")));
  box_.Complete(CancelledError("gone"));
  ASSERT_TRUE(stream_.finished) << "nothing in flight: finish at once";
}

TEST_F(OutboxTest, CancelledTokenStopsProducers) {
  token_.Cancel();
  EXPECT_FALSE(box_.Post(Accepted("a")));
  EXPECT_TRUE(stream_.written.empty());
}

// gRPC's side in a thread: completes each write shortly after it starts.
class AsyncWriter {
 public:
  explicit AsyncWriter(Outbox<Message>** box) : box_(box), thread_([this] { Loop(); }) {}
  ~AsyncWriter() {
    {
      std::lock_guard lock(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  Outbox<Message>::StartWriteFn StartWrite() {
    return [this](const Message* m) {
      std::lock_guard lock(mu_);
      pending_.push_back(m);
      cv_.notify_all();
    };
  }
  std::vector<Message> written() {
    std::lock_guard lock(mu_);
    return written_;
  }

 private:
  void Loop() {
    std::unique_lock lock(mu_);
    for (;;) {
      cv_.wait(lock, [&] { return stop_ || !pending_.empty(); });
      if (pending_.empty()) return;
      const Message* m = pending_.front();
      pending_.pop_front();
      written_.push_back(*m);
      lock.unlock();
      std::this_thread::sleep_for(std::chrono::microseconds(200));  // the network
      (*box_)->OnWriteDone(true);
      lock.lock();
    }
  }

  Outbox<Message>** box_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<const Message*> pending_;
  std::vector<Message> written_;
  bool stop_ = false;
  std::thread thread_;
};

TEST(Outbox, BulkProducerIsHeldToTheLimitAndEverythingArrivesInOrder) {
  CancelToken token;
  Outbox<Message>* box_ptr = nullptr;
  AsyncWriter writer(&box_ptr);
  std::mutex mu;
  std::condition_variable done_cv;
  bool done = false;
  const size_t kChunk = 4096, kLimit = 3 * kChunk;
  Outbox<Message> box(
      writer.StartWrite(),
      [&](const Status&) {
        std::lock_guard lock(mu);
        done = true;
        done_cv.notify_all();
      },
      &token, kLimit);
  box_ptr = &box;
  size_t max_queued = 0;
  std::thread progress([&] {
    for (int i = 0; i < 200; ++i) box.PostProgress(Progress(i / 200.0));
  });
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(box.Post(Bulk(kChunk), /*bulk=*/true));
    max_queued = std::max(max_queued, box.queued_bytes());
  }
  progress.join();
  box.Complete(Status::Ok());
  {
    std::unique_lock lock(mu);
    ASSERT_TRUE(done_cv.wait_for(lock, std::chrono::seconds(10), [&] { return done; }));
  }
  EXPECT_LE(max_queued, kLimit + 2 * kChunk) << "the producer ran ahead of the network";
  int bulk = 0;
  double last_fraction = -1;
  for (const Message& m : writer.written()) {
    bulk += m.has_voxels();
    if (m.has_progress()) {
      EXPECT_GT(m.progress().fraction(), last_fraction) << "progress went backwards";
      last_fraction = m.progress().fraction();
    }
  }
  EXPECT_EQ(bulk, 50);
}

TEST(Outbox, BreakWakesABulkProducerWaitingForTheNetwork) {
  CancelToken token;
  FakeStream stream;
  Outbox<Message> box(stream.StartWrite(), stream.Finish(), &token, /*max_bytes=*/1024);
  ASSERT_TRUE(box.Post(Bulk(4096), /*bulk=*/true));  // in flight, never acknowledged
  std::atomic<int> result{-1};
  std::thread producer([&] { result = box.Post(Bulk(4096), /*bulk=*/true) ? 1 : 0; });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(result.load(), -1) << "the producer should wait while over the limit";
  box.Break();
  producer.join();
  EXPECT_EQ(result.load(), 0);
}

}  // namespace
}  // namespace vc::server
