// Authenticate: a call's bearer token against the server's tokens (--token), for every vc.v1 call.
//
// Plain C++ (the gRPC adapter passes the call's "authorization" metadata), so it is tested without a
// call. Every token is compared in full, in time independent of the token's content.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"

namespace vc::server {

// Who a call is, as its token says.
struct Caller {
  // The token matched: it owns the call's detachable jobs ("" when the server takes any call).
  std::string owner;
};

// The caller of a call whose "authorization" metadata is `authorization` (nullopt: none sent),
// when it is "Bearer <token>" with one of `tokens`, or any call when `tokens` is empty.
// UNAUTHENTICATED saying what to pass otherwise.
[[nodiscard]] Result<Caller> Authenticate(std::optional<std::string_view> authorization,
                                          const std::vector<std::string>& tokens);

}  // namespace vc::server
