#include "vc/report/field_exports.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>

#include "vc/plan/keep_out.h"

namespace vc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

// A local position in the input's frame; a zero origin keeps the bits (so -0.0 stays -0.0, as
// plan.json and the earlier stations.csv wrote it).
WorldPoint InputFrame(const PlanResult& r, const WorldPoint& local) {
  return r.frame_origin_m.isZero() ? local : WorldPoint(local + r.frame_origin_m);
}
double InputFrameZ(const PlanResult& r, double local_z) {
  return r.frame_origin_m.z() == 0 ? local_z : local_z + r.frame_origin_m.z();
}

// `name` with what the CSV readers split or cut at, quotes and non-printable or non-ASCII bytes as '_'.
std::string CleanName(const std::string& name) {
  std::string out = name;
  for (char& c : out) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u > 0x7e || c == ',' || c == ';' || c == '#' || c == '"') c = '_';
  }
  const size_t first = out.find_first_not_of(' ');
  if (first == std::string::npos) return "";
  return out.substr(first, out.find_last_not_of(' ') - first + 1);
}

// The floor levels stations are labelled by (local frame, ascending): the planner's, or, without
// them (user candidates), the stations' floors grouped where they lie within 0.5 m of each other.
std::vector<double> LabelLevels(const PlanResult& r) {
  if (!r.floor_levels_m.empty()) return r.floor_levels_m;
  std::vector<double> floors;
  for (const PlannedStation& s : r.stations) {
    if (std::isfinite(s.floor_z_m)) floors.push_back(s.floor_z_m);
  }
  std::sort(floors.begin(), floors.end());
  std::vector<double> levels;
  double last = kNaN;
  for (double z : floors) {
    if (levels.empty() || z - last > 0.5) levels.push_back(z);
    last = z;
  }
  return levels;
}

// "L<i>" for the level nearest to `floor_z_m`; empty for a NaN floor or no levels.
std::string FloorLabel(const std::vector<double>& levels, double floor_z_m) {
  if (!std::isfinite(floor_z_m) || levels.empty()) return "";
  size_t best = 0;
  for (size_t i = 1; i < levels.size(); ++i) {
    if (std::fabs(levels[i] - floor_z_m) < std::fabs(levels[best] - floor_z_m)) best = i;
  }
  return std::string("L").append(std::to_string(best));
}

// Station indices in walking order: the route's, then those it leaves out in selection order.
std::vector<size_t> WalkingOrder(const PlanResult& r, std::vector<int>* route_position) {
  route_position->assign(r.stations.size(), 0);
  std::vector<size_t> order;
  for (size_t k = 0; k < r.route.order.size(); ++k) {
    const int s = r.route.order[k];
    if (s < 0 || static_cast<size_t>(s) >= r.stations.size() || (*route_position)[size_t(s)] != 0) continue;
    (*route_position)[size_t(s)] = static_cast<int>(k) + 1;
    order.push_back(size_t(s));
  }
  for (size_t s = 0; s < r.stations.size(); ++s) {
    if ((*route_position)[s] == 0) order.push_back(s);
  }
  return order;
}

// Names in walking order: fixed stations keep theirs; the others get S<n> from a counter that
// skips names already taken, zero-padded to the widest number (at least two digits).
void AssignNames(const PlanResult& r, const std::vector<std::string>& fixed_names, std::vector<FieldStation>& rows) {
  std::vector<std::string> own(r.stations.size());
  std::set<std::string> taken;
  size_t fixed_seen = 0;
  for (size_t s = 0; s < r.stations.size(); ++s) {
    if (!r.stations[s].fixed) continue;
    const size_t j = fixed_seen++;  // the fixed stations come first, in PlanOptions::fixed_stations order
    const std::string name = j < fixed_names.size() ? CleanName(fixed_names[j]) : "";
    if (name.empty() || !taken.insert(name).second) continue;
    own[s] = name;
  }
  size_t unnamed = 0;
  for (const FieldStation& f : rows) unnamed += own[f.index].empty() ? 1 : 0;
  // The largest number the counter can reach: one per unnamed station plus one per name it skips.
  const int width = static_cast<int>(std::max<size_t>(2, std::to_string(unnamed + taken.size()).size()));
  int next = 1;
  for (FieldStation& f : rows) {
    if (!own[f.index].empty()) {
      f.name = own[f.index];
      continue;
    }
    char buf[32];
    do {
      std::snprintf(buf, sizeof(buf), "S%0*d", width, next++);
    } while (taken.count(buf) != 0);
    f.name = buf;
  }
}

}  // namespace

