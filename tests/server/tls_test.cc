// TLS and mutual TLS with certificates made at test time by the openssl CLI.
#include <gtest/gtest.h>

#include <cstdlib>

#include "testing/test_paths.h"
#include "testing/test_server.h"
#include "vc/client/client.h"
#include "vc/wire/status_mapping.h"

namespace vc {
namespace {

// A CA, a server certificate for 127.0.0.1/localhost and a client certificate, in a temp dir.
class Tls : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir();
    const std::string script =
        "set -e; cd '" + dir_ + "'; " +
        "openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem -days 2 -subj /CN=vc-test-ca; "
        "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.ext; "
        "openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr -subj /CN=localhost; "
        "openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out server.pem -days 2 "
        "-extfile san.ext; "
        "openssl req -newkey rsa:2048 -nodes -keyout client.key -out client.csr -subj /CN=vc-test-client; "
        "openssl x509 -req -in client.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out client.pem -days 2";
    ASSERT_EQ(std::system(("bash -c \"" + script + "\" >/dev/null 2>&1").c_str()), 0) << "openssl failed";
  }
  std::string F(const std::string& name) const { return dir_ + "/" + name; }
  grpc::StatusCode Health(const server::Server& s, client::ConnectionOptions conn) const {
    conn.server = testing::Address(s);
    conn.max_attempts = 1;
    conn.timeout = std::chrono::seconds(5);
    auto c = client::Client::Create(conn);
    EXPECT_TRUE(c.ok()) << c.status().ToString();
    if (!c.ok()) return grpc::StatusCode::UNKNOWN;
    return wire::ToGrpcCode((*c)->Health().status().code());
  }
  std::string dir_;
};

TEST_F(Tls, ServerCertificateVerifiedByTheTestCa) {
  server::ServerOptions o;
  o.workers = 1;
  o.tls_cert_file = F("server.pem");
  o.tls_key_file = F("server.key");
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  client::ConnectionOptions tls;
  tls.tls_ca_file = F("ca.pem");
  EXPECT_EQ(Health(*server, tls), grpc::StatusCode::OK);
  client::ConnectionOptions plaintext;
  EXPECT_EQ(Health(*server, plaintext), grpc::StatusCode::UNAVAILABLE);
  client::ConnectionOptions wrong_ca;
  wrong_ca.tls_ca_file = F("client.pem");  // not the CA that signed the server certificate
  EXPECT_EQ(Health(*server, wrong_ca), grpc::StatusCode::UNAVAILABLE);
}

TEST_F(Tls, MutualTlsRequiresAClientCertificate) {
  server::ServerOptions o;
  o.workers = 1;
  o.tls_cert_file = F("server.pem");
  o.tls_key_file = F("server.key");
  o.tls_client_ca_file = F("ca.pem");
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  client::ConnectionOptions with_cert;
  with_cert.tls_ca_file = F("ca.pem");
  with_cert.tls_cert_file = F("client.pem");
  with_cert.tls_key_file = F("client.key");
  EXPECT_EQ(Health(*server, with_cert), grpc::StatusCode::OK);
  client::ConnectionOptions without_cert;
  without_cert.tls_ca_file = F("ca.pem");
  EXPECT_EQ(Health(*server, without_cert), grpc::StatusCode::UNAVAILABLE);
}

TEST_F(Tls, MissingCertificateFileIsNotFound) {
  server::ServerOptions o;
  o.listen = "127.0.0.1:0";
  o.tls_cert_file = F("nope.pem");
  o.tls_key_file = F("server.key");
  auto s = server::Server::Start(o);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kNotFound);
}

// Replicas speak TLS to each other when they speak it to clients (docs/DEPLOY.md, "Scaling out"):
// with mutual TLS the coordinator presents its own certificate; a peer whose certificate the
// --peer-tls-ca does not verify is left out with a warning, and the plan is the same.
TEST_F(Tls, ReplicasFanOutOverMutualTls) {
  server::ServerOptions o;
  o.workers = 2;
  o.threads_per_job = 1;
  o.tls_cert_file = F("server.pem");
  o.tls_key_file = F("server.key");
  o.tls_client_ca_file = F("ca.pem");
  auto peer = testing::StartServer(o);
  ASSERT_TRUE(peer);
  o.peers = {testing::Address(*peer)};
  o.shard_candidates = 4;
  o.local_shards = false;
  o.peer_tls_ca_file = F("ca.pem");
  auto coordinator = testing::StartServer(o);
  ASSERT_TRUE(coordinator);
  o.peer_tls_ca_file = F("client.pem");  // not a CA that signed the peer's certificate
  auto misconfigured = testing::StartServer(o);
  ASSERT_TRUE(misconfigured);

  client::ConnectionOptions conn;
  conn.tls_ca_file = F("ca.pem");
  conn.tls_cert_file = F("client.pem");
  conn.tls_key_file = F("client.key");
  conn.max_attempts = 1;
  PlanOptions plan;
  plan.solver = SelectionSolver::kGreedy;
  const client::Upload room{testing::BoxRoomPly({6, 4, 2.5}, 0.1), "room.ply"};
  auto plan_on = [&](const server::Server& s) {
    conn.server = testing::Address(s);
    auto c = client::Client::Create(conn);
    EXPECT_TRUE(c.ok());
    return (*c)->Plan(room, plan);
  };
  const auto fanned = plan_on(*coordinator);
  ASSERT_TRUE(fanned.ok()) << fanned.status().ToString();
  EXPECT_EQ(fanned->distribution.replicas, 1);  // the peer computed every shard
  EXPECT_GT(fanned->distribution.shards, 1);
  EXPECT_TRUE(fanned->warnings.empty());
  const auto alone = plan_on(*misconfigured);
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  ASSERT_FALSE(alone->warnings.empty());
  EXPECT_NE(alone->warnings[0].find(testing::Address(*peer)), std::string::npos) << alone->warnings[0];
  ASSERT_EQ(alone->stations.size(), fanned->stations.size());
  for (size_t k = 0; k < alone->stations.size(); ++k) {
    EXPECT_EQ(alone->stations[k].position, fanned->stations[k].position);
  }
  EXPECT_EQ(alone->covered_voxels, fanned->covered_voxels);
}

}  // namespace
}  // namespace vc
