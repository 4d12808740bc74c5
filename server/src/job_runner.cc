#include "vc/server/job_runner.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <memory>
#include <new>

#include "vc/server/upload_assembler.h"
#include "vc/wire/convert.h"
#include "vc/wire/sha256.h"

namespace vc::server {
namespace {

double SecondsSince(Job::Clock::time_point t) { return std::chrono::duration<double>(Job::Clock::now() - t).count(); }

}  // namespace

void JobLog::NoteTiming(std::string_view stage, double seconds) {
  timings_ += fmt::format(" {}={:.3f}s", stage, seconds);
}

Status JobRunner::Run(Job job, const CancelToken& cancel, ProgressFn progress, const JobFn& fn) const {
  const double wait_s = SecondsSince(job.submitted);
  const double upload_s = std::chrono::duration<double>(job.submitted - job.started).count();
  JobContext ctx;
  ctx.cancel = &cancel;
  ctx.progress = std::move(progress);
  JobLog log;
  Status s;
  try {
    s = Execute(job, ctx, log, fn);
  } catch (const std::bad_alloc&) {
    s = ResourceExhaustedError("the job (" + job.id +
                               ") ran out of memory on this server; lower its memory_budget_bytes "
                               "(--memory-budget-bytes), raise resolution_m or grid_spacing_m, or retry later");
  } catch (const std::exception& e) {
    spdlog::error("job {}: unexpected exception: {}", job.id, e.what());
    s = InternalError("the server failed unexpectedly (job " + job.id + "); retry or report it");
  }
  const auto level = s.ok() || s.code() == StatusCode::kInvalidArgument ? spdlog::level::info
                     : s.code() == StatusCode::kInternal                ? spdlog::level::err
                                                                        : spdlog::level::warn;
  // upload= counts the bytes sent: none for a scene taken from the cache.
  spdlog::log(level, "job {} {} peer={} upload={} upload={:.3f}s{} queued={:.3f}s{} elapsed={:.3f}s{} status={}",
              job.id, job.method, job.peer, HumanBytes(job.cache == "hit" ? 0 : job.upload.total_size_bytes()),
              upload_s, job.cache.empty() ? std::string() : " cache=" + job.cache, wait_s, log.timings(),
              SecondsSince(job.started), log.details(), s.ok() ? std::string("OK") : s.ToString());
  return s;
}

Status JobRunner::Execute(Job& job, const JobContext& ctx, JobLog& log, const JobFn& fn) const {
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("the job (while queued)"));
  ReadOptions read_options = ReadLimits(max_upload_bytes_, job.memory_budget_bytes);
  VC_ASSIGN_OR_RETURN(read_options.metres_per_unit, SpecMetresPerUnit(job.upload.units(), "the spec's units"));
  const auto t0 = Job::Clock::now();
  if (job.data == nullptr) return InternalError("job " + job.id + " has no upload");
  const std::string& data = *job.data;
  if (!job.upload.scene_sha256().empty() && job.cache != "hit") {
    const std::string sha256 = wire::Sha256Hex(data);
    if (sha256 != job.upload.scene_sha256()) {
      return InvalidArgumentError("the upload's SHA-256 is " + sha256 + " but its spec says " +
                                  job.upload.scene_sha256() + "; send the hash of the bytes uploaded");
    }
    job.cache = "miss";
    if (cache_ != nullptr) cache_->Put(sha256, job.data);
  }
  ctx.Report(Stage::kRead, 0.0, "parsing " + HumanBytes(data.size()));
  const v1::UploadSpec& upload = job.upload;
  const std::string source = upload.source_name().empty() ? "upload" : upload.source_name();
  VC_ASSIGN_OR_RETURN(SceneInput input, backend_->read_scene(data, source, read_options));
  log.NoteTiming(StageName(Stage::kRead), SecondsSince(t0));
  if (upload.format() != v1::INPUT_FORMAT_UNSPECIFIED && wire::ToProto(input.format) != upload.format()) {
    return InvalidArgumentError(source + " is " + std::string(InputFormatName(input.format)) +
                                " by its content, but the spec says " + v1::InputFormat_Name(upload.format()) +
                                "; fix the spec's format or leave it unspecified");
  }
  ctx.Report(Stage::kRead, 1.0, std::string(InputFormatName(input.format)));
  job.data.reset();
  const auto t1 = Job::Clock::now();
  Status s = fn(input, ctx, log);
  log.NoteTiming("run", SecondsSince(t1));
  return s;
}

}  // namespace vc::server
