// Scaling out (docs/DEPLOY.md, "Scaling out"): a plan fanned out over replicas is the plan of one
// replica, station for station; a peer that hangs, dies, answers for another scene or refuses the
// token costs time, not the plan; the calls between replicas check what they are sent.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>

#include "testing/test_server.h"
#include "vc/client/client.h"
#include "vc/plan/stages.h"
#include "vc/scene/scene_input.h"
#include "vc/server/peers.h"
#include "vc/wire/face_values_codec.h"
#include "vc/wire/sha256.h"
#include "vc/wire/status_mapping.h"
#include "vc/wire/voxel_set_codec.h"

namespace vc {
namespace {

// An 8 x 6 m room: about 35 candidates at the 1 m grid, so shards of 4 make nine.
const std::string& Room() {
  static const std::string ply = testing::BoxRoomPly({8, 6, 2.5}, 0.1);
  return ply;
}

PlanOptions Options() {
  PlanOptions o;
  o.solver = SelectionSolver::kGreedy;
  o.threads = 1;
  return o;
}

server::ServerOptions Replica() {
  server::ServerOptions o;
  o.workers = 2;
  o.threads_per_job = 1;
  return o;
}

server::ServerOptions Coordinator(std::vector<std::string> peers) {
  server::ServerOptions o = Replica();
  o.peers = std::move(peers);
  o.shard_candidates = 4;
  return o;
}

Result<PlanResult> PlanOn(const std::string& address, const std::string& token = "",
                          const PlanOptions& options = Options()) {
  client::ConnectionOptions conn;
  conn.server = address;
  conn.token = token;
  conn.max_attempts = 1;
  VC_ASSIGN_OR_RETURN(auto c, client::Client::Create(conn));
  return c->Plan({Room(), "room.ply"}, options);
}

// The same plan: stations, coverage, G and every candidate's count.
void ExpectSamePlan(const PlanResult& a, const PlanResult& b) {
  ASSERT_EQ(a.stations.size(), b.stations.size());
  for (size_t k = 0; k < a.stations.size(); ++k) {
    EXPECT_EQ(a.stations[k].position, b.stations[k].position) << "station " << k;
    EXPECT_EQ(a.stations[k].visible_voxels, b.stations[k].visible_voxels) << "station " << k;
  }
  EXPECT_EQ(a.covered_voxels, b.covered_voxels);
  EXPECT_EQ(a.coverable_voxels, b.coverable_voxels);
  EXPECT_EQ(a.evaluation.overall.global_visibility, b.evaluation.overall.global_visibility);
  EXPECT_EQ(a.heat_map.visible_voxels, b.heat_map.visible_voxels);
  EXPECT_EQ(a.reduction.matrix, b.reduction.matrix);
  EXPECT_EQ(a.reduction.removed, b.reduction.removed);
  EXPECT_EQ(a.reduction.global_visibility_after, b.reduction.global_visibility_after);
}

bool HasWarning(const PlanResult& r, const std::string& part) {
  for (const std::string& w : r.warnings) {
    if (w.find(part) != std::string::npos) return true;
  }
  return false;
}

std::string Warnings(const PlanResult& r) {
  std::string out;
  for (const std::string& w : r.warnings) out += w + "\n";
  return out;
}

// A peer that misbehaves: it hangs on every shard until cancelled (kHang), dies with its first
// shard in flight (kDie: the test shuts it down), or answers with sets of another scene
// (kOtherScene).
class FakePeer final : public v1::StationPlanner::CallbackService {
 public:
  // kOld: a replica older than ShardRequest.keep_join_state, in front of a real one (`behind`,
  // which must hold the scene already): it passes each shard on without that field.
  // kBadFigures: passes each shard on to `behind` as it is, then answers every station's figures
  // with a G that is not a number.
  enum class Mode { kHang, kDie, kOtherScene, kOld, kBadFigures };
  explicit FakePeer(Mode mode, const std::string& behind = "") : mode_(mode) {
    if (!behind.empty()) {
      behind_ = v1::StationPlanner::NewStub(grpc::CreateChannel(behind, grpc::InsecureChannelCredentials()));
    }
    grpc::ServerBuilder b;
    b.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    b.RegisterService(this);
    server_ = b.BuildAndStart();
  }
  ~FakePeer() override { Kill(); }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  void Kill() {
    if (server_) server_->Shutdown(std::chrono::system_clock::now());
    if (server_) server_->Wait();
    server_.reset();
  }
  int shards() const { return shards_.load(); }
  testing::Latch first_shard;