std::vector<FieldStation> FieldStations(const PlanResult& r, const std::vector<std::string>& fixed_station_names) {
  std::vector<int> route_position;
  const std::vector<size_t> order = WalkingOrder(r, &route_position);
  const std::vector<double> levels = LabelLevels(r);
  std::vector<FieldStation> rows;
  for (size_t k = 0; k < order.size(); ++k) {
    const PlannedStation& s = r.stations[order[k]];
    FieldStation f;
    f.number = static_cast<int>(k) + 1;
    f.index = order[k];
    f.position_m = InputFrame(r, s.position);
    f.floor = FloorLabel(levels, s.floor_z_m);
    f.floor_z_m = std::isfinite(s.floor_z_m) ? InputFrameZ(r, s.floor_z_m) : kNaN;
    f.tripod_height_m = std::isfinite(s.floor_z_m) ? s.position.z() - s.floor_z_m : kNaN;
    f.fixed = s.fixed;
    f.route_order = route_position[order[k]];
    f.gain_voxels = s.marginal_gain;
    f.cumulative_coverage = s.cumulative_coverage;
    rows.push_back(std::move(f));
  }
  AssignNames(r, fixed_station_names, rows);
  return rows;
}

namespace {

// The stations.csv units line's words for the input's frame.
std::string FrameWords(const CrsInfo* crs) {
  if (crs == nullptr) return "the input's frame";
  std::string words = "the input's frame, CRS " + (crs->epsg ? "EPSG:" + std::to_string(*crs->epsg) : crs->definition) +
                      " (" + crs->name + ")";
  if (crs->metres_per_unit != 1) {
    char factor[64];
    std::snprintf(factor, sizeof(factor), "%.10g", crs->metres_per_unit);
    words += " whose " + crs->axis_unit + " are given here in metres (1 " + crs->axis_unit + " = " + factor + " m)";
  }
  return words;
}

}  // namespace

std::string FieldStationsCsv(const std::vector<FieldStation>& stations, const CrsInfo* crs) {
  std::string out =
      "# vc stations: lengths in metres in " + FrameWords(crs) +
      " (x_m, y_m, z_m = the instrument's optical centre); "
      "rows in walking order; tripod_height_m above floor_z_m; gain_voxels and cumulative_coverage (0..1 of the "
      "coverable voxels) in selection order, empty for stations that were not selected (an evaluation's)\n"
      "station,name,x_m,y_m,z_m,floor,floor_z_m,tripod_height_m,fixed,route_order,selection_order,gain_voxels,"
      "cumulative_coverage\n";
  for (const FieldStation& f : stations) {
    const bool floor = std::isfinite(f.floor_z_m);
    const bool selected = std::isfinite(f.cumulative_coverage);
    out += std::to_string(f.number) + "," + f.name + "," + Fixed(f.position_m.x(), 6) + "," +
           Fixed(f.position_m.y(), 6) + "," + Fixed(f.position_m.z(), 6) + "," + f.floor + "," +
           (floor ? Fixed(f.floor_z_m, 3) : "") + "," + (floor ? Fixed(f.tripod_height_m, 3) : "") + "," +
           (f.fixed ? "existing" : "new") + "," + std::to_string(f.route_order) + "," + std::to_string(f.index + 1) +
           "," + (selected ? std::to_string(f.gain_voxels) + "," + Fixed(f.cumulative_coverage, 6) : ",") + "\n";
  }
  return out;
}

