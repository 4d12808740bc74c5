// Authenticate: a call's bearer token against the server's tokens.
#include "vc/server/authenticate.h"

#include <gtest/gtest.h>

namespace vc::server {
namespace {

const std::vector<std::string> kTokens = {"alpha", "beta"};

TEST(Authenticate, AnyCallWhenTheServerHasNoTokens) {
  const Result<Caller> without = Authenticate(std::nullopt, {});
  ASSERT_TRUE(without.ok());
  EXPECT_EQ(without->owner, "");
  const Result<Caller> with = Authenticate("Bearer whatever", {});
  ASSERT_TRUE(with.ok());
  EXPECT_EQ(with->owner, "") << "without tokens nobody owns a job";
}

TEST(Authenticate, TheMatchingTokenOwnsTheCall) {
  const Result<Caller> a = Authenticate("Bearer alpha", kTokens);
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_EQ(a->owner, "alpha");
  const Result<Caller> b = Authenticate("Bearer beta", kTokens);
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  EXPECT_EQ(b->owner, "beta");
}

TEST(Authenticate, AMissingTokenSaysHowToPassOne) {
  EXPECT_EQ(Authenticate(std::nullopt, kTokens).status(),
            UnauthenticatedError("this server requires a bearer token: pass --token (or set VC_TOKEN)"));
}

TEST(Authenticate, AWrongTokenIsRefused) {
  const Status wrong = UnauthenticatedError("the bearer token is wrong: check --token (or VC_TOKEN)");
  EXPECT_EQ(Authenticate("Bearer gamma", kTokens).status(), wrong);
  EXPECT_EQ(Authenticate("Bearer alph", kTokens).status(), wrong) << "a prefix of a token";
  EXPECT_EQ(Authenticate("Bearer alphabet", kTokens).status(), wrong) << "a token as a prefix";
  EXPECT_EQ(Authenticate("alpha", kTokens).status(), wrong) << "without the scheme";
  EXPECT_EQ(Authenticate("bearer alpha", kTokens).status(), wrong) << "the scheme is case-sensitive";
  EXPECT_EQ(Authenticate("", kTokens).status(), wrong);
}

}  // namespace
}  // namespace vc::server