  grpc::ServerUnaryReactor* PeerHello(grpc::CallbackServerContext* ctx, const v1::PeerHelloRequest*,
                                      v1::PeerHelloResponse* response) override {
    response->set_replica_id("fake");
    response->set_has_scene(true);
    auto* r = ctx->DefaultReactor();
    r->Finish(grpc::Status::OK);
    return r;
  }
  grpc::ServerUnaryReactor* ComputeShard(grpc::CallbackServerContext* ctx, const v1::ShardRequest* request,
                                         v1::ShardResponse* response) override {
    ++shards_;
    first_shard.Set();
    if (mode_ == Mode::kOld || mode_ == Mode::kBadFigures) {
      v1::ShardRequest passed = *request;
      if (mode_ == Mode::kOld) passed.clear_keep_join_state();
      grpc::ClientContext c;
      const grpc::Status st = behind_->ComputeShard(&c, passed, response);  // blocking: a test's fake
      if (mode_ == Mode::kBadFigures) {
        for (v1::FaceValues& m : *response->mutable_face_values()) {
          if (m.has_figures()) m.mutable_figures()->set_global_visibility(std::nan(""));
        }
      }
      auto* r = ctx->DefaultReactor();
      r->Finish(st);
      return r;
    }
    if (mode_ == Mode::kOtherScene) {
      response->set_occupied_voxels(3);
      response->set_scene_crc32c(7);
      for (int i = 0; i < request->viewpoints_size(); ++i) response->add_sets(wire::EncodeVoxelSet(VoxelSet(3)));
      auto* r = ctx->DefaultReactor();
      r->Finish(grpc::Status::OK);
      return r;
    }
    return new Hang();
  }

 private:
  // Answers only when the call is cancelled (by the coordinator, or a shutdown).
  struct Hang : grpc::ServerUnaryReactor {
    void OnCancel() override { Finish(grpc::Status(grpc::StatusCode::CANCELLED, "gone")); }
    void OnDone() override { delete this; }
  };
  const Mode mode_;
  std::unique_ptr<v1::StationPlanner::Stub> behind_;
  int port_ = 0;
  std::atomic<int> shards_{0};
  std::unique_ptr<grpc::Server> server_;
};

// `options` planned on a lone replica (B), then on a coordinator (A) that leaves every shard to B
// and C.
std::pair<Result<PlanResult>, Result<PlanResult>> PlanAloneAndFannedOut(const PlanOptions& options) {
  auto b = testing::StartServer(Replica());
  auto c = testing::StartServer(Replica());
  if (!b || !c) return {InternalError("no replica started"), InternalError("no replica started")};
  Result<PlanResult> alone = PlanOn(testing::Address(*b), "", options);
  server::ServerOptions o = Coordinator({testing::Address(*b), testing::Address(*c)});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  if (!a) return {std::move(alone), InternalError("no coordinator started")};
  return {std::move(alone), PlanOn(testing::Address(*a), "", options)};
}

// The reduction's shards of `stations` at --shard-candidates 4 (ShardViewpoints).
size_t ReductionShards(size_t stations) {
  const size_t per_shard = server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, stations, 4);
  return (stations + per_shard - 1) / per_shard;
}

// Shards of visibility sets hold --shard-candidates viewpoints; shards of face values are at least
// 12 where the stations allow, of 4 stations at least (a small plan's few stay on the coordinator)
// and of --shard-candidates at most.
TEST(FanOut, ShardSizes) {
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_VISIBILITY_SETS, 4065, 128), 128u);
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_VISIBILITY_SETS, 3, 128), 128u);
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, 61, 128), 6u);    // 11 shards
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, 696, 128), 58u);  // 12 shards
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, 18, 128), 4u);    // 5 shards
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, 3, 128), 4u);     // one: stays local
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, 100000, 128), 128u);
  EXPECT_EQ(server::ShardViewpoints(v1::SHARD_KIND_FACE_VALUES, 61, 2), 2u);
}

