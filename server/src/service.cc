#include "vc/server/service.h"

#include <fmt/format.h>

#include <random>
#include <vector>

#include "job_reactor.h"
#include "vc/wire/sha256.h"

namespace vc::server {
namespace internal {

std::string NewJobId(ServiceState& state) {
  static const uint64_t salt = [] {
    std::random_device rd;
    return (uint64_t{rd()} << 32) ^ rd();
  }();
  const uint64_t n = state.next_job.fetch_add(1);
  return fmt::format("j-{:012x}", (salt ^ (n * 0x9E3779B97F4A7C15ull)) & 0xFFFFFFFFFFFFull);
}

namespace {

class PlanReactor final : public JobReactor<v1::PlanRequest, v1::PlanResponse> {
 public:
  using JobReactor::JobReactor;

 private:
  Result<v1::UploadSpec> TakeSpec(const v1::PlanRequest& request) override {
    VC_ASSIGN_OR_RETURN(PlanOptions requested, wire::FromProto(request.spec().parameters()));
    VC_ASSIGN_OR_RETURN(options_, ApplyServerLimits(options(), std::move(requested)));
    return request.spec().upload();
  }

  uint64_t MemoryBudgetBytes() const override { return options_.memory_budget_bytes; }

  Status Run(const SceneInput& input, const JobContext& ctx, JobLog& log) override {
    log.set_details(" stations=0");
    // The plan's positions are local; the wire is in the input's frame (convert.h).
    frame_origin_m_ = input.frame_origin_m;
    PlanCallbacks callbacks;
    callbacks.on_heat_map = [this](const HeatMap& h) { PostHeatMap(h); };
    callbacks.on_station = [this](const PlannedStation& s, int index) {
      v1::PlanResponse r;
      r.mutable_station()->set_index(index);
      r.mutable_station()->set_provisional(true);
      *r.mutable_station()->mutable_station() = wire::ToProto(s, frame_origin_m_);
      channel().Post(std::move(r));
    };
    callbacks.on_final_stations = [this](const std::vector<PlannedStation>& stations) {
      v1::PlanResponse r;
      for (const PlannedStation& s : stations) {
        *r.mutable_final_stations()->add_stations() = wire::ToProto(s, frame_origin_m_);
      }
      channel().Post(std::move(r));
    };
    // The visibility stage and the reduction's evaluation over the replicas (the scene's hash once,
    // for both; the callbacks run within backend().plan below).
    std::optional<PeerFanOut::SceneRef> scene_ref;
    auto ref = [this, &scene_ref]() -> const PeerFanOut::SceneRef& {
      if (!scene_ref) {
        scene_ref.emplace();
        scene_ref->bytes = scene_bytes();
        scene_ref->sha256 =
            upload_spec().scene_sha256().empty() ? wire::Sha256Hex(*scene_ref->bytes) : upload_spec().scene_sha256();
        scene_ref->source_name = upload_spec().source_name();
        scene_ref->units = upload_spec().units();
      }
      return *scene_ref;
    };
    if (fan_out() != nullptr) {
      callbacks.visibility_sets = [this, ref](const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                              const VisibilitySetsOptions& set_options, const JobContext& c,
                                              const char* what) {
        return fan_out()->Compute(ref(), wire::ToProto(options_), scene, viewpoints, set_options, c, what);
      };
      callbacks.face_values = [this, ref](const VoxelScene& scene, const std::vector<WorldPoint>& stations,
                                          const EvaluateOptions& eval_options, const JobContext& c) {
        return fan_out()->ComputeFaceValues(ref(), wire::ToProto(options_), scene, stations, eval_options, c);
      };
    }
    VC_ASSIGN_OR_RETURN(const PlanResult result, backend().plan(input, options_, ctx, callbacks));
    for (const auto& t : result.timings) log.NoteTiming(StageName(t.stage), t.seconds);
    log.set_details(fmt::format(" stations={}", result.stations.size()));
    // The heat map went out once, when ready (unless the plan never reported it); then the voxels
    // and the summary: together the whole PlanResult.
    if (!heat_map_sent_) PostHeatMap(result.heat_map);
    wire::ForEachVoxelChunk(result, [this](v1::VoxelChunk&& c) {
      v1::PlanResponse r;
      *r.mutable_voxels() = std::move(c);
      return channel().Post(std::move(r), /*bulk=*/true);
    });
    v1::PlanResponse r;
    *r.mutable_result() = wire::ToProto(result);
    channel().Post(std::move(r), /*bulk=*/true);
    return ctx.CheckCancelled("the plan (while sending the result)");
  }

