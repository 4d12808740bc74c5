#include "vc/client/crs_flag.h"

#include <iomanip>
#include <sstream>
#include <utility>

namespace vc::client {

namespace {

// The format as people call it, for one that holds metres.
std::string MetricFormatName(InputFormat format) {
  return format == InputFormat::kE57 ? "E57, in metres by its standard (ASTM E2807)"
                                     : "an OctoMap octree, in metres (its resolution is in metres)";
}

}  // namespace

Result<CrsChoice> CheckCrsFlag(std::string_view crs_flag, std::string_view units_flag,
                               std::optional<InputFormat> file_format) {
  CrsChoice choice{std::nullopt, std::string(units_flag), ""};
  if (crs_flag.empty()) return choice;
  Result<Crs> crs = Crs::Create(crs_flag);
  if (!crs.ok()) return InvalidArgumentError("--crs: " + crs.status().message());
  const CrsInfo& info = crs->info();
  const std::string named = "--crs " + std::string(crs_flag) + " (" + info.name + ")";
  if (file_format && FormatHoldsMetres(*file_format)) {
    const std::string format = MetricFormatName(*file_format);
    if (!units_flag.empty() && units_flag != "m") {
      return InvalidArgumentError("--units " + std::string(units_flag) + " does not apply to the scene file: it is " +
                                  format + ", whatever the CRS's unit. Drop --units; " + named +
                                  " still labels the outputs");
    }
    if (info.metres_per_unit != 1.0) {
      std::ostringstream factor;
      factor << std::setprecision(10) << info.metres_per_unit;
      choice.note = "the scene file is " + format + ": read in metres, not in " + named + "'s " + info.axis_unit +
                    "; the outputs are in metres (the CRS's coordinates times " + factor.str() +
                    ") and stations.geojson is converted";
    }
    choice.units.clear();
    choice.crs = std::move(crs).value();
    return choice;
  }
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
