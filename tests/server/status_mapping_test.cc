#include "vc/server/status_mapping.h"

#include <gtest/gtest.h>

namespace vc::server {
namespace {

TEST(StatusMapping, EveryCodeKeepsItsCanonicalNumberAndName) {
  const StatusCode codes[] = {StatusCode::kOk, StatusCode::kCancelled, StatusCode::kInvalidArgument,
                              StatusCode::kDeadlineExceeded, StatusCode::kNotFound, StatusCode::kResourceExhausted,
                              StatusCode::kFailedPrecondition, StatusCode::kOutOfRange, StatusCode::kUnimplemented,
                              StatusCode::kInternal, StatusCode::kDataLoss};
  const int expected[] = {0, 1, 3, 4, 5, 8, 9, 11, 12, 13, 15};  // google.rpc.Code
  for (size_t i = 0; i < std::size(codes); ++i) {
    EXPECT_EQ(int(ToGrpcCode(codes[i])), expected[i]) << StatusCodeName(codes[i]);
  }
}

TEST(StatusMapping, KeepsTheMessage) {
  const grpc::Status g = ToGrpcStatus(InvalidArgumentError("resolution_m must be > 0"));
  EXPECT_EQ(g.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(g.error_message(), "resolution_m must be > 0");
  EXPECT_TRUE(ToGrpcStatus(Status::Ok()).ok());
}

}  // namespace
}  // namespace vc::server
