// fieldsheet.pdf read by real consumers (poppler's pdfinfo, pdftoppm and pdftotext): one page per
// floor, station markers drawn where the layout puts them (moved aside with leader lines where
// stations stand close), existing stations as squares, keep-out zones hatched, the station table
// continued on extra pages, the words a crew reads.
#include "vc/report/field_sheet.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "testing/test_paths.h"
#include "vc/report/crs.h"
#include "vc/report/field_exports.h"
#include "vc/report/plan_report.h"

namespace vc {
namespace {

using testing::CommandOutput;

constexpr double kDpi = 50;  // pdftoppm -r 50

bool HavePoppler() { return std::filesystem::exists(VC_PDFTOPPM) && std::filesystem::exists(VC_PDFINFO); }

// The PDF's text by pdftotext (poppler-utils, beside pdftoppm), laid out as on the page.
std::string PdfText(const std::string& path) {
  const std::string pdftotext = (std::filesystem::path(VC_PDFTOPPM).parent_path() / "pdftotext").string();
  return CommandOutput(pdftotext + " -layout " + path + " - 2>&1");
}

struct Page {
  int width = 0, height = 0;
  std::vector<uint8_t> grey;
  int at(int x, int y) const { return grey[size_t(y) * size_t(width) + size_t(x)]; }
  // The darkest grey in the 3 x 3 pixels around (x, y): thin lines and small dots are grey at 50 dpi.
  int Darkest(int x, int y) const {
    int g = 255;
    for (int v = std::max(0, y - 1); v <= std::min(height - 1, y + 1); ++v)
      for (int u = std::max(0, x - 1); u <= std::min(width - 1, x + 1); ++u) g = std::min(g, at(u, v));
    return g;
  }
  // Pixels darker than 128 in the square of half-size `half` around (x, y) (pixels).
  int DarkAround(int x, int y, int half) const {
    int n = 0;
    for (int v = std::max(0, y - half); v <= std::min(height - 1, y + half); ++v)
      for (int u = std::max(0, x - half); u <= std::min(width - 1, x + half); ++u) n += at(u, v) < 128 ? 1 : 0;
    return n;
  }
};

Page DecodeGreyPng(const std::string& path) {
  const std::string png = testing::ReadFileBytes(path);
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_memory(&image, png.data(), png.size())) << path;
  image.format = PNG_FORMAT_GRAY;
  Page p{int(image.width), int(image.height), std::vector<uint8_t>(PNG_IMAGE_SIZE(image))};
  EXPECT_TRUE(png_image_finish_read(&image, nullptr, p.grey.data(), 0, nullptr)) << path;
  return p;
}

// The PDF written to a temporary file, its page count by pdfinfo and its pages by pdftoppm.
struct ReadBack {
  std::string path;
  int pages = 0;
  std::string info;
  std::vector<Page> rasters;
};

ReadBack Rasterise(const std::string& pdf) {
  ReadBack b;
  const std::string dir = testing::MakeTempDir();
  b.path = dir + "/fieldsheet.pdf";
  std::ofstream(b.path, std::ios::binary) << pdf;
  b.info = CommandOutput(std::string(VC_PDFINFO) + " " + b.path + " 2>&1");
  const size_t at = b.info.find("Pages:");
  if (at != std::string::npos) b.pages = std::stoi(b.info.substr(at + 6));
  CommandOutput(std::string(VC_PDFTOPPM) + " -r 50 -png " + b.path + " " + dir + "/page 2>&1");
  for (int p = 1; p <= b.pages; ++p) {
    // pdftoppm numbers pages with as many digits as the last page number has.
    const std::string n = std::to_string(p), width = std::to_string(b.pages);
    b.rasters.push_back(DecodeGreyPng(dir + "/page-" + std::string(width.size() - n.size(), '0') + n + ".png"));
  }
  return b;
}

int Px(double pt) { return static_cast<int>(std::lround(pt * kDpi / 72)); }

// Two floors 3 m apart, each 4 x 3 m with a wall at x = 2 m; two stations below, one above.
PlanResult TwoFloorPlan() {
  PlanResult r;
  r.resolution_m = 0.1;
  r.options.grid_spacing_m = 1.0;
  r.heat_map.grid_spacing_m = 1.0;
  r.floor_levels_m = {0.1, 3.1};
  for (double level : {0.0, 3.0}) {
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) {
        r.heat_map.positions.emplace_back(0.5 + x, 0.5 + y, level + 1.6);
        r.heat_map.visible_voxels.push_back(100);
      }
    for (double y = 0.05; y < 3; y += 0.1)
      for (double z = 0.15; z < 1.6; z += 0.1) r.voxel_centers.emplace_back(2.05, y, level + z);
  }
  r.evaluation.best_face_values.resize(r.voxel_centers.size());
  auto station = [](double x, double y, double z, double floor) {
    PlannedStation s{WorldPoint(x, y, z), 100, 100, 0.5, 0.4, -1};
    s.floor_z_m = floor;
    return s;
  };
  r.stations = {station(0.5, 0.5, 1.6, 0.1), station(3.5, 2.5, 1.6, 0.1), station(0.5, 2.5, 4.6, 3.1)};
  r.route.order = {0, 1, 2};
  r.route.polylines = {{}, {WorldPoint(0.5, 0.5, 0.1), WorldPoint(3.5, 0.5, 0.1), WorldPoint(3.5, 2.5, 0.1)}, {}};
  r.occupied_voxels = 100;
  r.coverable_voxels = 90;
  r.covered_voxels = 80;
  r.field_time = {360, 300, 20, 680, 100};
  return r;
}

