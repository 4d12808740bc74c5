#include "testing/test_server.h"

#include <sstream>
#include <thread>

namespace vc::testing {

std::string BoxRoomPly(const Eigen::Vector3d& size, double s) {
  std::vector<Eigen::Vector3d> pts;
  const int nx = int(size.x() / s), ny = int(size.y() / s), nz = int(size.z() / s);
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      for (int k = 0; k <= nz; ++k) {
        const bool on_face = i == 0 || i == nx || j == 0 || j == ny || k == 0 || k == nz;
        if (on_face) pts.emplace_back(i * s + 0.013, j * s + 0.017, k * s + 0.011);
      }
    }
  }
  std::ostringstream ply;
  ply << "ply\nformat ascii 1.0\nelement vertex " << pts.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const auto& p : pts) ply << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  return ply.str();
}

server::Backend BlockingBackend::Make() {
  server::Backend b;
  b.read_scene = [](std::string_view, std::string_view, const ReadOptions&) -> Result<SceneInput> {
    return SceneInput{};
  };
  auto wait = [this](const JobContext& ctx) -> Status {
    started.Set();
    Status s;
    while ((s = ctx.CheckCancelled("blocking job")).ok()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // a core loop polling its token
    }
    {
      std::lock_guard lock(mu);
      returned_status = s;
      returned_at = std::chrono::steady_clock::now();
    }
    returned.Set();
    return s;
  };
  b.plan = [this, wait](const SceneInput&, const PlanOptions& o, const JobContext& ctx,
                        const PlanCallbacks& cb) -> Result<PlanResult> {
    if (!block) {
      PlanResult r = plan_result;
      r.options = o;
      if (cb.on_heat_map) cb.on_heat_map(r.heat_map);
      for (size_t i = 0; i < r.stations.size(); ++i) {
        if (cb.on_station) cb.on_station(r.stations[i], int(i));
      }
      if (cb.on_final_stations) cb.on_final_stations(r.stations);
      ctx.Report(Stage::kSelection, 1.0, "done");
      return r;
    }
    return wait(ctx);
  };
  b.evaluate = [wait](const SceneInput&, const EvaluateJobOptions&,
                      const JobContext& ctx) -> Result<EvaluateJobResult> { return wait(ctx); };
  return b;
}

std::unique_ptr<server::Server> StartServer(server::ServerOptions options, server::Backend backend) {
  options.listen = "127.0.0.1:0";
  auto s = server::Server::Start(options, std::move(backend));
  EXPECT_TRUE(s.ok()) << s.status().ToString();
  if (!s.ok()) return nullptr;
  return std::move(s).value();
}

std::string Address(const server::Server& s) { return "127.0.0.1:" + std::to_string(s.port()); }

v1::UploadSpec SpecFor(const std::string& bytes) {
  v1::UploadSpec spec;
  spec.set_total_size_bytes(bytes.size());
  spec.set_crc32c(ComputeCrc32c(bytes));
  spec.set_source_name("test.ply");
  return spec;
}

std::vector<v1::PlanRequest> PlanRequests(const std::string& bytes, const v1::PlanParameters& params, size_t chunk) {
  std::vector<v1::PlanRequest> rs(1);
  *rs[0].mutable_spec()->mutable_upload() = SpecFor(bytes);
  *rs[0].mutable_spec()->mutable_parameters() = params;
  for (size_t off = 0; off < bytes.size(); off += chunk) {
    rs.emplace_back().mutable_chunk()->set_data(bytes.substr(off, chunk));
  }
  return rs;
}

namespace {

template <typename Response, typename Stream>
RawCall<Response> Drive(grpc::ClientContext& ctx, Stream stream, const auto& requests) {
  RawCall<Response> out;
  for (const auto& r : requests) {
    if (!stream->Write(r)) break;
  }
  stream->WritesDone();
  Response resp;
  while (stream->Read(&resp)) out.responses.push_back(resp);
  out.status = stream->Finish();
  for (const auto& [k, v] : ctx.GetServerTrailingMetadata()) {
    out.trailers.emplace(std::string(k.data(), k.size()), std::string(v.data(), v.size()));
  }
  return out;
}

}  // namespace

RawCall<v1::PlanResponse> RawPlan(const std::string& address, const std::vector<v1::PlanRequest>& requests,
                                  const std::string& token) {
  auto stub = v1::StationPlanner::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  if (!token.empty()) ctx.AddMetadata("authorization", "Bearer " + token);
  return Drive<v1::PlanResponse>(ctx, stub->Plan(&ctx), requests);
}

RawCall<v1::EvaluateResponse> RawEvaluate(const std::string& address,
                                          const std::vector<v1::EvaluateRequest>& requests) {
  auto stub = v1::StationPlanner::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  return Drive<v1::EvaluateResponse>(ctx, stub->Evaluate(&ctx), requests);
}

}  // namespace vc::testing
