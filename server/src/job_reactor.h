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
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/scene_input.h"
#include "vc/server/authenticate.h"
#include "vc/server/backend.h"
#include "vc/server/job_runner.h"
#include "vc/server/kept_jobs.h"
#include "vc/server/outbox.h"
#include "vc/server/peers.h"
#include "vc/server/scene_cache.h"
#include "vc/server/server_options.h"
#include "vc/server/upload_assembler.h"
#include "vc/server/voxelized_scenes.h"
#include "vc/server/worker_pool.h"
#include "vc/v1/planner.pb.h"
#include "vc/wire/convert.h"
#include "vc/wire/status_mapping.h"

namespace vc::server::internal {

// Shared by every call of a service.
struct ServiceState {
  ServiceState(const ServerOptions& o, Backend b, std::string id, std::unique_ptr<PeerFanOut> peers)
      : options(o),
        backend(std::move(b)),
        replica_id(std::move(id)),
        fan_out(std::move(peers)),
        cache(o.scene_cache_bytes),
        runner(&backend, o.max_upload_bytes, &cache),
        kept(o.result_ttl, o.kept_results_bytes),
        pool(o.EffectiveWorkers(), o.queue) {}
  const ServerOptions options;
  const Backend backend;
  // This process's id among replicas (PeerHello), and the fan-out of its plans (null without peers).
  const std::string replica_id;
  const std::unique_ptr<PeerFanOut> fan_out;
  SceneCache cache;
  // The scenes voxelized for peers' shards (ComputeShard).
  VoxelizedScenes voxelized{2};
  const JobRunner runner;
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

 public:
  // Declared last, so destroyed first: the pool's destructor joins the workers, and a detached
  // job's worker may still unregister its call and release its kept events.
  KeptJobs kept;    // the detachable jobs, by id
  WorkerPool pool;  // the workers
};

// Authenticate (vc/server/authenticate.h) with the call's "authorization" metadata.
inline Result<Caller> AuthenticateCall(const grpc::CallbackServerContext& ctx, const std::vector<std::string>& tokens) {
  const auto& metadata = ctx.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return Authenticate(std::nullopt, tokens);
  return Authenticate(std::string_view(it->second.data(), it->second.size()), tokens);
}
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
        channel_(std::make_shared<JobChannel<Response>>(method, state->kept.budget())),
        outbox_(std::make_shared<Outbox<Response>>([this](const Response* r) { this->StartWrite(r); },
                                                   [this](const Status& s) {
                                                     finished_with_ = s;
                                                     this->Finish(wire::ToGrpcStatus(s));
                                                   },
                                                   &token())) {
    channel_->SetSink(outbox_);
  }

