// Fuzzes bzip2 decompression with its streaming size limit (readers/decompress.cc).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_options.h"
#include "readers/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  (void)vc::readers::Decompress(bytes, vc::Compression::kBzip2, "fuzz", vc::fuzz::Limits().max_decompressed_bytes);
  return 0;
}
