// Fuzzes the OctoMap binary (.bt) reader (octomap_adapter.h), which validates the stream before OctoMap sees it.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_options.h"
#include "vc/scene/octomap_adapter.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  (void)vc::ReadOctreeBinary(bytes, "fuzz", vc::fuzz::Limits().max_result_bytes);
  return 0;
}
