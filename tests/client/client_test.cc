// vc::client::Client against an in-process server with a fake backend: the streamed result is
// rebuilt exactly, events arrive, UNAVAILABLE is retried (but not an unknown host or TLS against a
// plain server), Attach finds a job of either kind, and CancelDetachedJob reaches the replica
// running the job. ReadUpload refuses an empty or unreadable scene file.
#include "vc/client/client.h"

#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "testing/test_paths.h"
#include "testing/test_server.h"
#include "vc/report/plan_report.h"

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

// stations.csv as vc::WritePlanOutputs writes it for `r`.
std::string StationsCsvOf(const PlanResult& r) {
  const std::string dir = testing::MakeTempDir();
  EXPECT_TRUE(WritePlanOutputs(r, dir).ok());
  return testing::ReadFileBytes(dir + "/stations.csv");
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

TEST(Client, AGeoreferencedPlanComesBackLocalAndWritesTheServersFilesInTheInputsFrame) {
  const WorldPoint origin(512000, 5612000, 0);
  testing::BlockingBackend backend;
  backend.block = false;
  backend.plan_result = BigResult();
  backend.plan_result.frame_origin_m = origin;
  backend.plan_result.stations[0].position = WorldPoint(345.457, 330.123, 1.6);
  server::Backend b = backend.Make();
  double metres_per_unit = 0;
  b.read_scene = [&](std::string_view, std::string_view, const ReadOptions& o) -> Result<SceneInput> {
    metres_per_unit = o.metres_per_unit;
    SceneInput in;
    in.frame_origin_m = origin;  // as a reader sets it for survey coordinates
    return in;
  };
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o, b);
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  std::vector<WorldPoint> picked;
  client::JobObserver obs;
  obs.on_station = [&](const PlannedStation& s, int) { picked.push_back(s.position); };
  auto r = (*c)->Plan({"some scene bytes", "survey.xyz", "mm"}, PlanOptions{}, obs);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(metres_per_unit, 0.001);  // the spec's units reached the reader
  EXPECT_EQ(r->frame_origin_m, origin);
  ASSERT_EQ(picked.size(), 2u);  // streamed picks are for people: the input's frame
  EXPECT_NEAR(picked[0].y(), 5612330.123, 1e-6);
  const PlanResult& sent = backend.plan_result;
  ASSERT_EQ(r->stations.size(), 2u);
  EXPECT_LT((r->stations[0].position - sent.stations[0].position).norm(), 1e-9);  // local again
  // What vc-client writes from the streamed result is what the server's own result gives.
  EXPECT_EQ(StationsCsvOf(*r), StationsCsvOf(sent));
  EXPECT_NE(StationsCsvOf(*r).find("512345.457000,5612330.123000"), std::string::npos) << StationsCsvOf(*r);
}

// An Evaluate's voxels come in VoxelChunk messages as a plan's do: Client::Evaluate rebuilds the
// server's EvaluateJobResult exactly (voxels local again), and vc-client's files from it are the
// server's result's.
TEST(Client, EvaluateRebuildsAChunkedEvaluationExactly) {
  const WorldPoint origin(512000, 5612000, 0);
  EvaluateJobResult sent;
  const PlanResult plan = BigResult();
  sent.voxel_centers = plan.voxel_centers;  // three voxel chunks
  sent.evaluation = plan.evaluation;
  sent.evaluation.resolution_m = plan.resolution_m;
  sent.evaluation.sole_viewer.assign(sent.voxel_centers.size(), kNoViewer);
  sent.evaluation.sole_viewer[7] = 1;
  sent.evaluation.per_viewpoint.resize(2);
  sent.frame_origin_m = origin;
  sent.viewpoints = {origin + WorldPoint(1, 0, 1.5), origin + WorldPoint(2, 1, 1.5)};
  testing::BlockingBackend backend;
  server::Backend b = backend.Make();
  b.evaluate = [&](const SceneInput&, const EvaluateJobOptions&, const JobContext&) -> Result<EvaluateJobResult> {
    return sent;
  };
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o, b);
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  EvaluateJobOptions options;
  options.viewpoints = sent.viewpoints;
  auto r = (*c)->Evaluate({"some scene bytes", "x.ply"}, options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, origin);
  EXPECT_EQ(r->viewpoints, sent.viewpoints);
  ASSERT_EQ(r->voxel_centers.size(), sent.voxel_centers.size());
  for (size_t i = 0; i < sent.voxel_centers.size(); i += 1001) {
    EXPECT_LT((r->voxel_centers[i] - sent.voxel_centers[i]).norm(), 1e-9) << i;
  }
  EXPECT_EQ(r->evaluation.best_face_values, sent.evaluation.best_face_values);
  EXPECT_EQ(r->evaluation.sole_viewer, sent.evaluation.sole_viewer);
  const std::string from_client = testing::MakeTempDir(), from_server = testing::MakeTempDir();
  ASSERT_TRUE(WriteEvaluationOutputs(*r, from_client).ok());
  ASSERT_TRUE(WriteEvaluationOutputs(sent, from_server).ok());
  EXPECT_EQ(testing::ReadFileBytes(from_client + "/stations.csv"),
            testing::ReadFileBytes(from_server + "/stations.csv"));
  EXPECT_EQ(testing::ReadFileBytes(from_client + "/visibility.ply"),
            testing::ReadFileBytes(from_server + "/visibility.ply"));
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

