// report.html in a real browser: plans a small synthetic scene (three rooms and a corridor), writes
// the plan's files, and opens report.html in headless chromium (software WebGL: SwiftShader
// through ANGLE). Checks the page's own state after its first frame (no script errors, one marker
// per station, every voxel drawn, a station selected from the URL with its sole voxels, a click on
// a marker selecting its station), and that a screenshot shows the scene: many distinct colours,
// red station markers and the selected station's sole voxels in magenta. On a two-storey scene
// with keep-out zones: the floor selector shows one floor's stations and voxels (from the URL
// and by choosing it in the <select>), a screenshot changes with the floor, and the zone is
// drawn (a screenshot redder where it stands than the same page without it). Printed to PDF, the
// page holds the view's snapshot, the tables, the coverage curve and the glossary, and none of its
// controls (read with poppler's pdftotext and pdfimages; skipped without them, as the field sheet's
// tests). Fails, never skips, when
// chromium is missing (scripts/install-deps.sh installs it); VC_CHROMIUM overrides its path.
#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "testing/scenes.h"
#include "testing/test_paths.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/planner.h"
#include "vc/report/field_exports.h"
#include "vc/report/plan_report.h"
#include "vc/report/report_html.h"

namespace vc {
namespace {

using testing::CommandOutput;

constexpr int kWidth = 1280, kHeight = 800;
constexpr int kPanelWidth = 460;  // report_page.css: #panel's width (px)

std::string Chromium() {
  if (const char* env = std::getenv("VC_CHROMIUM"); env != nullptr && *env != '\0') return env;
  return VC_CHROMIUM;
}

std::string ChromiumMissing() {
  return "chromium not found at '" + Chromium() +
         "': install it with scripts/install-deps.sh (Debian package chromium) or set VC_CHROMIUM";
}

// How long chromium lets the page run before it acts. Virtual time (15 s of it, as fast as the
// page allows) for --dump-dom and --screenshot; real time for --print-to-pdf, which Debian's
// Chromium 156.0.8078.129 never finishes under any --virtual-time-budget (the report page, 1 s or
// 15 s of budget: killed after 60 s). --timeout=15000 bounds the wait in real time; the page
// prints once loaded, in about 5 s, every word and the view's snapshot on paper.
enum class Wait { kVirtualTime, kRealTime };

// Runs headless chromium on `url` with `action` (--dump-dom, --screenshot=... or --print-to-pdf=...),
// stdout to `out`; its exit status.
int RunChromium(const std::string& dir, const std::string& url, const std::string& action, const std::string& out,
                Wait wait = Wait::kVirtualTime) {
  const std::string wait_flag = wait == Wait::kVirtualTime ? " --virtual-time-budget=15000 " : " --timeout=15000 ";
  const std::string command = "timeout 90 '" + Chromium() +
                              "' --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
                              " --disable-gpu-sandbox --no-first-run --disable-extensions --hide-scrollbars"
                              " --user-data-dir='" +
                              dir + "/profile' --window-size=" + std::to_string(kWidth) + "," +
                              std::to_string(kHeight) + wait_flag + action + " '" + url + "' >'" + out + "' 2>'" + dir +
                              "/chromium.log'";
  return std::system(command.c_str());
}

// A poppler-utils tool beside pdftoppm (tests/core/CMakeLists.txt finds pdftoppm).
std::string Poppler(const std::string& tool) {
  return (std::filesystem::path(VC_PDFTOPPM).parent_path() / tool).string();
}

// The attributes of the dumped DOM's <body> tag.
std::map<std::string, std::string> BodyAttributes(const std::string& dom) {
  std::map<std::string, std::string> attributes;
  const size_t start = dom.find("<body");
  if (start == std::string::npos) return attributes;
  const std::string tag = dom.substr(start, dom.find('>', start) - start);
  for (size_t at = tag.find(" data-"); at != std::string::npos; at = tag.find(" data-", at + 1)) {
    const size_t eq = tag.find("=\"", at);
    const size_t close = tag.find('"', eq + 2);
    if (eq == std::string::npos || close == std::string::npos) break;
    attributes[tag.substr(at + 1, eq - at - 1)] = tag.substr(eq + 2, close - eq - 2);
  }
  return attributes;
}

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

Picture ReadPng(const std::string& path) {
  Picture p;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return p;
  image.format = PNG_FORMAT_RGB;
  p.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, p.rgb.data(), 0, nullptr)) return Picture{};
  p.width = static_cast<int>(image.width);
  p.height = static_cast<int>(image.height);
  return p;
}

class ReportHtmlBrowserTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    PlanOptions o;
    o.resolution_m = 0.1;
    o.min_overlap = 0.3;
    o.solver = SelectionSolver::kGreedy;  // the page, not the bound (auto would spend 20 s here)
    Result<PlanResult> r = Plan(testing::Synthetic("rooms:3"), o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    plan_ = new PlanResult(std::move(*r));
    dir_ = new std::string(testing::MakeTempDir());
    ASSERT_TRUE(WritePlanOutputs(*plan_, *dir_).ok());
  }
  static void TearDownTestSuite() {
    delete plan_;
    delete dir_;
  }
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(Chromium())) << ChromiumMissing();
    ASSERT_NE(plan_, nullptr);
  }
  static std::string Url(const std::string& fragment = "") { return "file://" + *dir_ + "/report.html" + fragment; }
  static std::string Log() { return testing::ReadFileBytes(*dir_ + "/chromium.log"); }

  static PlanResult* plan_;
  static std::string* dir_;
};
PlanResult* ReportHtmlBrowserTest::plan_ = nullptr;
std::string* ReportHtmlBrowserTest::dir_ = nullptr;

TEST_F(ReportHtmlBrowserTest, PageRendersEveryStationWithoutErrors) {
  ASSERT_GE(plan_->stations.size(), 2u);
  const std::string dom_path = *dir_ + "/dom.html";
  ASSERT_EQ(RunChromium(*dir_, Url(), "--dump-dom", dom_path), 0) << Log();
  const std::string dom = testing::ReadFileBytes(dom_path);
  std::map<std::string, std::string> body = BodyAttributes(dom);
  const size_t errors_at = dom.find("<pre id=\"errors\">");
  const std::string errors = errors_at == std::string::npos ? "" : dom.substr(errors_at, 600);
  EXPECT_EQ(body["data-errors"], "0") << errors;
  ASSERT_EQ(body["data-ready"], "true") << "the page never rendered its first frame\n" << errors << Log();
  EXPECT_EQ(body["data-station-markers"], std::to_string(plan_->stations.size()));
  EXPECT_EQ(body["data-points-drawn"], std::to_string(plan_->voxel_centers.size()));
  EXPECT_NE(dom.find("vc plan report \u2014 ready</title>"), std::string::npos);
  // One table row per station.
  size_t rows = 0;
  for (size_t at = dom.find("<tr", dom.find("<tbody>")); at != std::string::npos && at < dom.find("</tbody>");
       at = dom.find("<tr", at + 1)) {
    ++rows;
  }
  EXPECT_EQ(rows, plan_->stations.size());
}

TEST_F(ReportHtmlBrowserTest, StationFromTheUrlIsSelected) {
  const std::string dom_path = *dir_ + "/dom-station.html";
  ASSERT_EQ(RunChromium(*dir_, Url("#station=2"), "--dump-dom", dom_path), 0) << Log();
  const std::string dom = testing::ReadFileBytes(dom_path);
  EXPECT_EQ(BodyAttributes(dom)["data-errors"], "0");
  EXPECT_EQ(BodyAttributes(dom)["data-ready"], "true");
  EXPECT_NE(dom.find("class=\"selected\">"), std::string::npos);
  // The plan carries sole viewers, so the page offers the highlight.
  ASSERT_EQ(plan_->evaluation.sole_viewer.size(), plan_->voxel_centers.size());
  EXPECT_NE(dom.find("Station 2: "), std::string::npos);
  EXPECT_NE(dom.find("voxels only it sees (magenta"), std::string::npos);
  EXPECT_EQ(dom.find("highlight of the voxels only it sees is unavailable"), std::string::npos);
}