  void PostHeatMap(const HeatMap& h) {
    heat_map_sent_ = true;
    for (auto& c : wire::HeatMapChunks(h, frame_origin_m_)) {
      v1::PlanResponse r;
      *r.mutable_heat_map() = std::move(c);
      if (!channel().Post(std::move(r), /*bulk=*/true)) return;
    }
  }

  PlanOptions options_;
  WorldPoint frame_origin_m_ = WorldPoint::Zero();  // the input's (SceneInput::frame_origin_m)
  bool heat_map_sent_ = false;                      // on the worker thread
};

class EvaluateReactor final : public JobReactor<v1::EvaluateRequest, v1::EvaluateResponse> {
 public:
  using JobReactor::JobReactor;

 private:
  Result<v1::UploadSpec> TakeSpec(const v1::EvaluateRequest& request) override {
    VC_ASSIGN_OR_RETURN(EvaluateJobOptions requested, wire::FromProto(request.spec().parameters()));
    VC_ASSIGN_OR_RETURN(options_, ApplyServerLimits(options(), std::move(requested)));
    return request.spec().upload();
  }

  uint64_t MemoryBudgetBytes() const override { return options_.memory_budget_bytes; }

  Status Run(const SceneInput& input, const JobContext& ctx, JobLog& log) override {
    log.set_details(fmt::format(" viewpoints={}", options_.viewpoints.size()));
    VC_ASSIGN_OR_RETURN(const EvaluateJobResult result, backend().evaluate(input, options_, ctx));
    // The voxels, the seen sets, then the summary: together the whole EvaluateJobResult, as a plan's result.
    wire::ForEachVoxelChunk(result, [this](v1::VoxelChunk&& c) {
      v1::EvaluateResponse r;
      *r.mutable_voxels() = std::move(c);
      return channel().Post(std::move(r), /*bulk=*/true);
    });
    wire::ForEachSeenSetChunk(result, [this](v1::SeenSetChunk&& c) {
      v1::EvaluateResponse r;
      *r.mutable_seen_set() = std::move(c);
      return channel().Post(std::move(r), /*bulk=*/true);
    });
    v1::EvaluateResponse r;
    *r.mutable_result() = wire::ToProto(result);
    channel().Post(std::move(r), /*bulk=*/true);
    return ctx.CheckCancelled("the evaluation (while sending the result)");
  }

  EvaluateJobOptions options_;
};

// AttachPlan / AttachEvaluate: follows a detachable job from a new call. The job's events so far
// are replayed into this call's outbox, then it follows the job live (JobChannel::Attach).
template <class Response>
class AttachReactor final : public grpc::ServerWriteReactor<Response> {
 public:
  AttachReactor(grpc::CallbackServerContext* ctx, ServiceState* state, const char* method)
      : ctx_(ctx), state_(state), method_(method) {}

  void Start(const std::string& job_id) {
    const Status s = Attach(job_id);
    if (!outbox_) outbox_ = MakeOutbox(&call_token_);
    spdlog::info("rpc {} job={} peer={} status={}{}{}", method_, job_id, ctx_->peer(), int(wire::ToGrpcCode(s.code())),
                 s.ok() ? "" : ": ", s.message());
    if (!s.ok()) outbox_->Complete(s);
  }

  void OnWriteDone(bool ok) override { outbox_->OnWriteDone(ok); }

  // The client went away again: the job runs on (its grace counts from now).
  void OnCancel() override {
    call_token_.Cancel();
    outbox_->Break();
    if (channel_) {
      detached_ = true;
      channel_->Detach(outbox_.get());
    }
    outbox_->Complete(CancelledError("the attach stream broke; the job runs on detached"));
  }

  void OnDone() override {
    // Delivered: this call ended with the job's own final status on a stream that did not break.
    if (channel_ && !detached_.load() && finished_with_ && channel_->Delivered(*finished_with_)) {
      state_->kept.Erase(job_id_);
    }
    delete this;
  }

 private:
  Status Attach(const std::string& job_id) {
    if (!state_->Register(&call_token_)) {
      return UnavailableError("this vc-server is shutting down; its jobs end with it");
    }
    registered_ = true;
    VC_ASSIGN_OR_RETURN(const Caller caller, AuthenticateCall(*ctx_, state_->options.tokens));
    if (job_id.empty()) return InvalidArgumentError("job_id is empty: pass the id the Accepted event gave");
    VC_ASSIGN_OR_RETURN(std::shared_ptr<KeptJob> job, state_->kept.Find(job_id, caller.owner));
    auto channel = std::dynamic_pointer_cast<JobChannel<Response>>(job);
    if (!channel) {
      return FailedPreconditionError("job " + job_id + " is a" + (job->method() == "Evaluate" ? "n " : " ") +
                                     job->method() + " job: attach with Attach" + job->method());
    }
    channel_ = std::move(channel);
    job_id_ = job_id;
    // While the job runs, the outbox watches its token, so a producer waiting on this (slow)
    // client wakes when the job is cancelled. A job that ended produces nothing more, and its
    // token may have expired since (the submitting call's deadline): then this call's own.
    outbox_ = MakeOutbox(channel_->state().done ? &call_token_ : &channel_->token());
    return channel_->Attach(job_id, outbox_);
  }