// A server that is not there at that name, or does not speak TLS, will not be there on a retry:
// both are reported at once, explained, with nothing uploaded.
TEST(Client, TlsAgainstAPlainServerIsNotRetriedAndSaysDropTls) {
  testing::BlockingBackend backend;
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o, backend.Make());
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  conn.tls = true;
  conn.initial_backoff = std::chrono::milliseconds(10);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  int retries = 0;
  client::JobObserver obs;
  obs.on_retry = [&](const Status&, std::chrono::milliseconds) { ++retries; };
  auto r = (*c)->Plan({"x", "x.ply", ""}, PlanOptions{}, obs);
  EXPECT_EQ(r.status().code(), StatusCode::kUnavailable);
  EXPECT_EQ(r.status().message().rfind("the server does not speak TLS: drop --tls", 0), 0u) << r.status().message();
  EXPECT_EQ(retries, 0);
  EXPECT_FALSE(backend.started.WaitFor(std::chrono::milliseconds(0)));
  EXPECT_EQ((*c)->last_job().job_id, "");
  // The same server without TLS is reached.
  conn.tls = false;
  EXPECT_TRUE(client::Client::Create(conn).value()->Health().ok());
}

TEST(Client, AnUnknownHostIsNotRetried) {
  client::ConnectionOptions conn;
  conn.server = "no-such-host.invalid:50051";
  conn.initial_backoff = std::chrono::milliseconds(10);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  int retries = 0;
  client::JobObserver obs;
  obs.on_retry = [&](const Status&, std::chrono::milliseconds) { ++retries; };
  auto r = (*c)->Plan({"x", "x.ply", ""}, PlanOptions{}, obs);
  EXPECT_EQ(r.status().code(), StatusCode::kUnavailable);
  EXPECT_EQ(r.status().message().rfind("cannot resolve host no-such-host.invalid: check the name in --server", 0), 0u)
      << r.status().message();
  EXPECT_EQ(retries, 0);
}

TEST(Client, OnlyPermanentConnectionErrorsAreExplained) {
  client::ConnectionOptions plain;
  plain.server = "dns:///scanner-hq.example:443";
  client::ConnectionOptions tls = plain;
  tls.tls = true;
  const Status dns =
      UnavailableError("DNS resolution failed for scanner-hq.example:443: C-ares status is not ARES_SUCCESS");
  EXPECT_EQ(client::PermanentConnectionError(dns, plain)->message().rfind("cannot resolve host scanner-hq.example:", 0),
            0u);
  const Status version =
      UnavailableError("failed to connect to all addresses; Ssl handshake failed: wrong version number");
  EXPECT_EQ(client::PermanentConnectionError(version, tls)->message().rfind("the server does not speak TLS", 0), 0u);
  EXPECT_FALSE(client::PermanentConnectionError(version, plain).has_value());
  const Status trust = UnavailableError("Handshake failed: CERTIFICATE_VERIFY_FAILED");
  EXPECT_NE(client::PermanentConnectionError(trust, tls)->message().find("--tls-ca"), std::string::npos);
  // Transient: retried as before.
  const Status refused = UnavailableError("failed to connect to all addresses; Connection refused");
  EXPECT_FALSE(client::PermanentConnectionError(refused, tls).has_value());
  EXPECT_FALSE(client::PermanentConnectionError(InvalidArgumentError("DNS resolution failed"), plain).has_value());
}