TEST_F(ReportHtmlBrowserTest, DecimatedPageDrawsItsCapAndSaysSo) {
  ReportHtmlOptions options;
  options.max_points = 1000;
  ASSERT_GT(plan_->voxel_centers.size(), options.max_points);
  std::ofstream(*dir_ + "/decimated.html", std::ios::binary) << PlanToHtml(*plan_, options);
  const std::string dom_path = *dir_ + "/dom-decimated.html";
  ASSERT_EQ(RunChromium(*dir_, "file://" + *dir_ + "/decimated.html#station=1", "--dump-dom", dom_path), 0) << Log();
  const std::string dom = testing::ReadFileBytes(dom_path);
  std::map<std::string, std::string> body = BodyAttributes(dom);
  EXPECT_EQ(body["data-errors"], "0");
  EXPECT_EQ(body["data-ready"], "true");
  EXPECT_EQ(body["data-points-drawn"], "1000");
  EXPECT_NE(dom.find("1,000 of "), std::string::npos) << "the panel does not say how many voxels are drawn";
}

TEST_F(ReportHtmlBrowserTest, ClickingAMarkerSelectsItsStation) {
  // A copy of the page that, once ready, clicks station 2's marker (a pointerdown and pointerup on
  // the canvas where the page says the marker is) and writes the selected row's number on <body>.
  std::string html = testing::ReadFileBytes(*dir_ + "/report.html");
  const size_t end = html.rfind("</body>");
  ASSERT_NE(end, std::string::npos);
  html.insert(end, R"js(<script>
(function click() {
  if (!window.vcReport.ready) { setTimeout(click, 20); return; }
  var xy = window.vcReport.markerScreenPosition(1);
  var canvas = document.querySelector('#view canvas');
  var at = {clientX: xy[0], clientY: xy[1], bubbles: true};
  canvas.dispatchEvent(new PointerEvent('pointerdown', at));
  canvas.dispatchEvent(new PointerEvent('pointerup', at));
  var row = document.querySelector('#stations tr.selected');
  document.body.setAttribute('data-clicked', row ? row.firstChild.textContent : 'none');
})();
</script>
)js");
  std::ofstream(*dir_ + "/click.html", std::ios::binary) << html;
  const std::string dom_path = *dir_ + "/dom-click.html";
  ASSERT_EQ(RunChromium(*dir_, "file://" + *dir_ + "/click.html", "--dump-dom", dom_path), 0) << Log();
  std::map<std::string, std::string> body = BodyAttributes(testing::ReadFileBytes(dom_path));
  EXPECT_EQ(body["data-errors"], "0");
  EXPECT_EQ(body["data-clicked"], "2");
}

TEST_F(ReportHtmlBrowserTest, ScreenshotShowsTheSceneAndASelectedStationsSoleVoxels) {
  // The station that alone sees the most voxels, selected from the URL.
  std::vector<size_t> sole(plan_->stations.size(), 0);
  for (int32_t s : plan_->evaluation.sole_viewer) {
    if (s >= 0 && static_cast<size_t>(s) < sole.size()) ++sole[s];
  }
  const size_t best = std::max_element(sole.begin(), sole.end()) - sole.begin();
  ASSERT_GT(sole[best], 100u) << "no station sees enough voxels alone to show them";
  const std::string png = *dir_ + "/screenshot.png";
  ASSERT_EQ(RunChromium(*dir_, Url("#station=" + std::to_string(best + 1)), "--screenshot='" + png + "'",
                        *dir_ + "/screenshot.out"),
            0)
      << Log();
  const Picture p = ReadPng(png);
  ASSERT_EQ(p.width, kWidth) << "no readable screenshot\n" << Log();
  ASSERT_EQ(p.height, kHeight);
  // The 3D view (left of the panel): not blank, i.e. many pixels differ from its background
  // (#24262b), in many colours (viridis voxels), with red station marker rings among them.
  const int view_width = kWidth - kPanelWidth;
  size_t scene_pixels = 0, red_pixels = 0, magenta_pixels = 0;
  std::set<uint32_t> colours;
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < view_width; ++x) {
      const uint8_t* c = &p.rgb[3 * (static_cast<size_t>(y) * p.width + x)];
      if (std::abs(c[0] - 0x24) + std::abs(c[1] - 0x26) + std::abs(c[2] - 0x2b) > 12) ++scene_pixels;
      if (c[0] > 180 && c[1] < 80 && c[2] < 80) ++red_pixels;
      if (c[0] > 200 && c[1] < 90 && c[2] > 170) ++magenta_pixels;
      colours.insert((c[0] >> 3) << 10 | (c[1] >> 3) << 5 | (c[2] >> 3));
    }
  }
  const size_t view_pixels = static_cast<size_t>(view_width) * p.height;
  EXPECT_GT(scene_pixels, view_pixels / 20) << scene_pixels << " of " << view_pixels << " pixels show the scene";
  EXPECT_GT(colours.size(), 100u) << "distinct colours (5 bits per channel)";
  EXPECT_GT(red_pixels, 50u) << "no red station marker rings";
  EXPECT_GT(magenta_pixels, 1000u) << "station " << best + 1 << "'s " << sole[best] << " sole voxels are not magenta";
}

