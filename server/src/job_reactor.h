// JobReactor: the protocol machinery shared by the Plan and Evaluate RPCs (private header).
//
// One reactor per call, living exactly as long as the call (the service is stateless). On gRPC's
// threads it only does protocol work: authenticate, take the spec, reserve a place in the pool,
// collect the chunks while checking size and CRC32C incrementally, and write queued responses one
// at a time. Once the upload is verified the job goes to the WorkerPool; the worker parses the
// scene and runs the RPC's core function (Run), posting responses to the reactor's outbox.
//
// Lifetime: Finish is called only when no worker task can touch the reactor any more (the task
// calls Complete as its last act), and gRPC calls OnDone after Finish, which deletes the reactor.
// Cancellation (client cancel, disconnect, deadline, server shutdown) arrives in OnCancel and
// cancels the job's CancelToken, which the core polls.
#pragma once

#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <string>

#include "vc/base/progress.h"
#include "vc/scene/scene_input.h"
#include "vc/base/status.h"
#include "vc/server/backend.h"
#include "vc/server/server_options.h"
#include "vc/server/worker_pool.h"
#include "vc/v1/planner.pb.h"
#include "vc/wire/convert.h"
#include "vc/wire/crc32c.h"
#include "vc/wire/status_mapping.h"

namespace vc::server::internal {

// Shared by every call of a service.
struct ServiceState {
  ServiceState(const ServerOptions& o, Backend b)
      : options(o), backend(std::move(b)), pool(o.EffectiveWorkers(), o.queue) {}
  const ServerOptions options;
  const Backend backend;
  WorkerPool pool;
  std::atomic<uint64_t> next_job{1};
};

// Constant-time comparison of the bearer token.
bool TokenMatches(const grpc::CallbackServerContext& ctx, const std::string& token, std::string* why);
// A fresh job id ("j-" + 12 hex digits).
std::string NewJobId(ServiceState& state);
// "12.3 MiB" style.
std::string HumanBytes(uint64_t bytes);

// Outbox bytes above which a worker posting bulk results waits for the network.
inline constexpr size_t kMaxOutboxBytes = size_t{8} << 20;

template <class Request, class Response>
class JobReactor : public grpc::ServerBidiReactor<Request, Response> {
 public:
  using Clock = std::chrono::steady_clock;

  JobReactor(grpc::CallbackServerContext* ctx, ServiceState* state, const char* method)
      : ctx_(ctx), state_(state), method_(method), start_(Clock::now()) {}