TEST(FanOut, ThreeReplicasPlanExactlyAsOne) {
  auto b = testing::StartServer(Replica());
  auto c = testing::StartServer(Replica());
  ASSERT_TRUE(b && c);
  const auto alone = PlanOn(testing::Address(*b));
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  EXPECT_EQ(alone->distribution.shards, 0);

  // A leaves every shard to B and C: both must have computed some.
  server::ServerOptions o = Coordinator({testing::Address(*b), testing::Address(*c)});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  const auto fanned = PlanOn(testing::Address(*a));
  ASSERT_TRUE(fanned.ok()) << fanned.status().ToString();
  ExpectSamePlan(*alone, *fanned);
  // The visibility stage's shards of candidates, then the reduction's of stations.
  const size_t viewpoints = fanned->candidate_count, stations = size_t(fanned->reduction.size);
  EXPECT_EQ(fanned->distribution.shards, int((viewpoints + 3) / 4 + ReductionShards(stations)));
  EXPECT_EQ(fanned->distribution.replicas, 2) << Warnings(*fanned);
  EXPECT_GT(fanned->distribution.bytes_exchanged, Room().size());  // the scene went to both, then sets came back
  EXPECT_TRUE(fanned->warnings.empty()) << Warnings(*fanned);

  // A coordinator that computes shards too: the same plan again (B and C now hold the scene).
  auto a2 = testing::StartServer(Coordinator({testing::Address(*b), testing::Address(*c)}));
  ASSERT_TRUE(a2);
  const auto mixed = PlanOn(testing::Address(*a2));
  ASSERT_TRUE(mixed.ok()) << mixed.status().ToString();
  ExpectSamePlan(*alone, *mixed);
  EXPECT_GE(mixed->distribution.replicas, 1);
  EXPECT_LE(mixed->distribution.replicas, 3);
}

// The reduction's evaluation of the stations is sharded too: with nine fixed stations (never
// removed, all evaluated) besides greedy's, it makes three or more shards of 4, and the matrix, the
// removals and G are the single replica's.
TEST(FanOut, TheReductionsEvaluationIsShardedAcrossReplicas) {
  PlanOptions options = Options();
  for (double x : {1.0, 4.0, 7.0}) {
    for (double y : {1.0, 3.0, 5.0}) options.fixed_stations.push_back(WorldPoint(x, y, 1.5));
  }
  const auto [alone, fanned] = PlanAloneAndFannedOut(options);
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  ASSERT_GE(alone->reduction.size, 9);
  ASSERT_TRUE(fanned.ok()) << fanned.status().ToString();
  ExpectSamePlan(*alone, *fanned);
  const size_t viewpoints = fanned->candidate_count + options.fixed_stations.size();
  const size_t stations = size_t(fanned->reduction.size);
  EXPECT_EQ(fanned->distribution.shards, int((viewpoints + 3) / 4 + ReductionShards(stations)));
  EXPECT_EQ(fanned->distribution.replicas, 2) << Warnings(*fanned);
  EXPECT_TRUE(fanned->warnings.empty()) << Warnings(*fanned);
}

