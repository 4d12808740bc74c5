// Fuzzes LZF decompression (PCD binary_compressed): the first 2 bytes give the expected size.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "readers/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const size_t expected = size_t{data[0]} | size_t{data[1]} << 8;
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 2, size - 2);
  (void)vc::readers::LzfDecompress(bytes, expected);
  return 0;
}
