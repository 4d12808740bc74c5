#include "vc/wire/status_mapping.h"

#include <gtest/gtest.h>

namespace vc::wire {
namespace {

TEST(StatusMapping, EveryCodeKeepsItsCanonicalNumberAndName) {
  const StatusCode codes[] = {StatusCode::kOk,
                              StatusCode::kCancelled,
                              StatusCode::kInvalidArgument,
                              StatusCode::kDeadlineExceeded,
                              StatusCode::kNotFound,
                              StatusCode::kResourceExhausted,
                              StatusCode::kFailedPrecondition,
                              StatusCode::kOutOfRange,
                              StatusCode::kUnimplemented,
                              StatusCode::kInternal,
                              StatusCode::kDataLoss,
                              StatusCode::kUnknown,
                              StatusCode::kAlreadyExists,
                              StatusCode::kPermissionDenied,
                              StatusCode::kAborted,
                              StatusCode::kUnavailable,
                              StatusCode::kUnauthenticated};
  const int expected[] = {0, 1, 3, 4, 5, 8, 9, 11, 12, 13, 15, 2, 6, 7, 10, 14, 16};  // google.rpc.Code
  for (size_t i = 0; i < std::size(codes); ++i) {
    EXPECT_EQ(int(ToGrpcCode(codes[i])), expected[i]) << StatusCodeName(codes[i]);
    EXPECT_EQ(FromGrpcCode(expected[i]), codes[i]) << StatusCodeName(codes[i]);
  }
}

TEST(StatusMapping, KeepsTheMessage) {
  const grpc::Status g = ToGrpcStatus(InvalidArgumentError("resolution_m must be > 0"));
  EXPECT_EQ(g.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(g.error_message(), "resolution_m must be > 0");
  EXPECT_TRUE(ToGrpcStatus(Status::Ok()).ok());
}

TEST(StatusMapping, GrpcStatusComesBackWithItsCodeAndMessage) {
  const Status s = FromGrpcStatus(grpc::Status(grpc::StatusCode::UNAVAILABLE, "failed to connect"));
  EXPECT_EQ(s.code(), StatusCode::kUnavailable);
  EXPECT_EQ(s.message(), "failed to connect");
  EXPECT_TRUE(FromGrpcStatus(grpc::Status::OK).ok());
}

TEST(StatusMapping, NumberOutsideGoogleRpcCodeIsUnknown) {
  EXPECT_EQ(FromGrpcCode(99), StatusCode::kUnknown);
  EXPECT_EQ(FromGrpcCode(-1), StatusCode::kUnknown);
}

}  // namespace
}  // namespace vc::wire