// Coarse then fine candidates (docs/PLANNING.md): the fine round's sets are fanned out too, as the
// visibility stage's; the plan is the single replica's.
TEST(FanOut, TheFineRoundsSetsAreShardedAcrossReplicas) {
  PlanOptions options = Options();
  options.coarse_above_candidates = 10;  // the room's ~35 candidates at 1 m: the 2 m grid first
  const auto [alone, fanned] = PlanAloneAndFannedOut(options);
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  const planner::LocalCandidatesReport& fine = alone->optimality.local_candidates;
  ASSERT_FALSE(fine.coarse_to_fine.empty());
  ASSERT_GT(fine.added, 0);
  ASSERT_TRUE(fanned.ok()) << fanned.status().ToString();
  ExpectSamePlan(*alone, *fanned);
  EXPECT_EQ(fanned->optimality.local_candidates.added, fine.added);
  const size_t coarse = fanned->candidate_count, added = size_t(fine.added);
  const size_t stations = size_t(fanned->reduction.size);
  EXPECT_EQ(fanned->distribution.shards, int((coarse + 3) / 4 + (added + 3) / 4 + ReductionShards(stations)));
  EXPECT_EQ(fanned->distribution.replicas, 2) << Warnings(*fanned);
  EXPECT_TRUE(fanned->warnings.empty()) << Warnings(*fanned);
}

// Nine fixed stations (never removed, and they cover the room, so none is removable) under a
// budget whose cache holds four stations at the worst case: the reduction asks the replicas in
// several batches.
PlanOptions SeveralReductionBatches() {
  PlanOptions options = Options();
  for (double x : {1.0, 4.0, 7.0}) {
    for (double y : {1.0, 3.0, 5.0}) options.fixed_stations.push_back(WorldPoint(x, y, 1.5));
  }
  auto input = ReadScene(Room(), "room.ply");
  auto voxelized = planner::RunVoxelizeStage({*input}, options, {});
  const uint64_t voxels = voxelized->scene.occupied.size();
  // Room for the join and its state in flight (15/32 of the budget for the table and the join).
  options.memory_budget_bytes =
      (planner::ReductionTableBytes(voxels) + planner::ReductionJoinBytes(voxels)) * 32 / 15 + 64;
  return options;
}

void ExpectSameEvaluation(const PlanResult& a, const PlanResult& b) {
  EXPECT_EQ(a.evaluation.overall.global_visibility, b.evaluation.overall.global_visibility);
  EXPECT_EQ(a.evaluation.overall.fully_visible_fraction, b.evaluation.overall.fully_visible_fraction);
  EXPECT_EQ(a.evaluation.overall.mean_full_visibility, b.evaluation.overall.mean_full_visibility);
  EXPECT_EQ(a.evaluation.overall.partially_visible_fraction, b.evaluation.overall.partially_visible_fraction);
  ASSERT_EQ(a.stations.size(), b.stations.size());
  for (size_t k = 0; k < a.stations.size(); ++k) {
    EXPECT_EQ(a.stations[k].global_visibility, b.stations[k].global_visibility) << k;
  }
}

// The replicas answer the reduction's first pass with each station's join state, which the
// coordinator joins into the final evaluation: the single replica's, bit for bit, over several
// batches (docs/PLANNING.md, "Reduction"; the core test PlannerTest.
// ReductionJoinsTheReplicasValuesIntoTheFinalEvaluation shows the evaluation stage then evaluates
// nothing).
TEST(FanOut, TheReplicasValuesJoinIntoTheFinalEvaluationAsOnOneReplica) {
  const PlanOptions options = SeveralReductionBatches();
  auto b = testing::StartServer(Replica());
  auto c = testing::StartServer(Replica());
  ASSERT_TRUE(b && c);
  const auto alone = PlanOn(testing::Address(*b), "", options);
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  ASSERT_TRUE(alone->reduction.removed.empty());
  ASSERT_GT(alone->stations.size(), 4u);
  EXPECT_TRUE(alone->warnings.empty()) << Warnings(*alone);
  server::ServerOptions o = Coordinator({testing::Address(*b), testing::Address(*c)});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  const auto fanned = PlanOn(testing::Address(*a), "", options);
  ASSERT_TRUE(fanned.ok()) << fanned.status().ToString();
  ExpectSamePlan(*alone, *fanned);
  ExpectSameEvaluation(*alone, *fanned);
  EXPECT_EQ(fanned->distribution.replicas, 2) << Warnings(*fanned);
  EXPECT_TRUE(fanned->warnings.empty()) << Warnings(*fanned);
}

