// vc/server/server_options.h: the defaults are valid, each bad field is refused naming its flag,
// and the 0 defaults of workers and per-job threads resolve to the cores.
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

}  // namespace
}  // namespace vc::server
