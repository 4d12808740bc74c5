// vc-client --crs: the CRS of the scene file's coordinates, checked with PROJ before anything is
// sent, and the units the file is then read in (docs/PLANNING.md, "A CRS for the outputs").
//
// Without --units the CRS's own unit is used: a file in a CRS's coordinates is in that CRS's unit
// (a file in EPSG:2263 is in US survey feet), so reading it in any other would be wrong by the
// ratio; a --units that disagrees with the CRS is refused rather than either one silently winning.
// Formats that fix metres (E57 by its standard, ASTM E2807; OctoMap octrees; vc::FormatHoldsMetres)
// are the exception: their coordinates are the CRS's converted to metres whatever the CRS's unit,
// so they are read in metres, the CRS only labels the outputs (which are in metres anyway), and a
// --units other than m is refused.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "vc/base/status.h"
#include "vc/report/crs.h"
#include "vc/scene/scene_input.h"

namespace vc::client {

// What --crs and --units settle together.
struct CrsChoice {
  std::optional<Crs> crs;  // none without --crs
  std::string units;       // the units to read the file in (MetresPerUnit names); empty = metres
  // For people, when the CRS's unit is not the file's: "site.e57 is E57, in metres by its standard
  // (ASTM E2807): read in metres; ...". Empty otherwise.
  std::string note;
};

// Checks `crs_flag` (empty: none) against `units_flag` (empty: not given) for a scene file of
// `file_format` (nullopt: not known, e.g. attach). INVALID_ARGUMENT naming --crs: PROJ's message
// for a CRS it does not know, a geographic CRS (give the projected one), a CRS whose axis unit vc
// cannot read files in, or one whose unit disagrees with --units; for a format that holds metres,
// naming --units when it is not m.
[[nodiscard]] Result<CrsChoice> CheckCrsFlag(std::string_view crs_flag, std::string_view units_flag,
                                             std::optional<InputFormat> file_format = std::nullopt);

}  // namespace vc::client