// A replica older than the join state answers values alone: the coordinator evaluates the final
// stations again, says so, and the plan is the same.
TEST(FanOut, AnOlderReplicasValuesFallBackToEvaluatingAgain) {
  const PlanOptions options = SeveralReductionBatches();
  auto b = testing::StartServer(Replica());
  ASSERT_TRUE(b);
  const auto alone = PlanOn(testing::Address(*b), "", options);  // b now holds the scene
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  FakePeer old(FakePeer::Mode::kOld, testing::Address(*b));
  server::ServerOptions o = Coordinator({old.address()});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  const auto fanned = PlanOn(testing::Address(*a), "", options);
  ASSERT_TRUE(fanned.ok()) << fanned.status().ToString();
  EXPECT_GT(old.shards(), 0);
  ExpectSamePlan(*alone, *fanned);
  ExpectSameEvaluation(*alone, *fanned);
  EXPECT_TRUE(HasWarning(*fanned, "older than this one")) << Warnings(*fanned);
}

// A replica whose stations' figures are not Evaluate's (here G is not a number) is left out of the
// rest of the reduction, naming why; the coordinator computes its shards and the plan and
// evaluation are one replica's.
TEST(FanOut, AReplicasFiguresOutsideTheirRangeAreRefused) {
  const PlanOptions options = SeveralReductionBatches();
  auto b = testing::StartServer(Replica());
  ASSERT_TRUE(b);
  const auto alone = PlanOn(testing::Address(*b), "", options);  // b now holds the scene
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  FakePeer bad(FakePeer::Mode::kBadFigures, testing::Address(*b));
  auto a = testing::StartServer(Coordinator({bad.address()}));
  ASSERT_TRUE(a);
  const auto r = PlanOn(testing::Address(*a), "", options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_GT(bad.shards(), 0);
  ExpectSamePlan(*alone, *r);
  ExpectSameEvaluation(*alone, *r);
  EXPECT_TRUE(HasWarning(*r, "not all finite and within [0, 1]")) << Warnings(*r);
  EXPECT_TRUE(HasWarning(*r, "was left out of the rest of the reduction")) << Warnings(*r);
}

TEST(FanOut, AReplicaListedAmongItsOwnPeersIsSkipped) {
  // The Kubernetes case: the headless Service resolves to every replica, this one included.
  server::ServerOptions o = Coordinator({});
  o.local_shards = false;
  auto b = testing::StartServer(Replica());
  ASSERT_TRUE(b);
  o.peers = {testing::Address(*b)};
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  // Restart A listing itself too: its own lane answers PeerHello with its own id and is dropped.
  const std::string self = testing::Address(*a);
  a.reset();
  o.listen = self;
  o.peers = {self, testing::Address(*b)};
  auto started = server::Server::Start(o);  // testing::StartServer would pick another port
  ASSERT_TRUE(started.ok()) << started.status().ToString();
  a = std::move(*started);
  const auto r = PlanOn(self);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->distribution.replicas, 1) << "only B computed: " << Warnings(*r);
  EXPECT_TRUE(r->warnings.empty()) << Warnings(*r);
}

TEST(FanOut, AHungPeersShardIsStartedAgainElsewhere) {
  auto reference = testing::StartServer(Replica());
  ASSERT_TRUE(reference);
  const auto alone = PlanOn(testing::Address(*reference));
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  FakePeer hung(FakePeer::Mode::kHang);
  auto a = testing::StartServer(Coordinator({hung.address()}));
  ASSERT_TRUE(a);
  const auto r = PlanOn(testing::Address(*a));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ExpectSamePlan(*alone, *r);
  EXPECT_GE(hung.shards(), 1);
  EXPECT_GE(r->distribution.retried, 1);
  EXPECT_EQ(r->distribution.replicas, 1);  // this replica computed every shard in the end
}

