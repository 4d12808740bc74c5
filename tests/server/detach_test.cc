// Detachable jobs over gRPC (docs/PROTOCOL.md, "Detachable jobs"): a job outlives a client that
// vanished, a new client attaches to it, results expire, grace runs out, jobs are owned.
//
// The first client is a raw stream that is cancelled once the job runs (what the server sees of a
// killed client: the stream breaks); the backend's plan waits at a gate the test opens, then plans
// for real, so the attached result can be compared with a plan that was never interrupted.
// scripts and tests/client/detach_cli_test.sh do the same with real vc-client processes.
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <thread>

#include "testing/test_server.h"
#include "vc/client/client.h"
#include "vc/server/service.h"

namespace vc {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

// A real backend whose plan and evaluate first wait at a gate (or for the job's cancellation).
struct GatedBackend {
  testing::Latch gate;
  testing::Latch started;
  testing::Latch returned;
  std::mutex mu;
  Status returned_status;

  server::Backend Make() {
    server::Backend b = server::Backend::Default();
    auto wait = [this](const JobContext& ctx) -> Status {
      started.Set();
      while (!gate.WaitFor(5ms)) {
        if (Status s = ctx.CheckCancelled("gated job"); !s.ok()) return Returned(s);
      }
      return Status::Ok();
    };
    b.plan = [this, wait, real = b.plan](const SceneInput& in, const PlanOptions& o, const JobContext& ctx,
                                         const PlanCallbacks& cb) -> Result<PlanResult> {
      VC_RETURN_IF_ERROR(wait(ctx));
      auto r = real(in, o, ctx, cb);
      Returned(r.ok() ? Status::Ok() : r.status());
      return r;
    };
    b.evaluate = [this, wait, real = b.evaluate](const SceneInput& in, const EvaluateJobOptions& o,
                                                 const JobContext& ctx) -> Result<EvaluateJobResult> {
      VC_RETURN_IF_ERROR(wait(ctx));
      auto r = real(in, o, ctx);
      Returned(r.ok() ? Status::Ok() : r.status());
      return r;
    };
    return b;
  }
  Status Returned(const Status& s) {
    {
      std::lock_guard lock(mu);
      returned_status = s;
    }
    returned.Set();
    return s;
  }
  Status last() {
    std::lock_guard lock(mu);
    return returned_status;
  }
};

// A TCP proxy on 127.0.0.1 to a local port: a site link as a client sees it. Break() cuts every
// connection open now (the client's stream fails with UNAVAILABLE); new connections still work.
class TcpProxy {
 public:
  explicit TcpProxy(int target_port) : target_port_(target_port) {
    listen_fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(listen(listen_fd_, 16), 0);
    socklen_t len = sizeof a;
    getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    acceptor_ = std::thread([this] { Accept(); });
  }
  ~TcpProxy() {
    shutdown(listen_fd_, SHUT_RDWR);  // wakes accept()
    acceptor_.join();
    Break();
    for (std::thread& t : pumps_) t.join();
    for (int fd : fds_) close(fd);
    close(listen_fd_);
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  void Break() {
    std::lock_guard lock(mu_);
    for (int fd : fds_) shutdown(fd, SHUT_RDWR);
  }

 private:
  void Accept() {
    for (;;) {
      const int client = accept(listen_fd_, nullptr, nullptr);
      if (client < 0) return;
      const int server = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      a.sin_port = htons(uint16_t(target_port_));
      if (connect(server, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        close(client);
        close(server);
        continue;
      }
      std::lock_guard lock(mu_);
      fds_.push_back(client);
      fds_.push_back(server);
      pumps_.emplace_back(Pump, client, server);
      pumps_.emplace_back(Pump, server, client);
    }
  }
  static void Pump(int from, int to) {
    char buf[1 << 16];
    for (;;) {
      const ssize_t n = read(from, buf, sizeof buf);
      if (n <= 0) break;
      for (ssize_t off = 0; off < n;) {
        // MSG_NOSIGNAL: a peer that is gone is an error here, not a SIGPIPE that kills the test.
        const ssize_t w = send(to, buf + off, size_t(n - off), MSG_NOSIGNAL);
        if (w <= 0) {
          shutdown(from, SHUT_RDWR);
          return;
        }
        off += w;
      }
    }
    shutdown(to, SHUT_RDWR);
  }

  const int target_port_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::thread acceptor_;
  std::mutex mu_;
  std::vector<int> fds_;
  std::vector<std::thread> pumps_;
};

// Calls `attach` until it is NOT_FOUND (at most 2 s); its last status.
template <typename Fn>
Status EventuallyNotFound(Fn&& attach) {
  const auto until = std::chrono::steady_clock::now() + 2s;
  Status s = attach();
  while (s.code() != StatusCode::kNotFound && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(50ms);
    s = attach();
  }
  return s;
}

class Detach : public ::testing::Test {
 protected:
  void Start(server::ServerOptions o = {}) {
    o.workers = 1;
    server_ = testing::StartServer(o, backend_.Make());
    ASSERT_NE(server_, nullptr);
  }

  client::ConnectionOptions Conn(const std::string& token = "") const {
    client::ConnectionOptions c;
    c.server = testing::Address(*server_);
    c.token = token;
    c.scene_cache = false;
    return c;
  }

  // Submits the box room with `grace_s` from a raw stream, waits until the job runs, then breaks
  // the stream as a killed client would. Returns the Accepted event.
  v1::Accepted SubmitAndVanish(uint32_t grace_s, const std::string& token = "") {
    auto stub = v1::StationPlanner::NewStub(
        grpc::CreateChannel(testing::Address(*server_), grpc::InsecureChannelCredentials()));
    grpc::ClientContext ctx;
    if (!token.empty()) ctx.AddMetadata("authorization", "Bearer " + token);
    auto stream = stub->Plan(&ctx);
    auto requests = testing::PlanRequests(scene_, params_);
    requests[0].mutable_spec()->mutable_control()->set_detach_grace_s(grace_s);
    for (const auto& r : requests) EXPECT_TRUE(stream->Write(r));
    EXPECT_TRUE(stream->WritesDone());
    v1::PlanResponse first;
    EXPECT_TRUE(stream->Read(&first));
    EXPECT_TRUE(first.has_accepted());
    EXPECT_TRUE(backend_.started.WaitFor(5s));
    ctx.TryCancel();
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
    std::this_thread::sleep_for(200ms);  // the server hears of the broken stream
    return first.accepted();
  }

  const std::string scene_ = testing::BoxRoomPly();
  v1::PlanParameters params_;
  GatedBackend backend_;
  std::unique_ptr<server::Server> server_;
};

TEST_F(Detach, AJobOutlivesItsClientAndANewClientGetsTheSameResultOnce) {
  Start();
  const v1::Accepted accepted = SubmitAndVanish(60);
  EXPECT_EQ(accepted.detach_grace_s(), 60u);
  EXPECT_FALSE(backend_.returned.WaitFor(300ms)) << "the job must run on without its client";
  backend_.gate.Set();

  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  std::vector<std::string> accepted_ids;
  client::JobObserver observer;
  observer.on_accepted = [&](const std::string& id, uint32_t) { accepted_ids.push_back(id); };
  auto attached = (*c)->AttachPlan(accepted.job_id(), observer);
  ASSERT_TRUE(attached.ok()) << attached.status().ToString();
  EXPECT_THAT(accepted_ids, ::testing::ElementsAre(accepted.job_id()));  // replayed

  // The same plan as one never interrupted.
  auto direct = (*c)->Plan({scene_, "box.ply"}, wire::FromProto(params_).value());
  ASSERT_TRUE(direct.ok()) << direct.status().ToString();
  ASSERT_EQ(attached->stations.size(), direct->stations.size());
  for (size_t i = 0; i < direct->stations.size(); ++i) {
    EXPECT_EQ(attached->stations[i].position, direct->stations[i].position);
  }
  EXPECT_EQ(attached->evaluation.overall.global_visibility, direct->evaluation.overall.global_visibility);

  // Delivered: the server forgets it (once its side of the call is done, a moment later).
  const auto again = EventuallyNotFound([&] { return (*c)->AttachPlan(accepted.job_id()).status(); });
  EXPECT_EQ(again.code(), StatusCode::kNotFound);
  EXPECT_THAT(again.message(), HasSubstr("no detachable job " + accepted.job_id()));
}

TEST_F(Detach, TheClientReattachesByItselfWhenTheLinkDropsAndGetsTheWholePlan) {
  Start();
  TcpProxy link(server_->port());
  client::ConnectionOptions conn = Conn();
  conn.server = link.address();
  conn.detach_grace_s = 30;
  conn.initial_backoff = 100ms;
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  testing::Latch accepted;
  std::atomic<int> reattaches{0};
  client::JobObserver observer;
  observer.on_accepted = [&](const std::string&, uint32_t) { accepted.Set(); };
  observer.on_reattach = [&](const client::JobTicket& t, const Status& s, std::chrono::milliseconds) {
    EXPECT_FALSE(t.job_id.empty());
    EXPECT_EQ(s.code(), StatusCode::kUnavailable) << s.ToString();
    ++reattaches;
  };
  Result<PlanResult> result = InternalError("not run");
  std::thread submit([&] { result = (*c)->Plan({scene_, "box.ply"}, PlanOptions{}, observer); });
  ASSERT_TRUE(accepted.WaitFor(10s));
  ASSERT_TRUE(backend_.started.WaitFor(5s));
  link.Break();  // the site link drops while the job runs
  std::this_thread::sleep_for(300ms);
  backend_.gate.Set();
  submit.join();
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_GE(reattaches.load(), 1);
  EXPECT_FALSE(result->stations.empty());
  EXPECT_GT(result->evaluation.overall.global_visibility, 0.5);
}

TEST_F(Detach, AResultNobodyAttachesToExpiresAfterItsTtl) {
  server::ServerOptions o;
  o.result_ttl = 300ms;
  Start(o);
  const v1::Accepted accepted = SubmitAndVanish(60);
  backend_.gate.Set();
  ASSERT_TRUE(backend_.returned.WaitFor(30s));
  EXPECT_TRUE(backend_.last().ok());
  std::this_thread::sleep_for(1500ms);  // ttl 0.3 s, swept every 0.25 s
  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  const auto r = (*c)->AttachPlan(accepted.job_id());
  EXPECT_EQ(r.status().code(), StatusCode::kNotFound);
}

TEST_F(Detach, OnlyTheSubmittingTokenMayAttachOrCancel) {
  server::ServerOptions o;
  o.tokens = {"alice-token", "bob-token"};
  Start(o);
  const v1::Accepted accepted = SubmitAndVanish(60, "alice-token");

  auto bob = client::Client::Create(Conn("bob-token"));
  ASSERT_TRUE(bob.ok());
  EXPECT_EQ((*bob)->AttachPlan(accepted.job_id()).status().code(), StatusCode::kPermissionDenied);
  EXPECT_EQ((*bob)->CancelJob(accepted.job_id()).status().code(), StatusCode::kPermissionDenied);
  auto nobody = client::Client::Create(Conn("mallory-token"));
  ASSERT_TRUE(nobody.ok());
  EXPECT_EQ((*nobody)->AttachPlan(accepted.job_id()).status().code(), StatusCode::kUnauthenticated);

  // Alice cancels: the worker is free within a second, and an attach hears why.
  auto alice = client::Client::Create(Conn("alice-token"));
  ASSERT_TRUE(alice.ok());
  const auto cancelled_at = std::chrono::steady_clock::now();
  const auto outcome = (*alice)->CancelJob(accepted.job_id());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(*outcome, "cancelled");
  ASSERT_TRUE(backend_.returned.WaitFor(2s));
  EXPECT_LT(std::chrono::steady_clock::now() - cancelled_at, 1s);
  EXPECT_EQ(backend_.last().code(), StatusCode::kCancelled);
  const auto r = (*alice)->AttachPlan(accepted.job_id());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_THAT(r.status().message(), HasSubstr("cancelled by CancelJob"));
  // That status reached a client: the job is forgotten.
  EXPECT_EQ(EventuallyNotFound([&] { return (*alice)->CancelJob(accepted.job_id()).status(); }).code(),
            StatusCode::kNotFound);
}

TEST_F(Detach, WhenTheGraceRunsOutWithoutAClientTheJobIsCancelled) {
  Start();
  const v1::Accepted accepted = SubmitAndVanish(1);
  ASSERT_TRUE(backend_.returned.WaitFor(3s));
  EXPECT_EQ(backend_.last().code(), StatusCode::kCancelled);
  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  const auto r = (*c)->AttachPlan(accepted.job_id());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_THAT(r.status().message(), HasSubstr("no client re-attached within its 1 s detach grace"));
}

TEST_F(Detach, TheServerCapsTheGraceAndTheCappedGraceRunsOut) {
  server::ServerOptions o;
  o.max_detach_grace = 2s;
  Start(o);
  const v1::Accepted capped = SubmitAndVanish(600);
  EXPECT_EQ(capped.detach_grace_s(), 2u);
  ASSERT_TRUE(backend_.returned.WaitFor(4s));  // cancelled by the capped grace
  EXPECT_EQ(backend_.last().code(), StatusCode::kCancelled);
}

TEST_F(Detach, WithoutAGraceTheJobEndsWithItsStreamAndCannotBeAttached) {
  Start();
  const v1::Accepted accepted = SubmitAndVanish(0);
  EXPECT_EQ(accepted.detach_grace_s(), 0u);
  ASSERT_TRUE(backend_.returned.WaitFor(2s));  // Blocking.CancellationFreesTheWorkerWithinASecond times it
  EXPECT_EQ(backend_.last().code(), StatusCode::kCancelled);
  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  EXPECT_EQ((*c)->AttachPlan(accepted.job_id()).status().code(), StatusCode::kNotFound);
  EXPECT_EQ((*c)->CancelJob(accepted.job_id()).status().code(), StatusCode::kNotFound);
}

TEST_F(Detach, AServerThatAllowsNoGraceGrantsNone) {
  server::ServerOptions o;
  o.max_detach_grace = 0s;
  Start(o);
  const v1::Accepted accepted = SubmitAndVanish(600);
  EXPECT_EQ(accepted.detach_grace_s(), 0u);
  ASSERT_TRUE(backend_.returned.WaitFor(2s));
  EXPECT_EQ(backend_.last().code(), StatusCode::kCancelled);
}

TEST_F(Detach, CancelJobEndsTheCallOfAClientStillAttachedWithCancelled) {
  Start();
  client::ConnectionOptions conn = Conn();
  conn.detach_grace_s = 30;
  auto submitter = client::Client::Create(conn);
  ASSERT_TRUE(submitter.ok());
  testing::Latch accepted;
  std::string job_id;
  client::JobObserver observer;
  observer.on_job = [&](const client::JobTicket& t) {
    job_id = t.job_id;
    accepted.Set();
  };
  Result<PlanResult> result = InternalError("not run");
  std::thread submit([&] { result = (*submitter)->Plan({scene_, "box.ply"}, PlanOptions{}, observer); });
  ASSERT_TRUE(accepted.WaitFor(10s));
  ASSERT_TRUE(backend_.started.WaitFor(5s));
  auto other = client::Client::Create(Conn());
  ASSERT_TRUE(other.ok());
  const auto outcome = (*other)->CancelJob(job_id);
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(*outcome, "cancelled");
  submit.join();
  EXPECT_EQ(result.status().code(), StatusCode::kCancelled);
  EXPECT_THAT(result.status().message(), HasSubstr("cancelled by CancelJob"));
}

TEST_F(Detach, ASecondAttachTakesTheJobOverAndTheFirstEndsWithAborted) {
  Start();
  const v1::Accepted accepted = SubmitAndVanish(60);
  auto stub =
      v1::StationPlanner::NewStub(grpc::CreateChannel(testing::Address(*server_), grpc::InsecureChannelCredentials()));
  v1::AttachRequest request;
  request.set_job_id(accepted.job_id());
  grpc::ClientContext first_ctx;
  auto first = stub->AttachPlan(&first_ctx, request);
  v1::PlanResponse r;
  ASSERT_TRUE(first->Read(&r));  // the replayed Accepted: the first is attached
  EXPECT_EQ(r.accepted().job_id(), accepted.job_id());
  backend_.gate.Set();  // the job finishes while the second client follows it
  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  const auto second = (*c)->AttachPlan(accepted.job_id());
  EXPECT_TRUE(second.ok()) << second.status().ToString();
  while (first->Read(&r)) {
  }
  const grpc::Status first_status = first->Finish();
  EXPECT_EQ(first_status.error_code(), grpc::StatusCode::ABORTED) << first_status.error_message();
}

TEST_F(Detach, AShutdownEndsDetachedJobsRunningAndQueued) {
  Start();
  const v1::Accepted running = SubmitAndVanish(60);
  // A second detached job waits for the single worker.
  auto stub =
      v1::StationPlanner::NewStub(grpc::CreateChannel(testing::Address(*server_), grpc::InsecureChannelCredentials()));
  {
    grpc::ClientContext ctx;
    auto stream = stub->Plan(&ctx);
    auto requests = testing::PlanRequests(scene_, params_);
    requests[0].mutable_spec()->mutable_control()->set_detach_grace_s(60);
    for (const auto& q : requests) EXPECT_TRUE(stream->Write(q));
    EXPECT_TRUE(stream->WritesDone());
    v1::PlanResponse first;
    ASSERT_TRUE(stream->Read(&first));
    EXPECT_EQ(first.accepted().queue_position(), 1u);
    ctx.TryCancel();
    stream->Finish();
  }
  std::this_thread::sleep_for(200ms);
  const auto t0 = std::chrono::steady_clock::now();
  server_->Shutdown(std::chrono::milliseconds(100));  // a short grace: both are cancelled
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 10s);
  ASSERT_TRUE(backend_.returned.WaitFor(1s));
  EXPECT_EQ(backend_.last().code(), StatusCode::kCancelled);
  server_.reset();  // joins the workers; nothing may touch freed state (run under ASan)
}

TEST_F(Detach, AttachingWithTheOtherRpcIsAFailedPreconditionNamingTheRightOne) {
  Start();
  const v1::Accepted accepted = SubmitAndVanish(60);
  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  const auto r = (*c)->AttachEvaluate(accepted.job_id());
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(r.status().message(), HasSubstr("AttachPlan"));
  const auto cancelled = (*c)->CancelJob(accepted.job_id());
  ASSERT_TRUE(cancelled.ok()) << cancelled.status().ToString();
  EXPECT_EQ(*cancelled, "cancelled");
  // Cancelling the job once it ended discards what was kept.
  ASSERT_TRUE(backend_.returned.WaitFor(2s));
  auto discarded = (*c)->CancelJob(accepted.job_id());
  for (int i = 0; i < 40 && discarded.ok() && *discarded == "cancelled"; ++i) {  // the worker is ending it
    std::this_thread::sleep_for(50ms);
    discarded = (*c)->CancelJob(accepted.job_id());
  }
  ASSERT_TRUE(discarded.ok()) << discarded.status().ToString();
  EXPECT_EQ(*discarded, "discarded");
  EXPECT_EQ((*c)->AttachPlan(accepted.job_id()).status().code(), StatusCode::kNotFound);
}

TEST_F(Detach, AnEvaluationIsDetachableToo) {
  Start();
  auto c = client::Client::Create(Conn());
  ASSERT_TRUE(c.ok());
  // Submitted by a client with a grace that stays: the normal path delivers and forgets.
  client::ConnectionOptions conn = Conn();
  conn.detach_grace_s = 30;
  auto with_grace = client::Client::Create(conn);
  ASSERT_TRUE(with_grace.ok());
  backend_.gate.Set();
  EvaluateJobOptions eval;
  eval.viewpoints = {{2, 1.5, 1.2}};
  const auto r = (*with_grace)->Evaluate({scene_, "box.ply"}, eval);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_GT(r->evaluation.overall.global_visibility, 0.5);
  const client::JobTicket& ticket = (*with_grace)->last_job();
  EXPECT_EQ(ticket.detach_grace_s, 30u);
  EXPECT_EQ(EventuallyNotFound([&] { return (*c)->AttachEvaluate(ticket.job_id).status(); }).code(),
            StatusCode::kNotFound);  // delivered
}

}  // namespace
}  // namespace vc
