#include "vc/report/field_sheet.h"

#include <cairo-ft.h>
#include <cairo-pdf.h>
#include <cairo.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "floor_plan.h"
#include "vc/plan/keep_out.h"
#include "vc/report/label_placement.h"

namespace vc {

namespace {

// Paper and layout, in points (1/72 inch).
constexpr double kPointsPerMetre = 72.0 / 0.0254;
constexpr double kMargin = 28;
constexpr double kTitleBand = 52;   // title and headline lines above the plan
constexpr double kGutter = 14;      // between the plan and the side column
constexpr double kSideBlock = 112;  // north arrow and scale bar
constexpr double kLegendRow = 17;
constexpr int kLegendRows = 7;
constexpr double kRowHeight = 12;    // station table
constexpr double kTableHeader = 30;  // the table's heading and column titles
constexpr double kMarkerRadius = 7;
constexpr double kDotRadius = 1.6;   // the dot at a station whose numbered marker is moved aside
constexpr double kNameHeight = 9;    // a name label's white ground
constexpr double kNameFontSize = 7;  // and its text
constexpr const char* kFont = "DejaVu Sans";
constexpr const char* kFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";  // Debian fonts-dejavu-core
constexpr const char* kBoldFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";

// DejaVu Sans, regular and bold, loaded from its files through FreeType once per process and kept
// (cairo locks a face while it uses it, so threads share them). Straight from the files, because
// cairo's toy font API asks fontconfig, which leaks a pattern per lookup (LeakSanitizer reports it
// in every test that writes a plan's outputs). Null where a file is missing: the toy API then picks
// the font.
struct FontFaces {
  cairo_font_face_t* regular = nullptr;
  cairo_font_face_t* bold = nullptr;
};

const FontFaces& DejaVuFaces() {
  static const FontFaces faces = [] {
    FontFaces f;
    FT_Library library = nullptr;
    if (FT_Init_FreeType(&library) != 0) return f;
    FT_Face regular = nullptr, bold = nullptr;
    if (FT_New_Face(library, kFontFile, 0, &regular) != 0 || FT_New_Face(library, kBoldFontFile, 0, &bold) != 0) {
      return f;
    }
    f.regular = cairo_ft_font_face_create_for_ft_face(regular, 0);
    f.bold = cairo_ft_font_face_create_for_ft_face(bold, 0);
    return f;
  }();
  return faces;
}

// Selects DejaVu Sans (bold or regular) at `size_pt` on `cr`.
void SetFont(cairo_t* cr, double size_pt, bool bold = false) {
  const FontFaces& faces = DejaVuFaces();
  if (faces.regular != nullptr && faces.bold != nullptr) {
    cairo_set_font_face(cr, bold ? faces.bold : faces.regular);
  } else {
    cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  }
  cairo_set_font_size(cr, size_pt);
}

struct Column {
  const char* title;
  double width_pt;
};
constexpr Column kColumns[] = {{"No.", 24},   {"Name", 58},       {"x (m)", 60},  {"y (m)", 60},
                               {"Floor", 34}, {"Tripod (m)", 54}, {"Station", 44}};

// The page geometry and what goes on each page, shared by the layout (for tests) and the drawing.
struct Sheet {
  double width = 0, height = 0, side_width = 0;
  floor_plan::Floors floors;
  double scale_denominator = 0, pt_per_m = 0;
  double plan_left = 0, plan_top = 0, plan_width = 0, plan_height = 0;
  double centre_x = 0, centre_y = 0;            // footprint centre (local, m), drawn at the plan area's centre
  double table_top = 0;                         // top of the station table in the side column
  std::vector<int> station_panel;               // per FieldStation given
  std::vector<std::string> names;               // per FieldStation: its label, name and tripod height
  std::vector<PlacedLabel> numbers;             // per FieldStation: its numbered marker's place
  std::vector<PlacedLabel> name_places;         // per FieldStation: its name label's place
  std::vector<std::vector<size_t>> floor_rows;  // per floor page, the stations in its table
  std::vector<std::vector<size_t>> table_page_rows;