namespace {

// DXF R12 text: one "code\nvalue\n" pair at a time.
class DxfWriter {
 public:
  void Pair(int code, const std::string& value) {
    char buf[16];
    std::snprintf(buf, sizeof(buf), "%3d\n", code);
    out_ += buf;
    out_ += value;
    out_ += "\n";
  }
  void Pair(int code, int value) { Pair(code, std::to_string(value)); }
  // Group codes 10, 20, 30: `p` (m) to the micrometre.
  void Point(const WorldPoint& p) {
    Pair(10, Fixed(p.x(), 6));
    Pair(20, Fixed(p.y(), 6));
    Pair(30, Fixed(p.z(), 6));
  }
  // A 3D polyline on `layer` through `points`, closed when `closed`.
  void Polyline3d(const std::string& layer, const std::vector<WorldPoint>& points, bool closed) {
    Pair(0, "POLYLINE");
    Pair(8, layer);
    Pair(66, 1);
    Point(WorldPoint::Zero());
    Pair(70, 8 | (closed ? 1 : 0));  // 8: a 3D polyline
    for (const WorldPoint& p : points) {
      Pair(0, "VERTEX");
      Pair(8, layer);
      Point(p);
      Pair(70, 32);  // a 3D polyline's vertex
    }
    Pair(0, "SEQEND");
    Pair(8, layer);
  }
  std::string Take() { return std::move(out_); }