  // Call once right after construction (from the RPC method).
  void Start() {
    const auto deadline = ctx_->deadline();
    if (deadline != std::chrono::system_clock::time_point::max()) {
      const auto at =
          Clock::now() + std::chrono::duration_cast<Clock::duration>(deadline - std::chrono::system_clock::now());
      token().SetDeadline(at);
    }
    registered_ = state_->Register(&token());
    if (!registered_) {
      Reject(UnavailableError("this vc-server is shutting down; retry (another replica will take the job)"));
      return;
    }
    Result<Caller> caller = AuthenticateCall(*ctx_, state_->options.tokens);
    if (!caller.ok()) {
      Reject(caller.status());
      return;
    }
    channel_->set_owner(std::move(caller->owner));
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

  void OnWriteDone(bool ok) override { outbox_->OnWriteDone(ok); }

  // The client cancelled, vanished, or the deadline passed. A detachable job that is queued or
  // running runs on without this call (docs/PROTOCOL.md, "Detachable jobs"); any other is cancelled.
  void OnCancel() override {
    const bool past_deadline = ctx_->deadline() != std::chrono::system_clock::time_point::max() &&
                               std::chrono::system_clock::now() >= ctx_->deadline();
    cancelled_ = true;
    outbox_->Break();
    if (submitted_.load() && channel_->detachable() && !past_deadline && !token().cancelled()) {
      channel_->Detach(outbox_.get());
      spdlog::info("job {} detached: its stream broke; it runs on for up to {:.0f} s without a client", job_id_,
                   std::chrono::duration<double>(channel_->grace()).count());
      outbox_->Complete(CancelledError("the stream broke; the job runs on detached"));
      return;
    }
    if (!past_deadline || !token().cancelled()) token().Cancel();
    // The call ends now (the worker, if any, holds the reactor until it stops); its status cannot
    // reach a client that is gone, and one past its deadline has its own.
    outbox_->Complete(past_deadline ? DeadlineExceededError("the call's deadline passed")
                                    : CancelledError("the call was cancelled"));
  }

  // The call is over; the reactor lives on while a detached job's worker still uses it.
  void OnDone() override {
    // Delivered: this call ended with the job's own final status on a stream that did not break.
    if (submitted_.load() && !cancelled_.load() && finished_with_ && channel_->Delivered(*finished_with_)) {
      state_->kept.Erase(job_id_);
    }
    ReleaseHold();
  }

 protected:
  // Takes the spec message: stores the parameters (checked) and returns the upload spec.
  virtual Result<v1::UploadSpec> TakeSpec(const Request& spec) = 0;
  // The job's memory budget, as TakeSpec capped it; bounds the reading of its upload.
  virtual uint64_t MemoryBudgetBytes() const = 0;
  // Runs the RPC's core function on the parsed input, posting responses; on a worker thread.
  virtual Status Run(const SceneInput& input, const JobContext& ctx, JobLog& log) = 0;

  JobChannel<Response>& channel() { return *channel_; }
  // The uploaded bytes, kept for the job's life only on a replica that fans plans out (null
  // otherwise): peers are sent the scene from them.
  const SceneCache::Bytes& scene_bytes() const { return scene_bytes_; }
  const v1::UploadSpec& upload_spec() const { return upload_spec_; }
  PeerFanOut* fan_out() const { return state_->fan_out.get(); }
  const std::string& replica_id() const { return state_->replica_id; }
  const ServerOptions& options() const { return state_->options; }
  const Backend& backend() const { return state_->backend; }

 private:
  Status OnMessage() {
    if (request_.has_spec()) {
      VC_RETURN_IF_ERROR(upload_.StartSpec());
      VC_ASSIGN_OR_RETURN(const v1::UploadSpec spec, TakeSpec(request_));
      const auto asked = std::chrono::milliseconds(int64_t{request_.spec().control().detach_grace_s()} * 1000);
      channel_->set_grace(std::min(asked, state_->options.max_detach_grace));
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
    if (const Status s = token().Check("the job (the server is shutting down)"); !s.ok()) {
      Reject(s);
      return;
    }
    Status s = upload_.Finish();
    if (!s.ok()) {
      Reject(s);
      return;
    }
    job_.id = NewJobId(*state_);
    job_id_ = job_.id;
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
      job_.data = cached;
      job_.cache = "hit";
    } else {
      job_.data = std::make_shared<const std::string>(upload_.TakeData());
    }
    upload_spec_ = job_.upload;
    if (state_->fan_out) scene_bytes_ = job_.data;
    job_.memory_budget_bytes = MemoryBudgetBytes();
    job_.started = start_;
    job_.submitted = Clock::now();
    if (channel_->detachable()) state_->kept.Add(job_.id, channel_);
    holds_.fetch_add(1);  // the worker's, released by Work
    submitted_.store(true);
    state_->pool.Submit(
        std::move(*upload_.TakeTicket()),
        [this, id = job_.id](uint32_t position) {
          Response r;
          r.mutable_accepted()->set_job_id(id);
          r.mutable_accepted()->set_queue_position(position);
          r.mutable_accepted()->set_attach_address(state_->options.advertise_address);
          r.mutable_accepted()->set_detach_grace_s(
              uint32_t(std::chrono::duration_cast<std::chrono::seconds>(channel_->grace()).count()));
          channel_->Post(std::move(r));
        },
        [this](WorkerPool::Ticket place) { Work(std::move(place)); });
  }

  // On a worker thread. The place goes back to the pool before the final status goes out, so a
  // client that submits again on hearing it is not refused as busy.
  void Work(WorkerPool::Ticket place) {
    const Status s = state_->runner.Run(
        std::move(job_), token(),
        [this](const ProgressEvent& e) {
          Response r;
          *r.mutable_progress() = wire::ToProto(e);
          channel_->PostProgress(std::move(r));
        },
        [this](const SceneInput& input, const JobContext& ctx, JobLog& log) { return Run(input, ctx, log); });
    place.Release();
    channel_->Complete(s);
    ReleaseHold();  // last touch of this reactor by the worker
  }

  CancelToken& token() { return channel_->token(); }

  // The call (OnDone) and the worker (Work) each hold the reactor; the last one deletes it.
  void ReleaseHold() {
    if (holds_.fetch_sub(1) != 1) return;
    if (registered_) state_->Unregister(&token());
    delete this;
  }

  // Ends a call that never reached a worker, with its log line (gRPC threads).
  void Reject(const Status& status) {
    upload_.TakeTicket();  // the place (if one was reserved) is free before the client hears the status
    spdlog::info("rpc {} peer={} upload={} rejected status={}: {}", method_, ctx_->peer(),
                 HumanBytes(upload_.declared_bytes()), int(wire::ToGrpcCode(status.code())), status.message());
    outbox_->Complete(status);
  }

  grpc::CallbackServerContext* const ctx_;
  ServiceState* const state_;
  const char* const method_;
  const Clock::time_point start_;
  bool registered_ = false;              // in the service's calls (Start); unregistered with the last hold
  std::atomic<int> holds_{1};            // the call's, plus the worker's once submitted
  std::atomic<bool> submitted_{false};   // the job went to the pool
  std::atomic<bool> cancelled_{false};   // OnCancel ran: the stream broke or was cancelled
  std::optional<Status> finished_with_;  // the status the outbox finished the call with
  std::string job_id_;                   // for the log, once submitted
  Request request_;                      // the message being read (gRPC threads, one reaction at a time)
  UploadAssembler upload_;               // gRPC threads until the job is submitted
  Job job_;                              // handed to the worker
  v1::UploadSpec upload_spec_;           // job_.upload, kept for the worker's Run
  SceneCache::Bytes scene_bytes_;        // with peers only: the upload, for them
  // The job's events and cancellation (kept in state_->kept when detachable), and this call's queue.
  const std::shared_ptr<JobChannel<Response>> channel_;
  const std::shared_ptr<Outbox<Response>> outbox_;
};

}  // namespace vc::server::internal
