#include "floor_plan.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace vc::floor_plan {

double LowestTripodHeight(const PlanResult& r) {
  const std::vector<double> heights = r.options.TripodHeights();
  return *std::min_element(heights.begin(), heights.end());
}

double HighestTripodHeight(const PlanResult& r) {
  const std::vector<double> heights = r.options.TripodHeights();
  return *std::max_element(heights.begin(), heights.end());
}

unsigned SlicePanels(const Floors& floors, const PlanResult& r, double z) {
  unsigned panels = 0;
  const double top = HighestTripodHeight(r);
  for (size_t p = 0; p < floors.floor_m.size(); ++p) {
    const double above = z - floors.floor_m[p];
    if (above >= 0.25 * r.resolution_m && above <= top) panels |= 1u << p;
  }
  return panels;
}

uint8_t SliceGrey(double above, double top) {
  const double t = std::clamp(above / std::max(top, 1e-6), 0.0, 1.0);
  return static_cast<uint8_t>(std::lround(175 - 135 * t));
}

int NearestPanel(const Floors& floors, double z) {
  int panel = 0;
  double best = 1e300;
  for (size_t p = 0; p < floors.panel_z.size(); ++p) {
    if (std::fabs(floors.panel_z[p] - z) < best) best = std::fabs(floors.panel_z[p] - z), panel = static_cast<int>(p);
  }
  return panel;
}

std::vector<double> ZoneOutlineLocal(const PlanResult& r, const KeepOutZone& z) {
  std::vector<double> xy =
      z.shape == KeepOutShape::kPolygon
          ? z.polygon_xy_m
          : std::vector<double>{z.min.x(), z.min.y(), z.max.x(), z.min.y(), z.max.x(), z.max.y(), z.min.x(), z.max.y()};
  for (size_t i = 0; i + 1 < xy.size(); i += 2) xy[i] -= r.frame_origin_m.x(), xy[i + 1] -= r.frame_origin_m.y();
  return xy;
}

bool ZoneOnPanel(const Floors& floors, const PlanResult& r, const KeepOutZone& zone, int panel) {
  const double floor = floors.floor_m[size_t(panel)];
  const double band_top = floor + HighestTripodHeight(r);
  const double zmin = zone.min.z() - r.frame_origin_m.z(), zmax = zone.max.z() - r.frame_origin_m.z();
  return zmax >= floor && zmin <= band_top;
}

std::vector<int> StationPanels(const Floors& floors, const PlanResult& r, const std::vector<FieldStation>& stations) {
  std::vector<int> panels;
  panels.reserve(stations.size());
  for (const FieldStation& f : stations) {
    const double z = f.index < r.stations.size() ? r.stations[f.index].position.z() : 0.0;
    panels.push_back(NearestPanel(floors, z));
  }
  return panels;
}

std::vector<std::string> PanelNames(const Floors& floors, const std::vector<FieldStation>& stations,
                                    const std::vector<int>& station_panel) {
  std::vector<std::string> names(floors.panel_z.size());
  for (size_t k = 0; k < stations.size() && k < station_panel.size(); ++k) {
    const auto p = static_cast<size_t>(station_panel[k]);
    if (p < names.size() && names[p].empty()) names[p] = stations[k].floor;
  }
  for (size_t p = 0; p < names.size(); ++p) {
    if (names[p].empty()) names[p] = std::to_string(p + 1);
  }
  return names;
}

namespace {

// The z a candidate's panel is chosen by: its floor plus the lowest tripod height when the floor is
// known (so a cell's candidates at several heights share one panel), else its own z. With one
// height that is the candidate's z.
std::vector<double> PanelKeys(const PlanResult& r) {
  const auto& pos = r.heat_map.positions;
  const double lowest = LowestTripodHeight(r);
  const bool floors = r.heat_map.floor_z_m.size() == pos.size();
  std::vector<double> keys;
  for (size_t i = 0; i < pos.size(); ++i) {
    keys.push_back(floors && std::isfinite(r.heat_map.floor_z_m[i]) ? r.heat_map.floor_z_m[i] + lowest : pos[i].z());
  }
  return keys;
}

}  // namespace

Floors ComputeFloors(const PlanResult& r, double pad_m) {
  Floors f;
  const auto& pos = r.heat_map.positions;
  const std::vector<double> keys = PanelKeys(r);
  std::vector<double> zs = keys;
  std::sort(zs.begin(), zs.end());
  std::vector<std::pair<double, double>> groups;  // [lo, hi]
  for (double z : zs) {
    if (groups.empty() || z - groups.back().second > 0.5) groups.push_back({z, z});
    groups.back().second = z;
  }
  if (groups.size() > 4) groups = {{zs.front(), zs.back()}};
  for (const auto& g : groups) f.panel_z.push_back(0.5 * (g.first + g.second));
  if (f.panel_z.empty()) f.panel_z.push_back(0.0);
  for (double key : keys) {
    int k = 0;
    while (k + 1 < static_cast<int>(groups.size()) && key > groups[k].second + 1e-9) ++k;
    f.candidate_panel.push_back(k);
  }
  bool any = false;
  auto grow = [&](const WorldPoint& p, double pad) {
    if (!any) f.x0 = p.x() - pad, f.x1 = p.x() + pad, f.y0 = p.y() - pad, f.y1 = p.y() + pad, any = true;
    f.x0 = std::min(f.x0, p.x() - pad), f.x1 = std::max(f.x1, p.x() + pad);
    f.y0 = std::min(f.y0, p.y() - pad), f.y1 = std::max(f.y1, p.y() + pad);
  };
  for (const WorldPoint& p : pos) grow(p, pad_m);
  for (const PlannedStation& s : r.stations) grow(s.position, pad_m);
  // The walls around the candidates belong to the floor plan: the footprint takes in the voxels
  // drawn on some panel.
  for (double z : f.panel_z) f.floor_m.push_back(z - LowestTripodHeight(r));
  for (const WorldPoint& v : r.voxel_centers) {
    if (SlicePanels(f, r, v.z()) != 0) grow(v, r.resolution_m / 2);
  }
  if (!any) f.x0 = 0, f.x1 = 1, f.y0 = 0, f.y1 = 1;
  return f;
}

}  // namespace vc::floor_plan
