// Fuzzes the LAS 1.0-1.4 reader directly, past format detection.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_options.h"
#include "readers/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  (void)vc::readers::ReadLas(bytes, "fuzz", vc::fuzz::Limits());
  return 0;
}