  std::shared_ptr<Outbox<Response>> MakeOutbox(const CancelToken* token) {
    return std::make_shared<Outbox<Response>>([this](const Response* r) { this->StartWrite(r); },
                                              [this](const Status& s) {
                                                finished_with_ = s;
                                                this->Finish(wire::ToGrpcStatus(s));
                                              },
                                              token);
  }

 public:
  ~AttachReactor() override {
    if (registered_) state_->Unregister(&call_token_);
  }

 private:
  grpc::CallbackServerContext* const ctx_;
  ServiceState* const state_;
  const char* const method_;
  CancelToken call_token_;  // this call's, for a shutdown's CancelAll (the job's is the channel's)
  bool registered_ = false;
  std::atomic<bool> detached_{false};
  std::string job_id_;                   // set with channel_
  std::optional<Status> finished_with_;  // the status the outbox finished the call with
  std::shared_ptr<JobChannel<Response>> channel_;
  std::shared_ptr<Outbox<Response>> outbox_;  // made by Start
};

template <class Response>
grpc::ServerWriteReactor<Response>* StartAttach(grpc::CallbackServerContext* ctx, ServiceState* state,
                                                const char* method, const std::string& job_id) {
  auto* reactor = new AttachReactor<Response>(ctx, state, method);
  reactor->Start(job_id);
  return reactor;
}

// CancelJob: a queued or running job is cancelled (its worker is free within a second); a finished
// one's kept result is discarded.
Result<std::string> CancelKeptJob(const grpc::CallbackServerContext& ctx, ServiceState& state, const std::string& id) {
  VC_ASSIGN_OR_RETURN(const Caller caller, AuthenticateCall(ctx, state.options.tokens));
  if (id.empty()) return InvalidArgumentError("job_id is empty: pass the id the Accepted event gave");
  VC_ASSIGN_OR_RETURN(std::shared_ptr<KeptJob> job, state.kept.Find(id, caller.owner));
  if (job->state().done) {
    state.kept.Erase(id);
    return std::string("discarded");
  }
  job->Cancel("job " + id + " was cancelled by CancelJob (vc-client cancel)");
  return std::string("cancelled");
}

}  // namespace
}  // namespace internal

StationPlannerService::StationPlannerService(const ServerOptions& options, Backend backend, std::string replica_id,
                                             std::unique_ptr<PeerFanOut> fan_out)
    : state_(std::make_unique<internal::ServiceState>(options, std::move(backend), std::move(replica_id),
                                                      std::move(fan_out))) {}

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

grpc::ServerWriteReactor<v1::PlanResponse>* StationPlannerService::AttachPlan(grpc::CallbackServerContext* ctx,
                                                                              const v1::AttachRequest* request) {
  return internal::StartAttach<v1::PlanResponse>(ctx, state_.get(), "AttachPlan", request->job_id());
}

grpc::ServerWriteReactor<v1::EvaluateResponse>* StationPlannerService::AttachEvaluate(
    grpc::CallbackServerContext* ctx, const v1::AttachRequest* request) {
  return internal::StartAttach<v1::EvaluateResponse>(ctx, state_.get(), "AttachEvaluate", request->job_id());
}

grpc::ServerUnaryReactor* StationPlannerService::CancelJob(grpc::CallbackServerContext* ctx,
                                                           const v1::CancelJobRequest* request,
                                                           v1::CancelJobResponse* response) {
  auto* reactor = ctx->DefaultReactor();
  const Result<std::string> outcome = internal::CancelKeptJob(*ctx, *state_, request->job_id());
  spdlog::info("rpc CancelJob job={} peer={} outcome={}", request->job_id(), ctx->peer(),
               outcome.ok() ? *outcome : outcome.status().message());
  if (outcome.ok()) response->set_outcome(*outcome);
  reactor->Finish(wire::ToGrpcStatus(outcome.ok() ? Status::Ok() : outcome.status()));
  return reactor;
}

void StationPlannerService::Drain() { state_->Drain(); }

bool StationPlannerService::WaitForCalls(std::chrono::steady_clock::time_point deadline) {
  return state_->WaitForCalls(deadline);
}

void StationPlannerService::CancelAll() { state_->CancelAll(); }

const WorkerPool& StationPlannerService::pool() const { return state_->pool; }

}  // namespace vc::server
