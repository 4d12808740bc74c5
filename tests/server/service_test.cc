// In-process tests of the StationPlanner service: each RPC's happy path and every protocol error.
#include "vc/server/service.h"

#include <bzlib.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "grpc/health/v1/health.grpc.pb.h"
#include "testing/test_server.h"
#include "vc/client/client.h"
#include "vc/wire/convert.h"
#include "vc/wire/sha256.h"

namespace vc {
namespace {

using ::testing::HasSubstr;
using testing::PlanRequests;
using testing::RawCall;
using testing::RawPlan;
using testing::SpecFor;

server::ServerOptions SmallServer() {
  server::ServerOptions o;
  o.workers = 1;
  o.queue = 0;
  o.threads_per_job = 2;
  return o;
}

v1::PlanParameters FastParams() {
  v1::PlanParameters p;
  p.set_resolution_m(0.2);
  p.set_grid_spacing_m(1.0);
  return p;
}

// --- Happy paths (real core) ---

TEST(PlanRpc, BoxRoomStreamsAcceptedProgressChunksAndResultInOrder) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  const auto call = RawPlan(testing::Address(*server), PlanRequests(testing::BoxRoomPly(), FastParams()));
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_GE(call.responses.size(), 3u);
  EXPECT_TRUE(call.responses.front().has_accepted());
  EXPECT_EQ(call.responses.front().accepted().queue_position(), 0u);
  EXPECT_FALSE(call.responses.front().accepted().job_id().empty());
  ASSERT_TRUE(call.responses.back().has_result());
  int progress = 0, stations = 0, voxel_chunks = 0;
  for (const auto& r : call.responses) {
    EXPECT_LE(r.ByteSizeLong(), size_t{1} << 20) << "a message over 1 MiB";
    progress += r.has_progress();
    stations += r.has_station();
    voxel_chunks += r.has_voxels();
  }
  EXPECT_GT(progress, 0);
  const auto& result = call.responses.back().result();
  EXPECT_GE(result.stations_size(), 1);
  EXPECT_GE(stations, result.stations_size());
  EXPECT_GT(result.occupied_voxels(), 0u);
  EXPECT_EQ(result.voxel_count(), result.occupied_voxels());
  EXPECT_GT(voxel_chunks, 0);
  EXPECT_DOUBLE_EQ(result.resolution_m(), 0.2);
}

TEST(PlanRpc, HeatMapOnceProvisionalPicksThenFinalStationsOnce) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  const auto call = RawPlan(testing::Address(*server), PlanRequests(testing::BoxRoomPly(), FastParams()));
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_TRUE(call.responses.back().has_result());
  const auto& result = call.responses.back().result();
  int heat_map_starts = 0, final_lists = 0;
  uint64_t heat_map_candidates = 0;
  bool final_seen = false;
  for (const auto& r : call.responses) {
    if (r.has_heat_map()) {
      heat_map_starts += r.heat_map().first_index() == 0;
      heat_map_candidates += r.heat_map().positions_size();
    }
    if (r.has_station()) {
      EXPECT_TRUE(r.station().provisional()) << "a selection pick is provisional";
      EXPECT_FALSE(final_seen) << "a provisional pick after the final list";
    }
    if (r.has_final_stations()) {
      ++final_lists;
      final_seen = true;
      ASSERT_EQ(r.final_stations().stations_size(), result.stations_size());
      for (int i = 0; i < result.stations_size(); ++i) {  // global_visibility comes with the evaluation
        v1::PlannedStation want = result.stations(i);
        want.clear_global_visibility();
        EXPECT_EQ(r.final_stations().stations(i).SerializeAsString(), want.SerializeAsString());
      }
    }
  }
  EXPECT_EQ(heat_map_starts, 1) << "the heat map is sent exactly once";
  EXPECT_EQ(heat_map_candidates, result.heat_map_candidates());
  EXPECT_EQ(final_lists, 1);
}

TEST(PlanRpc, ClientRebuildsTheWholePlanResult) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  PlanOptions o;
  o.resolution_m = 0.2;
  int accepted = 0;
  client::JobObserver obs;
  obs.on_accepted = [&](const std::string&, uint32_t) { ++accepted; };
  auto r = (*c)->Plan({testing::BoxRoomPly(), "box.ply"}, o, obs);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(accepted, 1);
  EXPECT_GE(r->stations.size(), 1u);
  EXPECT_EQ(r->voxel_centers.size(), r->occupied_voxels);
  EXPECT_EQ(r->heat_map.positions.size(), r->heat_map.visible_voxels.size());
  EXPECT_GT(r->heat_map.positions.size(), 0u);
}

