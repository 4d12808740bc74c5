// vc-client --crs: the CRS of the scene file's coordinates, checked with PROJ before anything is
// sent, and the units the file is then read in (docs/PLANNING.md, "A CRS for the outputs").
//
// Without --units the CRS's own unit is used: a file in a CRS's coordinates is in that CRS's unit
// (a file in EPSG:2263 is in US survey feet), so reading it in any other would be wrong by the
// ratio; a --units that disagrees with the CRS is refused rather than either one silently winning.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "vc/base/status.h"
#include "vc/report/crs.h"

namespace vc::client {

// What --crs and --units settle together.
struct CrsChoice {
  std::optional<Crs> crs;  // none without --crs
  std::string units;       // the units to read the file in (MetresPerUnit names); empty = metres
};

// Checks `crs_flag` (empty: none) against `units_flag` (empty: not given). INVALID_ARGUMENT naming
// --crs: PROJ's message for a CRS it does not know, a geographic CRS (give the projected one), a
// CRS whose axis unit vc cannot read files in, or one whose unit disagrees with --units.
[[nodiscard]] Result<CrsChoice> CheckCrsFlag(std::string_view crs_flag, std::string_view units_flag);

}  // namespace vc::client
