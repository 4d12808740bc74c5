// UploadAssembler without gRPC: every refusal of a spec or a stream, named after the failure, and
// the job's place in the pool.
#include "vc/server/upload_assembler.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "vc/base/crc32c.h"

namespace vc::server {
namespace {

using ::testing::HasSubstr;

v1::UploadSpec SpecFor(const std::string& bytes) {
  v1::UploadSpec spec;
  spec.set_total_size_bytes(bytes.size());
  spec.set_crc32c(ComputeCrc32c(bytes));
  spec.set_source_name("x.ply");
  return spec;
}

constexpr uint64_t kLimit = 1 << 20;

// An assembler with a one-worker pool and no queue; Begin sends the spec for `bytes`.
class UploadAssemblerTest : public ::testing::Test {
 protected:
  Status Begin(const std::string& bytes) {
    VC_RETURN_IF_ERROR(assembler_.StartSpec());
    return assembler_.AcceptSpec(SpecFor(bytes));
  }
  WorkerPool pool_{1, 0};
  UploadAssembler assembler_{kLimit, &pool_};
};

TEST_F(UploadAssemblerTest, ChunksAddUpToTheVerifiedUploadAndItsTicket) {
  const std::string bytes = "some scene bytes";
  ASSERT_TRUE(Begin(bytes).ok());
  EXPECT_EQ(pool_.admitted(), 1);
  for (size_t off = 0; off < bytes.size(); off += 3) ASSERT_TRUE(assembler_.AddChunk(bytes.substr(off, 3)).ok());
  EXPECT_TRUE(assembler_.Finish().ok());
  EXPECT_EQ(assembler_.TakeData(), bytes);
  EXPECT_TRUE(assembler_.TakeTicket().has_value());
}

TEST_F(UploadAssemblerTest, SecondSpecIsInvalidArgument) {
  ASSERT_TRUE(assembler_.StartSpec().ok());
  const Status s = assembler_.StartSpec();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("second spec"));
}

TEST_F(UploadAssemblerTest, ChunkBeforeTheSpecIsInvalidArgument) {
  const Status s = assembler_.AddChunk("abc");
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("before the spec"));
}

TEST_F(UploadAssemblerTest, EmptyUploadIsInvalidArgument) {
  ASSERT_TRUE(assembler_.StartSpec().ok());
  EXPECT_EQ(assembler_.AcceptSpec(SpecFor("")).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(pool_.admitted(), 0) << "refused before admission";
}

TEST_F(UploadAssemblerTest, UnknownFormatIsInvalidArgument) {
  v1::UploadSpec spec = SpecFor("abc");
  spec.set_format(v1::InputFormat(99));
  ASSERT_TRUE(assembler_.StartSpec().ok());
  EXPECT_EQ(assembler_.AcceptSpec(spec).code(), StatusCode::kInvalidArgument);
}

TEST_F(UploadAssemblerTest, UnknownUnitsAreInvalidArgumentNamingTheField) {
  v1::UploadSpec spec = SpecFor("abc");
  spec.set_units("furlong");
  ASSERT_TRUE(assembler_.StartSpec().ok());
  const Status s = assembler_.AcceptSpec(spec);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("the spec's units"));
  EXPECT_THAT(s.message(), HasSubstr("furlong"));
  EXPECT_THAT(s.message(), HasSubstr("us-ft"));
  EXPECT_EQ(pool_.admitted(), 0) << "refused before admission";
}

TEST_F(UploadAssemblerTest, MillimetresAreAccepted) {
  v1::UploadSpec spec = SpecFor("abc");
  spec.set_units("mm");
  ASSERT_TRUE(assembler_.StartSpec().ok());
  EXPECT_TRUE(assembler_.AcceptSpec(spec).ok());
}

TEST(SpecMetresPerUnit, EmptyIsMetresAndTheNamesAreMetresPerUnits) {
  EXPECT_EQ(*SpecMetresPerUnit("", "units"), 1.0);
  EXPECT_EQ(*SpecMetresPerUnit("mm", "units"), 0.001);
  EXPECT_EQ(*SpecMetresPerUnit("us-ft", "units"), 1200.0 / 3937.0);
  const Result<double> bad = SpecMetresPerUnit("MM", "ComputeShard's units");
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("ComputeShard's units"));
}

TEST(UploadAssembler, UploadOverTheLimitIsResourceExhaustedNamingTheFlag) {
  WorkerPool pool(1, 0);
  UploadAssembler a(/*max_upload_bytes=*/8, &pool);
  ASSERT_TRUE(a.StartSpec().ok());
  const Status s = a.AcceptSpec(SpecFor("123456789"));
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(s.message(), HasSubstr("--max-upload-bytes"));
  EXPECT_FALSE(a.busy());
  EXPECT_EQ(a.declared_bytes(), 9u) << "the refused size is still known for the log line";
  EXPECT_EQ(pool.admitted(), 0);
}

TEST(UploadAssembler, FullPoolIsBusyAndSaysRetry) {
  WorkerPool pool(1, 0);
  auto held = pool.TryAdmit();
  ASSERT_TRUE(held);
  UploadAssembler a(kLimit, &pool);
  ASSERT_TRUE(a.StartSpec().ok());
  const Status s = a.AcceptSpec(SpecFor("abc"));
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(s.message(), HasSubstr("retry"));
  EXPECT_TRUE(a.busy());
}

