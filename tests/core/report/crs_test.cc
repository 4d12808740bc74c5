// The CRS of vc-client --crs through PROJ: what is accepted and what refused (with PROJ's words),
// longitude/latitude at points whose values are known, and the angle to true north checked against
// the direction of the meridian found from ToLonLat itself.
#include "vc/report/crs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace vc {
namespace {

constexpr double kDegPerRad = 180 / std::numbers::pi;

std::string MessageOf(std::string_view definition) {
  const Result<Crs> crs = Crs::Create(definition);
  EXPECT_FALSE(crs.ok()) << definition;
  if (crs.ok()) return "";
  EXPECT_EQ(crs.status().code(), StatusCode::kInvalidArgument);
  return crs.status().message();
}

TEST(CrsTest, AnEpsgCodeNamesTheCrsItsCodeAndItsUnit) {
  const Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok()) << crs.status().message();
  EXPECT_EQ(crs->info().definition, "EPSG:25832");
  EXPECT_EQ(crs->info().name, "ETRS89 / UTM zone 32N");
  EXPECT_EQ(crs->info().epsg, 25832);
  EXPECT_EQ(crs->info().axis_unit, "metre");
  EXPECT_EQ(crs->info().metres_per_unit, 1.0);
  EXPECT_EQ(crs->info().units, "m");
}

TEST(CrsTest, AProjStringAndWktAreAcceptedTheStringWithoutAnEpsgCode) {
  const Result<Crs> proj = Crs::Create("+proj=utm +zone=32 +ellps=GRS80 +units=m +no_defs +type=crs");
  ASSERT_TRUE(proj.ok()) << proj.status().message();
  EXPECT_FALSE(proj->info().epsg.has_value());
  EXPECT_EQ(proj->info().units, "m");
  const Result<Crs> wkt = Crs::Create(
      "PROJCRS[\"ETRS89 / UTM zone 33N\",BASEGEOGCRS[\"ETRS89\",DATUM[\"European Terrestrial Reference System "
      "1989\",ELLIPSOID[\"GRS 1980\",6378137,298.257222101]]],CONVERSION[\"UTM zone 33N\",METHOD[\"Transverse "
      "Mercator\"],PARAMETER[\"Latitude of natural origin\",0],PARAMETER[\"Longitude of natural origin\",15],"
      "PARAMETER[\"Scale factor at natural origin\",0.9996],PARAMETER[\"False easting\",500000],PARAMETER[\"False "
      "northing\",0]],CS[Cartesian,2],AXIS[\"easting\",east,LENGTHUNIT[\"metre\",1]],AXIS[\"northing\",north,"
      "LENGTHUNIT[\"metre\",1]],ID[\"EPSG\",25833]]");
  ASSERT_TRUE(wkt.ok()) << wkt.status().message();
  EXPECT_EQ(wkt->info().epsg, 25833);
  const Result<LonLat> centre = wkt->ToLonLat(500000, 0);
  ASSERT_TRUE(centre.ok());
  EXPECT_NEAR(centre->lon_deg, 15, 1e-9);
  EXPECT_NEAR(centre->lat_deg, 0, 1e-9);
}

TEST(CrsTest, ACompoundCrsIsReadByItsHorizontalPart) {
  const Result<Crs> crs = Crs::Create("EPSG:25832+5783");  // UTM 32N + DHHN2016 heights
  ASSERT_TRUE(crs.ok()) << crs.status().message();
  EXPECT_EQ(crs->info().epsg, 25832);
}

TEST(CrsTest, AFootCrsSaysItsUnitAndTakesMetres) {
  const Result<Crs> crs = Crs::Create("EPSG:2263");  // NAD83 / New York Long Island (ftUS)
  ASSERT_TRUE(crs.ok()) << crs.status().message();
  EXPECT_EQ(crs->info().units, "us-ft");
  EXPECT_NEAR(crs->info().metres_per_unit, 1200.0 / 3937.0, 1e-15);
  // Its false origin: 300,000 m east at 74°W, 40°10'N; the same point given in metres.
  const Result<LonLat> origin = crs->ToLonLat(300000, 0);
  ASSERT_TRUE(origin.ok()) << origin.status().message();
  EXPECT_NEAR(origin->lon_deg, -74, 1e-9);
  EXPECT_NEAR(origin->lat_deg, 40 + 10.0 / 60, 1e-9);
}

