// vc/server/server_options.h: the defaults are valid, each bad field is refused naming its flag,
// the 0 defaults of workers and per-job threads resolve to the cores, and ApplyServerLimits gives
// every job (Plan, Evaluate, a peer's shard) what this server allows.
#include "vc/server/server_options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace vc::server {
namespace {

using ::testing::HasSubstr;

TEST(ServerOptionsTest, TheDefaultsAreValidAndFanOutOnlyWithPeers) {
  ServerOptions o;
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().ToString();
  EXPECT_FALSE(o.HasPeers());
  o.peers = {"10.0.0.2:50051"};
  EXPECT_TRUE(o.HasPeers());
  EXPECT_TRUE(o.Validate().ok());
  o.peers.clear();
  o.peers_dns = "vc-server-peers.default.svc.cluster.local:50051";
  EXPECT_TRUE(o.HasPeers());
  EXPECT_TRUE(o.Validate().ok());
}

TEST(ServerOptionsTest, EachBadFieldIsRefusedNamingItsFlag) {
  struct Case {
    std::function<void(ServerOptions&)> spoil;
    std::string flag;
  };
  const std::vector<Case> cases = {
      {[](ServerOptions& o) { o.listen = "50051"; }, "--listen '50051' is not host:port"},
      {[](ServerOptions& o) { o.listen = ""; }, "--listen"},
      {[](ServerOptions& o) { o.workers = -1; }, "--workers"},
      {[](ServerOptions& o) { o.queue = -1; }, "--queue"},
      {[](ServerOptions& o) { o.max_upload_bytes = 0; }, "--max-upload-bytes"},
      {[](ServerOptions& o) { o.max_memory_budget_bytes = 0; }, "--max-memory-budget-bytes"},
      {[](ServerOptions& o) { o.threads_per_job = -2; }, "--threads-per-job"},
      {[](ServerOptions& o) { o.tls_cert_file = "cert.pem"; }, "--tls-cert and --tls-key must be given together"},
      {[](ServerOptions& o) { o.tls_key_file = "key.pem"; }, "--tls-cert and --tls-key must be given together"},
      {[](ServerOptions& o) { o.tls_client_ca_file = "ca.pem"; }, "--tls-client-ca needs --tls-cert"},
      {[](ServerOptions& o) { o.tokens.emplace_back(""); }, "--token: a token is empty"},
      {[](ServerOptions& o) { o.max_detach_grace = std::chrono::milliseconds(-1); }, "--max-detach-grace-seconds"},
      {[](ServerOptions& o) { o.result_ttl = std::chrono::milliseconds(-1); }, "--result-ttl-seconds"},
      {[](ServerOptions& o) { o.shutdown_grace = std::chrono::milliseconds(-1); }, "--shutdown-grace"},
      {[](ServerOptions& o) { o.peers.emplace_back("10.0.0.3"); }, "--peers: '10.0.0.3' is not host:port"},
      {[](ServerOptions& o) { o.peers.emplace_back("10.0.0.3:"); }, "--peers: '10.0.0.3:'"},
      {[](ServerOptions& o) { o.peers_dns = "peers.local"; }, "--peers-dns 'peers.local' is not NAME:PORT"},
      {[](ServerOptions& o) { o.shard_candidates = 0; }, "--shard-candidates"},
      {[](ServerOptions& o) { o.shard_deadline = std::chrono::milliseconds(0); }, "--shard-deadline-seconds"},
      {[](ServerOptions& o) { o.peer_tls_ca_file = "ca.pem"; }, "--peer-tls-ca needs --tls-cert"},
  };
  for (const Case& c : cases) {
    ServerOptions o;
    c.spoil(o);
    const Status s = o.Validate();
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << c.flag;
    EXPECT_THAT(s.message(), HasSubstr(c.flag));
  }
  ServerOptions tls;
  tls.tls_cert_file = "cert.pem";
  tls.tls_key_file = "key.pem";
  tls.tls_client_ca_file = "ca.pem";
  tls.peer_tls_ca_file = "ca.pem";
  EXPECT_TRUE(tls.Validate().ok()) << tls.Validate().ToString();
}

TEST(ServerOptionsTest, ZeroWorkersAndThreadsResolveToTheCores) {
  const int cores = std::max(1, int(std::thread::hardware_concurrency()));
  ServerOptions o;
  EXPECT_EQ(o.EffectiveWorkers(), cores);
  EXPECT_EQ(o.EffectiveThreadsPerJob(), 1);  // cores / cores
  o.workers = 2;
  EXPECT_EQ(o.EffectiveWorkers(), 2);
  EXPECT_EQ(o.EffectiveThreadsPerJob(), std::max(1, cores / 2));
  o.workers = 4 * cores;
  EXPECT_EQ(o.EffectiveThreadsPerJob(), 1);
  o.threads_per_job = 7;
  EXPECT_EQ(o.EffectiveThreadsPerJob(), 7);
}

ServerOptions Server() {
  ServerOptions o;
  o.max_memory_budget_bytes = uint64_t{1} << 30;
  o.threads_per_job = 4;
  return o;
}

EvaluateJobOptions OneViewpoint() {
  EvaluateJobOptions o;
  o.viewpoints.emplace_back(1, 1, 1);
  return o;
}

TEST(ApplyServerLimits, CapsTheMemoryBudget) {
  PlanOptions big;
  big.memory_budget_bytes = uint64_t{8} << 30;
  const Result<PlanOptions> capped = ApplyServerLimits(Server(), big);
  ASSERT_TRUE(capped.ok()) << capped.status().ToString();
  EXPECT_EQ(capped->memory_budget_bytes, uint64_t{1} << 30);
  PlanOptions small;
  small.memory_budget_bytes = 1000;
  const Result<PlanOptions> kept = ApplyServerLimits(Server(), small);
  ASSERT_TRUE(kept.ok()) << kept.status().ToString();
  EXPECT_EQ(kept->memory_budget_bytes, 1000u);
}

TEST(ApplyServerLimits, ThreadsAreTheShareOrFewer) {
  for (const auto& [requested, expected] : {std::pair{0, 4}, std::pair{2, 2}, std::pair{4, 4}, std::pair{9, 4}}) {
    PlanOptions plan;
    plan.threads = requested;
    const Result<PlanOptions> p = ApplyServerLimits(Server(), plan);
    ASSERT_TRUE(p.ok()) << p.status().ToString();
    EXPECT_EQ(p->threads, expected) << "plan asked for " << requested;
    EvaluateJobOptions evaluate = OneViewpoint();
    evaluate.threads = requested;
    const Result<EvaluateJobOptions> e = ApplyServerLimits(Server(), evaluate);
    ASSERT_TRUE(e.ok()) << e.status().ToString();
    EXPECT_EQ(e->threads, expected) << "evaluation asked for " << requested;
  }
}

TEST(ApplyServerLimits, NegativeThreadsAreRefusedBeforeAnyOtherParameter) {
  PlanOptions plan;
  plan.threads = -2;
  plan.resolution_m = -1;
  const Result<PlanOptions> p = ApplyServerLimits(Server(), plan);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.status(), InvalidArgumentError("threads must be >= 0 (0 = the server's share)"));
  EvaluateJobOptions evaluate;  // no viewpoint either
  evaluate.threads = -1;
  const Result<EvaluateJobOptions> e = ApplyServerLimits(Server(), evaluate);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status(), InvalidArgumentError("threads must be >= 0 (0 = the server's share)"));
}

TEST(ApplyServerLimits, TheCappedOptionsAreValidated) {
  PlanOptions plan;
  plan.resolution_m = -1;
  EXPECT_EQ(ApplyServerLimits(Server(), plan).status().code(), StatusCode::kInvalidArgument);
  PlanOptions no_budget;
  no_budget.memory_budget_bytes = 0;
  EXPECT_EQ(ApplyServerLimits(Server(), no_budget).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ApplyServerLimits(Server(), EvaluateJobOptions{}).status().code(), StatusCode::kInvalidArgument)
      << "an evaluation without viewpoints";
}

}  // namespace
}  // namespace vc::server