TEST(FieldSheetTest, OnePagePerFloorWithEachStationOnItsFloorsPage) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  const PlanResult plan = TwoFloorPlan();
  const std::vector<FieldStation> stations = FieldStations(plan);
  const FieldSheetLayout layout = ComputeFieldSheetLayout(plan, stations);
  const Result<std::string> pdf = FieldSheetPdf(plan, stations);
  ASSERT_TRUE(pdf.ok()) << pdf.status().message();
  const ReadBack b = Rasterise(*pdf);
  ASSERT_EQ(b.pages, 2) << b.info;
  EXPECT_EQ(layout.floor_pages, 2);
  EXPECT_EQ(layout.table_pages, 0);
  EXPECT_NE(b.info.find("1190.55 x 841.89 pts"), std::string::npos) << "A3 landscape: " << b.info;
  ASSERT_EQ(layout.markers.size(), 3u);
  for (size_t k = 0; k < stations.size(); ++k) {
    const StationMarkerPlace& m = layout.markers[k];
    const bool upstairs = plan.stations[stations[k].index].position.z() > 3;
    EXPECT_EQ(m.page, upstairs ? 1 : 0) << stations[k].name;
    const Page& here = b.rasters[size_t(m.page)];
    const Page& other = b.rasters[size_t(1 - m.page)];
    EXPECT_GE(here.DarkAround(Px(m.x_pt), Px(m.y_pt), 3), 4) << stations[k].name << ": the number is drawn";
    EXPECT_EQ(other.DarkAround(Px(m.x_pt), Px(m.y_pt), 3), 0) << stations[k].name << ": not on the other floor";
  }
}

// The plan view is drawn at the markers' transform: the wall at x = 2.05 m is dark, the open
// floor beside it white.
TEST(FieldSheetTest, DrawsTheFloorsWallsBetweenTheStations) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  const PlanResult plan = TwoFloorPlan();
  const std::vector<FieldStation> stations = FieldStations(plan);
  const FieldSheetLayout layout = ComputeFieldSheetLayout(plan, stations);
  const ReadBack b = Rasterise(*FieldSheetPdf(plan, stations));
  ASSERT_EQ(b.pages, 2);
  // Stations 1 and 2 (0.5, 0.5) and (3.5, 2.5) fix the page transform.
  const StationMarkerPlace a = layout.markers[0], c = layout.markers[1];
  ASSERT_EQ(stations[0].position_m.x(), 0.5);
  ASSERT_EQ(stations[1].position_m.x(), 3.5);
  const double pt_per_m = (c.x_pt - a.x_pt) / 3.0;
  EXPECT_NEAR((a.y_pt - c.y_pt) / 2.0, pt_per_m, 1e-9) << "same scale in x and y, y up";
  EXPECT_NEAR(72 / 0.0254 / pt_per_m, layout.scale_denominator, 1e-6);
  auto page_x = [&](double x) { return Px(a.x_pt + (x - 0.5) * pt_per_m); };
  auto page_y = [&](double y) { return Px(a.y_pt - (y - 0.5) * pt_per_m); };
  const Page& ground = b.rasters[0];
  EXPECT_LT(ground.at(page_x(2.05), page_y(1.5)), 100) << "the wall";
  EXPECT_GT(ground.at(page_x(1.2), page_y(1.5)), 240) << "open floor";
  int dark = 0;
  for (uint8_t g : ground.grey) dark += g < 128 ? 1 : 0;
  EXPECT_GT(dark, 2000) << "text, table, legend and plan: not blank";
}

