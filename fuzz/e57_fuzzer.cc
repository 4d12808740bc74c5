// Fuzzes the E57 reader directly, past format detection: once on the input as it is, and once with
// the header's file length and every page's CRC-32C rewritten to match, so that mutations reach the
// XML and the binary sections instead of stopping at the first checksum. Seeds: tests' E57 writer
// (write_e57_seeds, see fuzz/make_seeds.py).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_options.h"
#include "readers/readers.h"
#include "vc/base/crc32c.h"
#include "vc/scene/e57.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  (void)vc::readers::ReadE57(bytes, "fuzz", vc::fuzz::Limits());
  if (bytes.size() >= 48) {
    const uint64_t length = bytes.size();
    std::memcpy(bytes.data() + 16, &length, sizeof length);
  }
  for (size_t page = 0; (page + 1) * 1024 <= bytes.size(); ++page) {
    const uint32_t crc = vc::ComputeCrc32c(std::string_view(bytes).substr(page * 1024, 1020));
    for (int i = 0; i < 4; ++i) bytes[page * 1024 + 1020 + i] = static_cast<char>(crc >> (24 - 8 * i));
  }
  (void)vc::readers::ReadE57(bytes, "fuzz", vc::fuzz::Limits());
  (void)vc::ReadE57Scans(bytes, "fuzz");
  return 0;
}
