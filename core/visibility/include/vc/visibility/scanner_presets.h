// Instrument presets: the scanner model (vc/visibility/visibility.h) of real terrestrial laser
// scanners, from their manufacturers' public data sheets (docs/SCANNERS.md lists each value with its
// source and the quality setting it is for).
//
// A preset fixes what the instrument can do: the range, the vertical field of view and the angular
// step (and the time of one scan) at one usual quality setting; every instrument listed turns all
// round, so each keeps hfov_deg 360. It leaves the user's quality
// requirement off: max_incidence_deg 90 and max_spacing_m 0. Explicit values override a preset's
// (vc-client `--scanner NAME --max-range 40`; the proto's ScannerModel.name, docs/SCANNERS.md).
//
// The table is constant and built once; the functions are thread-safe.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"
#include "vc/visibility/visibility.h"

namespace vc {

struct ScannerPreset {
  std::string_view name;          // id, lower case ("leica-rtc360"); ScannerModel::name
  std::string_view display_name;  // "Leica RTC360"
  std::string_view setting;       // the quality setting angular_step_deg and scan_time_s are for
  ScannerModel model;             // name, range (m), vfov (deg), angular step (deg) at `setting`; no
                                  // incidence or spacing requirement
  double scan_time_s = 0;         // one full-dome scan at `setting`, in seconds (docs/SCANNERS.md)
  std::string_view source;        // the data sheet the values come from
};

// Every preset, in a fixed order (by manufacturer, then model). Each one's model Validate()s.
const std::vector<ScannerPreset>& ScannerPresets();

// The preset called `name` (exact, lower case), or nullptr.
const ScannerPreset* FindScannerPreset(std::string_view name);

// The preset's scanner model (name set). INVALID_ARGUMENT naming scanner.name and listing the
// known presets for an unknown name.
Result<ScannerModel> ScannerFromPreset(std::string_view name);

// The presets' names, comma-separated ("leica-rtc360, leica-blk360-g1, ...").
std::string ScannerPresetNames();

}  // namespace vc