TEST(CrsTest, UnknownCrsIsRefusedWithProjsMessage) {
  const std::string m = MessageOf("EPSG:99999");
  EXPECT_NE(m.find("\"EPSG:99999\" is not a CRS PROJ knows ("), std::string::npos) << m;
  EXPECT_NE(m.find("crs not found"), std::string::npos) << m;
  EXPECT_NE(MessageOf("not a crs at all").find("is not a CRS PROJ knows"), std::string::npos);
}

TEST(CrsTest, AGeographicCrsIsRefusedSayingToGiveTheProjectedOne) {
  const std::string m = MessageOf("EPSG:4326");
  EXPECT_NE(m.find("(WGS 84) is a geographic CRS"), std::string::npos) << m;
  EXPECT_NE(m.find("degrees"), std::string::npos) << m;
  EXPECT_NE(m.find("UTM zone"), std::string::npos) << m;
}

TEST(CrsTest, AnOperationOrAGeocentricCrsIsRefused) {
  EXPECT_NE(MessageOf("+proj=utm +zone=32").find("needs +type=crs"), std::string::npos);
  EXPECT_NE(MessageOf("EPSG:4978").find("is not a projected CRS"), std::string::npos);
}

TEST(CrsTest, LonLatOfAZonesCentralMeridianOnTheEquator) {
  const Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok());
  const Result<LonLat> ll = crs->ToLonLat(500000, 0);
  ASSERT_TRUE(ll.ok());
  EXPECT_NEAR(ll->lon_deg, 9, 1e-12);
  EXPECT_NEAR(ll->lat_deg, 0, 1e-12);
}

// The angle from grid north to true north (counter-clockwise) found without proj_factors: grid
// north's bearing east of true north, from two points 1 m apart along grid north measured on the
// ellipsoid (GRS 80); true north lies that far counter-clockwise of grid north.
double TrueNorthByDifferenceRad(const Crs& crs, double x_m, double y_m) {
  const LonLat a = *crs.ToLonLat(x_m, y_m);
  const LonLat b = *crs.ToLonLat(x_m, y_m + 1);
  constexpr double kA = 6378137, kE2 = 0.00669438002290;
  const double phi = a.lat_deg / kDegPerRad;
  const double w = 1 - kE2 * std::sin(phi) * std::sin(phi);
  const double n = kA / std::sqrt(w), m = kA * (1 - kE2) / (w * std::sqrt(w));
  const double east = (b.lon_deg - a.lon_deg) / kDegPerRad * n * std::cos(phi);
  const double north = (b.lat_deg - a.lat_deg) / kDegPerRad * m;
  return std::atan2(east, north);
}

TEST(CrsTest, TrueNorthIsGridNorthOnTheCentralMeridianAndTurnsWestOfItToTheEast) {
  const Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok());
  const Result<double> on_meridian = crs->TrueNorthFromGridNorthRad(500000, 5612000);
  ASSERT_TRUE(on_meridian.ok()) << on_meridian.status().message();
  EXPECT_NEAR(*on_meridian, 0, 1e-12);
  for (const double x_m : {300000.0, 512345.0, 700000.0}) {
    const Result<double> angle = crs->TrueNorthFromGridNorthRad(x_m, 5612330);
    ASSERT_TRUE(angle.ok()) << angle.status().message();
    EXPECT_NEAR(*angle, TrueNorthByDifferenceRad(*crs, x_m, 5612330), 2e-7) << x_m;
    EXPECT_EQ(*angle > 0, x_m > 500000) << x_m;  // counter-clockwise (west of grid north) east of the meridian
  }
  // About (lon - 9°) sin(lat): 2.19° at 700 km east, 50.6°N.
  EXPECT_NEAR(*crs->TrueNorthFromGridNorthRad(700000, 5612000) * kDegPerRad, 2.1866, 1e-3);
}

TEST(CrsTest, APointProjCannotPlaceIsAnError) {
  const Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok());
  const Result<LonLat> far = crs->ToLonLat(1e30, 1e30);
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(far.status().message().find("cannot place"), std::string::npos) << far.status().message();
}

}  // namespace
}  // namespace vc