TEST(ReadUploadTest, EmptyAndUnreadableFilesAreRefusedPlainly) {
  const std::string dir = testing::MakeTempDir();
  const std::string empty = dir + "/empty.ply";
  { std::ofstream(empty, std::ios::binary); }
  Result<client::Upload> r = client::ReadUpload(empty);
  EXPECT_EQ(r.status(), InvalidArgumentError("the scene file " + empty +
                                             " is empty (0 bytes): nothing to upload; export the scene again"));
  r = client::ReadUpload(dir + "/missing.ply");
  EXPECT_EQ(r.status(), NotFoundError("cannot read the scene file " + dir + "/missing.ply: No such file or directory"));
  r = client::ReadUpload(dir);
  EXPECT_EQ(r.status(), InvalidArgumentError("the scene file " + dir + " is a directory; give the file in it"));
  const std::string one = dir + "/one.xyz";
  { std::ofstream(one, std::ios::binary) << "1 2 3\n"; }
  r = client::ReadUpload(one);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->bytes, "1 2 3\n");
  EXPECT_EQ(r->source_name, "one.xyz");
}

TEST(Client, MissingTlsFileIsNotFound) {
  client::ConnectionOptions conn;
  conn.tls_ca_file = "/nonexistent/ca.pem";
  auto c = client::Client::Create(conn);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), StatusCode::kNotFound);
}

// BlockingBackend's scene reading, with a plan and an evaluation that wait for `gate` (or the
// job's cancellation) and then return fixed results (the plan fails with `plan_failure` if set).
struct GatedBackend {
  static constexpr double kEvaluationG = 0.625;
  testing::BlockingBackend blocking;
  testing::Latch gate;
  PlanResult plan_result = BigResult();
  Status plan_failure;

  server::Backend Make() {
    server::Backend b = blocking.Make();
    auto wait = [this](const JobContext& ctx) -> Status {
      while (!gate.WaitFor(std::chrono::milliseconds(5))) {
        if (Status s = ctx.CheckCancelled("gated job"); !s.ok()) return s;
      }
      return Status::Ok();
    };
    b.plan = [this, wait](const SceneInput&, const PlanOptions&, const JobContext& ctx,
                          const PlanCallbacks&) -> Result<PlanResult> {
      VC_RETURN_IF_ERROR(wait(ctx));
      if (!plan_failure.ok()) return plan_failure;
      return plan_result;
    };
    b.evaluate = [wait](const SceneInput&, const EvaluateJobOptions& o,
                        const JobContext& ctx) -> Result<EvaluateJobResult> {
      VC_RETURN_IF_ERROR(wait(ctx));
      EvaluateJobResult e;
      e.evaluation.overall.global_visibility = kEvaluationG;
      e.viewpoints = o.viewpoints;  // as vc::RunEvaluation gives them back
      return e;
    };
    return b;
  }
};

// A job submitted with `submit(client, observer)` by a client with a detach grace, then attached
// to with Client::Attach by a second client, which takes it over (the first ends with ABORTED);
// the gate opens once the second client has the job's replayed Accepted event.
template <typename Submit>
Result<client::AttachedJob> SubmitThenAttach(GatedBackend& backend, Submit&& submit) {
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o, backend.Make());
  if (!server) return InternalError("no server");
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  conn.detach_grace_s = 30;
  auto submitter = client::Client::Create(conn);
  auto attacher = client::Client::Create(conn);
  if (!submitter.ok() || !attacher.ok()) return InternalError("no client");
  testing::Latch accepted;
  std::string job_id;
  client::JobObserver submitted;
  submitted.on_accepted = [&](const std::string& id, uint32_t) {
    job_id = id;
    accepted.Set();
  };
  Status submit_status;
  std::thread submitting([&] { submit_status = submit(**submitter, submitted); });
  if (!accepted.WaitFor(std::chrono::seconds(10))) {
    backend.gate.Set();
    submitting.join();
    return InternalError("the job was not accepted: " + submit_status.ToString());
  }
  std::vector<std::string> replayed;
  client::JobObserver attached;
  attached.on_accepted = [&](const std::string& id, uint32_t) {
    replayed.push_back(id);
    backend.gate.Set();
  };
  auto job = (*attacher)->Attach(job_id, attached);
  backend.gate.Set();
  submitting.join();
  EXPECT_EQ(submit_status.code(), StatusCode::kAborted) << submit_status.ToString();
  EXPECT_EQ(replayed, std::vector<std::string>{job_id});
  return job;
}