TEST(FanOut, AHungPeerDoesNotStallACoordinatorThatLeavesShardsToItsPeers) {
  auto b = testing::StartServer(Replica());
  ASSERT_TRUE(b);
  const auto alone = PlanOn(testing::Address(*b));
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  FakePeer hung(FakePeer::Mode::kHang);
  server::ServerOptions o = Coordinator({testing::Address(*b), hung.address()});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  const auto r = PlanOn(testing::Address(*a));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ExpectSamePlan(*alone, *r);
  EXPECT_GE(hung.shards(), 1);
  EXPECT_GE(r->distribution.retried, 1);  // the hung shard, started again by B or this replica
}

TEST(FanOut, AReplicaThatDiesMidPlanCostsTimeNotThePlan) {
  auto b = testing::StartServer(Replica());
  ASSERT_TRUE(b);
  const auto alone = PlanOn(testing::Address(*b));
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  FakePeer dying(FakePeer::Mode::kDie);
  server::ServerOptions o = Coordinator({testing::Address(*b), dying.address()});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  std::thread killer([&] {
    if (dying.first_shard.WaitFor(std::chrono::seconds(60))) dying.Kill();
  });
  const auto r = PlanOn(testing::Address(*a));
  killer.join();
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ExpectSamePlan(*alone, *r);
  EXPECT_GE(r->distribution.retried, 1);
  EXPECT_TRUE(HasWarning(*r, dying.address())) << Warnings(*r);
}

TEST(FanOut, APeerWithAnotherVoxelizationIsLeftOut) {
  auto reference = testing::StartServer(Replica());
  ASSERT_TRUE(reference);
  const auto alone = PlanOn(testing::Address(*reference));
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  FakePeer other(FakePeer::Mode::kOtherScene);
  server::ServerOptions o = Coordinator({other.address()});
  o.local_shards = false;
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  const auto r = PlanOn(testing::Address(*a));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ExpectSamePlan(*alone, *r);
  EXPECT_EQ(other.shards(), 1);
  EXPECT_TRUE(HasWarning(*r, "voxelization differs")) << Warnings(*r);
}

TEST(FanOut, AWrongTokenBetweenReplicasIsRefused) {
  server::ServerOptions peer = Replica();
  peer.tokens = {"right"};
  auto b = testing::StartServer(peer);
  ASSERT_TRUE(b);
  server::ServerOptions o = Coordinator({testing::Address(*b)});
  o.tokens = {"right"};
  o.peer_token = "wrong";
  auto a = testing::StartServer(o);
  ASSERT_TRUE(a);
  const auto r = PlanOn(testing::Address(*a), "right");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->distribution.replicas, 1);
  EXPECT_TRUE(HasWarning(*r, "UNAUTHENTICATED")) << Warnings(*r);

  // Without --peer-token the coordinator presents its own first token, which B accepts.
  o.peer_token.clear();
  auto a2 = testing::StartServer(o);
  ASSERT_TRUE(a2);
  const auto ok = PlanOn(testing::Address(*a2), "right");
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  EXPECT_TRUE(ok->warnings.empty()) << Warnings(*ok);
  ExpectSamePlan(*r, *ok);
}

