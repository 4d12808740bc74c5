// CRC32C (Castagnoli): the upload checksum of the vc.v1 protocol (docs/PROTOCOL.md) and the page
// checksum of E57 files (ASTM E2807). In base so that both the scene readers and the wire layer use
// one copy. Hand-written (about 30 lines) because no Debian 12 library offers CRC-32C on its own.
// Polynomial 0x1EDC6F41 reflected (0x82F63B78), initial value and final xor 0xFFFFFFFF, so
// Crc32c("123456789") == 0xE3069283. Table-driven, slice-by-8; thread-safe (no mutable state).
#pragma once

#include <cstdint>
#include <string_view>

namespace vc {

// Incremental CRC32C: Update() with consecutive pieces, then value().
class Crc32c {
 public:
  void Update(std::string_view bytes);
  uint32_t value() const { return ~state_; }

 private:
  uint32_t state_ = 0xFFFFFFFFu;
};

// CRC32C of `bytes` in one call.
uint32_t ComputeCrc32c(std::string_view bytes);

}  // namespace vc
