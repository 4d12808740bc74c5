#include "vc/base/status.h"

#include <gtest/gtest.h>

#include "vc/base/progress.h"

namespace vc {
namespace {

Result<int> Half(int x) {
  if (x % 2 != 0) return InvalidArgumentError("odd: " + std::to_string(x));
  return x / 2;
}

Result<int> Quarter(int x) {
  VC_ASSIGN_OR_RETURN(int h, Half(x));
  VC_ASSIGN_OR_RETURN(int q, Half(h));
  return q;
}

TEST(StatusTest, OkAndErrorCarryCodeAndMessage) {
  EXPECT_TRUE(Status::Ok().ok());
  Status s = ResourceExhaustedError("too big");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(s.ToString(), "RESOURCE_EXHAUSTED: too big");
  EXPECT_EQ(s.WithContext("scan.ply").message(), "scan.ply: too big");
}

TEST(StatusTest, AssignOrReturnPropagatesFirstError) {
  EXPECT_EQ(*Quarter(8), 2);
  Result<int> r = Quarter(6);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "odd: 3");
}

TEST(CancelTokenTest, CancelAndDeadline) {
  CancelToken t;
  EXPECT_TRUE(t.Check("x").ok());
  t.Cancel();
  EXPECT_EQ(t.Check("planning").code(), StatusCode::kCancelled);
  CancelToken d;
  d.SetDeadline(std::chrono::steady_clock::now() - std::chrono::seconds(1));
  EXPECT_EQ(d.Check("planning").code(), StatusCode::kDeadlineExceeded);
}

}  // namespace
}  // namespace vc
