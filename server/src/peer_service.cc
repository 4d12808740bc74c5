// The calls between replicas (docs/DEPLOY.md, "Scaling out"): PeerHello, ShareScene and
// ComputeShard, a peer's side of a plan fanned out by another replica's PeerFanOut (peers.h).
// Authenticated like every vc.v1 call; a shard runs on the worker pool like a job, so a busy
// replica answers RESOURCE_EXHAUSTED and the coordinator gives the shard to another.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>

#include "job_reactor.h"
#include "vc/plan/stages.h"
#include "vc/server/service.h"
#include "vc/wire/convert.h"
#include "vc/wire/face_values_codec.h"
#include "vc/wire/sha256.h"
#include "vc/wire/voxel_set_codec.h"

namespace vc::server {
namespace internal {
namespace {

using Clock = std::chrono::steady_clock;
// The most a face-values shard's answer may carry (the coordinator computes a bigger one itself).
constexpr uint64_t kMaxFaceValuesBytes = uint64_t{1} << 30;

// ComputeShard's work, on a worker thread.
Status RunShard(ServiceState& state, const v1::ShardRequest& request, v1::ShardResponse* response,
                const JobContext& ctx) {
  const SceneCache::Bytes bytes = state.cache.Get(request.scene_sha256());
  if (!bytes) {
    return NotFoundError("scene " + request.scene_sha256().substr(0, 12) +
                         "... is not in this replica's scene cache; share it (ShareScene) and call again");
  }
  VC_ASSIGN_OR_RETURN(PlanOptions requested, wire::FromProto(request.parameters()));
  requested.threads = 0;  // this replica's share, whatever the coordinator's own job had
  VC_ASSIGN_OR_RETURN(const PlanOptions options, ApplyServerLimits(state.options, std::move(requested)));
  std::vector<WorldPoint> viewpoints;
  viewpoints.reserve(size_t(request.viewpoints_size()));
  for (const v1::Point& p : request.viewpoints()) viewpoints.push_back(wire::FromProto(p));
  VC_ASSIGN_OR_RETURN(const double metres_per_unit, SpecMetresPerUnit(request.units(), "ComputeShard's units"));
  const std::string key = VoxelizedSceneKey(request.scene_sha256(), options.resolution_m, request.units());
  VC_ASSIGN_OR_RETURN(const VoxelizedScenes::Scene scene, state.voxelized.Get(key, [&]() -> Result<VoxelScene> {
    const std::string source = request.source_name().empty() ? "shared scene" : request.source_name();
    ReadOptions read_options = ReadLimits(state.options.max_upload_bytes, options.memory_budget_bytes);
    read_options.metres_per_unit = metres_per_unit;
    VC_ASSIGN_OR_RETURN(const SceneInput input, state.backend.read_scene(*bytes, source, read_options));
    // Not cancelled with this shard: other shards may be waiting for the same scene.
    VC_ASSIGN_OR_RETURN(planner::VoxelizeOutput v, planner::RunVoxelizeStage({input}, options, JobContext{}));
    return std::move(v.scene);
  }));
  response->set_replica_id(state.replica_id);
  response->set_occupied_voxels(scene->occupied.size());
  response->set_scene_crc32c(SceneFingerprint(*scene));
  switch (request.kind()) {
    case v1::SHARD_KIND_VISIBILITY_SETS: {
      VC_RETURN_IF_ERROR(planner::CheckVisibilitySetBudget(viewpoints.size(), scene->occupied.size(),
                                                           options.memory_budget_bytes, "this shard"));
      VC_ASSIGN_OR_RETURN(const std::vector<VoxelSet> sets,
                          ComputeVisibilitySets(*scene, viewpoints, planner::VisibilitySetsOptionsFor(options), ctx));
      for (const VoxelSet& s : sets) response->add_sets(wire::EncodeVoxelSet(s));
      return Status::Ok();
    }
    case v1::SHARD_KIND_FACE_VALUES: {
      EvaluateOptions eval_options = planner::ReductionEvaluateOptions(options);
      eval_options.keep_sparse_join_state = request.keep_join_state();
      VC_ASSIGN_OR_RETURN(const Evaluation e, Evaluate(*scene, viewpoints, eval_options, ctx));
      // On the wire: 4 bytes a face and a float V, or with the join state a double V and a perception.
      const uint64_t per_face = request.keep_join_state() ? 4 + 8 + 1 : 4 + 4;
      uint64_t bytes = 0;
      for (const SparseFaceValues& v : e.per_viewpoint_sparse_values) bytes += v.size() * per_face;
      if (bytes > kMaxFaceValuesBytes) {  // far below protobuf's 2 GiB per message
        return InvalidArgumentError(fmt::format(
            "ComputeShard: the face values of {} stations take {}, over {} per shard; lower the coordinator's "
            "--shard-candidates",
            viewpoints.size(), HumanBytes(bytes), HumanBytes(kMaxFaceValuesBytes)));
      }
      for (size_t k = 0; k < e.per_viewpoint_sparse_values.size(); ++k) {
        v1::FaceValues* m = response->add_face_values();
        *m = wire::EncodeFaceValues(e.per_viewpoint_sparse_values[k]);
        if (request.keep_join_state()) *m->mutable_figures() = wire::ToProto(e.per_viewpoint[k]);
      }
      return Status::Ok();
    }
    default:
      return InvalidArgumentError(
          fmt::format("ComputeShard: unknown shard kind {}; is this replica older than the "
                      "coordinator?",
                      int(request.kind())));
  }
}

// One ComputeShard call: admitted to the worker pool like a job, cancelled with its call.
class ShardReactor final : public grpc::ServerUnaryReactor {
 public:
  ShardReactor(grpc::CallbackServerContext* ctx, ServiceState* state, const v1::ShardRequest* request,
               v1::ShardResponse* response)
      : ctx_(ctx), state_(state), request_(request), response_(response), start_(Clock::now()) {}