TEST(EvaluateRpc, ViewpointInsideTheBoxSeesItsWalls) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  EvaluateJobOptions o;
  o.resolution_m = 0.2;
  o.viewpoints = {{2.0, 1.5, 1.2}};
  auto r = (*c)->Evaluate({testing::BoxRoomPly(), "box.ply"}, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->evaluation.per_viewpoint.size(), 1u);
  EXPECT_GT(r->evaluation.overall.global_visibility, 0.0);
  EXPECT_GT(r->evaluation.faces_total, 0u);
  EXPECT_EQ(r->viewpoints, o.viewpoints);
  EXPECT_FALSE(r->voxel_centers.empty());
  EXPECT_EQ(r->evaluation.best_face_values.size(), r->voxel_centers.size());
  EXPECT_EQ(r->evaluation.sole_viewer.size(), r->voxel_centers.size());
}

// An Evaluate streams its voxels as a Plan does: VoxelChunk messages in order, under 1 MiB each,
// before the result, which counts them; a sampled evaluation sends their centres without values.
TEST(EvaluateRpc, StreamsVoxelChunksInOrderBeforeTheResult) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  const std::string bytes = testing::BoxRoomPly({8, 6, 3}, 0.05);
  for (const uint64_t sample : {uint64_t{0}, uint64_t{500}}) {
    std::vector<v1::EvaluateRequest> rs(2);
    *rs[0].mutable_spec()->mutable_upload() = SpecFor(bytes);
    v1::EvaluateParameters* p = rs[0].mutable_spec()->mutable_parameters();
    *p->add_viewpoints() = wire::ToProto(WorldPoint(6, 5, 1.5));
    p->set_resolution_m(0.05);
    p->set_sample_faces(sample);
    rs[1].mutable_chunk()->set_data(bytes);
    const auto call = testing::RawEvaluate(testing::Address(*server), rs);
    ASSERT_TRUE(call.status.ok()) << call.status.error_message();
    ASSERT_TRUE(call.responses.back().has_result());
    const v1::EvaluateResult& result = call.responses.back().result();
    uint64_t next = 0;
    int chunks = 0;
    for (const auto& r : call.responses) {
      EXPECT_LE(r.ByteSizeLong(), size_t{1} << 20) << "a message over 1 MiB";
      if (!r.has_voxels()) continue;
      ++chunks;
      EXPECT_EQ(r.voxels().first_voxel_id(), next);
      EXPECT_EQ(r.voxels().total_voxels(), result.voxel_count());
      EXPECT_EQ(r.voxels().best_face_values_size(), sample == 0 ? r.voxels().centers_xyz_m_size() * 2 : 0);
      next += uint64_t(r.voxels().centers_xyz_m_size() / 3);
    }
    EXPECT_GT(chunks, 1) << "the box at 5 cm takes more than one chunk";
    EXPECT_GT(result.voxel_count(), 0u);
    EXPECT_EQ(next, result.voxel_count());
    EXPECT_EQ(result.evaluation().face_value_voxels(), sample == 0 ? result.voxel_count() : 0u);
    EXPECT_EQ(result.viewpoints_size(), 1);
  }
}

