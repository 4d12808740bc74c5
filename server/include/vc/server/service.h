// StationPlannerService: the vc.v1.StationPlanner gRPC service (callback API, gRFC L67).
//
// Stateless: a job lives as long as its stream, unless the client asked for a detach grace; then it
// may outlive it, and its events are kept in memory for a re-attach (kept_jobs.h), never on disk. Reactions on gRPC's
// threads only do protocol work; every job runs on the service's own bounded WorkerPool. Each RPC body is thin: convert
// the spec (vc::wire::FromProto), call one Backend function, stream the converted result, and map the vc::Status with
// ToGrpcStatus. Thread-safe; destroying the service joins its workers (shut the grpc::Server down first).
#pragma once

#include <chrono>
#include <memory>

#include "vc/server/backend.h"
#include "vc/server/peers.h"
#include "vc/server/server_options.h"
#include "vc/server/worker_pool.h"
#include "vc/v1/planner.grpc.pb.h"

namespace vc::server {

namespace internal {
struct ServiceState;
}

class StationPlannerService final : public v1::StationPlanner::CallbackService {
 public:
  // `replica_id` names this process to its peers (PeerHello); `fan_out` (may be null) spreads
  // its plans' visibility stages over them.
  StationPlannerService(const ServerOptions& options, Backend backend, std::string replica_id = {},
                        std::unique_ptr<PeerFanOut> fan_out = nullptr);
  ~StationPlannerService() override;

  grpc::ServerBidiReactor<v1::PlanRequest, v1::PlanResponse>* Plan(grpc::CallbackServerContext* ctx) override;
  grpc::ServerBidiReactor<v1::EvaluateRequest, v1::EvaluateResponse>* Evaluate(
      grpc::CallbackServerContext* ctx) override;
  // Detachable jobs (docs/PROTOCOL.md, "Detachable jobs").
  grpc::ServerWriteReactor<v1::PlanResponse>* AttachPlan(grpc::CallbackServerContext* ctx,
                                                         const v1::AttachRequest* request) override;
  grpc::ServerWriteReactor<v1::EvaluateResponse>* AttachEvaluate(grpc::CallbackServerContext* ctx,
                                                                 const v1::AttachRequest* request) override;
  grpc::ServerUnaryReactor* CancelJob(grpc::CallbackServerContext* ctx, const v1::CancelJobRequest* request,
                                      v1::CancelJobResponse* response) override;
  // Between replicas (peer_service.cc; docs/DEPLOY.md, "Scaling out").
  grpc::ServerUnaryReactor* PeerHello(grpc::CallbackServerContext* ctx, const v1::PeerHelloRequest* request,
                                      v1::PeerHelloResponse* response) override;
  grpc::ServerReadReactor<v1::SceneChunk>* ShareScene(grpc::CallbackServerContext* ctx,
                                                      v1::ShareSceneResponse* response) override;
  grpc::ServerUnaryReactor* ComputeShard(grpc::CallbackServerContext* ctx, const v1::ShardRequest* request,
                                         v1::ShardResponse* response) override;

  // For a shutdown (Server::Shutdown), all thread-safe. Drain: from now on new calls are refused
  // with UNAVAILABLE ("shutting down; retry"), which clients retry on another replica.
  // WaitForCalls: true once every call alive has ended, false at `deadline`. CancelAll: cancels
  // every call alive (running, queued or uploading); each ends with CANCELLED as soon as its job
  // reaches a cancellation point (the core polls at least every second).
  void Drain();
  bool WaitForCalls(std::chrono::steady_clock::time_point deadline);
  void CancelAll();

  // The pool running the jobs (for observation in tests and logs).
  const WorkerPool& pool() const;

 private:
  std::unique_ptr<internal::ServiceState> state_;
};

}  // namespace vc::server