  // Call once right after construction (from the RPC method).
  void Start() {
    const auto deadline = ctx_->deadline();
    if (deadline != std::chrono::system_clock::time_point::max()) {
      token_.SetDeadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                            deadline - std::chrono::system_clock::now()));
    }
    std::string why;
    if (!TokenMatches(*ctx_, state_->options.token, &why)) {
      Reject(grpc::Status(grpc::StatusCode::UNAUTHENTICATED, why));
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
      Reject(wire::ToGrpcStatus(s));
      return;
    }
    this->StartRead(&request_);
  }

  void OnWriteDone(bool ok) override {
    std::optional<grpc::Status> finish;
    const Response* next = nullptr;
    {
      std::lock_guard lock(mu_);
      outbox_bytes_ -= outbox_.front().ByteSizeLong();
      outbox_.pop_front();
      if (!ok) {
        broken_ = true;  // the client is gone; OnCancel follows
        outbox_.clear();
        outbox_bytes_ = 0;
      }
      if (!outbox_.empty()) {
        next = &outbox_.front();
      } else {
        writing_ = false;
        if (final_ && !finished_) {
          finished_ = true;
          finish = final_;
        }
      }
    }
    drained_.notify_all();
    if (next != nullptr) {
      this->StartWrite(next);
    } else if (finish) {
      this->Finish(*finish);
    }
  }

  void OnCancel() override {
    const bool past_deadline = ctx_->deadline() != std::chrono::system_clock::time_point::max() &&
                               std::chrono::system_clock::now() >= ctx_->deadline();
    if (!past_deadline || !token_.cancelled()) token_.Cancel();
    {
      std::lock_guard lock(mu_);
      broken_ = true;
    }
    drained_.notify_all();
  }

  void OnDone() override { delete this; }

 protected:
  // Takes the spec message: stores the parameters (checked) and returns the upload spec.
  virtual Result<v1::UploadSpec> TakeSpec(const Request& spec) = 0;
  // Runs the RPC's core function on the parsed input, posting responses; on a worker thread.
  virtual Status Run(const SceneInput& input, const JobContext& ctx) = 0;
  // Extra fields for the log line ("stations=7").
  virtual std::string LogDetails() const { return {}; }

  // Queues a response (worker thread). Bulk responses wait while the outbox is over
  // kMaxOutboxBytes; false when the call is cancelled or broken (stop producing).
  bool Post(Response&& response, bool bulk = false) {
    const Response* start = nullptr;
    {
      std::unique_lock lock(mu_);
      while (bulk && !broken_ && outbox_bytes_ >= kMaxOutboxBytes && !token_.cancelled()) {
        drained_.wait_for(lock, std::chrono::milliseconds(100));
      }
      if (broken_ || token_.cancelled()) return false;
      outbox_bytes_ += response.ByteSizeLong();
      outbox_.push_back(std::move(response));
      if (!writing_) {
        writing_ = true;
        start = &outbox_.front();
      }
    }
    if (start != nullptr) this->StartWrite(start);
    return true;
  }

  // Queues a progress event, replacing one still waiting in the outbox (worker threads; cheap).
  void PostProgress(const ProgressEvent& e) {
    Response r;
    *r.mutable_progress() = wire::ToProto(e);
    {
      std::lock_guard lock(mu_);
      if (outbox_.size() >= 2 && outbox_.back().has_progress()) {
        outbox_bytes_ -= outbox_.back().ByteSizeLong();
        outbox_bytes_ += r.ByteSizeLong();
        outbox_.back() = std::move(r);
        return;
      }
    }
    Post(std::move(r));
  }

  // Notes a stage's duration for the log line.
  void NoteTiming(std::string_view stage, double seconds) {
    std::lock_guard lock(mu_);
    timings_ += " " + std::string(stage) + "=" + fmt::format("{:.3f}s", seconds);
  }

  const ServerOptions& options() const { return state_->options; }
  const Backend& backend() const { return state_->backend; }
  const std::string& job_id() const { return job_id_; }

 private:
  Status OnMessage() {
    if (request_.has_spec()) {
      if (have_spec_) return InvalidArgumentError("a second spec arrived; send exactly one spec, first");
      return AcceptSpec();
    }
    if (request_.has_chunk()) {
      if (!have_spec_) {
        return InvalidArgumentError("a data chunk arrived before the spec; the first message must be the spec");
      }
      const std::string& data = request_.chunk().data();
      if (data.size() > upload_.total_size_bytes() - data_.size()) {
        return InvalidArgumentError("the upload carries more than the " + std::to_string(upload_.total_size_bytes()) +
                                    " bytes its spec declares; fix total_size_bytes");
      }
      data_.append(data);
      crc_.Update(data);
      return Status::Ok();
    }
    return InvalidArgumentError("an empty request message arrived; send a spec, then data chunks");
  }

  Status AcceptSpec() {
    have_spec_ = true;
    VC_ASSIGN_OR_RETURN(upload_, TakeSpec(request_));
    if (upload_.format() != v1::INPUT_FORMAT_UNSPECIFIED) {
      VC_RETURN_IF_ERROR(wire::FromProto(upload_.format()).status());
    }
    if (upload_.total_size_bytes() == 0) {
      return InvalidArgumentError("the spec declares an empty upload (total_size_bytes = 0); send the file's size");
    }
    const uint64_t limit = state_->options.max_upload_bytes;
    if (upload_.total_size_bytes() > limit) {
      return ResourceExhaustedError("the upload of " + HumanBytes(upload_.total_size_bytes()) +
                                    " exceeds this server's limit of " + HumanBytes(limit) +
                                    " (--max-upload-bytes); send a smaller or downsampled scene");
    }
    ticket_ = state_->pool.TryAdmit();
    if (!ticket_) {
      ctx_->AddTrailingMetadata("retry-after-ms", "2000");
      return ResourceExhaustedError(
          "the server is busy: all " + std::to_string(state_->pool.workers()) + " workers are running and the " +
          std::to_string(state_->pool.queue_capacity()) + "-job queue is full; retry in a few seconds");
    }
    data_.reserve(upload_.total_size_bytes());
    return Status::Ok();
  }

  void OnUploadEnd() {
    if (ctx_->IsCancelled()) {
      Reject(grpc::Status(grpc::StatusCode::CANCELLED, "the client cancelled the call during the upload"));
      return;
    }
    Status s = VerifyUpload();
    if (!s.ok()) {
      Reject(wire::ToGrpcStatus(s));
      return;
    }
    submitted_at_ = Clock::now();
    upload_seconds_ = std::chrono::duration<double>(submitted_at_ - start_).count();
    job_id_ = NewJobId(*state_);
    state_->pool.Submit(
        std::move(*ticket_),
        [&](uint32_t position) {
          Response r;
          r.mutable_accepted()->set_job_id(job_id_);
          r.mutable_accepted()->set_queue_position(position);
          Post(std::move(r));
        },
        [this] { Work(); });
    ticket_.reset();
  }

  Status VerifyUpload() const {
    if (!have_spec_) {
      return InvalidArgumentError("the stream ended before any spec; send a spec message first, then the data");
    }
    if (data_.size() != upload_.total_size_bytes()) {
      return InvalidArgumentError("the upload ended after " + std::to_string(data_.size()) + " of the " +
                                  std::to_string(upload_.total_size_bytes()) +
                                  " bytes its spec declares; send all the data or fix total_size_bytes");
    }
    if (crc_.value() != upload_.crc32c()) {
      return DataLossError(fmt::format(
          "the upload's CRC32C is {:08x} but its spec declares {:08x}; the data was corrupted or the spec is "
          "wrong: retry the upload",
          crc_.value(), upload_.crc32c()));
    }
    return Status::Ok();
  }

  // On a worker thread.
  void Work() {
    const double wait_s = std::chrono::duration<double>(Clock::now() - submitted_at_).count();
    Status s;
    try {
      s = RunJob();
    } catch (const std::exception& e) {
      spdlog::error("job {}: unexpected exception: {}", job_id_, e.what());
      s = InternalError("the server failed unexpectedly (job " + job_id_ + "); retry or report it");
    }
    const double total = std::chrono::duration<double>(Clock::now() - start_).count();
    {
      std::lock_guard lock(mu_);
      const auto level = s.ok() || s.code() == StatusCode::kInvalidArgument ? spdlog::level::info
                         : s.code() == StatusCode::kInternal                  ? spdlog::level::err
                                                                              : spdlog::level::warn;
      spdlog::log(level, "job {} {} peer={} upload={} upload={:.3f}s queued={:.3f}s{} elapsed={:.3f}s{} status={}",
                  job_id_, method_, ctx_->peer(), HumanBytes(upload_.total_size_bytes()), upload_seconds_, wait_s,
                  timings_, total, LogDetails(), s.ok() ? std::string("OK") : s.ToString());
    }
    data_.clear();
    data_.shrink_to_fit();
    Complete(wire::ToGrpcStatus(s));  // last touch of this reactor by the worker
  }

  Status RunJob() {
    VC_RETURN_IF_ERROR(token_.Check("the job (while queued)"));
    JobContext ctx;
    ctx.cancel = &token_;
    ctx.progress = [this](const ProgressEvent& e) { PostProgress(e); };
    ReadOptions read_options;
    read_options.max_decompressed_bytes = state_->options.max_memory_budget_bytes;
    const auto t0 = Clock::now();
    ctx.Report(Stage::kRead, 0.0, "parsing " + HumanBytes(data_.size()));
    const std::string source = upload_.source_name().empty() ? "upload" : upload_.source_name();
    VC_ASSIGN_OR_RETURN(SceneInput input, state_->backend.read_scene(data_, source, read_options));
    NoteTiming(StageName(Stage::kRead), std::chrono::duration<double>(Clock::now() - t0).count());
    if (upload_.format() != v1::INPUT_FORMAT_UNSPECIFIED && wire::ToProto(input.format) != upload_.format()) {
      return InvalidArgumentError(source + " is " + std::string(InputFormatName(input.format)) +
                                  " by its content, but the spec says " + v1::InputFormat_Name(upload_.format()) +
                                  "; fix the spec's format or leave it unspecified");
    }
    ctx.Report(Stage::kRead, 1.0, std::string(InputFormatName(input.format)));
    data_.clear();
    data_.shrink_to_fit();
    const auto t1 = Clock::now();
    Status s = Run(input, ctx);
    NoteTiming("run", std::chrono::duration<double>(Clock::now() - t1).count());
    return s;
  }

  // Ends a call that never reached a worker, with its log line (gRPC threads).
  void Reject(const grpc::Status& status) {
    spdlog::info("rpc {} peer={} upload={} rejected status={}: {}", method_, ctx_->peer(),
                 HumanBytes(have_spec_ ? upload_.total_size_bytes() : 0), int(status.error_code()),
                 status.error_message());
    Complete(status);
  }

  // Ends the call with `status` once the outbox is written (any thread). Once only.
  void Complete(const grpc::Status& status) {
    bool finish_now = false;
    {
      std::lock_guard lock(mu_);
      if (final_) return;
      final_ = status;
      if (!status.ok()) {  // an error replaces whatever has not been written yet
        while (outbox_.size() > (writing_ ? 1 : 0)) {
          outbox_bytes_ -= outbox_.back().ByteSizeLong();
          outbox_.pop_back();
        }
      }
      if (!writing_) {
        finished_ = true;
        finish_now = true;
      }
    }
    if (finish_now) this->Finish(status);
  }

  grpc::CallbackServerContext* const ctx_;
  ServiceState* const state_;
  const char* const method_;
  const Clock::time_point start_;
  CancelToken token_;

  // Upload (gRPC threads, one reaction at a time).
  Request request_;
  bool have_spec_ = false;
  v1::UploadSpec upload_;
  std::string data_;
  wire::Crc32c crc_;
  std::optional<WorkerPool::Ticket> ticket_;
  std::string job_id_;
  Clock::time_point submitted_at_;
  double upload_seconds_ = 0;

  // Outbox (any thread, under mu_).
  std::mutex mu_;
  std::condition_variable drained_;
  std::deque<Response> outbox_;
  size_t outbox_bytes_ = 0;
  bool writing_ = false;
  bool broken_ = false;
  bool finished_ = false;
  std::optional<grpc::Status> final_;
  std::string timings_;
};

}  // namespace vc::server::internal