  void Start() {
    const auto deadline = ctx_->deadline();
    if (deadline != std::chrono::system_clock::time_point::max()) {
      token_.SetDeadline(Clock::now() +
                         std::chrono::duration_cast<Clock::duration>(deadline - std::chrono::system_clock::now()));
    }
    registered_ = state_->Register(&token_);
    if (!registered_) return Done(UnavailableError("this vc-server is shutting down; give the shard to another"));
    if (const Result<Caller> caller = AuthenticateCall(*ctx_, state_->options.tokens); !caller.ok()) {
      return Done(caller.status());
    }
    std::optional<WorkerPool::Ticket> ticket = state_->pool.TryAdmit();
    if (!ticket) {
      ctx_->AddTrailingMetadata("retry-after-ms", "500");
      return Done(ResourceExhaustedError("this replica's workers and queue are all taken; give the shard to another"));
    }
    state_->pool.Submit(
        std::move(*ticket), [](uint32_t) {},
        [this](WorkerPool::Ticket place) {
          JobContext ctx;
          ctx.cancel = &token_;
          Status s = ctx.CheckCancelled("the shard (while queued)");
          if (s.ok()) {
            try {
              s = RunShard(*state_, *request_, response_, ctx);
            } catch (const std::bad_alloc&) {
              s = ResourceExhaustedError("this replica ran out of memory on the shard");
            } catch (const std::exception& e) {
              s = InternalError(std::string("this replica failed on the shard: ") + e.what());
            }
          }
          place.Release();
          Done(s);
        });
  }

  void OnCancel() override { token_.Cancel(); }
  void OnDone() override {
    if (registered_) state_->Unregister(&token_);
    delete this;
  }

 private:
  void Done(const Status& s) {
    spdlog::log(s.ok() ? spdlog::level::info : spdlog::level::warn,
                "rpc ComputeShard peer={} scene={} viewpoints={}+{} elapsed={:.3f}s status={}", ctx_->peer(),
                request_->scene_sha256().substr(0, 12), request_->first_index(), request_->viewpoints_size(),
                std::chrono::duration<double>(Clock::now() - start_).count(), s.ok() ? "OK" : s.ToString());
    if (s.ok()) response_->set_compute_seconds(std::chrono::duration<double>(Clock::now() - start_).count());
    Finish(wire::ToGrpcStatus(s));  // last touch: OnDone may delete this at once
  }

