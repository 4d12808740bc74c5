// Fuzzes vc::ParseKeepOutCsv, the parser of user-supplied keep-out zones (--keep-out), and checks
// two properties of what it accepts: every zone is valid, and its CSV line reads back to the same
// zone. Containment is exercised on each zone's corners and centre.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/plan/keep_out.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  vc::Result<std::vector<vc::KeepOutZone>> zones = vc::ParseKeepOutCsv(text, "fuzz");
  if (!zones.ok()) return 0;
  for (const vc::KeepOutZone& zone : *zones) {
    if (!vc::ValidateKeepOutZone(zone, "fuzz").ok()) __builtin_trap();
    const std::string line = vc::KeepOutCsvLine(zone);
    vc::Result<std::vector<vc::KeepOutZone>> back = vc::ParseKeepOutCsv(line, "fuzz");
    if (!back.ok() || back->size() != 1) __builtin_trap();
    const vc::KeepOutZone& again = back->front();
    if (again.shape != zone.shape || again.min != zone.min || again.max != zone.max ||
        again.polygon_xy_m != zone.polygon_xy_m) {
      __builtin_trap();
    }
    (void)vc::KeepOutContains(zone, zone.min);
    (void)vc::KeepOutContains(zone, zone.max);
    (void)vc::KeepOutContains(zone, 0.5 * (zone.min + zone.max));
  }
  return 0;
}
