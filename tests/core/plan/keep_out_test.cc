// Keep-out zones: the CSV parser (a good file; a header and boxes without their kind; every kind
// of bad line named by file:line and what is wrong), the checks, containment of boxes and polygons (boundary included),
// and the CSV line read back exactly.
#include "vc/plan/keep_out.h"

#include <gtest/gtest.h>

#include <string>

namespace vc {
namespace {

TEST(KeepOutCsvTest, ParsesBoxesPolygonsCommentsAndBlankLines) {
  const std::string text =
      "# zones of the hall\n"
      "\n"
      "box, 0, 0, -1, 2, 3, 4   # the machine\n"
      "POLYGON,0,3.5,10,10,12,10,12,12,10,12\n"
      "  \t\n"
      "polygon,-1,1,0,0,1,0,0,1";  // no final newline
  Result<std::vector<KeepOutZone>> zones = ParseKeepOutCsv(text, "zones.csv");
  ASSERT_TRUE(zones.ok()) << zones.status().ToString();
  ASSERT_EQ(zones->size(), 3u);
  const KeepOutZone& box = (*zones)[0];
  EXPECT_EQ(box.shape, KeepOutShape::kBox);
  EXPECT_EQ(box.min, WorldPoint(0, 0, -1));
  EXPECT_EQ(box.max, WorldPoint(2, 3, 4));
  const KeepOutZone& square = (*zones)[1];
  EXPECT_EQ(square.shape, KeepOutShape::kPolygon);
  EXPECT_EQ(square.polygon_xy_m, (std::vector<double>{10, 10, 12, 10, 12, 12, 10, 12}));
  EXPECT_EQ(square.min, WorldPoint(10, 10, 0));
  EXPECT_EQ(square.max, WorldPoint(12, 12, 3.5));
  EXPECT_EQ((*zones)[2].polygon_xy_m.size(), 6u);
  EXPECT_TRUE(ParseKeepOutCsv("", "empty.csv")->empty());
  EXPECT_TRUE(ParseKeepOutCsv("# nothing\n\n", "empty.csv")->empty());
}

// A header line (only the first line that is not blank or a comment) and boxes as six plain
// numbers, as a spreadsheet exports them, beside the kinds; each zone knows its line.
TEST(KeepOutCsvTest, TakesAHeaderAndBoxesWithoutTheirKind) {
  const std::string text =
      "\xEF\xBB\xBF# exported\n"
      "xmin,ymin,zmin,xmax,ymax,zmax\n"
      "0,0,-1,2,3,4\n"
      "\n"
      " 5 , 5 , 0 , 6 , 6 , 1 \n"
      "box,7,7,0,8,8,1\n"
      "polygon,0,1,0,0,1,0,0,1\n";
  Result<KeepOutFile> file = ParseKeepOutFile(text, "zones.csv");
  ASSERT_TRUE(file.ok()) << file.status().ToString();
  ASSERT_EQ(file->zones.size(), 4u);
  EXPECT_EQ(file->lines, (std::vector<size_t>{3, 5, 6, 7}));
  EXPECT_EQ(file->zones[0].shape, KeepOutShape::kBox);
  EXPECT_EQ(file->zones[0].min, WorldPoint(0, 0, -1));
  EXPECT_EQ(file->zones[0].max, WorldPoint(2, 3, 4));
  EXPECT_EQ(file->zones[1].min, WorldPoint(5, 5, 0));
  EXPECT_EQ(file->zones[1].max, WorldPoint(6, 6, 1));
  EXPECT_EQ(file->zones[3].shape, KeepOutShape::kPolygon);

  Result<std::vector<KeepOutZone>> with_kind =
      ParseKeepOutCsv("kind,xmin,ymin,zmin,xmax,ymax,zmax\nbox,0,0,0,1,1,1\n", "k.csv");
  ASSERT_TRUE(with_kind.ok()) << with_kind.status().ToString();
  EXPECT_EQ(with_kind->size(), 1u);
  EXPECT_TRUE(ParseKeepOutCsv("xmin,ymin,zmin,xmax,ymax,zmax\n", "header-only.csv")->empty());
}

TEST(KeepOutCsvTest, OnlyTheFirstLineMayBeAHeader) {
  Result<std::vector<KeepOutZone>> zones = ParseKeepOutCsv("box,0,0,0,1,1,1\nxmin,ymin,zmin,xmax,ymax,zmax\n", "z.csv");
  ASSERT_FALSE(zones.ok());
  EXPECT_EQ(zones.status().message(), "z.csv:2: unknown zone kind 'xmin'; use box, polygon, or six numbers for a box");
  // A typo in the kind is not a header: the line has numbers.
  zones = ParseKeepOutCsv("boks,0,0,0,1,1,1\n", "z.csv");
  ASSERT_FALSE(zones.ok());
  EXPECT_EQ(zones.status().message(), "z.csv:1: unknown zone kind 'boks'; use box, polygon, or six numbers for a box");
}

struct BadLine {
  const char* line;
  const char* what;  // a part of the message
};

TEST(KeepOutCsvTest, EveryBadLineIsNamedByFileLineAndWhatIsWrong) {
  const BadLine cases[] = {
      {"box,0,0,0,1,1,nan", "zmax is not finite"},
      {"box,0,0,0,inf,1,1", "xmax is not finite"},
      {"box,2,0,0,1,1,1", "xmin (2) exceeds xmax (1)"},
      {"box,0,0,5,1,1,1", "zmin (5) exceeds zmax (1)"},
      {"box,0,0,0,1,1", "a box has 7 fields"},
      {"box,0,0,0,1,1,1,1", "a box has 7 fields"},
      {"box,0,0,0,1,one,1", "field 6 'one' is not a number"},
      {"box,0,0,,1,1,1", "field 4 '' is not a number"},
      {"polygon,0,2,0,0,1,0", "2 vertices; it needs at least 3"},
      {"polygon,0,2", "0 vertices; it needs at least 3"},
      {"polygon,0", "a polygon needs zmin,zmax"},
      {"polygon,0,2,0,0,1,0,1", "odd number of vertex coordinates"},
      {"polygon,3,2,0,0,1,0,1,1", "zmin (3) exceeds zmax (2)"},
      {"polygon,0,2,0,0,nan,0,1,1", "vertex 2 x is not finite"},
      {"circle,0,0,1", "unknown zone kind 'circle'"},
      {",0,0,0,1,1,1", "unknown zone kind ''"},
      {"0,0,0,1,1", "a box without its kind has 6 numbers (xmin,ymin,zmin,xmax,ymax,zmax); this line has 5 fields"},
      {"0,0,0,1,1,1,1", "a box without its kind has 6 numbers"},
      {"0,0,0,1,x,1", "field 5 'x' is not a number"},
      {"0,0,3,1,1,1", "zmin (3) exceeds zmax (1)"},
  };
  for (const BadLine& c : cases) {
    SCOPED_TRACE(c.line);
    // The bad line is line 3, after a comment and a good zone.
    const std::string text = "# zones\nbox,0,0,0,1,1,1\n" + std::string(c.line) + "\nbox,0,0,0,1,1,1\n";
    Result<std::vector<KeepOutZone>> zones = ParseKeepOutCsv(text, "site/zones.csv");
    ASSERT_FALSE(zones.ok());
    EXPECT_EQ(zones.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(zones.status().message().rfind("site/zones.csv:3: ", 0), 0u) << zones.status().message();
    EXPECT_NE(zones.status().message().find(c.what), std::string::npos) << zones.status().message();
  }
}

TEST(KeepOutTest, BoxesContainTheirBoundary) {
  const KeepOutZone box = KeepOutBox({0, 0, 0}, {2, 1, 3});
  EXPECT_TRUE(KeepOutContains(box, {1, 0.5, 1.5}));
  EXPECT_TRUE(KeepOutContains(box, {2, 1, 3}));
  EXPECT_TRUE(KeepOutContains(box, {0, 0, 0}));
  EXPECT_FALSE(KeepOutContains(box, {2.001, 0.5, 1}));
  EXPECT_FALSE(KeepOutContains(box, {1, 0.5, -0.001}));
  EXPECT_FALSE(KeepOutContains(box, {std::nan(""), 0.5, 1}));
}

TEST(KeepOutTest, PolygonsContainTheirInteriorAndEdgesWithinTheirZRange) {
  // An L: the unit square (0..2, 0..2) without the quarter (1..2, 1..2).
  const KeepOutZone l = KeepOutPolygon(0, 3, {0, 0, 2, 0, 2, 1, 1, 1, 1, 2, 0, 2});
  EXPECT_TRUE(KeepOutContains(l, {0.5, 0.5, 1}));
  EXPECT_TRUE(KeepOutContains(l, {1.5, 0.5, 1}));
  EXPECT_TRUE(KeepOutContains(l, {0.5, 1.5, 1}));
  EXPECT_FALSE(KeepOutContains(l, {1.5, 1.5, 1}));  // the missing quarter
  EXPECT_TRUE(KeepOutContains(l, {1.5, 1.0, 1}));   // on an edge
  EXPECT_TRUE(KeepOutContains(l, {1.0, 1.5, 1}));   // on an edge
  EXPECT_TRUE(KeepOutContains(l, {2, 0, 0}));       // a vertex, at zmin
  EXPECT_FALSE(KeepOutContains(l, {0.5, 0.5, 3.01}));
  EXPECT_FALSE(KeepOutContains(l, {-0.01, 1, 1}));
  const std::vector<KeepOutZone> zones = {KeepOutBox({5, 5, 0}, {6, 6, 1}), l};
  EXPECT_EQ(KeepOutZoneContaining(zones, {0.5, 0.5, 1}), 1);
  EXPECT_EQ(KeepOutZoneContaining(zones, {5.5, 5.5, 0.5}), 0);
  EXPECT_EQ(KeepOutZoneContaining(zones, {9, 9, 9}), -1);
}

TEST(KeepOutTest, ValidateNamesTheZone) {
  const Status s = ValidateKeepOutZone(KeepOutBox({0, 0, 0}, {1, -1, 1}), "keep_out[4]");
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message().rfind("keep_out[4]: box ymin (0) exceeds ymax (-1)", 0), 0u) << s.message();
  EXPECT_TRUE(ValidateKeepOutZone(KeepOutPolygon(0, 0, {0, 0, 1, 0, 0, 1}), "z").ok());
}

TEST(KeepOutTest, CsvLinesReadBackExactly) {
  const std::vector<KeepOutZone> zones = {KeepOutBox({0.1, -2.5, 1.0 / 3}, {0.2, 7, 2}),
                                          KeepOutPolygon(-0.7, 2.25, {1e-3, 0, 1, 0.1, 0.3, 1.0 / 7})};
  std::string text;
  for (const KeepOutZone& z : zones) text += KeepOutCsvLine(z) + "\n";
  Result<std::vector<KeepOutZone>> back = ParseKeepOutCsv(text, "x");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ((*back)[i].shape, zones[i].shape);
    EXPECT_EQ((*back)[i].min, zones[i].min);
    EXPECT_EQ((*back)[i].max, zones[i].max);
    EXPECT_EQ((*back)[i].polygon_xy_m, zones[i].polygon_xy_m);
  }
}

}  // namespace
}  // namespace vc
