// JobReactor: the gRPC adapter shared by the Plan and Evaluate RPCs (private header).
//
// One reactor per call, living exactly as long as the call (the service is stateless). It only
// connects gRPC's callbacks to the plain-C++ pieces: the UploadAssembler checks the spec, admits
// the job and collects the chunks; the JobRunner reads the scene and runs the RPC's core function
// on a WorkerPool thread; the Outbox queues the responses and writes them one at a time. The RPC
// subclasses say how to take their spec and what to run.
//
// Lifetime: the call finishes (Outbox::Complete) only when no worker task can touch the reactor
// any more (the task completes as its last act), and gRPC calls OnDone after Finish, which deletes
// the reactor. Cancellation (client cancel, disconnect, deadline, server shutdown) arrives in
// OnCancel and cancels the job's CancelToken, which the core polls.
#pragma once

#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <set>
#include <string>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/scene_input.h"
#include "vc/server/backend.h"
#include "vc/server/job_runner.h"
#include "vc/server/outbox.h"
#include "vc/server/scene_cache.h"
#include "vc/server/server_options.h"
#include "vc/server/upload_assembler.h"
#include "vc/server/worker_pool.h"
#include "vc/v1/planner.pb.h"
#include "vc/wire/convert.h"
#include "vc/wire/status_mapping.h"

namespace vc::server::internal {

// Shared by every call of a service.
struct ServiceState {
  ServiceState(const ServerOptions& o, Backend b)
      : options(o),
        backend(std::move(b)),
        cache(o.scene_cache_bytes),
        runner(&backend, o.max_upload_bytes, &cache),
        pool(o.EffectiveWorkers(), o.queue) {}
  const ServerOptions options;
  const Backend backend;
  SceneCache cache;
  const JobRunner runner;
  WorkerPool pool;
  std::atomic<uint64_t> next_job{1};

  // The calls alive now, by their cancel tokens, for a shutdown: Drain refuses new calls,
  // WaitForCalls waits for the others to end, CancelAll cancels them.
  // Registers a new call; false when the service is draining (the call must be refused).
  bool Register(CancelToken* token) {
    std::lock_guard lock(calls_mu);
    if (draining) return false;
    calls.insert(token);
    return true;
  }
  void Unregister(CancelToken* token) {
    {
      std::lock_guard lock(calls_mu);
      calls.erase(token);
    }
    calls_ended.notify_all();
  }
  void Drain() {
    std::lock_guard lock(calls_mu);
    draining = true;
  }
  // True when no call is alive (any more) at `deadline`.
  bool WaitForCalls(std::chrono::steady_clock::time_point deadline) {
    std::unique_lock lock(calls_mu);
    return calls_ended.wait_until(lock, deadline, [&] { return calls.empty(); });
  }
  void CancelAll() {
    std::lock_guard lock(calls_mu);
    for (CancelToken* t : calls) t->Cancel();
  }

 private:
  std::mutex calls_mu;
  std::condition_variable calls_ended;
  std::set<CancelToken*> calls;
  bool draining = false;
};

// Constant-time comparison of the bearer token.
bool TokenMatches(const grpc::CallbackServerContext& ctx, const std::string& token, std::string* why);
// A fresh job id ("j-" + 12 hex digits).
std::string NewJobId(ServiceState& state);

template <class Request, class Response>
class JobReactor : public grpc::ServerBidiReactor<Request, Response> {
 public:
  using Clock = std::chrono::steady_clock;

  JobReactor(grpc::CallbackServerContext* ctx, ServiceState* state, const char* method)
      : ctx_(ctx),
        state_(state),
        method_(method),
        start_(Clock::now()),
        upload_(state->options.max_upload_bytes, &state->pool),
        outbox_([this](const Response* r) { this->StartWrite(r); },
                [this](const Status& s) { this->Finish(wire::ToGrpcStatus(s)); }, &token_) {}

  // Call once right after construction (from the RPC method).
  void Start() {
    const auto deadline = ctx_->deadline();
    if (deadline != std::chrono::system_clock::time_point::max()) {
      token_.SetDeadline(Clock::now() +
                         std::chrono::duration_cast<Clock::duration>(deadline - std::chrono::system_clock::now()));
    }
    registered_ = state_->Register(&token_);
    if (!registered_) {
      Reject(UnavailableError("this vc-server is shutting down; retry (another replica will take the job)"));
      return;
    }
    std::string why;
    if (!TokenMatches(*ctx_, state_->options.token, &why)) {
      Reject(UnauthenticatedError(why));
      return;
    }
    this->StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      OnUploadEnd();
      return;
    }
    Status s = OnMessage();
    if (!s.ok()) {
      Reject(s);
      return;
    }
    this->StartRead(&request_);
  }

  void OnWriteDone(bool ok) override { outbox_.OnWriteDone(ok); }

  void OnCancel() override {
    const bool past_deadline = ctx_->deadline() != std::chrono::system_clock::time_point::max() &&
                               std::chrono::system_clock::now() >= ctx_->deadline();
    if (!past_deadline || !token_.cancelled()) token_.Cancel();
    outbox_.Break();
  }