// A decompression bomb through the real reader: the upload limit bounds what it may decompress
// to (ReadLimits: 16 x --max-upload-bytes), so a few hundred bytes of bzip2 that inflate to 8 MiB
// are refused with RESOURCE_EXHAUSTED naming the flag, and the server keeps serving.
TEST(ServiceLimits, DecompressionBombIsResourceExhaustedNamingTheUploadLimit) {
  auto o = SmallServer();
  o.max_upload_bytes = 4096;
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  std::string zeros(size_t{8} << 20, '\0');
  std::string bomb(4096, '\0');
  unsigned int bomb_size = bomb.size();
  ASSERT_EQ(BZ2_bzBuffToBuffCompress(bomb.data(), &bomb_size, zeros.data(), zeros.size(), 9, 0, 0), BZ_OK);
  bomb.resize(bomb_size);
  auto requests = PlanRequests(bomb);
  requests[0].mutable_spec()->mutable_upload()->set_source_name("bomb.xyz.bz2");
  const auto call = RawPlan(testing::Address(*server), requests);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << call.status.error_message();
  EXPECT_THAT(call.status.error_message(), HasSubstr("--max-upload-bytes"));
  // The next job reaches a worker and the reader again (a 10-byte file that is no scene).
  const auto again = RawPlan(testing::Address(*server), PlanRequests("0123456789"));
  EXPECT_EQ(again.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << again.status.error_message();
}

// --- Protocol errors ---

class PlanErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    auto o = SmallServer();
    o.max_upload_bytes = 4096;
    server_ = testing::StartServer(o, backend_.Make());
    ASSERT_TRUE(server_);
    backend_.block = false;
  }
  testing::RawCall<v1::PlanResponse> Send(const std::vector<v1::PlanRequest>& rs) {
    return RawPlan(testing::Address(*server_), rs);
  }
  testing::BlockingBackend backend_;
  std::unique_ptr<server::Server> server_;
};

TEST_F(PlanErrors, ValidUploadIsAcceptedByTheFakeBackend) {  // the control for the tests below
  const auto call = Send(PlanRequests("0123456789"));
  EXPECT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_FALSE(call.responses.empty());
  EXPECT_TRUE(call.responses.back().has_result());
}

TEST_F(PlanErrors, NoSpec) {
  const auto call = Send({});
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("spec"));
  EXPECT_TRUE(call.responses.empty());
}

TEST_F(PlanErrors, ChunkBeforeSpec) {
  auto rs = PlanRequests("0123456789");
  std::swap(rs[0], rs[1]);
  const auto call = Send(rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("before the spec"));
}

