// vc-client --crs with --units: the CRS's unit when --units is absent, and each refusal naming the flag.
#include "vc/client/crs_flag.h"

#include <gtest/gtest.h>

#include <optional>
#include <string>

namespace vc::client {
namespace {

std::string Refusal(std::string_view crs, std::string_view units, std::optional<InputFormat> format = std::nullopt) {
  const Result<CrsChoice> choice = CheckCrsFlag(crs, units, format);
  EXPECT_FALSE(choice.ok()) << crs << " " << units;
  if (choice.ok()) return "";
  EXPECT_EQ(choice.status().code(), StatusCode::kInvalidArgument);
  return choice.status().message();
}

TEST(CrsFlagTest, WithoutCrsTheUnitsFlagStandsAndThereIsNoCrs) {
  const Result<CrsChoice> choice = CheckCrsFlag("", "mm");
  ASSERT_TRUE(choice.ok());
  EXPECT_FALSE(choice->crs.has_value());
  EXPECT_EQ(choice->units, "mm");
}

TEST(CrsFlagTest, WithoutUnitsTheCrsUnitIsUsed) {
  const Result<CrsChoice> feet = CheckCrsFlag("EPSG:2263", "");
  ASSERT_TRUE(feet.ok()) << feet.status().message();
  ASSERT_TRUE(feet->crs.has_value());
  EXPECT_EQ(feet->units, "us-ft");
  const Result<CrsChoice> metres = CheckCrsFlag("EPSG:25832", "m");
  ASSERT_TRUE(metres.ok()) << metres.status().message();
  EXPECT_EQ(metres->units, "m");
  EXPECT_EQ(metres->crs->info().epsg, 25832);
}

TEST(CrsFlagTest, UnknownCrsNamesTheFlagAndGivesProjsMessage) {
  EXPECT_EQ(Refusal("EPSG:99999", "").rfind("--crs: \"EPSG:99999\" is not a CRS PROJ knows (", 0), 0u);
}

TEST(CrsFlagTest, GeographicCrsIsRefusedNamingTheFlag) {
  const std::string m = Refusal("EPSG:4326", "");
  EXPECT_EQ(m.rfind("--crs: \"EPSG:4326\" (WGS 84) is a geographic CRS", 0), 0u) << m;
}

TEST(CrsFlagTest, AUnitsFlagThatDisagreesWithTheCrsIsRefused) {
  EXPECT_EQ(Refusal("EPSG:25832", "mm"),
            "--crs EPSG:25832 (ETRS89 / UTM zone 32N) has its axes in metre (--units m) but --units says mm: a file "
            "in the CRS's coordinates is in its unit. Drop --units (the CRS's unit is used), or give the CRS the file "
            "is in");
  EXPECT_NE(Refusal("EPSG:2263", "ft").find("has its axes in US survey foot (--units us-ft) but --units says ft"),
            std::string::npos);
}

// An E57 holds metres by its standard and an octree by its resolution: with a CRS in feet they are
// read in metres (the outputs are metres either way), with a note; a --units other than m is refused.
TEST(CrsFlagTest, AFileInMetresByItsFormatIsReadInMetresWhateverTheCrsUnit) {
  for (InputFormat format : {InputFormat::kE57, InputFormat::kOctomapBinary}) {
    const Result<CrsChoice> feet = CheckCrsFlag("EPSG:2263", "", format);
    ASSERT_TRUE(feet.ok()) << feet.status().message();
    ASSERT_TRUE(feet->crs.has_value());
    EXPECT_EQ(feet->crs->info().units, "us-ft");
    EXPECT_EQ(feet->units, "");  // metres
    EXPECT_NE(feet->note.find("read in metres, not in --crs EPSG:2263"), std::string::npos) << feet->note;
    EXPECT_NE(feet->note.find("times 0.3048006096"), std::string::npos) << feet->note;
    const Result<CrsChoice> said_m = CheckCrsFlag("EPSG:2263", "m", format);
    ASSERT_TRUE(said_m.ok()) << said_m.status().message();
    EXPECT_EQ(said_m->units, "");
    const Result<CrsChoice> metres = CheckCrsFlag("EPSG:25832", "", format);
    ASSERT_TRUE(metres.ok()) << metres.status().message();
    EXPECT_EQ(metres->units, "");
    EXPECT_EQ(metres->note, "");
  }
  EXPECT_EQ(Refusal("EPSG:2263", "us-ft", InputFormat::kE57),
            "--units us-ft does not apply to the scene file: it is E57, in metres by its standard (ASTM E2807), "
            "whatever the CRS's unit. Drop --units; --crs EPSG:2263 (NAD83 / New York Long Island (ftUS)) still "
            "labels the outputs");
  // Other formats take the CRS's unit, as before.
  const Result<CrsChoice> xyz = CheckCrsFlag("EPSG:2263", "", InputFormat::kXyz);
  ASSERT_TRUE(xyz.ok()) << xyz.status().message();
  EXPECT_EQ(xyz->units, "us-ft");
  EXPECT_EQ(xyz->note, "");
}

}  // namespace
}  // namespace vc::client