TEST_F(ReportHtmlBrowserTest, PrintedPageHoldsTheViewTablesCurveAndGlossaryWithoutControls) {
  if (!std::filesystem::exists(Poppler("pdftotext")) || !std::filesystem::exists(Poppler("pdfimages"))) {
    GTEST_SKIP() << "pdftotext/pdfimages (poppler-utils) not found";
  }
  const std::string pdf = *dir_ + "/printed.pdf";
  ASSERT_EQ(RunChromium(*dir_, Url(), "--no-pdf-header-footer --print-to-pdf='" + pdf + "'", *dir_ + "/print.out",
                        Wait::kRealTime),
            0)
      << Log();
  const std::string text = CommandOutput(Poppler("pdftotext") + " '" + pdf + "' - 2>&1");
  for (const std::string words : {"GLOSSARY", "Visibility score", "COVERAGE CURVE", "80 % of what can be covered",
                                  "tripod height", "walking order", "Grid squares of"}) {
    EXPECT_NE(text.find(words), std::string::npos) << words << " is not on paper";
  }
  for (const FieldStation& f : FieldStations(*plan_)) EXPECT_NE(text.find(f.name), std::string::npos) << f.name;
  // No controls: neither the checkboxes' labels nor the mouse hint.
  EXPECT_EQ(text.find("(score 0) in red"), std::string::npos);
  EXPECT_EQ(text.find("drag: rotate"), std::string::npos);
  // The view's snapshot: an image as wide as the view (the legend's colour bar is 255 x 1).
  const std::string images = CommandOutput(Poppler("pdfimages") + " -list '" + pdf + "' 2>&1");
  bool snapshot = false;
  std::istringstream lines(images);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    int page = 0, num = 0, width = 0, height = 0;
    std::string type;
    if (fields >> page >> num >> type >> width >> height && type == "image") {
      snapshot = snapshot || (width == kWidth - kPanelWidth && height >= kHeight / 2);
    }
  }
  EXPECT_TRUE(snapshot) << "no snapshot of the view:\n" << images;
}