 private:
  std::string out_;
};

struct DxfLayer {
  const char* name;
  int colour;  // AutoCAD colour index
};
// Layer 0 (every drawing's own), then one per kind of entity.
constexpr DxfLayer kDxfLayers[] = {{"0", 7}, {"STATIONS", 1}, {"LABELS", 7}, {"ROUTE", 30}, {"KEEP_OUT", 5}};

// The tables the entities name: the CONTINUOUS line type, the layers and the labels' STANDARD text style.
void DxfTables(DxfWriter& w) {
  w.Pair(0, "SECTION");
  w.Pair(2, "TABLES");
  w.Pair(0, "TABLE");
  w.Pair(2, "LTYPE");
  w.Pair(70, 1);
  w.Pair(0, "LTYPE");
  w.Pair(2, "CONTINUOUS");
  w.Pair(70, 0);
  w.Pair(3, "Solid line");
  w.Pair(72, 65);
  w.Pair(73, 0);
  w.Pair(40, "0.0");
  w.Pair(0, "ENDTAB");
  w.Pair(0, "TABLE");
  w.Pair(2, "LAYER");
  w.Pair(70, static_cast<int>(std::size(kDxfLayers)));
  for (const DxfLayer& l : kDxfLayers) {
    w.Pair(0, "LAYER");
    w.Pair(2, l.name);
    w.Pair(70, 0);
    w.Pair(62, l.colour);
    w.Pair(6, "CONTINUOUS");
  }
  w.Pair(0, "ENDTAB");
  w.Pair(0, "TABLE");
  w.Pair(2, "STYLE");
  w.Pair(70, 1);
  w.Pair(0, "STYLE");
  w.Pair(2, "STANDARD");
  w.Pair(70, 0);
  w.Pair(40, "0.0");  // no fixed height: each TEXT gives its own
  w.Pair(41, "1.0");
  w.Pair(50, "0.0");
  w.Pair(71, 0);
  w.Pair(42, "0.2");
  w.Pair(3, "txt");
  w.Pair(4, "");
  w.Pair(0, "ENDTAB");
  w.Pair(0, "ENDSEC");
}

// The route's walking paths (input frame), one per walkable part: the legs' polylines joined, a
// leg no path links (NaN) starting the next.
std::vector<std::vector<WorldPoint>> RouteParts(const PlanResult& r) {
  std::vector<std::vector<WorldPoint>> parts(1);
  for (size_t k = 0; k < r.route.polylines.size(); ++k) {
    if (k < r.route.legs_m.size() && std::isnan(r.route.legs_m[k]) && !parts.back().empty()) parts.emplace_back();
    for (const WorldPoint& local : r.route.polylines[k]) {
      const WorldPoint p = InputFrame(r, local);
      if (parts.back().empty() || (p - parts.back().back()).norm() > 1e-9) parts.back().push_back(p);
    }
  }
  std::erase_if(parts, [](const std::vector<WorldPoint>& p) { return p.size() < 2; });
  return parts;
}

// A keep-out zone's outline (input frame) at its lowest z.
std::vector<WorldPoint> ZoneOutline(const KeepOutZone& z) {
  std::vector<WorldPoint> out;
  if (z.shape == KeepOutShape::kBox) {
    for (const auto& [x, y] : {std::pair{z.min.x(), z.min.y()}, std::pair{z.max.x(), z.min.y()},
                               std::pair{z.max.x(), z.max.y()}, std::pair{z.min.x(), z.max.y()}}) {
      out.emplace_back(x, y, z.min.z());
    }
    return out;
  }
  for (size_t i = 0; i + 1 < z.polygon_xy_m.size(); i += 2) {
    out.emplace_back(z.polygon_xy_m[i], z.polygon_xy_m[i + 1], z.min.z());
  }
  return out;
}

// RFC 7946's position of the input-frame point `p`: [longitude, latitude], rounded to 1e-9 degrees
// (0.1 mm).
Result<nlohmann::json> Position(const Crs& crs, const WorldPoint& p) {
  VC_ASSIGN_OR_RETURN(const LonLat ll, crs.ToLonLat(p.x(), p.y()));
  const auto round9 = [](double deg) { return std::round(deg * 1e9) / 1e9; };
  return nlohmann::json::array({round9(ll.lon_deg), round9(ll.lat_deg)});
}

nlohmann::json Feature(nlohmann::json geometry, nlohmann::json properties) {
  return {{"type", "Feature"}, {"geometry", std::move(geometry)}, {"properties", std::move(properties)}};
}

// A keep-out zone's footprint as a GeoJSON Polygon: one ring, closed, counter-clockwise (RFC 7946 §3.1.6).
Result<nlohmann::json> FootprintPolygon(const Crs& crs, const KeepOutZone& zone) {
  nlohmann::json ring = nlohmann::json::array();
  for (const WorldPoint& p : ZoneOutline(zone)) {
    VC_ASSIGN_OR_RETURN(nlohmann::json position, Position(crs, p));
    ring.push_back(std::move(position));
  }
  double twice_area = 0;
  for (size_t i = 0; i < ring.size(); ++i) {
    const nlohmann::json& a = ring[i];
    const nlohmann::json& b = ring[(i + 1) % ring.size()];
    twice_area += a[0].get<double>() * b[1].get<double>() - b[0].get<double>() * a[1].get<double>();
  }
  if (twice_area < 0) std::reverse(ring.begin(), ring.end());
  ring.push_back(ring.front());
  return nlohmann::json{{"type", "Polygon"}, {"coordinates", nlohmann::json::array({std::move(ring)})}};
}

}  // namespace