  grpc::CallbackServerContext* const ctx_;
  ServiceState* const state_;
  const v1::ShardRequest* const request_;
  v1::ShardResponse* const response_;
  const Clock::time_point start_;
  CancelToken token_;
  bool registered_ = false;
};

// One ShareScene call: the chunks into one string, checked against the first chunk's size and
// hash, then into the scene cache.
class ShareSceneReactor final : public grpc::ServerReadReactor<v1::SceneChunk> {
 public:
  ShareSceneReactor(grpc::CallbackServerContext* ctx, ServiceState* state, v1::ShareSceneResponse* response)
      : ctx_(ctx), state_(state), response_(response) {
    if (const Result<Caller> caller = AuthenticateCall(*ctx_, state_->options.tokens); !caller.ok()) {
      Done(caller.status());
      return;
    }
    StartRead(&chunk_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      Done(Check());
      return;
    }
    if (first_) {
      first_ = false;
      sha256_ = chunk_.sha256();
      size_ = chunk_.total_size_bytes();
      if (sha256_.size() != 64) return Done(InvalidArgumentError("ShareScene: the first chunk must name the SHA-256"));
      if (size_ > state_->options.max_upload_bytes) {
        return Done(
            ResourceExhaustedError(fmt::format("ShareScene: {} is over this replica's --max-upload-bytes ({})",
                                               HumanBytes(size_), HumanBytes(state_->options.max_upload_bytes))));
      }
      if (size_ > state_->cache.capacity_bytes()) {
        return Done(ResourceExhaustedError(
            fmt::format("ShareScene: {} does not fit this replica's scene cache ({}); raise its --scene-cache-bytes",
                        HumanBytes(size_), HumanBytes(state_->cache.capacity_bytes()))));
      }
      data_.reserve(size_);
    }
    if (data_.size() + chunk_.data().size() > size_) {
      return Done(InvalidArgumentError(fmt::format("ShareScene: more than the {} bytes announced", size_)));
    }
    data_ += chunk_.data();
    StartRead(&chunk_);
  }

  void OnDone() override { delete this; }

 private:
  Status Check() {
    if (data_.size() != size_) {
      return InvalidArgumentError(fmt::format("ShareScene: {} bytes arrived of {} announced", data_.size(), size_));
    }
    if (wire::Sha256Hex(data_) != sha256_)
      return InvalidArgumentError("ShareScene: the bytes' SHA-256 is not " + sha256_);
    const bool kept = state_->cache.Put(sha256_, std::make_shared<const std::string>(std::move(data_)));
    if (!kept) return ResourceExhaustedError("ShareScene: this replica's scene cache could not keep the scene");
    response_->set_kept(true);
    spdlog::info("rpc ShareScene peer={} scene={} size={}", ctx_->peer(), sha256_.substr(0, 12), HumanBytes(size_));
    return Status::Ok();
  }
  void Done(const Status& s) {
    if (done_) return;
    done_ = true;
    if (!s.ok()) spdlog::warn("rpc ShareScene peer={} status={}", ctx_->peer(), s.ToString());
    Finish(wire::ToGrpcStatus(s));
  }

  grpc::CallbackServerContext* const ctx_;
  ServiceState* const state_;
  v1::ShareSceneResponse* const response_;
  v1::SceneChunk chunk_;
  bool first_ = true;
  bool done_ = false;
  std::string sha256_;
  uint64_t size_ = 0;
  std::string data_;
};

}  // namespace
}  // namespace internal

grpc::ServerUnaryReactor* StationPlannerService::PeerHello(grpc::CallbackServerContext* ctx,
                                                           const v1::PeerHelloRequest* request,
                                                           v1::PeerHelloResponse* response) {
  auto* reactor = ctx->DefaultReactor();
  if (const Result<Caller> caller = internal::AuthenticateCall(*ctx, state_->options.tokens); !caller.ok()) {
    reactor->Finish(wire::ToGrpcStatus(caller.status()));
    return reactor;
  }
  response->set_replica_id(state_->replica_id);
  response->set_has_scene(!request->scene_sha256().empty() && state_->cache.Get(request->scene_sha256()) != nullptr);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerReadReactor<v1::SceneChunk>* StationPlannerService::ShareScene(grpc::CallbackServerContext* ctx,
                                                                           v1::ShareSceneResponse* response) {
  return new internal::ShareSceneReactor(ctx, state_.get(), response);
}

grpc::ServerUnaryReactor* StationPlannerService::ComputeShard(grpc::CallbackServerContext* ctx,
                                                              const v1::ShardRequest* request,
                                                              v1::ShardResponse* response) {
  auto* reactor = new internal::ShardReactor(ctx, state_.get(), request, response);
  reactor->Start();
  return reactor;
}

}  // namespace vc::server