  double PageX(double x_m) const { return plan_left + plan_width / 2 + (x_m - centre_x) * pt_per_m; }
  double PageY(double y_m) const { return plan_top + plan_height / 2 - (y_m - centre_y) * pt_per_m; }
  double SideLeft() const { return width - kMargin - side_width; }
};

// The smallest round scale 1:N (1, 1.25, 2, 2.5, 5 x 10^k, at least 1:20) at which `extent_m` fits in
// `room_pt`.
double RoundScale(double extent_m, double room_pt) {
  const double needed = extent_m * kPointsPerMetre / std::max(room_pt, 1.0);
  for (double decade = 10; decade < 1e9; decade *= 10) {
    for (double m : {1.0, 1.25, 2.0, 2.5, 5.0}) {
      if (m * decade >= std::max(needed, 20.0)) return m * decade;
    }
  }
  return needed;
}

// The station table's rows: each floor page lists its stations in walking order, up to
// `table_capacity`; the rest continue on table pages of `table_page_capacity` rows.
void AssignRows(Sheet& s, size_t stations, int table_capacity, int table_page_capacity) {
  s.floor_rows.assign(s.floors.panel_z.size(), {});
  std::vector<size_t> overflow;
  for (size_t k = 0; k < stations; ++k) {
    auto& rows = s.floor_rows[size_t(s.station_panel[k])];
    if (static_cast<int>(rows.size()) < table_capacity) {
      rows.push_back(k);
    } else {
      overflow.push_back(k);
    }
  }
  for (size_t start = 0; start < overflow.size(); start += size_t(table_page_capacity)) {
    const size_t end = std::min(overflow.size(), start + size_t(table_page_capacity));
    s.table_page_rows.emplace_back(overflow.begin() + long(start), overflow.begin() + long(end));
  }
}

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

// A station's label beside its marker: "S03  h 1.60 m", or the name alone without a floor.
std::string NameLabel(const FieldStation& f) {
  return std::isfinite(f.tripod_height_m) ? f.name + "  h " + Fixed(f.tripod_height_m, 2) + " m" : f.name;
}

// Where each floor page draws its stations' numbered markers and names (PlaceLabels, in walking
// order): a marker centred on its station unless that covers another station or marker, else moved
// aside with a leader line back to a dot at the station; then each name beside its marker, or
// further out with a leader line. Text is measured on a PDF surface that writes nothing, with the
// fonts the sheet draws with.
void PlaceStationLabels(Sheet& s, const PlanResult& r, const std::vector<FieldStation>& stations) {
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(nullptr, nullptr, s.width, s.height);
  cairo_t* cr = cairo_create(surface);
  SetFont(cr, kNameFontSize);
  s.names.resize(stations.size());
  s.numbers.resize(stations.size());
  s.name_places.resize(stations.size());
  LabelPlacementOptions options;
  options.bounds = {s.plan_left, s.plan_top, s.plan_left + s.plan_width, s.plan_top + s.plan_height};
  for (size_t panel = 0; panel < s.floors.panel_z.size(); ++panel) {
    std::vector<size_t> here;
    std::vector<LabelRequest> markers, names;
    for (size_t k = 0; k < stations.size(); ++k) {
      if (s.station_panel[k] != static_cast<int>(panel) || stations[k].index >= r.stations.size()) continue;
      const WorldPoint& p = r.stations[stations[k].index].position;
      // A circle of radius 7 or a square of half-side 9, and half their 1.3 pt ring.
      const double side = 2 * ((stations[k].fixed ? kMarkerRadius + 2 : kMarkerRadius) + 0.65);
      markers.push_back({{s.PageX(p.x()), s.PageY(p.y())}, kDotRadius + 0.5, side, side});
      here.push_back(k);
    }
    options.centred_first = true;
    const std::vector<PlacedLabel> placed = PlaceLabels(markers, {}, options);
    std::vector<LabelBox> taken;
    for (size_t i = 0; i < here.size(); ++i) {
      taken.push_back(placed[i].box);
      const LabelPoint& a = markers[i].anchor;
      taken.push_back({a.x - markers[i].anchor_radius, a.y - markers[i].anchor_radius, a.x + markers[i].anchor_radius,
                       a.y + markers[i].anchor_radius});
      s.numbers[here[i]] = placed[i];
      s.names[here[i]] = NameLabel(stations[here[i]]);
      cairo_text_extents_t e;
      cairo_text_extents(cr, s.names[here[i]].c_str(), &e);
      const LabelBox& b = placed[i].box;
      names.push_back({{0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1)}, kMarkerRadius + 2, e.x_advance + 2, kNameHeight});
    }
    options.centred_first = false;
    const std::vector<PlacedLabel> named = PlaceLabels(names, taken, options);
    for (size_t i = 0; i < here.size(); ++i) s.name_places[here[i]] = named[i];
  }
  cairo_destroy(cr);
  cairo_surface_destroy(surface);
}

Sheet ComputeSheet(const PlanResult& r, const std::vector<FieldStation>& stations, const FieldSheetOptions& o) {
  Sheet s;
  const bool a3 = o.paper == PaperSize::kA3;
  s.width = a3 ? 1190.55 : 841.89;
  s.height = a3 ? 841.89 : 595.28;
  double side = 0;
  for (const Column& c : kColumns) side += c.width_pt;
  s.side_width = side;
  const double cell = r.heat_map.grid_spacing_m > 0 ? r.heat_map.grid_spacing_m : 1.0;
  s.floors = floor_plan::ComputeFloors(r, cell / 2);
  s.plan_left = kMargin;
  s.plan_top = kMargin + kTitleBand;
  s.plan_width = s.width - 2 * kMargin - side - kGutter;
  s.plan_height = s.height - s.plan_top - kMargin;
  const double w = std::max(s.floors.x1 - s.floors.x0, 1e-3), h = std::max(s.floors.y1 - s.floors.y0, 1e-3);
  s.scale_denominator = std::max(RoundScale(w, s.plan_width), RoundScale(h, s.plan_height));
  s.pt_per_m = kPointsPerMetre / s.scale_denominator;
  s.centre_x = 0.5 * (s.floors.x0 + s.floors.x1);
  s.centre_y = 0.5 * (s.floors.y0 + s.floors.y1);
  s.station_panel = floor_plan::StationPanels(s.floors, r, stations);
  s.table_top = s.plan_top + kSideBlock + kLegendRows * kLegendRow + 24;
  const int capacity = static_cast<int>((s.height - kMargin - s.table_top - kTableHeader) / kRowHeight);
  const int page_capacity = static_cast<int>((s.height - 2 * kMargin - kTitleBand - kTableHeader) / kRowHeight);
  AssignRows(s, stations.size(), std::max(capacity, 0), std::max(page_capacity, 1));
  PlaceStationLabels(s, r, stations);
  return s;
}

// A tripod height for the table; "-" for a station with no floor below it.
std::string Height(double h_m) { return std::isfinite(h_m) ? Fixed(h_m, 2) : "-"; }

// "2 h 05 min", "35 min", "40 s".
std::string Duration(double seconds) {
  const long total_min = std::lround(seconds / 60);
  if (seconds < 60) return std::to_string(std::lround(seconds)) + " s";
  if (total_min < 60) return std::to_string(total_min) + " min";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%ld h %02ld min", total_min / 60, total_min % 60);
  return buf;
}

// Draws the pages of one sheet onto a cairo context.
class FieldSheetPainter {
 public:
  FieldSheetPainter(cairo_t* cr, const PlanResult& r, const std::vector<FieldStation>& stations,
                    const FieldSheetOptions& options, const Sheet& sheet)
      : cr_(cr), r_(r), stations_(stations), options_(options), s_(sheet) {}