// The calls themselves, as a coordinator makes them.
class PeerCalls : public ::testing::Test {
 protected:
  void SetUp() override {
    server::ServerOptions o = Replica();
    o.tokens = {"t"};
    server_ = testing::StartServer(o);
    ASSERT_TRUE(server_);
    stub_ = v1::StationPlanner::NewStub(
        grpc::CreateChannel(testing::Address(*server_), grpc::InsecureChannelCredentials()));
  }
  void Prepare(grpc::ClientContext* c, const std::string& token = "t") {
    c->AddMetadata("authorization", "Bearer " + token);
  }
  grpc::Status Share(const std::string& sha, uint64_t size, const std::string& bytes, const std::string& token = "t") {
    grpc::ClientContext c;
    Prepare(&c, token);
    v1::ShareSceneResponse resp;
    auto w = stub_->ShareScene(&c, &resp);
    v1::SceneChunk chunk;
    chunk.set_sha256(sha);
    chunk.set_total_size_bytes(size);
    chunk.set_data(bytes);
    w->Write(chunk);
    w->WritesDone();
    return w->Finish();
  }
  bool HasScene(const std::string& sha) {
    grpc::ClientContext c;
    Prepare(&c);
    v1::PeerHelloRequest req;
    req.set_scene_sha256(sha);
    v1::PeerHelloResponse resp;
    EXPECT_TRUE(stub_->PeerHello(&c, req, &resp).ok());
    return resp.has_scene();
  }
  grpc::Status Shard(const std::string& sha, v1::ShardResponse* resp, const std::string& token = "t",
                     v1::ShardKind kind = v1::SHARD_KIND_VISIBILITY_SETS, bool keep_join_state = false) {
    grpc::ClientContext c;
    Prepare(&c, token);
    v1::ShardRequest req;
    req.set_scene_sha256(sha);
    req.set_kind(kind);
    req.set_keep_join_state(keep_join_state);
    *req.mutable_parameters() = wire::ToProto(Options());
    *req.add_viewpoints() = wire::ToProto(WorldPoint(2, 2, 1.5));
    *req.add_viewpoints() = wire::ToProto(WorldPoint(100, 100, 100));  // outside the room: sees nothing
    return stub_->ComputeShard(&c, req, resp);
  }
  std::unique_ptr<server::Server> server_;
  std::unique_ptr<v1::StationPlanner::Stub> stub_;
};

