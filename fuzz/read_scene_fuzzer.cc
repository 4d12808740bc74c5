// Fuzzes vc::ReadScene, the content-sniffing entry every upload goes through (all formats, gzip,
// bzip2). Any crash, sanitizer report, leak or allocation above -malloc_limit_mb is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_options.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  (void)vc::ReadScene(bytes, "fuzz", vc::fuzz::Limits());
  return 0;
}