  void DrawAll() {
    const int pages = static_cast<int>(s_.floors.panel_z.size() + s_.table_page_rows.size());
    for (size_t p = 0; p < s_.floors.panel_z.size(); ++p) {
      DrawFloorPage(static_cast<int>(p), pages);
      cairo_show_page(cr_);
    }
    for (size_t t = 0; t < s_.table_page_rows.size(); ++t) {
      const int page = static_cast<int>(s_.floors.panel_z.size() + t);
      DrawTitle("Stations, continued", page, pages);
      DrawTable(s_.table_page_rows[t], kMargin, kMargin + kTitleBand, "Stations, continued (in walking order)");
      cairo_show_page(cr_);
    }
  }

 private:
  void Font(double size_pt, bool bold = false) { SetFont(cr_, size_pt, bold); }
  // Text with its baseline at y; `align` 0 left, 0.5 centred, 1 right.
  void Text(double x, double y, const std::string& text, double align = 0) {
    cairo_text_extents_t e;
    cairo_text_extents(cr_, text.c_str(), &e);
    cairo_move_to(cr_, x - align * e.x_advance, y);
    cairo_show_text(cr_, text.c_str());
  }
  void Grey(double g) { cairo_set_source_rgb(cr_, g, g, g); }

  std::string FloorName(int panel) const {
    return floor_plan::PanelNames(s_.floors, stations_, s_.station_panel)[size_t(panel)];
  }