TEST_F(PeerCalls, ShareSceneChecksTheHashAndTheSize) {
  const std::string sha = wire::Sha256Hex(Room());
  EXPECT_FALSE(HasScene(sha));
  EXPECT_EQ(Share(sha, Room().size(), Room(), "wrong").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Share(sha, Room().size() + 1, Room()).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(Share(sha, Room().size() - 1, Room()).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(Share(std::string(64, '0'), Room().size(), Room()).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(Share("short", Room().size(), Room()).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_FALSE(HasScene(sha));
  const grpc::Status s = Share(sha, Room().size(), Room());
  EXPECT_TRUE(s.ok()) << s.error_message();
  EXPECT_TRUE(HasScene(sha));
}

TEST_F(PeerCalls, ComputeShardNeedsTheTokenAndTheSceneAndAnswersWithCheckableSets) {
  const std::string sha = wire::Sha256Hex(Room());
  v1::ShardResponse resp;
  EXPECT_EQ(Shard(sha, &resp, "wrong").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  const grpc::Status missing = Shard(sha, &resp);
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(missing.error_message().find("ShareScene"), std::string::npos) << missing.error_message();
  ASSERT_TRUE(Share(sha, Room().size(), Room()).ok());
  const grpc::Status s = Shard(sha, &resp);
  ASSERT_TRUE(s.ok()) << s.error_message();
  ASSERT_EQ(resp.sets_size(), 2);
  EXPECT_GT(resp.occupied_voxels(), 0u);
  const auto inside = wire::DecodeVoxelSet(resp.sets(0), resp.occupied_voxels());
  const auto outside = wire::DecodeVoxelSet(resp.sets(1), resp.occupied_voxels());
  ASSERT_TRUE(inside.ok() && outside.ok());
  EXPECT_GT(inside->count(), resp.occupied_voxels() / 10);
  EXPECT_EQ(outside->count(), 0u);
}

// The reduction's shards: each station's faces with V > 0, exactly as this process evaluates them.
TEST_F(PeerCalls, ComputeShardAnswersFaceValuesAsEvaluateGivesThem) {
  const std::string sha = wire::Sha256Hex(Room());
  ASSERT_TRUE(Share(sha, Room().size(), Room()).ok());
  v1::ShardResponse resp;
  const grpc::Status s = Shard(sha, &resp, "t", v1::SHARD_KIND_FACE_VALUES);
  ASSERT_TRUE(s.ok()) << s.error_message();
  EXPECT_EQ(resp.sets_size(), 0);
  ASSERT_EQ(resp.face_values_size(), 2);
  auto input = ReadScene(Room(), "room.ply");
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  auto voxelized = planner::RunVoxelizeStage({*input}, Options(), {});
  ASSERT_TRUE(voxelized.ok());
  ASSERT_EQ(voxelized->scene.occupied.size(), resp.occupied_voxels());
  auto local = Evaluate(voxelized->scene, {WorldPoint(2, 2, 1.5), WorldPoint(100, 100, 100)},
                        planner::ReductionEvaluateOptions(Options()));
  ASSERT_TRUE(local.ok());
  for (int k = 0; k < 2; ++k) {
    auto got = wire::DecodeFaceValues(resp.face_values(k), resp.occupied_voxels() * kFacesPerVoxel);
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    EXPECT_EQ(got->faces, local->per_viewpoint_sparse_values[k].faces) << k;
    EXPECT_EQ(got->values, local->per_viewpoint_sparse_values[k].values) << k;
  }
  EXPECT_GT(local->per_viewpoint_sparse_values[0].size(), 1000u);
  EXPECT_EQ(local->per_viewpoint_sparse_values[1].size(), 0u);
  for (int k = 0; k < 2; ++k) EXPECT_FALSE(resp.face_values(k).has_figures());  // not asked for
}

// Asked for the join state: each station's doubles, perceptions and figures, as Evaluate gives
// them with keep_sparse_join_state; no floats on the wire.
TEST_F(PeerCalls, ComputeShardAnswersTheJoinStateWhenAskedFor) {
  const std::string sha = wire::Sha256Hex(Room());
  ASSERT_TRUE(Share(sha, Room().size(), Room()).ok());
  v1::ShardResponse resp;
  const grpc::Status s = Shard(sha, &resp, "t", v1::SHARD_KIND_FACE_VALUES, true);
  ASSERT_TRUE(s.ok()) << s.error_message();
  ASSERT_EQ(resp.face_values_size(), 2);
  auto input = ReadScene(Room(), "room.ply");
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  auto voxelized = planner::RunVoxelizeStage({*input}, Options(), {});
  ASSERT_TRUE(voxelized.ok());
  EvaluateOptions eval_options = planner::ReductionEvaluateOptions(Options());
  eval_options.keep_sparse_join_state = true;
  auto local = Evaluate(voxelized->scene, {WorldPoint(2, 2, 1.5), WorldPoint(100, 100, 100)}, eval_options);
  ASSERT_TRUE(local.ok());
  for (int k = 0; k < 2; ++k) {
    const v1::FaceValues& m = resp.face_values(k);
    EXPECT_TRUE(m.values().empty()) << k;
    ASSERT_TRUE(m.has_figures()) << k;
    EXPECT_EQ(m.figures().global_visibility(), local->per_viewpoint[k].global_visibility) << k;
    EXPECT_EQ(m.figures().fully_visible_fraction(), local->per_viewpoint[k].fully_visible_fraction) << k;
    auto got = wire::DecodeFaceValues(m, resp.occupied_voxels() * kFacesPerVoxel);
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    const SparseFaceValues& want = local->per_viewpoint_sparse_values[k];
    EXPECT_EQ(got->faces, want.faces) << k;
    EXPECT_EQ(got->values, want.values) << k;
    EXPECT_EQ(got->exact_values, want.exact_values) << k;
    EXPECT_EQ(got->perceptions, want.perceptions) << k;
  }
  EXPECT_GT(local->per_viewpoint_sparse_values[0].size(), 1000u);
  EXPECT_GT(local->per_viewpoint[0].global_visibility, 0.0);
}

}  // namespace
}  // namespace vc
