#include "vc/server/service.h"

#include <fmt/format.h>

#include <algorithm>
#include <random>
#include <vector>

#include "job_reactor.h"

namespace vc::server {
namespace internal {

bool TokenMatches(const grpc::CallbackServerContext& ctx, const std::string& token, std::string* why) {
  if (token.empty()) return true;
  const auto& md = ctx.client_metadata();
  const auto it = md.find("authorization");
  if (it == md.end()) {
    *why = "this server requires a bearer token: pass --token (or set VC_TOKEN)";
    return false;
  }
  const std::string_view got(it->second.data(), it->second.size());
  const std::string expected = "Bearer " + token;
  unsigned diff = got.size() == expected.size() ? 0u : 1u;
  for (size_t i = 0; i < expected.size(); ++i) diff |= unsigned(expected[i] ^ (i < got.size() ? got[i] : 0));
  if (diff != 0) {
    *why = "the bearer token is wrong: check --token (or VC_TOKEN)";
    return false;
  }
  return true;
}

std::string NewJobId(ServiceState& state) {
  static const uint64_t salt = [] {
    std::random_device rd;
    return (uint64_t{rd()} << 32) ^ rd();
  }();
  const uint64_t n = state.next_job.fetch_add(1);
  return fmt::format("j-{:012x}", (salt ^ (n * 0x9E3779B97F4A7C15ull)) & 0xFFFFFFFFFFFFull);
}

namespace {

// The job's thread count: the request's, capped by the server's per-job share (0 = the share).
int JobThreads(int requested, const ServerOptions& o) {
  const int share = o.EffectiveThreadsPerJob();
  return requested <= 0 ? share : std::min(requested, share);
}

class PlanReactor final : public JobReactor<v1::PlanRequest, v1::PlanResponse> {
 public:
  using JobReactor::JobReactor;

 private:
  Result<v1::UploadSpec> TakeSpec(const v1::PlanRequest& request) override {
    VC_ASSIGN_OR_RETURN(options_, wire::FromProto(request.spec().parameters()));
    options_.memory_budget_bytes = std::min(options_.memory_budget_bytes, options().max_memory_budget_bytes);
    if (options_.threads < 0) return InvalidArgumentError("threads must be >= 0 (0 = the server's share)");
    options_.threads = JobThreads(options_.threads, options());
    VC_RETURN_IF_ERROR(options_.Validate());
    return request.spec().upload();
  }

  uint64_t MemoryBudgetBytes() const override { return options_.memory_budget_bytes; }

  Status Run(const SceneInput& input, const JobContext& ctx, JobLog& log) override {
    log.set_details(" stations=0");
    PlanCallbacks callbacks;
    callbacks.on_heat_map = [this](const HeatMap& h) { PostHeatMap(h); };
    callbacks.on_station = [this](const PlannedStation& s, int index) {
      v1::PlanResponse r;
      r.mutable_station()->set_index(index);
      r.mutable_station()->set_provisional(true);
      *r.mutable_station()->mutable_station() = wire::ToProto(s);
      outbox().Post(std::move(r));
    };
    callbacks.on_final_stations = [this](const std::vector<PlannedStation>& stations) {
      v1::PlanResponse r;
      for (const PlannedStation& s : stations) *r.mutable_final_stations()->add_stations() = wire::ToProto(s);
      outbox().Post(std::move(r));
    };
    VC_ASSIGN_OR_RETURN(const PlanResult result, backend().plan(input, options_, ctx, callbacks));
    for (const auto& t : result.timings) log.NoteTiming(StageName(t.stage), t.seconds);
    log.set_details(fmt::format(" stations={}", result.stations.size()));
    // The heat map went out once, when ready (unless the plan never reported it); then the voxels
    // and the summary: together the whole PlanResult.
    if (!heat_map_sent_) PostHeatMap(result.heat_map);
    wire::ForEachVoxelChunk(result, [this](v1::VoxelChunk&& c) {
      v1::PlanResponse r;
      *r.mutable_voxels() = std::move(c);
      return outbox().Post(std::move(r), /*bulk=*/true);
    });
    v1::PlanResponse r;
    *r.mutable_result() = wire::ToProto(result);
    outbox().Post(std::move(r), /*bulk=*/true);
    return ctx.CheckCancelled("the plan (while sending the result)");
  }

  void PostHeatMap(const HeatMap& h) {
    heat_map_sent_ = true;
    for (auto& c : wire::HeatMapChunks(h)) {
      v1::PlanResponse r;
      *r.mutable_heat_map() = std::move(c);
      if (!outbox().Post(std::move(r), /*bulk=*/true)) return;
    }
  }

  PlanOptions options_;
  bool heat_map_sent_ = false;  // on the worker thread
};

class EvaluateReactor final : public JobReactor<v1::EvaluateRequest, v1::EvaluateResponse> {
 public:
  using JobReactor::JobReactor;

 private:
  Result<v1::UploadSpec> TakeSpec(const v1::EvaluateRequest& request) override {
    VC_ASSIGN_OR_RETURN(options_, wire::FromProto(request.spec().parameters()));
    options_.memory_budget_bytes = std::min(options_.memory_budget_bytes, options().max_memory_budget_bytes);
    VC_RETURN_IF_ERROR(options_.Validate());
    options_.threads = JobThreads(options_.threads, options());
    return request.spec().upload();
  }

  uint64_t MemoryBudgetBytes() const override { return options_.memory_budget_bytes; }

  Status Run(const SceneInput& input, const JobContext& ctx, JobLog& log) override {
    log.set_details(fmt::format(" viewpoints={}", options_.viewpoints.size()));
    VC_ASSIGN_OR_RETURN(const Evaluation evaluation, backend().evaluate(input, options_, ctx));
    v1::EvaluateResponse r;
    *r.mutable_result() = wire::ToProto(evaluation, options_.viewpoints);
    outbox().Post(std::move(r));
    return ctx.CheckCancelled("the evaluation (while sending the result)");
  }

  EvaluateJobOptions options_;
};

}  // namespace
}  // namespace internal

StationPlannerService::StationPlannerService(const ServerOptions& options, Backend backend)
    : state_(std::make_unique<internal::ServiceState>(options, std::move(backend))) {}

StationPlannerService::~StationPlannerService() = default;

grpc::ServerBidiReactor<v1::PlanRequest, v1::PlanResponse>* StationPlannerService::Plan(
    grpc::CallbackServerContext* ctx) {
  auto* reactor = new internal::PlanReactor(ctx, state_.get(), "Plan");
  reactor->Start();
  return reactor;
}

grpc::ServerBidiReactor<v1::EvaluateRequest, v1::EvaluateResponse>* StationPlannerService::Evaluate(
    grpc::CallbackServerContext* ctx) {
  auto* reactor = new internal::EvaluateReactor(ctx, state_.get(), "Evaluate");
  reactor->Start();
  return reactor;
}

void StationPlannerService::Drain() { state_->Drain(); }

bool StationPlannerService::WaitForCalls(std::chrono::steady_clock::time_point deadline) {
  return state_->WaitForCalls(deadline);
}

void StationPlannerService::CancelAll() { state_->CancelAll(); }

const WorkerPool& StationPlannerService::pool() const { return state_->pool; }

}  // namespace vc::server