  void DrawTitle(const std::string& title, int page, int pages) {
    Grey(0);
    Font(16, true);
    Text(kMargin, kMargin + 14, title);
    Font(9);
    Text(s_.width - kMargin, kMargin + 14,
         "fieldsheet.pdf   page " + std::to_string(page + 1) + " of " + std::to_string(pages), 1);
    const double occupied = static_cast<double>(r_.occupied_voxels);
    const double covered = occupied > 0 ? 100.0 * static_cast<double>(r_.covered_voxels) / occupied : 0.0;
    size_t existing = 0;
    for (const PlannedStation& st : r_.stations) existing += st.fixed ? 1 : 0;
    const std::string scanning =
        r_.field_time.scan_seconds_per_station > 0 ? "scanning " + Duration(r_.field_time.scan_s) : "scan time unknown";
    Font(10);
    Text(kMargin, kMargin + 32,
         std::to_string(r_.stations.size()) + " stations (" + std::to_string(r_.stations.size() - existing) + " new, " +
             std::to_string(existing) + " existing)   covers " + Fixed(covered, 1) +
             " % of the scene   field time about " + Duration(r_.field_time.total_s) + " (set-up " +
             Duration(r_.field_time.setup_s) + ", " + scanning + ", walking " + Duration(r_.field_time.walk_s) + ")");
  }

  void DrawFloorPage(int panel, int pages) {
    const std::string label = FloorName(panel);
    const double floor_z = s_.floors.floor_m[size_t(panel)] + r_.frame_origin_m.z();
    std::string title = "Field sheet: floor " + label;
    title += " (floor at z = " + Fixed(floor_z, 2) + " m)";
    DrawTitle(title, panel, pages);
    cairo_save(cr_);
    cairo_rectangle(cr_, s_.plan_left, s_.plan_top, s_.plan_width, s_.plan_height);
    cairo_clip(cr_);
    DrawSlice(panel);
    DrawZones(panel);
    DrawRoute(panel);
    DrawStations(panel);
    cairo_restore(cr_);
    cairo_set_line_width(cr_, 0.8);
    Grey(0);
    cairo_rectangle(cr_, s_.plan_left, s_.plan_top, s_.plan_width, s_.plan_height);
    cairo_stroke(cr_);
    DrawNorthArrow(s_.SideLeft(), s_.plan_top);
    DrawScaleBar(s_.SideLeft() + 120, s_.plan_top + 20);
    DrawLegend(s_.SideLeft(), s_.plan_top + kSideBlock);
    DrawTable(s_.floor_rows[size_t(panel)], s_.SideLeft(), s_.table_top, "Stations on this floor (in walking order)");
  }

  void DrawSlice(int panel);
  void DrawZones(int panel);
  void DrawRoute(int panel);
  void DrawStations(int panel);
  void DrawArrowHead(double x, double y, double dx, double dy, double size);
  void DrawNorthArrow(double left, double top);
  void DrawScaleBar(double left, double top);
  void DrawLegend(double left, double top);
  void DrawTable(const std::vector<size_t>& rows, double left, double top, const std::string& heading);
  void HatchPath(double spacing_pt);
  void StationMarker(double x, double y, const FieldStation& f);

  cairo_t* cr_;
  const PlanResult& r_;
  const std::vector<FieldStation>& stations_;
  const FieldSheetOptions& options_;
  const Sheet& s_;
};

// The panel's slice (walls and objects, floor_plan::SlicePanels) as a grey image at voxel
// resolution (coarser when the footprint would exceed 4000 cells a side), without smoothing.
void FieldSheetPainter::DrawSlice(int panel) {
  if (r_.resolution_m <= 0) return;
  const floor_plan::Floors& f = s_.floors;
  const double cell = std::max(r_.resolution_m, std::max(f.x1 - f.x0, f.y1 - f.y0) / 4000);
  const int nx = std::max(1, static_cast<int>(std::ceil((f.x1 - f.x0) / cell)));
  const int ny = std::max(1, static_cast<int>(std::ceil((f.y1 - f.y0) / cell)));
  std::vector<float> above(size_t(nx) * size_t(ny), -1.f);
  for (const WorldPoint& v : r_.voxel_centers) {
    if (!((floor_plan::SlicePanels(f, r_, v.z()) >> panel) & 1)) continue;
    const int ix = std::clamp(static_cast<int>(std::floor((v.x() - f.x0) / cell)), 0, nx - 1);
    const int iy = std::clamp(static_cast<int>(std::floor((f.y1 - v.y()) / cell)), 0, ny - 1);
    float& a = above[size_t(iy) * size_t(nx) + size_t(ix)];
    a = std::max(a, static_cast<float>(v.z() - f.floor_m[size_t(panel)]));
  }
  cairo_surface_t* img = cairo_image_surface_create(CAIRO_FORMAT_RGB24, nx, ny);
  cairo_surface_flush(img);
  unsigned char* data = cairo_image_surface_get_data(img);
  const int stride = cairo_image_surface_get_stride(img);
  const double top = floor_plan::HighestTripodHeight(r_);
  for (int y = 0; y < ny; ++y) {
    auto* row = reinterpret_cast<uint32_t*>(data + size_t(y) * size_t(stride));
    for (int x = 0; x < nx; ++x) {
      const float a = above[size_t(y) * size_t(nx) + size_t(x)];
      const uint32_t g = a >= 0 ? floor_plan::SliceGrey(a, top) : 255u;
      row[x] = (g << 16) | (g << 8) | g;
    }
  }
  cairo_surface_mark_dirty(img);
  cairo_save(cr_);
  cairo_translate(cr_, s_.PageX(f.x0), s_.PageY(f.y1));
  cairo_scale(cr_, cell * s_.pt_per_m, cell * s_.pt_per_m);
  cairo_set_source_surface(cr_, img, 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr_), CAIRO_FILTER_NEAREST);
  cairo_paint(cr_);
  cairo_restore(cr_);
  cairo_surface_destroy(img);
}

