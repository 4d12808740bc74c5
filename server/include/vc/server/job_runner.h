// JobRunner: what a worker does with one verified upload, whatever the RPC.
//
// Parses the scene through Backend::read_scene (the stated format must match the content), hands
// it to the RPC's function (plan or evaluate, posting its responses itself), and writes the one
// log line per job: method, peer, upload size and time, queueing, per-stage timings, the RPC's
// details and the status. An exception escaping the core is a bug: it is logged and becomes
// INTERNAL naming the job id, so a worker never dies.
//
// Thread-safe: Run may be called on several workers at once (the runner is immutable).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"
#include "vc/server/backend.h"
#include "vc/server/scene_cache.h"
#include "vc/v1/planner.pb.h"

namespace vc::server {

// One job as the RPC adapter hands it to a worker.
struct Job {
  using Clock = std::chrono::steady_clock;
  std::string id;          // "j-" + 12 hex digits
  std::string method;      // "Plan", "Evaluate"
  std::string peer;        // the client's address, for the log
  v1::UploadSpec upload;   // source name, stated format, size
  SceneCache::Bytes data;  // the verified upload (shared with the scene cache; dropped once parsed)
  // "hit": data came from the scene cache; "miss": uploaded with its SHA-256 (checked by Run, then
  // kept in the cache); empty: uploaded without one.
  std::string cache;
  // The job's memory budget (already capped by --max-memory-budget-bytes); bounds the reading.
  uint64_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
  Clock::time_point started;    // the call began
  Clock::time_point submitted;  // the upload was verified and queued
};

// The RPC function's additions to the log line (on the worker thread).
class JobLog {
 public:
  // Adds " stage=1.234s".
  void NoteTiming(std::string_view stage, double seconds);
  // Extra fields, e.g. " stations=7".
  void set_details(std::string details) { details_ = std::move(details); }
  const std::string& timings() const { return timings_; }
  const std::string& details() const { return details_; }

 private:
  std::string timings_;
  std::string details_;
};

// Runs the RPC's core function on the parsed scene; posts its responses itself.
using JobFn = std::function<Status(const SceneInput& input, const JobContext& ctx, JobLog& log)>;

class JobRunner {
 public:
  // `backend` must outlive the runner. Each job is read with ReadLimits(max_upload_bytes, the
  // job's memory_budget_bytes) (vc/scene/scene_input.h): a decompression bomb or a lying header is
  // refused before it is allocated.
  // With `cache`, a job uploaded with its SHA-256 is checked against it (INVALID_ARGUMENT when
  // they differ) and kept there.
  JobRunner(const Backend* backend, uint64_t max_upload_bytes, SceneCache* cache = nullptr)
      : backend_(backend), max_upload_bytes_(max_upload_bytes), cache_(cache) {}

  // On a worker thread: reads job.data, runs `fn`, logs the line; the job's status. CANCELLED or
  // DEADLINE_EXCEEDED when `cancel` fired while queued; the reader's and fn's errors as they are;
  // RESOURCE_EXHAUSTED when memory ran out (std::bad_alloc), INTERNAL for any other exception.
  Status Run(Job job, const CancelToken& cancel, ProgressFn progress, const JobFn& fn) const;

 private:
  Status Execute(Job& job, const JobContext& ctx, JobLog& log, const JobFn& fn) const;

  const Backend* const backend_;
  const uint64_t max_upload_bytes_;
  SceneCache* const cache_;
};

}  // namespace vc::server
