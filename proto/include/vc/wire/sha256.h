// SHA-256 of a scene's bytes, the name the scene cache knows it by (docs/PROTOCOL.md, "The scene
// cache"). OpenSSL's libcrypto (already linked for gRPC's TLS) does the hashing.
#pragma once

#include <string>
#include <string_view>

namespace vc::wire {

// 64 lower-case hex digits.
std::string Sha256Hex(std::string_view bytes);
// True for 64 lower-case hex digits.
bool IsSha256Hex(std::string_view text);

}  // namespace vc::wire