// The two-storey scene (storeys 3 m high on a 0.3 m slab, the upper floor's top at z = 3.3) with a
// keep-out box on the lower floor and a triangle on the upper, planned; its report.html written.
class ReportHtmlBrowserTwoFloorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    PlanOptions o;
    o.resolution_m = 0.1;
    o.solver = SelectionSolver::kGreedy;
    o.keep_out = {KeepOutBox(WorldPoint(0.5, 3.5, 0), WorldPoint(2.5, 5.5, 2)),
                  KeepOutPolygon(3.3, 5.3, {5, 3.5, 7, 3.5, 6, 5.5})};
    Result<PlanResult> r = Plan(testing::Synthetic("twofloor"), o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    two_floor_ = new PlanResult(std::move(*r));
    two_floor_dir_ = new std::string(testing::MakeTempDir());
    ASSERT_TRUE(WritePlanOutputs(*two_floor_, *two_floor_dir_).ok());
  }
  static void TearDownTestSuite() {
    delete two_floor_;
    delete two_floor_dir_;
  }
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(Chromium())) << ChromiumMissing();
    ASSERT_NE(two_floor_, nullptr);
  }
  // The DOM of `page` (a file in the test's directory) opened with `fragment`, after its first frame.
  static std::string Dom(const std::string& page, const std::string& fragment, const std::string& out) {
    const std::string path = *two_floor_dir_ + "/" + out;
    if (RunChromium(*two_floor_dir_, "file://" + *two_floor_dir_ + "/" + page + fragment, "--dump-dom", path) != 0) {
      return "";
    }
    return testing::ReadFileBytes(path);
  }
  static Picture Screenshot(const std::string& page, const std::string& fragment, const std::string& out) {
    const std::string png = *two_floor_dir_ + "/" + out;
    if (RunChromium(*two_floor_dir_, "file://" + *two_floor_dir_ + "/" + page + fragment, "--screenshot='" + png + "'",
                    png + ".out") != 0) {
      return Picture{};
    }
    return ReadPng(png);
  }
  static std::string TwoFloorLog() { return testing::ReadFileBytes(*two_floor_dir_ + "/chromium.log"); }
  // Stations standing on the lower floor (under the slab at z = 3.0).
  static size_t LowerStations() {
    size_t n = 0;
    for (const PlannedStation& s : two_floor_->stations) n += s.position.z() < 3.0 ? 1 : 0;
    return n;
  }

  static PlanResult* two_floor_;
  static std::string* two_floor_dir_;
};
PlanResult* ReportHtmlBrowserTwoFloorTest::two_floor_ = nullptr;
std::string* ReportHtmlBrowserTwoFloorTest::two_floor_dir_ = nullptr;

TEST_F(ReportHtmlBrowserTwoFloorTest, FloorFromTheUrlShowsOnlyThatFloorsStationsAndVoxels) {
  const size_t lower = LowerStations(), total = two_floor_->stations.size();
  ASSERT_GE(lower, 1u);
  ASSERT_GE(total - lower, 1u) << "no station upstairs";
  size_t points_on_floors = 0;
  for (const auto& [floor, stations] : {std::pair{"L0", lower}, std::pair{"L1", total - lower}}) {
    const std::string dom = Dom("report.html", std::string("#floor=") + floor, std::string("dom-") + floor + ".html");
    std::map<std::string, std::string> body = BodyAttributes(dom);
    ASSERT_EQ(body["data-ready"], "true") << TwoFloorLog();
    EXPECT_EQ(body["data-errors"], "0");
    EXPECT_EQ(body["data-floor"], floor);
    EXPECT_EQ(body["data-station-markers"], std::to_string(total));
    EXPECT_EQ(body["data-visible-station-markers"], std::to_string(stations)) << floor;
    // The other floor's rows are hidden.
    const std::string table = dom.substr(dom.find("<tbody>"), dom.find("</tbody>") - dom.find("<tbody>"));
    size_t hidden = 0;
    for (size_t at = table.find(" hidden=\"\""); at != std::string::npos; at = table.find(" hidden=\"\"", at + 1)) {
      ++hidden;
    }
    EXPECT_EQ(hidden, total - stations) << floor;
    const size_t points = std::stoul(body["data-points-on-floor"]);
    EXPECT_GT(points, two_floor_->voxel_centers.size() / 4) << floor;
    EXPECT_LT(points, two_floor_->voxel_centers.size() * 3 / 4) << floor;
    points_on_floors += points;
    EXPECT_NE(dom.find("on floor " + std::string(floor)), std::string::npos) << "the scale note names the floor";
  }
  EXPECT_EQ(points_on_floors, two_floor_->voxel_centers.size()) << "the floors' bands share no voxel and miss none";
}

