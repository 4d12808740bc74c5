// The instrument presets (vc/visibility/scanner_presets.h): every one is a valid scanner model with
// physically sensible values, the instruments docs/SCANNERS.md promises are there, and a name
// resolves to its model or to INVALID_ARGUMENT naming scanner.name.
#include "vc/visibility/scanner_presets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <string>

namespace vc {
namespace {

TEST(ScannerPresetsTest, EveryPresetValidatesAndIsPhysicallySensible) {
  ASSERT_FALSE(ScannerPresets().empty());
  std::set<std::string_view> names;
  for (const ScannerPreset& p : ScannerPresets()) {
    SCOPED_TRACE(std::string(p.name));
    const ScannerModel& m = p.model;
    EXPECT_TRUE(m.Validate().ok()) << m.Validate().ToString();
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate name";
    for (char c : p.name) EXPECT_TRUE((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-') << c;
    EXPECT_EQ(m.name, p.name);
    EXPECT_FALSE(p.display_name.empty());
    EXPECT_FALSE(p.setting.empty());
    EXPECT_FALSE(p.source.empty());
    // Ranges of terrestrial scanners: a near limit under 2 m, a far one of tens to hundreds of m.
    EXPECT_GT(m.min_range_m, 0.0);
    EXPECT_LT(m.min_range_m, 2.0);
    EXPECT_GE(m.max_range_m, 30.0);
    EXPECT_LE(m.max_range_m, 2000.0);
    // A tripod scanner sees up to the zenith or near it, and below the horizon.
    EXPECT_GE(m.vfov_max_deg, 45.0);
    EXPECT_LE(m.vfov_max_deg, 90.0);
    EXPECT_LT(m.vfov_min_deg, 0.0);
    EXPECT_GE(m.vfov_min_deg, -90.0);
    EXPECT_TRUE(m.HasVerticalFieldOfView()) << "no instrument sees straight down through its tripod";
    // The step at the usual setting: 1 to 25 mm between points at 10 m.
    const double spacing_at_10m_mm = 10000.0 * std::tan(m.angular_step_deg * std::numbers::pi / 180.0);
    EXPECT_GE(spacing_at_10m_mm, 1.0);
    EXPECT_LE(spacing_at_10m_mm, 25.0);
    // The user's quality requirement is not the instrument's: off in every preset.
    EXPECT_FALSE(m.HasIncidenceLimit());
    EXPECT_FALSE(m.HasSpacingLimit());
    // Every instrument listed turns all round (docs/SCANNERS.md), and a plan refuses less: a
    // preset below 360 deg would make the preset unusable for planning.
    EXPECT_EQ(m.hfov_deg, 360.0);
    EXPECT_FALSE(m.HasHorizontalFieldOfView());
    // Seconds to an hour per station.
    EXPECT_GE(p.scan_time_s, 5.0);
    EXPECT_LE(p.scan_time_s, 3600.0);
  }
}

TEST(ScannerPresetsTest, TheDocumentedInstrumentsAreThere) {
  for (std::string_view name : {"leica-rtc360", "leica-blk360-g1", "leica-blk360-g2", "faro-focus-s70",
                                "faro-focus-premium-150", "trimble-x7", "zf-imager-5016", "riegl-vz-400i"}) {
    EXPECT_NE(FindScannerPreset(name), nullptr) << name;
  }
}

TEST(ScannerPresetsTest, ANameGivesItsPresetsModel) {
  const Result<ScannerModel> m = ScannerFromPreset("leica-rtc360");
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_EQ(m->name, "leica-rtc360");
  EXPECT_EQ(m->min_range_m, 0.5);
  EXPECT_EQ(m->max_range_m, 130.0);
  EXPECT_EQ(m->vfov_min_deg, -60.0);  // 300 deg about the zenith
  EXPECT_EQ(m->vfov_max_deg, 90.0);
  EXPECT_GT(m->angular_step_deg, 0.0);
}

TEST(ScannerPresetsTest, UnknownNameIsInvalidArgumentNamingScannerNameAndListingThePresets) {
  for (std::string_view name : {"leica-rtc", "Leica-RTC360", ""}) {
    const Result<ScannerModel> m = ScannerFromPreset(name);
    ASSERT_FALSE(m.ok()) << name;
    EXPECT_EQ(m.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(m.status().message().find("scanner.name"), std::string::npos) << m.status().message();
    for (const ScannerPreset& p : ScannerPresets()) {
      EXPECT_NE(m.status().message().find(p.name), std::string::npos) << p.name;
    }
  }
}

}  // namespace
}  // namespace vc
