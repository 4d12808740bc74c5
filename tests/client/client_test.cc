// vc::client::Client against an in-process server with a fake backend: the streamed result is
// rebuilt exactly, events arrive, and UNAVAILABLE is retried.
#include "vc/client/client.h"

#include <gtest/gtest.h>

#include "testing/test_server.h"

namespace vc {
namespace {

PlanResult BigResult() {
  PlanResult r;
  r.resolution_m = 0.05;
  r.selection_test = SelectionTest::kSurfaceVisibility;
  const size_t n = 2 * wire::kVoxelsPerChunk + 123;  // three voxel chunks
  for (size_t i = 0; i < n; ++i) {
    r.voxel_centers.emplace_back(0.05 * double(i % 100), 0.05 * double(i / 100), 1.0);
    r.evaluation.best_face_values.push_back({0.f, 0.1f, 0.2f, 0.3f, 0.4f, float(i % 7) / 7.f});
  }
  r.occupied_voxels = n;
  r.heat_map.grid_spacing_m = 1;
  r.heat_map.positions = {{0, 0, 1.5}, {1, 0, 1.5}};
  r.heat_map.visible_voxels = {10, 20};
  r.stations.push_back({{1, 0, 1.5}, 20, 20, 0.8, 0.3, 1});
  r.stations.push_back({{0, 0, 1.5}, 10, 5, 1.0, 0.2, 0});
  return r;
}

TEST(Client, PlanRebuildsAChunkedResultExactlyAndReportsEvents) {
  testing::BlockingBackend backend;
  backend.block = false;
  backend.plan_result = BigResult();
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o, backend.Make());
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  conn.chunk_bytes = 3;  // many chunks for a tiny upload
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  int accepted = 0, heat_maps = 0, progress = 0;
  std::vector<int> station_indices;
  size_t final_stations = 0;
  int final_lists = 0;
  client::JobObserver obs;
  obs.on_accepted = [&](const std::string& id, uint32_t) { accepted += !id.empty(); };
  obs.on_heat_map = [&](const HeatMap& h) { heat_maps += h.positions.size() == 2; };
  obs.on_progress = [&](const ProgressEvent&) { ++progress; };
  obs.on_station = [&](const PlannedStation&, int i) { station_indices.push_back(i); };
  obs.on_final_stations = [&](const std::vector<PlannedStation>& s) {
    final_stations = s.size();
    ++final_lists;
  };
  PlanOptions options;
  options.max_stations = 7;
  auto r = (*c)->Plan({"some scene bytes", "x.ply"}, options, obs);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const PlanResult& want = backend.plan_result;
  EXPECT_EQ(r->voxel_centers, want.voxel_centers);
  EXPECT_EQ(r->evaluation.best_face_values, want.evaluation.best_face_values);
  EXPECT_EQ(r->heat_map.positions, want.heat_map.positions);
  ASSERT_EQ(r->stations.size(), 2u);
  EXPECT_EQ(r->stations[1].marginal_gain, 5u);
  EXPECT_EQ(r->options.max_stations, 7) << "the options that ran come back";
  EXPECT_EQ(accepted, 1);
  EXPECT_GE(heat_maps, 1);
  EXPECT_GE(progress, 1);
  EXPECT_EQ(station_indices, (std::vector<int>{0, 1}));
  EXPECT_EQ(final_lists, 1);
  EXPECT_EQ(final_stations, 2u);
}

TEST(Client, UnavailableServerIsRetriedWithBackoffThenReported) {
  // Reserve a free port, then shut the server down so nothing listens there.
  int port = 0;
  {
    server::ServerOptions o;
    o.workers = 1;
    auto s = testing::StartServer(o);
    ASSERT_TRUE(s);
    port = s->port();
  }
  client::ConnectionOptions conn;
  conn.server = "127.0.0.1:" + std::to_string(port);
  conn.max_attempts = 3;
  conn.initial_backoff = std::chrono::milliseconds(10);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  std::vector<std::chrono::milliseconds> waits;
  client::JobObserver obs;
  obs.on_retry = [&](const Status& s, std::chrono::milliseconds w) {
    EXPECT_EQ(s.code(), StatusCode::kUnavailable);
    waits.push_back(w);
  };
  auto r = (*c)->Plan({"x", "x.ply"}, PlanOptions{}, obs);
  EXPECT_EQ(r.status().code(), StatusCode::kUnavailable);
  EXPECT_EQ(waits,
            (std::vector<std::chrono::milliseconds>{std::chrono::milliseconds(10), std::chrono::milliseconds(20)}));
}

TEST(Client, MissingTlsFileIsNotFound) {
  client::ConnectionOptions conn;
  conn.tls_ca_file = "/nonexistent/ca.pem";
  auto c = client::Client::Create(conn);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace vc
