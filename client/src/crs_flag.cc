#include "vc/client/crs_flag.h"

#include <utility>

namespace vc::client {

Result<CrsChoice> CheckCrsFlag(std::string_view crs_flag, std::string_view units_flag) {
  CrsChoice choice{std::nullopt, std::string(units_flag)};
  if (crs_flag.empty()) return choice;
  Result<Crs> crs = Crs::Create(crs_flag);
  if (!crs.ok()) return InvalidArgumentError("--crs: " + crs.status().message());
  const CrsInfo& info = crs->info();
  const std::string named = "--crs " + std::string(crs_flag) + " (" + info.name + ")";
  if (info.units.empty()) {
    return InvalidArgumentError(named + " has its axes in " + info.axis_unit +
                                ", a unit vc does not read files in (m, cm, mm, ft, us-ft)");
  }
  if (!units_flag.empty() && units_flag != info.units) {
    return InvalidArgumentError(named + " has its axes in " + info.axis_unit + " (--units " + info.units +
                                ") but --units says " + std::string(units_flag) +
                                ": a file in the CRS's coordinates is in its unit. Drop --units (the CRS's unit is "
                                "used), or give the CRS the file is in");
  }
  choice.units = info.units;
  choice.crs = std::move(crs).value();
  return choice;
}

}  // namespace vc::client