TEST(UploadAssembler, TicketIsReleasedWhenTheCallEndsBeforeSubmission) {
  WorkerPool pool(1, 0);
  {
    UploadAssembler a(kLimit, &pool);
    ASSERT_TRUE(a.StartSpec().ok());
    ASSERT_TRUE(a.AcceptSpec(SpecFor("abc")).ok());
    EXPECT_EQ(pool.admitted(), 1);
  }
  EXPECT_EQ(pool.admitted(), 0);
}

TEST_F(UploadAssemblerTest, BytesBeyondTheDeclaredSizeAreInvalidArgument) {
  ASSERT_TRUE(Begin("123456789").ok());
  ASSERT_TRUE(assembler_.AddChunk("12345").ok());
  const Status s = assembler_.AddChunk("67890");
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("more than the 9 bytes"));
}

TEST_F(UploadAssemblerTest, ShortUploadIsInvalidArgumentWithTheCounts) {
  ASSERT_TRUE(Begin("12345678901").ok());
  ASSERT_TRUE(assembler_.AddChunk("1234567890").ok());
  const Status s = assembler_.Finish();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("10 of the 11 bytes"));
}

TEST_F(UploadAssemblerTest, CorruptedBytesAreDataLoss) {
  ASSERT_TRUE(Begin("abcdef").ok());
  ASSERT_TRUE(assembler_.AddChunk("abcdeF").ok());
  const Status s = assembler_.Finish();
  EXPECT_EQ(s.code(), StatusCode::kDataLoss);
  EXPECT_THAT(s.message(), HasSubstr("CRC32C"));
}

TEST_F(UploadAssemblerTest, StreamWithoutSpecIsInvalidArgument) {
  const Status s = assembler_.Finish();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("before any spec"));
}

// Found by upload_assembler_fuzzer: after a refused spec (here the pool was full), chunks were
// still taken and Finish was OK, for an upload that holds no place (the reactor would submit
// *TakeTicket() of an empty optional).
TEST(UploadAssembler, NoChunkOrFinishAfterARefusedSpec) {
  WorkerPool pool(1, 0);
  auto held = pool.TryAdmit();
  ASSERT_TRUE(held);
  UploadAssembler a(kLimit, &pool);
  ASSERT_TRUE(a.StartSpec().ok());
  ASSERT_EQ(a.AcceptSpec(SpecFor("abc")).code(), StatusCode::kResourceExhausted);
  const Status chunk = a.AddChunk("abc");
  EXPECT_EQ(chunk.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(chunk.message(), HasSubstr("refused spec"));
  const Status finish = a.Finish();
  EXPECT_EQ(finish.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(finish.message(), HasSubstr("refused"));
  EXPECT_TRUE(a.data().empty());
  EXPECT_FALSE(a.TakeTicket().has_value());
  EXPECT_EQ(pool.admitted(), 1) << "only the held place";
}

// The same when the RPC refused its own parameters after StartSpec and never called AcceptSpec:
// the empty upload of the default spec (0 bytes, CRC32C 0) was OK.
TEST_F(UploadAssemblerTest, NoFinishWhenTheSpecWasNeverAccepted) {
  ASSERT_TRUE(assembler_.StartSpec().ok());
  EXPECT_EQ(assembler_.AddChunk("").code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(assembler_.Finish().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(pool_.admitted(), 0);
}

TEST_F(UploadAssemblerTest, ASecondAcceptedSpecIsInvalidArgumentAndKeepsTheFirst) {
  ASSERT_TRUE(Begin("abc").ok());
  const Status s = assembler_.AcceptSpec(SpecFor("abcdef"));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(assembler_.declared_bytes(), 3u);
  EXPECT_EQ(pool_.admitted(), 1);
}

// Found by upload_assembler_fuzzer: TakeTicket moved the ticket out but left the optional engaged,
// so a second TakeTicket returned a ticket that holds no place (and TakeData a moved-from string).
TEST_F(UploadAssemblerTest, TakingTheTicketAndDataLeavesNeither) {
  const std::string bytes = "abc";
  ASSERT_TRUE(Begin(bytes).ok());
  ASSERT_TRUE(assembler_.AddChunk(bytes).ok());
  ASSERT_TRUE(assembler_.Finish().ok());
  EXPECT_EQ(assembler_.TakeData(), bytes);
  EXPECT_TRUE(assembler_.data().empty());
  auto ticket = assembler_.TakeTicket();
  EXPECT_TRUE(ticket.has_value());
  EXPECT_FALSE(assembler_.TakeTicket().has_value());
  EXPECT_EQ(pool_.admitted(), 1);
  ticket.reset();
  EXPECT_EQ(pool_.admitted(), 0);
}

TEST(HumanBytes, PicksTheUnit) {
  EXPECT_EQ(HumanBytes(512), "512 B");
  EXPECT_EQ(HumanBytes(1536), "1.5 KiB");
  EXPECT_EQ(HumanBytes(uint64_t{3} << 20), "3.0 MiB");
  EXPECT_EQ(HumanBytes(uint64_t{5} << 30), "5.00 GiB");
}

}  // namespace
}  // namespace vc::server