  void OnDone() override {
    if (registered_) state_->Unregister(&token_);
    delete this;
  }

 protected:
  // Takes the spec message: stores the parameters (checked) and returns the upload spec.
  virtual Result<v1::UploadSpec> TakeSpec(const Request& spec) = 0;
  // The job's memory budget, as TakeSpec capped it; bounds the reading of its upload.
  virtual uint64_t MemoryBudgetBytes() const = 0;
  // Runs the RPC's core function on the parsed input, posting responses; on a worker thread.
  virtual Status Run(const SceneInput& input, const JobContext& ctx, JobLog& log) = 0;

  Outbox<Response>& outbox() { return outbox_; }
  const ServerOptions& options() const { return state_->options; }
  const Backend& backend() const { return state_->backend; }

 private:
  Status OnMessage() {
    if (request_.has_spec()) {
      VC_RETURN_IF_ERROR(upload_.StartSpec());
      VC_ASSIGN_OR_RETURN(const v1::UploadSpec spec, TakeSpec(request_));
      Status s = upload_.AcceptSpec(spec);
      if (upload_.busy()) ctx_->AddTrailingMetadata("retry-after-ms", "2000");
      return s;
    }
    if (request_.has_chunk()) return upload_.AddChunk(request_.chunk().data());
    return InvalidArgumentError("an empty request message arrived; send a spec, then data chunks");
  }

  void OnUploadEnd() {
    if (ctx_->IsCancelled()) {
      Reject(CancelledError("the client cancelled the call during the upload"));
      return;
    }
    if (const Status s = token_.Check("the job (the server is shutting down)"); !s.ok()) {
      Reject(s);
      return;
    }
    Status s = upload_.Finish();
    if (!s.ok()) {
      Reject(s);
      return;
    }
    job_.id = NewJobId(*state_);
    job_.method = method_;
    job_.peer = ctx_->peer();
    job_.upload = upload_.spec();
    if (job_.upload.from_cache()) {
      const SceneCache::Bytes cached = state_->cache.Get(job_.upload.scene_sha256());
      if (!cached) {
        Reject(NotFoundError("scene " + job_.upload.scene_sha256().substr(0, 12) +
                             "... is not in this server's scene cache (it was never sent here, or it was evicted "
                             "or the replica restarted); upload it"));
        return;
      }
      if (cached->size() != job_.upload.total_size_bytes()) {
        Reject(InvalidArgumentError("the cached scene " + job_.upload.scene_sha256().substr(0, 12) + "... has " +
                                    std::to_string(cached->size()) + " bytes, the spec says " +
                                    std::to_string(job_.upload.total_size_bytes())));
        return;
      }
      job_.data = *cached;
      job_.cache = "hit";
    } else {
      job_.data = upload_.TakeData();
    }
    job_.memory_budget_bytes = MemoryBudgetBytes();
    job_.started = start_;
    job_.submitted = Clock::now();
    state_->pool.Submit(
        std::move(*upload_.TakeTicket()),
        [this, id = job_.id](uint32_t position) {
          Response r;
          r.mutable_accepted()->set_job_id(id);
          r.mutable_accepted()->set_queue_position(position);
          outbox_.Post(std::move(r));
        },
        [this](WorkerPool::Ticket place) { Work(std::move(place)); });
  }

  // On a worker thread. The place goes back to the pool before the final status goes out, so a
  // client that submits again on hearing it is not refused as busy.
  void Work(WorkerPool::Ticket place) {
    const Status s = state_->runner.Run(
        std::move(job_), token_,
        [this](const ProgressEvent& e) {
          Response r;
          *r.mutable_progress() = wire::ToProto(e);
          outbox_.PostProgress(std::move(r));
        },
        [this](const SceneInput& input, const JobContext& ctx, JobLog& log) { return Run(input, ctx, log); });
    place.Release();
    outbox_.Complete(s);  // last touch of this reactor by the worker
  }

  // Ends a call that never reached a worker, with its log line (gRPC threads).
  void Reject(const Status& status) {
    upload_.TakeTicket();  // the place (if one was reserved) is free before the client hears the status
    spdlog::info("rpc {} peer={} upload={} rejected status={}: {}", method_, ctx_->peer(),
                 HumanBytes(upload_.declared_bytes()), int(wire::ToGrpcCode(status.code())), status.message());
    outbox_.Complete(status);
  }

  grpc::CallbackServerContext* const ctx_;
  ServiceState* const state_;
  const char* const method_;
  const Clock::time_point start_;
  CancelToken token_;
  bool registered_ = false;  // in the service's calls (Start); unregistered in OnDone
  Request request_;          // the message being read (gRPC threads, one reaction at a time)
  UploadAssembler upload_;   // gRPC threads until the job is submitted
  Job job_;                  // handed to the worker
  Outbox<Response> outbox_;
};

}  // namespace vc::server::internal