Result<std::string> StationsGeoJson(const PlanResult& r, const std::vector<FieldStation>& stations, const Crs& crs) {
  nlohmann::json features = nlohmann::json::array();
  for (const FieldStation& f : stations) {
    VC_ASSIGN_OR_RETURN(nlohmann::json position, Position(crs, f.position_m));
    const bool floor = std::isfinite(f.floor_z_m);
    features.push_back(Feature({{"type", "Point"}, {"coordinates", std::move(position)}},
                               {{"kind", "station"},
                                {"station", f.number},
                                {"name", f.name},
                                {"tripod_height_m", floor ? nlohmann::json(std::round(f.tripod_height_m * 1e3) / 1e3)
                                                          : nlohmann::json(nullptr)},
                                {"floor", floor ? nlohmann::json(f.floor) : nlohmann::json(nullptr)},
                                {"fixed", f.fixed},
                                {"route_order", f.route_order},
                                {"z_m", std::round(f.position_m.z() * 1e6) / 1e6}}));
  }
  const std::vector<std::vector<WorldPoint>> parts = RouteParts(r);
  for (size_t k = 0; k < parts.size(); ++k) {
    nlohmann::json line = nlohmann::json::array();
    for (const WorldPoint& p : parts[k]) {
      VC_ASSIGN_OR_RETURN(nlohmann::json position, Position(crs, p));
      line.push_back(std::move(position));
    }
    features.push_back(
        Feature({{"type", "LineString"}, {"coordinates", std::move(line)}}, {{"kind", "route"}, {"part", k + 1}}));
  }
  for (size_t k = 0; k < r.options.keep_out.size(); ++k) {
    const KeepOutZone& zone = r.options.keep_out[k];
    VC_ASSIGN_OR_RETURN(nlohmann::json polygon, FootprintPolygon(crs, zone));
    features.push_back(
        Feature(std::move(polygon),
                {{"kind", "keep_out"}, {"zone", k + 1}, {"z_min_m", zone.min.z()}, {"z_max_m", zone.max.z()}}));
  }
  const nlohmann::json collection = {{"type", "FeatureCollection"}, {"features", std::move(features)}};
  return collection.dump(1) + "\n";
}

std::string StationsDxf(const PlanResult& r, const std::vector<FieldStation>& stations) {
  const std::vector<std::vector<WorldPoint>> route = RouteParts(r);
  std::vector<std::vector<WorldPoint>> zones;
  for (const KeepOutZone& z : r.options.keep_out) zones.push_back(ZoneOutline(z));
  // The drawing's extents, so that a CAD program opens on the stations, not on the origin of a
  // survey frame kilometres away.
  Eigen::AlignedBox3d extents;
  for (const FieldStation& f : stations) extents.extend(f.position_m);
  for (const std::vector<WorldPoint>& line : route) {
    for (const WorldPoint& p : line) extents.extend(p);
  }
  for (const std::vector<WorldPoint>& outline : zones) {
    for (const WorldPoint& p : outline) extents.extend(p);
  }
  if (extents.isEmpty()) extents = Eigen::AlignedBox3d(WorldPoint::Zero(), WorldPoint::Zero());

  DxfWriter w;
  w.Pair(999, "vc stations.dxf: metres, the input's frame; layers STATIONS, LABELS, ROUTE, KEEP_OUT");
  w.Pair(0, "SECTION");
  w.Pair(2, "HEADER");
  w.Pair(9, "$ACADVER");
  w.Pair(1, "AC1009");
  w.Pair(9, "$EXTMIN");
  w.Point(extents.min());
  w.Pair(9, "$EXTMAX");
  w.Point(extents.max());
  w.Pair(0, "ENDSEC");
  DxfTables(w);
  w.Pair(0, "SECTION");
  w.Pair(2, "ENTITIES");
  constexpr double kTextHeightM = 0.2;
  for (const FieldStation& f : stations) {
    w.Pair(0, "POINT");
    w.Pair(8, "STATIONS");
    w.Point(f.position_m);
    w.Pair(0, "TEXT");
    w.Pair(8, "LABELS");
    w.Point(f.position_m + WorldPoint(kTextHeightM, kTextHeightM, 0));
    w.Pair(40, Fixed(kTextHeightM, 3));
    w.Pair(1, f.name + (std::isfinite(f.tripod_height_m) ? " h=" + Fixed(f.tripod_height_m, 2) : ""));
  }
  for (const std::vector<WorldPoint>& part : route) w.Polyline3d("ROUTE", part, false);
  for (const std::vector<WorldPoint>& outline : zones) w.Polyline3d("KEEP_OUT", outline, true);
  w.Pair(0, "ENDSEC");
  w.Pair(0, "EOF");
  return w.Take();
}

}  // namespace vc