// Diagonal hatching inside the current path (which it consumes), lines `spacing_pt` apart.
void FieldSheetPainter::HatchPath(double spacing_pt) {
  double x0, y0, x1, y1;
  cairo_path_extents(cr_, &x0, &y0, &x1, &y1);
  cairo_save(cr_);
  cairo_clip(cr_);
  cairo_set_line_width(cr_, 0.7);
  for (double d = -(y1 - y0); d < x1 - x0; d += spacing_pt) {
    cairo_move_to(cr_, x0 + d, y1);
    cairo_line_to(cr_, x0 + d + (y1 - y0), y0);
  }
  cairo_stroke(cr_);
  cairo_restore(cr_);
}

// Keep-out zones whose z range meets the panel's band (floor to the highest tripod height):
// outlined and hatched.
void FieldSheetPainter::DrawZones(int panel) {
  for (const KeepOutZone& z : r_.options.keep_out) {
    if (!floor_plan::ZoneOnPanel(s_.floors, r_, z, panel)) continue;
    const std::vector<double> xy = floor_plan::ZoneOutlineLocal(r_, z);
    auto outline = [&] {
      cairo_new_path(cr_);
      for (size_t i = 0; i + 1 < xy.size(); i += 2) cairo_line_to(cr_, s_.PageX(xy[i]), s_.PageY(xy[i + 1]));
      cairo_close_path(cr_);
    };
    Grey(1);
    outline();
    cairo_fill(cr_);
    Grey(0);
    outline();
    HatchPath(5);
    outline();
    cairo_set_line_width(cr_, 1.2);
    cairo_stroke(cr_);
  }
}

// A filled arrow head with its tip at (x, y) pointing along (dx, dy).
void FieldSheetPainter::DrawArrowHead(double x, double y, double dx, double dy, double size) {
  const double len = std::hypot(dx, dy);
  if (len <= 0) return;
  dx /= len, dy /= len;
  cairo_move_to(cr_, x, y);
  cairo_line_to(cr_, x - size * dx + 0.45 * size * dy, y - size * dy - 0.45 * size * dx);
  cairo_line_to(cr_, x - size * dx - 0.45 * size * dy, y - size * dy + 0.45 * size * dx);
  cairo_close_path(cr_);
  cairo_fill(cr_);
}

// The walking route's paths on this floor: a dashed black line with an arrow head every 60 pt of
// paper along it, in walking order. Steps between floors (stairs) are not drawn.
void FieldSheetPainter::DrawRoute(int panel) {
  const double lowest = floor_plan::LowestTripodHeight(r_);
  Grey(0);
  cairo_set_line_width(cr_, 1.4);
  const double dash[] = {6, 3};
  double travelled = 0, next_arrow = 30;  // along the drawn route, pt of paper
  for (const std::vector<WorldPoint>& line : r_.route.polylines) {
    for (size_t k = 1; k < line.size(); ++k) {
      if (floor_plan::NearestPanel(s_.floors, line[k - 1].z() + lowest) != panel ||
          floor_plan::NearestPanel(s_.floors, line[k].z() + lowest) != panel)
        continue;
      const double ax = s_.PageX(line[k - 1].x()), ay = s_.PageY(line[k - 1].y());
      const double bx = s_.PageX(line[k].x()), by = s_.PageY(line[k].y());
      cairo_set_dash(cr_, dash, 2, 0);
      cairo_move_to(cr_, ax, ay);
      cairo_line_to(cr_, bx, by);
      cairo_stroke(cr_);
      cairo_set_dash(cr_, nullptr, 0, 0);
      const double len = std::hypot(bx - ax, by - ay);
      for (; next_arrow <= travelled + len; next_arrow += 60) {
        const double t = (next_arrow - travelled) / len;
        DrawArrowHead(ax + t * (bx - ax), ay + t * (by - ay), bx - ax, by - ay, 8);
      }
      travelled += len;
    }
  }
}