TEST_F(ReportHtmlBrowserTwoFloorTest, ChoosingAFloorInTheSelectorSwitchesFloors) {
  // A copy of the page that, once ready, chooses the upper floor in the <select> as a user would.
  std::string html = testing::ReadFileBytes(*two_floor_dir_ + "/report.html");
  const size_t end = html.rfind("</body>");
  ASSERT_NE(end, std::string::npos);
  html.insert(end, R"js(<script>
(function choose() {
  if (!window.vcReport.ready) { setTimeout(choose, 20); return; }
  var select = document.getElementById('floor');
  document.body.setAttribute('data-options', Array.prototype.map.call(select.options, function (o) {
    return o.textContent.split(' (')[0];
  }).join('|'));
  select.value = '1';
  select.dispatchEvent(new Event('change'));
})();
</script>
)js");
  std::ofstream(*two_floor_dir_ + "/choose.html", std::ios::binary) << html;
  std::map<std::string, std::string> body = BodyAttributes(Dom("choose.html", "", "dom-choose.html"));
  EXPECT_EQ(body["data-errors"], "0");
  EXPECT_EQ(body["data-options"], "All floors|floor L0|floor L1");
  EXPECT_EQ(body["data-floor"], "L1");
  EXPECT_EQ(body["data-visible-station-markers"], std::to_string(two_floor_->stations.size() - LowerStations()));
}

// The view's pixels (left of the panel) that differ between two screenshots by more than 40 in
// some channel, and those of them redder in `b` than in `a` (red up, green and blue down).
struct PixelChange {
  size_t changed = 0;
  size_t redder = 0;
};
PixelChange CompareViews(const Picture& a, const Picture& b) {
  PixelChange c;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < kWidth - kPanelWidth; ++x) {
      const uint8_t* p = &a.rgb[3 * (static_cast<size_t>(y) * a.width + x)];
      const uint8_t* q = &b.rgb[3 * (static_cast<size_t>(y) * b.width + x)];
      const int dr = q[0] - p[0], dg = q[1] - p[1], db = q[2] - p[2];
      if (std::max({std::abs(dr), std::abs(dg), std::abs(db)}) > 40) ++c.changed;
      if (dr - std::max(dg, db) > 40) ++c.redder;
    }
  }
  return c;
}

TEST_F(ReportHtmlBrowserTwoFloorTest, ScreenshotChangesWithTheFloorShown) {
  const Picture lower = Screenshot("report.html", "#floor=L0", "floor-L0.png");
  const Picture upper = Screenshot("report.html", "#floor=L1", "floor-L1.png");
  ASSERT_EQ(lower.width, kWidth) << TwoFloorLog();
  ASSERT_EQ(upper.width, kWidth);
  const size_t view_pixels = static_cast<size_t>(kWidth - kPanelWidth) * kHeight;
  EXPECT_GT(CompareViews(lower, upper).changed, view_pixels / 20) << "the two floors look alike";
}

TEST_F(ReportHtmlBrowserTwoFloorTest, KeepOutZonesAreDrawnAndListed) {
  const std::string dom = Dom("report.html", "#floor=L0", "dom-zones.html");
  std::map<std::string, std::string> body = BodyAttributes(dom);
  EXPECT_EQ(body["data-errors"], "0");
  EXPECT_EQ(body["data-keep-out-zones"], "2");
  EXPECT_NE(dom.find("<li>zone 1, box x 0.50 to 2.50, y 3.50 to 5.50, z 0.00 to 2.00 m</li>"), std::string::npos);
  EXPECT_NE(dom.find("<li>zone 2, polygon of 3 corners within x 5.00 to 7.00, y 3.50 to 5.50, z 3.30 to 5.30 m</li>"),
            std::string::npos);
  // The same page without the zones: the lower floor's screenshot is redder where its zone stands
  // (the upper floor's polygon lies above the floor's band).
  PlanResult without = *two_floor_;
  without.options.keep_out.clear();
  std::ofstream(*two_floor_dir_ + "/no-zones.html", std::ios::binary) << PlanToHtml(without);
  const Picture zoned = Screenshot("report.html", "#floor=L0", "zones.png");
  const Picture bare = Screenshot("no-zones.html", "#floor=L0", "no-zones.png");
  ASSERT_EQ(zoned.width, kWidth) << TwoFloorLog();
  ASSERT_EQ(bare.width, kWidth);
  const PixelChange c = CompareViews(bare, zoned);
  EXPECT_GT(c.redder, 2000u) << "the keep-out zone is not drawn";
  EXPECT_GT(c.redder, c.changed * 8 / 10) << "the zone changes the view in other ways than a red tint";
}

}  // namespace
}  // namespace vc