// Existing stations are squares, new ones circles; a keep-out zone is hatched (part dark, part
// white) where the plan without it is white.
TEST(FieldSheetTest, ExistingStationsAreSquaresAndKeepOutZonesHatched) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  PlanResult plan = TwoFloorPlan();
  plan.stations[0].fixed = true;
  plan.options.fixed_stations = {plan.stations[0].position};
  const PlanResult without_zone = plan;
  plan.options.keep_out = {KeepOutBox(WorldPoint(2.4, 0.9, 0.0), WorldPoint(3.4, 1.9, 2.5))};
  const std::vector<FieldStation> stations = FieldStations(plan, {"OLD7"});
  ASSERT_TRUE(stations[0].fixed);
  EXPECT_EQ(stations[0].name, "OLD7");
  const FieldSheetLayout layout = ComputeFieldSheetLayout(plan, stations);
  const ReadBack b = Rasterise(*FieldSheetPdf(plan, stations));
  const ReadBack plain = Rasterise(*FieldSheetPdf(without_zone, FieldStations(without_zone, {"OLD7"})));
  ASSERT_EQ(b.pages, 2);
  // Just inside the corner below-right of each marker: the square's ring, or nothing beside a circle.
  for (size_t k = 0; k < 2; ++k) {
    const StationMarkerPlace& m = layout.markers[k];
    const int corner = b.rasters[0].DarkAround(Px(m.x_pt + 8.5), Px(m.y_pt + 8.5), 0);
    EXPECT_EQ(corner, stations[k].fixed ? 1 : 0) << stations[k].name;
  }
  const double pt_per_m = (layout.markers[1].x_pt - layout.markers[0].x_pt) / 3.0;
  int dark = 0, light = 0, dark_without = 0;
  for (double x = 2.6; x < 3.3; x += 0.05)
    for (double y = 1.1; y < 1.8; y += 0.05) {
      const int u = Px(layout.markers[0].x_pt + (x - 0.5) * pt_per_m);
      const int v = Px(layout.markers[0].y_pt - (y - 0.5) * pt_per_m);
      (b.rasters[0].at(u, v) < 160 ? dark : light) += 1;
      dark_without += plain.rasters[0].at(u, v) < 160 ? 1 : 0;
    }
  EXPECT_GT(dark, 10) << "hatch lines";
  EXPECT_GT(light, 10) << "between the hatch lines";
  EXPECT_EQ(dark_without, 0);
  const std::string text = PdfText(b.path);
  for (const char* words : {"grid north", "Keep-out zone", "Existing station", "OLD7", "existing", "Scale 1:"}) {
    EXPECT_NE(text.find(words), std::string::npos) << words << " in:\n" << text;
  }
  EXPECT_EQ(text.find("true north"), std::string::npos) << "no true north without an angle";
}