TEST_F(PlanErrors, SecondSpec) {
  auto rs = PlanRequests("0123456789");
  rs.push_back(rs[0]);
  EXPECT_EQ(Send(rs).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(PlanErrors, FewerBytesThanDeclared) {
  auto rs = PlanRequests("0123456789");
  rs[0].mutable_spec()->mutable_upload()->set_total_size_bytes(11);
  const auto call = Send(rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("10 of the 11 bytes"));
}

TEST_F(PlanErrors, MoreBytesThanDeclared) {
  auto rs = PlanRequests("0123456789");
  rs[0].mutable_spec()->mutable_upload()->set_total_size_bytes(9);
  const auto call = Send(rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("more than the 9 bytes"));
}

TEST_F(PlanErrors, ChecksumMismatch) {
  auto rs = PlanRequests("0123456789");
  rs[0].mutable_spec()->mutable_upload()->set_crc32c(rs[0].spec().upload().crc32c() ^ 1u);
  const auto call = Send(rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::DATA_LOSS);
  EXPECT_THAT(call.status.error_message(), HasSubstr("CRC32C"));
  EXPECT_TRUE(call.responses.empty()) << "no job may start before the upload is verified";
}

// One worker and no queue: every call's place must be free by the time its client hears the final
// status, whether the call was refused during the upload or ran to the end, so back-to-back calls
// are never refused as busy.
TEST_F(PlanErrors, BackToBackCallsFindThePlaceFreeAfterAnErrorOrAResult) {
  for (int i = 0; i < 20; ++i) {
    auto bad = PlanRequests("0123456789");
    bad[0].mutable_spec()->mutable_upload()->set_crc32c(bad[0].spec().upload().crc32c() ^ 1u);
    ASSERT_EQ(Send(bad).status.error_code(), grpc::StatusCode::DATA_LOSS) << i;
    const auto good = Send(PlanRequests("0123456789"));
    ASSERT_TRUE(good.status.ok()) << i << ": " << good.status.error_message();
  }
}

TEST_F(PlanErrors, EmptyUpload) {
  EXPECT_EQ(Send(PlanRequests("")).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(PlanErrors, TooLargeIsRefusedFromTheSpecAlone) {
  std::vector<v1::PlanRequest> rs(1);
  rs[0].mutable_spec()->mutable_upload()->set_total_size_bytes(5000);  // limit is 4096
  const auto call = Send(rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(call.status.error_message(), HasSubstr("--max-upload-bytes"));
}

TEST_F(PlanErrors, UnknownFormatEnumValue) {
  auto rs = PlanRequests("0123456789");
  rs[0].mutable_spec()->mutable_upload()->set_format(static_cast<v1::InputFormat>(99));
  EXPECT_EQ(Send(rs).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

struct BadParam {
  const char* name;
  void (*apply)(v1::PlanParameters*);
};

class PlanInvalidParameters : public PlanErrors, public ::testing::WithParamInterface<BadParam> {};

TEST_P(PlanInvalidParameters, AreRefusedBeforeTheUpload) {
  v1::PlanParameters p;
  GetParam().apply(&p);
  std::vector<v1::PlanRequest> rs = PlanRequests("0123456789", p);
  const auto call = Send(rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << call.status.error_message();
  EXPECT_TRUE(call.responses.empty());
}

INSTANTIATE_TEST_SUITE_P(
    Each, PlanInvalidParameters,
    ::testing::Values(
        BadParam{"NegativeResolution", [](v1::PlanParameters* p) { p->set_resolution_m(-0.1); }},
        BadParam{"NanResolution", [](v1::PlanParameters* p) { p->set_resolution_m(std::nan("")); }},
        BadParam{"InfiniteResolution", [](v1::PlanParameters* p) { p->set_resolution_m(INFINITY); }},
        BadParam{"ZeroGridSpacing", [](v1::PlanParameters* p) { p->set_grid_spacing_m(0); }},
        BadParam{"NegativeGridSpacing", [](v1::PlanParameters* p) { p->set_grid_spacing_m(-1); }},
        BadParam{"NanTargetCoverage", [](v1::PlanParameters* p) { p->set_target_coverage(std::nan("")); }},
        BadParam{"NegativeThreads", [](v1::PlanParameters* p) { p->set_threads(-2); }},
        BadParam{"UnknownSelectionTest",
                 [](v1::PlanParameters* p) { p->set_selection_test(static_cast<v1::SelectionTest>(7)); }},
        BadParam{"VfovMinAboveMax",
                 [](v1::PlanParameters* p) {
                   p->mutable_scanner()->set_vfov_min_deg(30);
                   p->mutable_scanner()->set_vfov_max_deg(10);
                 }},
        BadParam{"NanVfov", [](v1::PlanParameters* p) { p->mutable_scanner()->set_vfov_max_deg(std::nan("")); }},
        BadParam{"ZeroIncidence", [](v1::PlanParameters* p) { p->mutable_scanner()->set_max_incidence_deg(0); }},
        BadParam{"SpacingWithoutAngularStep",
                 [](v1::PlanParameters* p) { p->mutable_scanner()->set_max_spacing_m(0.01); }}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(EvaluateErrors, InvalidParametersAreRefused) {
  testing::BlockingBackend backend;
  auto server = testing::StartServer(SmallServer(), backend.Make());
  ASSERT_TRUE(server);
  const std::string bytes = "0123456789";
  auto request = [&](void (*apply)(v1::EvaluateParameters*)) {
    std::vector<v1::EvaluateRequest> rs(2);
    *rs[0].mutable_spec()->mutable_upload() = SpecFor(bytes);
    *rs[0].mutable_spec()->mutable_parameters()->add_viewpoints() = wire::ToProto(WorldPoint(1, 1, 1));
    apply(rs[0].mutable_spec()->mutable_parameters());
    rs[1].mutable_chunk()->set_data(bytes);
    return testing::RawEvaluate(testing::Address(*server), rs).status;
  };
  EXPECT_EQ(request([](v1::EvaluateParameters* p) { p->clear_viewpoints(); }).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(request([](v1::EvaluateParameters* p) { p->mutable_viewpoints(0)->set_x_m(std::nan("")); }).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(request([](v1::EvaluateParameters* p) { p->set_resolution_m(-1); }).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(request([](v1::EvaluateParameters* p) { p->set_resolution_m(std::nan("")); }).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(backend.started.WaitFor(std::chrono::milliseconds(0)), false) << "a job ran despite bad parameters";
}

// --- Bad content (real readers) ---

// --- The scene cache ---

// A Plan of the box room named by its SHA-256: uploaded (with the hash) or only named (from_cache).
RawCall<v1::PlanResponse> CachedPlan(const std::string& address, const std::string& bytes, bool from_cache,
                                     const std::string& sha256) {
  std::vector<v1::PlanRequest> rs = PlanRequests(bytes, FastParams());
  rs[0].mutable_spec()->mutable_upload()->set_scene_sha256(sha256);
  rs[0].mutable_spec()->mutable_upload()->set_from_cache(from_cache);
  if (from_cache) rs.resize(1);  // the spec only
  return RawPlan(address, rs);
}

TEST(SceneCacheRpc, AnUploadWithItsHashIsKeptAndASecondPlanNeedsOnlyTheHash) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  const std::string address = testing::Address(*server);
  const std::string ply = testing::BoxRoomPly();
  const std::string sha = wire::Sha256Hex(ply);
  // Not sent yet: NOT_FOUND, telling the client to upload.
  auto miss = CachedPlan(address, ply, true, sha);
  EXPECT_EQ(miss.status.error_code(), grpc::StatusCode::NOT_FOUND) << miss.status.error_message();
  EXPECT_THAT(miss.status.error_message(), HasSubstr("upload it"));
  auto first = CachedPlan(address, ply, false, sha);
  ASSERT_TRUE(first.status.ok()) << first.status.error_message();
  auto second = CachedPlan(address, ply, true, sha);
  ASSERT_TRUE(second.status.ok()) << second.status.error_message();
  ASSERT_FALSE(first.responses.empty());
  // The same plan both times: the results' stations agree.
  auto result_of = [](const RawCall<v1::PlanResponse>& c) {
    for (const auto& r : c.responses)
      if (r.has_result()) return r.result().stations_size();
    return -1;
  };
  EXPECT_GT(result_of(first), 0);
  EXPECT_EQ(result_of(first), result_of(second));
}

TEST(SceneCacheRpc, AWrongHashABadHashOrDataWithFromCacheIsInvalidArgument) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  const std::string address = testing::Address(*server);
  const std::string ply = testing::BoxRoomPly();
  auto wrong = CachedPlan(address, ply, false, wire::Sha256Hex("something else"));
  EXPECT_EQ(wrong.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(wrong.status.error_message(), HasSubstr("SHA-256"));
  // The wrong upload was not kept under either hash.
  EXPECT_EQ(CachedPlan(address, ply, true, wire::Sha256Hex(ply)).status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(CachedPlan(address, ply, false, "ABC").status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  std::vector<v1::PlanRequest> rs = PlanRequests(ply, FastParams());
  rs[0].mutable_spec()->mutable_upload()->set_from_cache(true);
  rs[0].mutable_spec()->mutable_upload()->set_scene_sha256(wire::Sha256Hex(ply));
  const auto with_data = RawPlan(address, rs);
  EXPECT_EQ(with_data.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(with_data.status.error_message(), HasSubstr("send none"));
}

TEST(SceneCacheRpc, WithoutACacheEveryPlanUploadsAndTheClientRecovers) {
  server::ServerOptions o = SmallServer();
  o.scene_cache_bytes = 0;
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  PlanOptions options = *wire::FromProto(FastParams());
  for (int i = 0; i < 2; ++i) {
    auto r = (*c)->Plan({testing::BoxRoomPly(), "box.ply"}, options);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_FALSE((*c)->last_upload().from_cache);
    EXPECT_EQ((*c)->last_upload().bytes_sent, testing::BoxRoomPly().size());
  }
}

TEST(SceneCacheRpc, TheClientUploadsOnceThenNamesTheSceneOnly) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  PlanOptions options = *wire::FromProto(FastParams());
  const std::string ply = testing::BoxRoomPly();
  auto first = (*c)->Plan({ply, "box.ply"}, options);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_FALSE((*c)->last_upload().from_cache);
  EXPECT_EQ((*c)->last_upload().scene_sha256, wire::Sha256Hex(ply));
  options.grid_spacing_m = 0.5;  // other parameters, the same scene
  auto second = (*c)->Plan({ply, "box.ply"}, options);
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_TRUE((*c)->last_upload().from_cache);
  EXPECT_EQ((*c)->last_upload().bytes_sent, 0u);
  EXPECT_GT(second->candidate_count, first->candidate_count);
  EvaluateJobOptions eval;
  eval.resolution_m = 0.2;
  eval.viewpoints = {first->stations[0].position};
  auto ev = (*c)->Evaluate({ply, "box.ply"}, eval);
  ASSERT_TRUE(ev.ok()) << ev.status().ToString();
  EXPECT_TRUE((*c)->last_upload().from_cache);
}

TEST(PlanContent, UnknownFormatIsInvalidArgument) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  std::string junk(2000, '\0');
  for (size_t i = 0; i < junk.size(); ++i) junk[i] = char((i * 131 + 7) % 256);
  const auto call = RawPlan(testing::Address(*server), PlanRequests(junk));
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << call.status.error_message();
  EXPECT_FALSE(call.status.error_message().empty());
}

TEST(PlanContent, TruncatedPlyIsInvalidArgument) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  std::string ply = testing::BoxRoomPly();
  ply.resize(ply.size() / 2);
  ply.resize(ply.rfind('\n') + 1);  // whole lines, but fewer vertices than the header declares
  const auto call = RawPlan(testing::Address(*server), PlanRequests(ply));
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << call.status.error_message();
}

TEST(PlanContent, StatedFormatThatDisagreesWithTheContent) {
  auto server = testing::StartServer(SmallServer());
  ASSERT_TRUE(server);
  auto rs = PlanRequests(testing::BoxRoomPly(), FastParams());
  rs[0].mutable_spec()->mutable_upload()->set_format(v1::INPUT_FORMAT_LAS);
  const auto call = RawPlan(testing::Address(*server), rs);
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(call.status.error_message(), HasSubstr("ply"));
}

TEST(PlanContent, OverTheMemoryBudgetIsResourceExhausted) {
  auto o = SmallServer();
  o.max_memory_budget_bytes = 64;  // caps the request's 4 GiB
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  const auto call = RawPlan(testing::Address(*server), PlanRequests(testing::BoxRoomPly(), FastParams()));
  EXPECT_EQ(call.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << call.status.error_message();
}

// --- Cancellation, queue, deadline ---

class Blocking : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = testing::StartServer(SmallServer(), backend_.Make());
    ASSERT_TRUE(server_);
    stub_ = v1::StationPlanner::NewStub(
        grpc::CreateChannel(testing::Address(*server_), grpc::InsecureChannelCredentials()));
  }
  // Starts a plan whose job blocks, and waits until it runs on the worker.
  std::unique_ptr<grpc::ClientReaderWriter<v1::PlanRequest, v1::PlanResponse>> StartBlockedJob(
      grpc::ClientContext* ctx) {
    auto stream = stub_->Plan(ctx);
    for (const auto& r : PlanRequests(bytes_)) EXPECT_TRUE(stream->Write(r));
    EXPECT_TRUE(stream->WritesDone());
    v1::PlanResponse accepted;
    EXPECT_TRUE(stream->Read(&accepted));
    EXPECT_TRUE(accepted.has_accepted());
    EXPECT_TRUE(backend_.started.WaitFor(std::chrono::seconds(5)));
    return stream;
  }
  const std::string bytes_ = "0123456789";
  testing::BlockingBackend backend_;
  std::unique_ptr<server::Server> server_;
  std::unique_ptr<v1::StationPlanner::Stub> stub_;
};

TEST_F(Blocking, CancellationFreesTheWorkerWithinASecond) {
  grpc::ClientContext ctx;
  auto stream = StartBlockedJob(&ctx);
  EXPECT_EQ(server_->pool().running(), 1);
  const auto cancelled_at = std::chrono::steady_clock::now();
  ctx.TryCancel();
  ASSERT_TRUE(backend_.returned.WaitFor(std::chrono::seconds(2)));
  {
    std::lock_guard lock(backend_.mu);
    EXPECT_EQ(backend_.returned_status.code(), StatusCode::kCancelled);
    EXPECT_LT(backend_.returned_at - cancelled_at, std::chrono::seconds(1));
  }
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
  // The job's place is released when its stream is done, which can trail the client's status by
  // a moment: it must be free within a second of the cancellation.
  while (server_->pool().admitted() != 0 && std::chrono::steady_clock::now() - cancelled_at < std::chrono::seconds(1)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(server_->pool().admitted(), 0);
  EXPECT_EQ(server_->pool().running(), 0);
  // The single worker takes a new job now.
  backend_.block = false;
  const auto next = RawPlan(testing::Address(*server_), PlanRequests(bytes_));
  EXPECT_TRUE(next.status.ok()) << next.status.error_message();
}

TEST_F(Blocking, FullQueueGivesResourceExhaustedAtOnceWithARetryHint) {
  grpc::ClientContext ctx;
  auto stream = StartBlockedJob(&ctx);
  std::vector<v1::PlanRequest> spec_only(1, PlanRequests(bytes_)[0]);
  const auto t0 = std::chrono::steady_clock::now();
  const auto busy = RawPlan(testing::Address(*server_), spec_only);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
  EXPECT_EQ(busy.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(busy.status.error_message(), HasSubstr("retry"));
  EXPECT_EQ(busy.trailers.count("retry-after-ms"), 1u);
  ctx.TryCancel();
  (void)stream->Finish();
}

TEST_F(Blocking, DeadlineGivesDeadlineExceededAndStopsTheJob) {
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(500));
  auto stream = StartBlockedJob(&ctx);
  v1::PlanResponse r;
  while (stream->Read(&r)) {
  }
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  ASSERT_TRUE(backend_.returned.WaitFor(std::chrono::seconds(2)));
  std::lock_guard lock(backend_.mu);
  EXPECT_FALSE(backend_.returned_status.ok());
}

TEST_F(Blocking, ShutdownCancelsRunningJobsAfterTheGracePeriod) {
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));  // bounds a failure
  auto stream = StartBlockedJob(&ctx);
  const auto t0 = std::chrono::steady_clock::now();
  server_->Shutdown(std::chrono::milliseconds(200));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(3));
  EXPECT_TRUE(backend_.returned.WaitFor(std::chrono::seconds(0))) << "Shutdown returned before the job ended";
  v1::PlanResponse r;
  while (stream->Read(&r)) {
  }
  const grpc::Status s = stream->Finish();
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << "the call was not ended by the shutdown";
  // Ended by our cancellation at the end of the grace, not by gRPC's own shutdown (UNAVAILABLE).
  EXPECT_EQ(s.error_code(), grpc::StatusCode::CANCELLED) << s.error_message();
}

TEST_F(Blocking, DuringTheDrainNewCallsAreRefusedWithUnavailableAndHealthIsNotServing) {
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));  // bounds a failure
  auto stream = StartBlockedJob(&ctx);
  std::thread shutdown([&] { server_->Shutdown(std::chrono::milliseconds(1500)); });
  // The listener stays open during the grace: a new call is refused by the service itself.
  grpc::Status refused;
  for (int i = 0; i < 50; ++i) {
    refused = RawPlan(testing::Address(*server_), PlanRequests(bytes_)).status;
    if (refused.error_code() == grpc::StatusCode::UNAVAILABLE) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_THAT(refused.error_message(), HasSubstr("shutting down"));
  auto health = grpc::health::v1::Health::NewStub(
      grpc::CreateChannel(testing::Address(*server_), grpc::InsecureChannelCredentials()));
  grpc::ClientContext hctx;
  grpc::health::v1::HealthCheckRequest hreq;
  grpc::health::v1::HealthCheckResponse hresp;
  const grpc::Status hs = health->Check(&hctx, hreq, &hresp);
  EXPECT_TRUE(hs.ok()) << hs.error_message();
  EXPECT_EQ(hresp.status(), grpc::health::v1::HealthCheckResponse::NOT_SERVING);
  v1::PlanResponse r;
  while (stream->Read(&r)) {
  }
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
  shutdown.join();
}

// --- Authentication ---

TEST(Auth, WrongOrMissingTokenIsUnauthenticated) {
  testing::BlockingBackend backend;
  backend.block = false;
  auto o = SmallServer();
  o.tokens = {"s3cret"};
  auto server = testing::StartServer(o, backend.Make());
  ASSERT_TRUE(server);
  const auto rs = PlanRequests("0123456789");
  const auto addr = testing::Address(*server);
  EXPECT_EQ(RawPlan(addr, rs, "").status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  const auto wrong = RawPlan(addr, rs, "s3cres");
  EXPECT_EQ(wrong.status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(wrong.status.error_message(), HasSubstr("token"));
  EXPECT_TRUE(RawPlan(addr, rs, "s3cret").status.ok());
}

// --- Health ---

TEST(Health, ServingWhileUpAndHealthNeedsNoToken) {
  auto o = SmallServer();
  o.tokens = {"s3cret"};
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  auto h = (*c)->Health();
  ASSERT_TRUE(h.ok()) << h.status().ToString();
  EXPECT_EQ(*h, "SERVING");
}

}  // namespace
}  // namespace vc
