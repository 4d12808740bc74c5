#include "vc/visibility/scanner_presets.h"

namespace vc {
namespace {

// A preset's scanner model: the instrument's limits, no incidence or spacing requirement.
ScannerModel Model(std::string_view name, double min_range_m, double max_range_m, double vfov_min_deg,
                   double vfov_max_deg, double angular_step_deg) {
  ScannerModel m;
  m.name = std::string(name);
  m.min_range_m = min_range_m;
  m.max_range_m = max_range_m;
  m.vfov_min_deg = vfov_min_deg;
  m.vfov_max_deg = vfov_max_deg;
  m.angular_step_deg = angular_step_deg;
  return m;
}

ScannerPreset Preset(std::string_view name, std::string_view display_name, std::string_view setting, double min_range_m,
                     double max_range_m, double vfov_min_deg, double vfov_max_deg, double angular_step_deg,
                     double scan_time_s, std::string_view source) {
  return {name,        display_name,
          setting,     Model(name, min_range_m, max_range_m, vfov_min_deg, vfov_max_deg, angular_step_deg),
          scan_time_s, source};
}

// Values and their sources: docs/SCANNERS.md (keep the two in step). A vertical field of view of
// V degrees about the zenith is the elevation range [90 - V/2, 90]. A step given as "x mm @ 10 m"
// is atan(x / 10 m).
std::vector<ScannerPreset> BuildPresets() {
  return {
      Preset("leica-rtc360", "Leica RTC360", "6 mm @ 10 m (medium resolution), without imaging", 0.5, 130.0, -60.0,
             90.0, 0.0344, 26.0, "Leica RTC360 data sheet, Leica Geosystems, 2018"),
      Preset("leica-blk360-g1", "Leica BLK360 (G1)", "standard density, 10 mm @ 10 m, with spherical imaging", 0.6,
             60.0, -60.0, 90.0, 0.0573, 180.0, "Leica BLK360 data sheet, Leica Geosystems, 2017"),
      Preset("leica-blk360-g2", "Leica BLK360 (G2)", "medium density, 10 mm @ 10 m, with spherical HDR imaging", 0.5,
             45.0, -45.0, 90.0, 0.0573, 20.0, "Leica BLK360 (2nd generation) data sheet, Leica Geosystems, 2022"),
      Preset("faro-focus-s70", "FARO Focus S 70",
             "1/4 resolution, 4x quality (10240 points per 360 deg), without colour", 0.6, 70.0, -60.0, 90.0, 0.0352,
             460.0, "FARO Focus S 70 Tech Sheet, FARO Technologies, 2018"),
      Preset("faro-focus-premium-150", "FARO Focus Premium 150",
             "1/4 resolution, 4x quality (10240 points per 360 deg), without colour", 0.5, 150.0, -60.0, 90.0, 0.0352,
             230.0, "FARO Focus Premium Tech Sheet, FARO Technologies, 2022"),
      Preset("trimble-x7", "Trimble X7", "6 mm @ 10 m, without imaging", 0.6, 80.0, -51.0, 90.0, 0.0344, 90.0,
             "Trimble X7 3D Laser Scanning System data sheet, Trimble, 2020"),
      Preset("zf-imager-5016", "Z+F IMAGER 5016",
             "high resolution (10000 points per 360 deg), normal quality, without imaging", 0.3, 365.0, -70.0, 90.0,
             0.036, 102.0, "Z+F IMAGER 5016 data sheet, Zoller + Froehlich, 2017"),
      Preset("riegl-vz-400i", "RIEGL VZ-400i", "0.04 deg step (7 mm @ 10 m), without imaging", 0.5, 800.0, -40.0, 60.0,
             0.04, 45.0, "RIEGL VZ-400i data sheet, RIEGL Laser Measurement Systems, 2019"),
  };
}

}  // namespace

const std::vector<ScannerPreset>& ScannerPresets() {
  static const std::vector<ScannerPreset> presets = BuildPresets();
  return presets;
}

const ScannerPreset* FindScannerPreset(std::string_view name) {
  for (const ScannerPreset& p : ScannerPresets()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

Result<ScannerModel> ScannerFromPreset(std::string_view name) {
  if (const ScannerPreset* p = FindScannerPreset(name)) return p->model;
  return InvalidArgumentError("scanner.name \"" + std::string(name) + "\" is not a known scanner preset; use one of " +
                              ScannerPresetNames() + " (vc-client scanners lists them), or leave it empty");
}

std::string ScannerPresetNames() {
  std::string names;
  for (const ScannerPreset& p : ScannerPresets()) {
    if (!names.empty()) names += ", ";
    names += p.name;
  }
  return names;
}

}  // namespace vc