// Twelve stations 0.08 m apart (11 pt at 1:20) beside station 1: their markers would cover each
// other. No two markers or name labels overlap, none leaves the plan, every number is drawn where
// its marker went, a moved marker has a dot at its station and a leader line to it, and every
// name is on the page.
TEST(FieldSheetTest, CloseStationsGetMarkersAndNamesThatDoNotOverlap) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  PlanResult plan = TwoFloorPlan();
  for (int i = 0; i < 12; ++i) {
    PlannedStation s = plan.stations[0];
    s.position = WorldPoint(0.7 + 0.08 * i, 1.0, 1.6);
    plan.stations.push_back(s);
  }
  const std::vector<FieldStation> stations = FieldStations(plan);
  const FieldSheetLayout layout = ComputeFieldSheetLayout(plan, stations);
  EXPECT_EQ(layout.scale_denominator, 20);
  std::vector<LabelBox> boxes;
  int moved = 0;
  for (const StationMarkerPlace& m : layout.markers) {
    if (m.page != 0) continue;
    EXPECT_FALSE(m.number.overlaps);
    EXPECT_FALSE(m.name.overlaps);
    boxes.push_back(m.number.box);
    boxes.push_back(m.name.box);
    moved += m.number.leader ? 1 : 0;
  }
  EXPECT_GE(moved, 6) << "at most every other marker fits on its station";
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = i + 1; j < boxes.size(); ++j) EXPECT_FALSE(boxes[i].Overlaps(boxes[j])) << i << " and " << j;
  const ReadBack b = Rasterise(*FieldSheetPdf(plan, stations));
  ASSERT_EQ(b.pages, 2);
  const Page& page = b.rasters[0];
  for (size_t k = 0; k < stations.size(); ++k) {
    const StationMarkerPlace& m = layout.markers[k];
    if (m.page != 0) continue;
    const double cx = 0.5 * (m.number.box.x0 + m.number.box.x1), cy = 0.5 * (m.number.box.y0 + m.number.box.y1);
    EXPECT_GE(page.DarkAround(Px(cx), Px(cy), 2), 3) << stations[k].name << ": its number";
    if (!m.number.leader) continue;
    EXPECT_LT(page.Darkest(Px(m.x_pt), Px(m.y_pt)), 160) << stations[k].name << ": the dot at the station";
    // Halfway from the dot to the marker's ring: the leader line (thin: grey at 50 dpi).
    const double r = std::hypot(cx - m.x_pt, cy - m.y_pt), along = 0.5 * (r - 8 + 2);
    const int u = Px(m.x_pt + along * (cx - m.x_pt) / r), v = Px(m.y_pt + along * (cy - m.y_pt) / r);
    EXPECT_LT(page.Darkest(u, v), 200) << stations[k].name << ": the leader at " << u << "," << v;
  }
  const std::string text = PdfText(b.path);
  int heights = 0;
  for (size_t at = text.find("h 1.50 m"); at != std::string::npos; at = text.find("h 1.50 m", at + 1)) ++heights;
  EXPECT_EQ(heights, 15) << "every label, 14 on the ground floor and 1 upstairs:\n" << text;
}

// On A4 a long station table continues on extra pages; a true-north angle is shown.
TEST(FieldSheetTest, A4SheetContinuesALongTableOnExtraPages) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  PlanResult plan = TwoFloorPlan();
  for (int i = 0; i < 60; ++i) {
    PlannedStation s = plan.stations[0];
    s.position = WorldPoint(0.3 + 0.05 * i, 0.3, 1.6);
    plan.stations.push_back(s);
  }
  FieldSheetOptions options;
  options.paper = PaperSize::kA4;
  options.true_north_from_grid_deg = -1.5;
  const std::vector<FieldStation> stations = FieldStations(plan);
  const FieldSheetLayout layout = ComputeFieldSheetLayout(plan, stations, options);
  EXPECT_EQ(layout.floor_pages, 2);
  EXPECT_GE(layout.table_pages, 1);
  const ReadBack b = Rasterise(*FieldSheetPdf(plan, stations, options));
  EXPECT_EQ(b.pages, layout.floor_pages + layout.table_pages);
  EXPECT_NE(b.info.find("841.89 x 595.28 pts"), std::string::npos) << b.info;
  const std::string text = PdfText(b.path);
  EXPECT_NE(text.find("Stations, continued"), std::string::npos);
  EXPECT_NE(text.find("true north"), std::string::npos);
  EXPECT_NE(text.find(stations.back().name), std::string::npos) << "every station is in a table";
}

