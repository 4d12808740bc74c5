// Fuzzes vc::ParseStationsCsv, the parser of user-supplied candidate and viewpoint lists.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "vc/report/plan_report.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)vc::ParseStationsCsv(text, "fuzz");
  return 0;
}