// A station's marker: a new station a white disc with a black ring, an existing one a white
// square with a double ring; the number inside, the name and tripod height beside it.
void FieldSheetPainter::StationMarker(double x, double y, const FieldStation& f) {
  const double r = kMarkerRadius;
  cairo_new_path(cr_);  // text leaves a current point an arc would join
  cairo_set_line_width(cr_, 1.3);
  if (f.fixed) {
    Grey(1);
    cairo_rectangle(cr_, x - r - 2, y - r - 2, 2 * r + 4, 2 * r + 4);
    cairo_fill_preserve(cr_);
    Grey(0);
    cairo_stroke(cr_);
    cairo_rectangle(cr_, x - r + 0.5, y - r + 0.5, 2 * r - 1, 2 * r - 1);
    cairo_set_line_width(cr_, 0.8);
    cairo_stroke(cr_);
  } else {
    Grey(1);
    cairo_arc(cr_, x, y, r, 0, 2 * M_PI);
    cairo_fill_preserve(cr_);
    Grey(0);
    cairo_stroke(cr_);
  }
  const std::string number = std::to_string(f.number);
  Font(number.size() > 2 ? 5.5 : 7, true);
  Text(x, y + 2.5, number, 0.5);
}

// The floor's stations where PlaceStationLabels put them: first the leader lines (thin, black) of
// markers and names moved aside and the dots at their stations, then the markers, then each label
// ("S03  h 1.60 m") on a white ground.
void FieldSheetPainter::DrawStations(int panel) {
  std::vector<size_t> here;
  for (size_t k = 0; k < stations_.size(); ++k) {
    if (s_.station_panel[k] == panel && stations_[k].index < r_.stations.size()) here.push_back(k);
  }
  auto centre = [](const LabelBox& b) { return LabelPoint{0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1)}; };
  Grey(0);
  cairo_new_path(cr_);
  cairo_set_line_width(cr_, 0.8);
  for (size_t k : here) {
    const WorldPoint& p = r_.stations[stations_[k].index].position;
    if (s_.numbers[k].leader) {
      cairo_move_to(cr_, s_.PageX(p.x()), s_.PageY(p.y()));
      cairo_line_to(cr_, centre(s_.numbers[k].box).x, centre(s_.numbers[k].box).y);
    }
    if (s_.name_places[k].leader) {
      cairo_move_to(cr_, s_.name_places[k].leader_start.x, s_.name_places[k].leader_start.y);
      cairo_line_to(cr_, s_.name_places[k].leader_end.x, s_.name_places[k].leader_end.y);
    }
  }
  cairo_stroke(cr_);
  for (size_t k : here) {
    if (!s_.numbers[k].leader) continue;
    const WorldPoint& p = r_.stations[stations_[k].index].position;
    cairo_new_path(cr_);
    cairo_arc(cr_, s_.PageX(p.x()), s_.PageY(p.y()), kDotRadius, 0, 2 * M_PI);
    cairo_fill(cr_);
  }
  for (size_t k : here) StationMarker(centre(s_.numbers[k].box).x, centre(s_.numbers[k].box).y, stations_[k]);
  Font(kNameFontSize);
  for (size_t k : here) {
    const LabelBox& b = s_.name_places[k].box;
    Grey(1);
    cairo_rectangle(cr_, b.x0, b.y0, b.x1 - b.x0, b.y1 - b.y0);
    cairo_fill(cr_);
    Grey(0);
    Text(b.x0 + 1, b.y1 - 2, s_.names[k]);
  }
}