// A plan in survey coordinates (frame origin far from zero) draws the same plan as one near its
// origin, keep-out zones given in the input's frame included, and its table lists the input's frame.
TEST(FieldSheetTest, APlanInSurveyCoordinatesDrawsTheSamePlanAndListsTheInputsFrame) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  PlanResult near = TwoFloorPlan();
  near.options.keep_out = {KeepOutBox(WorldPoint(2.4, 0.9, 0.0), WorldPoint(3.4, 1.9, 2.5))};
  PlanResult survey = near;
  const WorldPoint origin(500000, 5400000, 300);
  survey.frame_origin_m = origin;
  survey.options.keep_out = {KeepOutBox(WorldPoint(2.4, 0.9, 0.0) + origin, WorldPoint(3.4, 1.9, 2.5) + origin)};
  const FieldSheetLayout a = ComputeFieldSheetLayout(near, FieldStations(near));
  const FieldSheetLayout b = ComputeFieldSheetLayout(survey, FieldStations(survey));
  ASSERT_EQ(a.markers.size(), b.markers.size());
  for (size_t k = 0; k < a.markers.size(); ++k) {
    EXPECT_EQ(a.markers[k].page, b.markers[k].page);
    EXPECT_DOUBLE_EQ(a.markers[k].x_pt, b.markers[k].x_pt);
    EXPECT_DOUBLE_EQ(a.markers[k].y_pt, b.markers[k].y_pt);
  }
  const ReadBack pa = Rasterise(*FieldSheetPdf(near, FieldStations(near)));
  const ReadBack pb = Rasterise(*FieldSheetPdf(survey, FieldStations(survey)));
  ASSERT_EQ(pb.pages, 2);
  const double pt_per_m = (a.markers[1].x_pt - a.markers[0].x_pt) / 3.0;
  int zone_a = 0, zone_b = 0;
  for (double x = 2.5; x < 3.35; x += 0.05)
    for (double y = 1.0; y < 1.85; y += 0.05) {
      const int u = Px(a.markers[0].x_pt + (x - 0.5) * pt_per_m), v = Px(a.markers[0].y_pt - (y - 0.5) * pt_per_m);
      zone_a += pa.rasters[0].at(u, v) < 160 ? 1 : 0;
      zone_b += pb.rasters[0].at(u, v) < 160 ? 1 : 0;
    }
  EXPECT_GT(zone_a, 10) << "the zone is hatched";
  EXPECT_EQ(zone_b, zone_a) << "and in the same place";
  const std::string text = PdfText(pb.path);
  for (const char* words : {"500000.500", "5400000.500", "z = 300.10 m"}) {
    EXPECT_NE(text.find(words), std::string::npos) << words << " in:\n" << text;
  }
}

TEST(FieldSheetTest, WritePlanOutputsWritesTheFieldSheet) {
  const PlanResult plan = TwoFloorPlan();
  const std::string dir = testing::MakeTempDir() + "/out";
  ASSERT_TRUE(WritePlanOutputs(plan, dir).ok());
  EXPECT_EQ(testing::ReadFileBytes(dir + "/fieldsheet.pdf").substr(0, 5), "%PDF-");
}

// With a CRS, WritePlanOutputs draws true north where PROJ puts it at the stations' mean: in UTM
// zone 32N 200 km east of the central meridian it lies west of grid north (a negative clockwise
// angle, about 2.2 degrees at 50.6 N); without a CRS the sheet shows grid north only.
TEST(FieldSheetTest, WithACrsTheSheetShowsTrueNorthFromProj) {
  if (!HavePoppler()) GTEST_SKIP() << "pdftoppm/pdfinfo (poppler-utils) not found";
  PlanResult plan = TwoFloorPlan();
  plan.frame_origin_m = WorldPoint(700000, 5607000, 0);
  Result<Crs> crs = Crs::Create("EPSG:25832");
  ASSERT_TRUE(crs.ok()) << crs.status().ToString();
  WorldPoint mean = WorldPoint::Zero();
  for (const PlannedStation& s : plan.stations) mean += s.position;
  mean = mean / static_cast<double>(plan.stations.size()) + plan.frame_origin_m;
  Result<double> ccw_rad = crs->TrueNorthFromGridNorthRad(mean.x(), mean.y());
  ASSERT_TRUE(ccw_rad.ok());
  const double clockwise_deg = -*ccw_rad * 180 / M_PI;
  EXPECT_LT(clockwise_deg, -2.0);
  EXPECT_GT(clockwise_deg, -2.4);
  char expected[64];
  std::snprintf(expected, sizeof(expected), "true north (%.1f", clockwise_deg);

  const std::string dir = testing::MakeTempDir() + "/out";
  ASSERT_TRUE(WritePlanOutputs(plan, dir, nullptr, {}, &*crs).ok());
  EXPECT_NE(PdfText(dir + "/fieldsheet.pdf").find(expected), std::string::npos) << expected;
  const std::string plain = testing::MakeTempDir() + "/out";
  ASSERT_TRUE(WritePlanOutputs(plan, plain).ok());
  EXPECT_EQ(PdfText(plain + "/fieldsheet.pdf").find("true north"), std::string::npos);
}

}  // namespace
}  // namespace vc
