#include "vc/server/authenticate.h"

namespace vc::server {

Result<Caller> Authenticate(std::optional<std::string_view> authorization, const std::vector<std::string>& tokens) {
  if (tokens.empty()) return Caller{};
  if (!authorization)
    return UnauthenticatedError("this server requires a bearer token: pass --token (or set VC_TOKEN)");
  const std::string_view got = *authorization;
  const std::string* matched = nullptr;
  for (const std::string& token : tokens) {
    const std::string expected = "Bearer " + token;
    unsigned diff = got.size() == expected.size() ? 0u : 1u;
    for (size_t i = 0; i < expected.size(); ++i) diff |= unsigned(expected[i] ^ (i < got.size() ? got[i] : 0));
    if (diff == 0) matched = &token;
  }
  if (matched == nullptr) return UnauthenticatedError("the bearer token is wrong: check --token (or VC_TOKEN)");
  return Caller{*matched};
}

}  // namespace vc::server
