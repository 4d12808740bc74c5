// JobChannel and KeptJobs without gRPC: a sink is an Outbox whose writes complete at once into a
// vector; the sweeper is driven by explicit Sweep(now) calls.
#include "vc/server/kept_jobs.h"

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/test_messages.h"
#include "vc/v1/planner.pb.h"

namespace vc::server {
namespace {

using Message = v1::PlanResponse;
using Channel = JobChannel<Message>;
using namespace std::chrono_literals;

Message Accepted(const std::string& id) { return testing::AcceptedMessage(id); }
Message Progress(double fraction) { return testing::ProgressMessage(fraction); }
Message Bulk(size_t bytes) { return testing::BulkMessage(bytes); }

// An outbox whose writes complete at once: what a healthy client received, and its final status.
struct RecordingSink {
  explicit RecordingSink(const CancelToken* token)
      : outbox(std::make_shared<Outbox<Message>>(
            [this](const Message* m) {
              {
                std::lock_guard lock(mu);
                received.push_back(*m);
              }
              outbox->OnWriteDone(true);
            },
            [this](const Status& s) {
              std::lock_guard lock(mu);
              final = s;
            },
            token)) {}
  std::vector<Message::EventCase> Events() {
    std::lock_guard lock(mu);
    std::vector<Message::EventCase> e;
    for (const Message& m : received) e.push_back(m.event_case());
    return e;
  }
  std::optional<Status> Final() {
    std::lock_guard lock(mu);
    return final;
  }
  std::mutex mu;
  std::vector<Message> received;
  std::optional<Status> final;
  std::shared_ptr<Outbox<Message>> outbox;
};

TEST(JobChannelTest, ADetachedJobKeepsItsEventsAndALaterSinkGetsThemThenTheLiveOnesThenTheStatus) {
  KeptBudget budget(1 << 20);
  Channel channel("Plan", &budget);
  channel.set_grace(60s);
  const CancelToken call;
  RecordingSink first(&call);
  channel.SetSink(first.outbox);
  EXPECT_TRUE(channel.Post(Accepted("j-1")));
  channel.PostProgress(Progress(0.1));
  EXPECT_EQ(first.Events().size(), 2u);

  first.outbox->Break();  // the client vanished
  channel.Detach(first.outbox.get());
  EXPECT_FALSE(channel.state().attached);
  EXPECT_TRUE(channel.Post(Bulk(1000), /*bulk=*/true));  // the job runs on
  channel.PostProgress(Progress(0.5));
  channel.PostProgress(Progress(0.7));  // only the latest progress is kept

  RecordingSink second(&call);
  ASSERT_TRUE(channel.Attach("j-1", second.outbox).ok());
  EXPECT_TRUE(channel.state().attached);
  EXPECT_EQ(second.Events(),
            (std::vector<Message::EventCase>{Message::kAccepted, Message::kVoxels, Message::kProgress}));
  EXPECT_DOUBLE_EQ(second.received.back().progress().fraction(), 0.7);
  EXPECT_TRUE(channel.Post(Bulk(100), true));  // live
  channel.Complete(Status::Ok());
  EXPECT_EQ(second.Events().size(), 4u);
  ASSERT_TRUE(second.Final());
  EXPECT_TRUE(second.Final()->ok());
  EXPECT_FALSE(first.Final());  // the broken sink heard nothing more

  // A third client, after the end: the kept events (not the finished job's progress) and the status.
  RecordingSink third(&call);
  ASSERT_TRUE(channel.Attach("j-1", third.outbox).ok());
  EXPECT_EQ(third.Events(), (std::vector<Message::EventCase>{Message::kAccepted, Message::kVoxels, Message::kVoxels}));
  ASSERT_TRUE(third.Final());
  EXPECT_TRUE(third.Final()->ok());
}

TEST(JobChannelTest, WithoutAGraceNothingIsKeptAndABrokenSinkStopsTheProducer) {
  KeptBudget budget(1 << 20);
  Channel channel("Plan", &budget);
  const CancelToken call;
  RecordingSink sink(&call);
  channel.SetSink(sink.outbox);
  EXPECT_TRUE(channel.Post(Bulk(1000), true));
  EXPECT_EQ(budget.used_bytes(), 0u);
  sink.outbox->Break();
  EXPECT_FALSE(channel.Post(Bulk(1000), true));
}

TEST(JobChannelTest, ASecondAttachTakesOverAndTheFirstEndsWithAborted) {
  KeptBudget budget(1 << 20);
  Channel channel("Plan", &budget);
  channel.set_grace(60s);
  const CancelToken call;
  RecordingSink a(&call), b(&call);
  ASSERT_TRUE(channel.Attach("j-2", a.outbox).ok());
  ASSERT_TRUE(channel.Attach("j-2", b.outbox).ok());
  ASSERT_TRUE(a.Final());
  EXPECT_EQ(a.Final()->code(), StatusCode::kAborted);
  channel.Complete(CancelledError("stopped"));
  ASSERT_TRUE(b.Final());
  EXPECT_EQ(b.Final()->code(), StatusCode::kCancelled);
}

TEST(JobChannelTest, OverTheBudgetAJobStopsKeepingAndAnAttachIsResourceExhausted) {
  KeptBudget budget(10'000);
  Channel small("Plan", &budget), big("Plan", &budget);
  small.set_grace(60s);
  big.set_grace(60s);
  EXPECT_TRUE(small.Post(Bulk(2000), true));
  const uint64_t small_bytes = budget.used_bytes();
  EXPECT_GT(small_bytes, 2000u);
  EXPECT_TRUE(big.Post(Bulk(4000), true));
  EXPECT_TRUE(big.Post(Bulk(8000), true));  // over: big drops what it kept, the job runs on
  EXPECT_EQ(budget.used_bytes(), small_bytes);
  const CancelToken call;
  RecordingSink sink(&call);
  const Status s = big.Attach("j-big", sink.outbox);
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  EXPECT_NE(s.message().find("--kept-results-bytes"), std::string::npos) << s.message();
  EXPECT_TRUE(small.Attach("j-small", sink.outbox).ok());
}

TEST(JobChannelTest, ACancelReasonBecomesTheFinalStatusMessage) {
  KeptBudget budget(1 << 20);
  Channel channel("Plan", &budget);
  channel.set_grace(60s);
  channel.Cancel("job j-3 was cancelled by CancelJob");
  EXPECT_TRUE(channel.token().cancelled());
  EXPECT_FALSE(channel.Post(Accepted("j-3")));
  channel.Complete(CancelledError("the plan was cancelled"));
  const CancelToken call;
  RecordingSink sink(&call);
  ASSERT_TRUE(channel.Attach("j-3", sink.outbox).ok());
  ASSERT_TRUE(sink.Final());
  EXPECT_EQ(*sink.Final(), CancelledError("job j-3 was cancelled by CancelJob"));
}

TEST(KeptJobsTest, TheSweeperCancelsAfterTheGraceAndForgetsAfterTheTtlOrOnDelivery) {
  KeptJobs jobs(/*ttl=*/10s, 1 << 20, /*sweep_every=*/1h);  // swept by hand below
  auto running = std::make_shared<Channel>("Plan", jobs.budget());
  running->set_grace(5s);
  auto done = std::make_shared<Channel>("Plan", jobs.budget());
  done->set_grace(5s);
  auto delivered = std::make_shared<Channel>("Evaluate", jobs.budget());
  delivered->set_grace(5s);
  jobs.Add("j-run", running);
  jobs.Add("j-done", done);
  jobs.Add("j-delivered", delivered);
  done->Complete(Status::Ok());
  delivered->Complete(Status::Ok());
  EXPECT_FALSE(delivered->Delivered(CancelledError("another status")));
  EXPECT_TRUE(delivered->Delivered(Status::Ok()));
  const auto t0 = KeptJob::Clock::now();

  jobs.Sweep(t0 + 1s);
  EXPECT_EQ(jobs.size(), 2u);  // the delivered one is forgotten at once
  EXPECT_FALSE(running->token().cancelled());
  jobs.Sweep(t0 + 6s);  // past the grace: cancelled, not forgotten (its status is still to be told)
  EXPECT_TRUE(running->token().cancelled());
  EXPECT_EQ(jobs.size(), 2u);
  jobs.Sweep(t0 + 11s);  // past the ttl of the finished one
  EXPECT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs.Find("j-done", "").status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(jobs.Find("j-run", "").ok());
}

TEST(KeptJobsTest, OnlyTheOwnersTokenFindsAJob) {
  KeptJobs jobs(10s, 1 << 20);
  auto job = std::make_shared<Channel>("Plan", jobs.budget());
  job->set_owner("alice-token");
  jobs.Add("j-a", job);
  EXPECT_TRUE(jobs.Find("j-a", "alice-token").ok());
  EXPECT_EQ(jobs.Find("j-a", "bob-token").status().code(), StatusCode::kPermissionDenied);
  EXPECT_EQ(jobs.Find("j-b", "alice-token").status().code(), StatusCode::kNotFound);
}

TEST(KeptJobsTest, ProducerAndAttachingClientsRaceSafely) {  // for ThreadSanitizer
  KeptJobs jobs(10s, 64 << 20, 1ms);
  auto channel = std::make_shared<Channel>("Plan", jobs.budget());
  channel->set_grace(60s);
  jobs.Add("j-race", channel);
  std::thread producer([&] {
    channel->Post(Accepted("j-race"));
    for (int i = 0; i < 200; ++i) {
      channel->Post(Bulk(64), true);
      channel->PostProgress(Progress(i / 200.0));
    }
    channel->Complete(Status::Ok());
  });
  const CancelToken call;
  std::vector<std::unique_ptr<RecordingSink>> sinks;
  for (int i = 0; i < 20; ++i) {
    sinks.push_back(std::make_unique<RecordingSink>(&call));
    ASSERT_TRUE(channel->Attach("j-race", sinks.back()->outbox).ok());
    if (i % 3 == 0) channel->Detach(sinks.back()->outbox.get());
  }
  producer.join();
  RecordingSink last(&call);
  ASSERT_TRUE(channel->Attach("j-race", last.outbox).ok());
  EXPECT_EQ(last.Events().size(), 201u);  // Accepted and every bulk event, in order
  ASSERT_TRUE(last.Final());
  EXPECT_TRUE(last.Final()->ok());
}

}  // namespace
}  // namespace vc::server