// Grid north (+y of the input's frame) as an arrow; with a known angle, true north beside it.
void FieldSheetPainter::DrawNorthArrow(double left, double top) {
  auto arrow = [&](double cx, double angle_deg, const std::string& caption, bool filled) {
    const double a = angle_deg * M_PI / 180, len = 46, cy = top + 12 + len / 2;
    const double dx = std::sin(a), dy = -std::cos(a);
    Grey(0);
    cairo_set_line_width(cr_, 1.5);
    cairo_move_to(cr_, cx - dx * len / 2, cy - dy * len / 2);
    cairo_line_to(cr_, cx + dx * (len / 2 - 8), cy + dy * (len / 2 - 8));
    cairo_stroke(cr_);
    DrawArrowHead(cx + dx * len / 2, cy + dy * len / 2, dx, dy, 14);
    if (!filled) {
      Grey(1);
      DrawArrowHead(cx + dx * (len / 2 - 3), cy + dy * (len / 2 - 3), dx, dy, 8);
      Grey(0);
    }
    Font(11, true);
    Text(cx + dx * (len / 2 + 9), cy + dy * (len / 2 + 9) + 4, "N", 0.5);
    Font(7.5);
    Text(cx, top + len + 34, caption, 0.5);
  };
  arrow(left + 26, 0, "grid north", true);
  if (std::isfinite(options_.true_north_from_grid_deg)) {
    arrow(left + 86, options_.true_north_from_grid_deg,
          "true north (" + Fixed(options_.true_north_from_grid_deg, 1) + "\u00b0)", false);
  }
}

// A scale bar of a round length (1, 2, 5 x 10^k m, at most 150 pt of paper) in four alternate
// black and white parts, and the drawing's scale.
void FieldSheetPainter::DrawScaleBar(double left, double top) {
  double length_m = 0.01;
  for (double decade = 0.01; decade < 1e6; decade *= 10) {
    for (double m : {1.0, 2.0, 5.0}) {
      if (m * decade * s_.pt_per_m <= 150) length_m = m * decade;
    }
  }
  const double w = length_m * s_.pt_per_m, h = 6;
  cairo_set_line_width(cr_, 0.8);
  for (int i = 0; i < 4; ++i) {
    cairo_rectangle(cr_, left + i * w / 4, top + 14, w / 4, h);
    Grey(i % 2 == 0 ? 0 : 1);
    cairo_fill_preserve(cr_);
    Grey(0);
    cairo_stroke(cr_);
  }
  auto metres = [](double v) { return v >= 1 ? Fixed(v, v == std::floor(v) ? 0 : 1) : Fixed(v, 2); };
  Font(7.5);
  Text(left, top + 10, "0", 0.5);
  Text(left + w / 2, top + 10, metres(length_m / 2), 0.5);
  Text(left + w, top + 10, metres(length_m) + " m", 0.5);
  Font(9);
  Text(left, top + 38,
       "Scale 1:" + Fixed(s_.scale_denominator, 0) + " on " + (options_.paper == PaperSize::kA3 ? "A3" : "A4"));
  Font(7.5);
  Text(left, top + 52, "Coordinates: the input's frame, metres");
}

void FieldSheetPainter::DrawLegend(double left, double top) {
  Font(9, true);
  Grey(0);
  Text(left, top, "Legend");
  const double floor_to = floor_plan::HighestTripodHeight(r_);
  const std::string rows[kLegendRows] = {
      "New station: number = order in which to set up",
      "Existing station (already scanned, kept)",
      "Walking route; arrows point the way",
      "Keep-out zone: no tripod here",
      "Wall or object up to the tripod (" + Fixed(floor_to, 2) + " m above the floor)",
      "Low object, e.g. furniture (lighter = lower)",
      "Station name and tripod height above the floor",
  };
  for (int i = 0; i < kLegendRows; ++i) {
    const double cy = top + 12 + i * kLegendRow, cx = left + 12;
    Grey(0);
    cairo_set_line_width(cr_, 1.2);
    cairo_new_path(cr_);
    switch (i) {
      case 0:
        cairo_arc(cr_, cx, cy, 6, 0, 2 * M_PI);
        cairo_stroke(cr_);
        break;
      case 1:
        cairo_rectangle(cr_, cx - 6, cy - 6, 12, 12);
        cairo_rectangle(cr_, cx - 4, cy - 4, 8, 8);
        cairo_stroke(cr_);
        break;
      case 2: {
        const double dash[] = {6, 3};
        cairo_set_dash(cr_, dash, 2, 0);
        cairo_move_to(cr_, cx - 11, cy);
        cairo_line_to(cr_, cx + 4, cy);
        cairo_stroke(cr_);
        cairo_set_dash(cr_, nullptr, 0, 0);
        DrawArrowHead(cx + 11, cy, 1, 0, 8);
        break;
      }
      case 3:
        cairo_rectangle(cr_, cx - 10, cy - 6, 20, 12);
        HatchPath(4);
        cairo_rectangle(cr_, cx - 10, cy - 6, 20, 12);
        cairo_stroke(cr_);
        break;
      case 4:
      case 5: {
        const double g = floor_plan::SliceGrey(i == 4 ? floor_to : 0.0, floor_to) / 255.0;
        cairo_rectangle(cr_, cx - 10, cy - 6, 20, 12);
        Grey(g);
        cairo_fill(cr_);
        break;
      }
      default:
        Font(7);
        Text(cx - 11, cy + 3, "h 1.60");
        break;
    }
    Grey(0);
    Font(8);
    Text(left + 30, cy + 3, rows[i]);
  }
}