TEST(Client, AttachFollowsAPlanJob) {
  GatedBackend backend;
  const auto job = SubmitThenAttach(backend, [](client::Client& c, const client::JobObserver& observer) {
    return c.Plan({"some scene bytes", "x.ply"}, PlanOptions{}, observer).status();
  });
  ASSERT_TRUE(job.ok()) << job.status().ToString();
  EXPECT_EQ(job->kind, client::AttachedJob::Kind::kPlan);
  EXPECT_EQ(job->plan.voxel_centers, backend.plan_result.voxel_centers);
  EXPECT_EQ(job->plan.stations.size(), backend.plan_result.stations.size());
}

TEST(Client, AttachToAPlanJobThatFailsWithFailedPreconditionReturnsThePlansError) {
  GatedBackend backend;
  backend.plan_failure = FailedPreconditionError("no floor found: try a lower tripod_height_m");
  const auto job = SubmitThenAttach(backend, [](client::Client& c, const client::JobObserver& observer) {
    return c.Plan({"some scene bytes", "x.ply"}, PlanOptions{}, observer).status();
  });
  ASSERT_FALSE(job.ok()) << "the plan failed";
  EXPECT_EQ(job.status().code(), StatusCode::kFailedPrecondition) << job.status().ToString();
  EXPECT_NE(job.status().message().find("no floor found: try a lower tripod_height_m"), std::string::npos)
      << "the plan's own message, not AttachEvaluate's: " << job.status().ToString();
}

TEST(Client, AttachFallsBackToAttachEvaluateForAnEvaluateJob) {
  GatedBackend backend;
  EvaluateJobOptions eval;
  eval.viewpoints = {{2, 1.5, 1.2}, {1, 1, 1.5}};
  const auto job = SubmitThenAttach(backend, [&](client::Client& c, const client::JobObserver& observer) {
    return c.Evaluate({"some scene bytes", "x.ply"}, eval, observer).status();
  });
  ASSERT_TRUE(job.ok()) << job.status().ToString();
  EXPECT_EQ(job->kind, client::AttachedJob::Kind::kEvaluation);
  EXPECT_EQ(job->evaluation.evaluation.overall.global_visibility, GatedBackend::kEvaluationG);
  EXPECT_EQ(job->evaluation.viewpoints, eval.viewpoints) << "the server echoes the viewpoints";
}

TEST(Client, AttachToAnUnknownJobIsNotFound) {
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o);
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ((*c)->Attach("j-unknown").status().code(), StatusCode::kNotFound);
}

TEST(Client, CancelDetachedJobCancelsOnTheReplicaNamedInTheTicket) {
  testing::BlockingBackend backend;
  server::ServerOptions o;
  o.workers = 1;
  auto server = testing::StartServer(o, backend.Make());
  ASSERT_TRUE(server);
  client::ConnectionOptions conn;
  conn.server = testing::Address(*server);
  conn.detach_grace_s = 30;
  auto c = client::Client::Create(conn);
  ASSERT_TRUE(c.ok());
  testing::Latch accepted;
  client::JobTicket ticket;
  client::JobObserver observer;
  observer.on_job = [&](const client::JobTicket& t) {
    ticket = t;
    accepted.Set();
  };
  Status planned;
  std::thread submitting([&] {
    planned = (*c)->Plan({"some scene bytes", "x.ply"}, PlanOptions{}, observer).status();
  });
  ASSERT_TRUE(accepted.WaitFor(std::chrono::seconds(10)));
  ASSERT_TRUE(backend.started.WaitFor(std::chrono::seconds(10)));

  // The ticket names the replica running the job; the address the client was given is elsewhere.
  ticket.attach_address = testing::Address(*server);
  client::ConnectionOptions elsewhere = conn;
  elsewhere.server = "127.0.0.1:1";
  const auto r = client::CancelDetachedJob(elsewhere, ticket);
  submitting.join();
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(*r, "cancelled");
  EXPECT_EQ(planned.code(), StatusCode::kCancelled) << planned.ToString();
}

}  // namespace
}  // namespace vc
