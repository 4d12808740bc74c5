// JobRunner with a fake backend: the scene reaches the RPC's function, the stated format is
// checked against the content, cancellation while queued skips the work, and a bug is INTERNAL.
#include "vc/server/job_runner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace vc::server {
namespace {

using ::testing::HasSubstr;

struct Fixture {
  int reads = 0;
  std::string read_source;
  ReadOptions read_options;
  Backend backend;
  Fixture() {
    backend.read_scene = [this](std::string_view bytes, std::string_view source,
                                const ReadOptions& o) -> Result<SceneInput> {
      ++reads;
      read_source = std::string(source);
      read_options = o;
      if (bytes == "bad") return InvalidArgumentError("line 1: not a number");
      SceneInput in;
      in.format = InputFormat::kPly;
      in.points.resize(bytes.size());
      return in;
    };
  }
  Job MakeJob(std::string data, v1::InputFormat format = v1::INPUT_FORMAT_UNSPECIFIED) const {
    Job job;
    job.id = "j-000000000001";
    job.method = "Plan";
    job.peer = "ipv4:127.0.0.1:1";
    job.upload.set_source_name("room.ply");
    job.upload.set_format(format);
    job.upload.set_total_size_bytes(data.size());
    job.data = std::make_shared<const std::string>(std::move(data));
    job.started = job.submitted = Job::Clock::now();
    return job;
  }
};

TEST(JobRunner, TheParsedSceneReachesTheFunctionWithProgressAndTimings) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  std::vector<ProgressEvent> events;
  size_t points = 0;
  const Status s = runner.Run(
      f.MakeJob("12345", v1::INPUT_FORMAT_PLY), token, [&](const ProgressEvent& e) { events.push_back(e); },
      [&](const SceneInput& in, const JobContext& ctx, JobLog& log) {
        points = in.points.size();
        EXPECT_EQ(ctx.cancel, &token);
        log.NoteTiming("selection", 0.5);
        log.set_details(" stations=3");
        EXPECT_THAT(log.timings(), HasSubstr("read="));
        EXPECT_THAT(log.timings(), HasSubstr("selection=0.500s"));
        return Status::Ok();
      });
  EXPECT_TRUE(s.ok()) << s.ToString();
  EXPECT_EQ(points, 5u);
  EXPECT_EQ(f.read_source, "room.ply");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].stage, Stage::kRead);
  EXPECT_DOUBLE_EQ(events[0].fraction, 0.0);
  EXPECT_DOUBLE_EQ(events[1].fraction, 1.0);
}

TEST(JobRunner, UnnamedUploadIsCalledUpload) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  Job job = f.MakeJob("1");
  job.upload.clear_source_name();
  ASSERT_TRUE(
      runner.Run(std::move(job), token, {}, [](const SceneInput&, const JobContext&, JobLog&) { return Status::Ok(); })
          .ok());
  EXPECT_EQ(f.read_source, "upload");
}

TEST(JobRunner, CancelledWhileQueuedSkipsTheWork) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  token.Cancel();
  bool ran = false;
  const Status s = runner.Run(f.MakeJob("1"), token, {}, [&](const SceneInput&, const JobContext&, JobLog&) {
    ran = true;
    return Status::Ok();
  });
  EXPECT_EQ(s.code(), StatusCode::kCancelled);
  EXPECT_EQ(f.reads, 0);
  EXPECT_FALSE(ran);
}

TEST(JobRunner, StatedFormatDisagreeingWithTheContentIsInvalidArgument) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  bool ran = false;
  const Status s =
      runner.Run(f.MakeJob("1", v1::INPUT_FORMAT_PCD), token, {}, [&](const SceneInput&, const JobContext&, JobLog&) {
        ran = true;
        return Status::Ok();
      });
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("by its content"));
  EXPECT_THAT(s.message(), HasSubstr("INPUT_FORMAT_PCD"));
  EXPECT_FALSE(ran);
}

TEST(JobRunner, ReaderErrorIsReturnedAsItIs) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  const Status s = runner.Run(f.MakeJob("bad"), token, {},
                              [](const SceneInput&, const JobContext&, JobLog&) { return Status::Ok(); });
  EXPECT_EQ(s, InvalidArgumentError("line 1: not a number"));
}

TEST(JobRunner, FunctionErrorIsReturnedAsItIs) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  const Status s = runner.Run(f.MakeJob("1"), token, {}, [](const SceneInput&, const JobContext&, JobLog&) {
    return FailedPreconditionError("no candidate position");
  });
  EXPECT_EQ(s, FailedPreconditionError("no candidate position"));
}

TEST(JobRunner, TheUploadIsReadWithinTheLimitsOfTheUploadAndTheJobsBudget) {
  Fixture f;
  JobRunner runner(&f.backend, uint64_t{1} << 20);
  CancelToken token;
  Job job = f.MakeJob("1");
  job.memory_budget_bytes = uint64_t{64} << 20;
  ASSERT_TRUE(
      runner.Run(std::move(job), token, {}, [](const SceneInput&, const JobContext&, JobLog&) { return Status::Ok(); })
          .ok());
  const ReadOptions want = ReadLimits(uint64_t{1} << 20, uint64_t{64} << 20);
  EXPECT_EQ(f.read_options.max_decompressed_bytes, want.max_decompressed_bytes);
  EXPECT_EQ(f.read_options.max_points, want.max_points);
  EXPECT_EQ(f.read_options.max_result_bytes, want.max_result_bytes);
  EXPECT_EQ(want.max_decompressed_bytes, uint64_t{16} << 20) << "16 x the upload limit, under half the budget";
}

TEST(JobRunner, TheUploadIsReadInTheSpecsUnits) {
  Fixture f;
  JobRunner runner(&f.backend, uint64_t{1} << 20);
  CancelToken token;
  const auto nothing = [](const SceneInput&, const JobContext&, JobLog&) { return Status::Ok(); };
  ASSERT_TRUE(runner.Run(f.MakeJob("1"), token, {}, nothing).ok());
  EXPECT_EQ(f.read_options.metres_per_unit, 1.0);
  Job job = f.MakeJob("1");
  job.upload.set_units("mm");
  ASSERT_TRUE(runner.Run(std::move(job), token, {}, nothing).ok());
  EXPECT_EQ(f.read_options.metres_per_unit, 0.001);
  job = f.MakeJob("1");
  job.upload.set_units("yards");
  const Status s = runner.Run(std::move(job), token, {}, nothing);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("units"));
}

TEST(JobRunner, OutOfMemoryIsResourceExhaustedNamingTheJob) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  const Status s = runner.Run(f.MakeJob("1"), token, {},
                              [](const SceneInput&, const JobContext&, JobLog&) -> Status { throw std::bad_alloc(); });
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(s.message(), HasSubstr("j-000000000001"));
  EXPECT_THAT(s.message(), HasSubstr("--memory-budget-bytes"));
}

TEST(JobRunner, ExceptionIsInternalNamingTheJob) {
  Fixture f;
  JobRunner runner(&f.backend, 1 << 20);
  CancelToken token;
  const Status s = runner.Run(f.MakeJob("1"), token, {}, [](const SceneInput&, const JobContext&, JobLog&) -> Status {
    throw std::logic_error("a bug");
  });
  EXPECT_EQ(s.code(), StatusCode::kInternal);
  EXPECT_THAT(s.message(), HasSubstr("j-000000000001"));
  EXPECT_THAT(s.message(), ::testing::Not(HasSubstr("a bug"))) << "no internal details to the client";
}

}  // namespace
}  // namespace vc::server