// The station table: number, name, x, y (the input's frame), floor, tripod height, new/existing.
void FieldSheetPainter::DrawTable(const std::vector<size_t>& rows, double left, double top,
                                  const std::string& heading) {
  Grey(0);
  Font(9, true);
  Text(left, top + 10, heading);
  Font(7.5, true);
  double x = left;
  for (const Column& c : kColumns) {
    Text(x + c.width_pt - 4, top + 24, c.title, 1);
    x += c.width_pt;
  }
  cairo_set_line_width(cr_, 0.6);
  cairo_move_to(cr_, left, top + kTableHeader - 3);
  cairo_line_to(cr_, x, top + kTableHeader - 3);
  cairo_stroke(cr_);
  Font(7.5);
  for (size_t i = 0; i < rows.size(); ++i) {
    const FieldStation& f = stations_[rows[i]];
    const double y = top + kTableHeader + (static_cast<double>(i) + 1) * kRowHeight - 3;
    if (i % 2 == 1) {
      Grey(0.92);
      cairo_rectangle(cr_, left, y - kRowHeight + 3, x - left, kRowHeight);
      cairo_fill(cr_);
      Grey(0);
    }
    const std::string cells[] = {std::to_string(f.number),        f.name,
                                 Fixed(f.position_m.x(), 3),      Fixed(f.position_m.y(), 3),
                                 f.floor.empty() ? "-" : f.floor, Height(f.tripod_height_m),
                                 f.fixed ? "existing" : "new"};
    double cx = left;
    for (size_t c = 0; c < std::size(kColumns); ++c) {
      Text(cx + kColumns[c].width_pt - 4, y, cells[c], 1);
      cx += kColumns[c].width_pt;
    }
  }
}

cairo_status_t AppendToString(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

FieldSheetLayout ComputeFieldSheetLayout(const PlanResult& result, const std::vector<FieldStation>& stations,
                                         const FieldSheetOptions& options) {
  const Sheet s = ComputeSheet(result, stations, options);
  FieldSheetLayout layout;
  layout.page_width_pt = s.width;
  layout.page_height_pt = s.height;
  layout.floor_pages = static_cast<int>(s.floors.panel_z.size());
  layout.table_pages = static_cast<int>(s.table_page_rows.size());
  layout.scale_denominator = s.scale_denominator;
  for (size_t k = 0; k < stations.size(); ++k) {
    const WorldPoint p =
        stations[k].index < result.stations.size() ? result.stations[stations[k].index].position : WorldPoint(0, 0, 0);
    layout.markers.push_back({s.station_panel[k], s.PageX(p.x()), s.PageY(p.y()), s.numbers[k], s.name_places[k]});
  }
  return layout;
}

Result<std::string> FieldSheetPdf(const PlanResult& result, const std::vector<FieldStation>& stations,
                                  const FieldSheetOptions& options) {
  const Sheet s = ComputeSheet(result, stations, options);
  std::string pdf;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(AppendToString, &pdf, s.width, s.height);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, "Field sheet");
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "vc");
  cairo_t* cr = cairo_create(surface);
  FieldSheetPainter(cr, result, stations, options, s).DrawAll();
  const cairo_status_t drawn = cairo_status(cr);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t finished = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  for (cairo_status_t status : {drawn, finished}) {
    if (status != CAIRO_STATUS_SUCCESS) {
      return InternalError(std::string("fieldsheet.pdf: cairo failed: ") + cairo_status_to_string(status));
    }
  }
  return pdf;
}

}  // namespace vc
