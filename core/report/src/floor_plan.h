// The floors of a plan as heatmap.png and fieldsheet.pdf draw them (docs/PLANNING.md, "heatmap.png"):
// the candidates grouped into floor panels by height, the footprint that takes in the walls around
// them, and the slice of occupied voxels that is a floor's plan view (walls and objects between the
// floor and the highest tripod height), with the keep-out zones each floor shows. One place, so both
// pictures show the same floors. Everything here is in the result's local frame. Internal to
// vc_core; pure functions, thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vc/plan/keep_out.h"
#include "vc/plan/planner.h"
#include "vc/report/field_exports.h"

namespace vc::floor_plan {

// A plan's floors: at most 4 panels, else one; every height and bound in the local frame (m).
struct Floors {
  std::vector<double> panel_z;            // representative z of each panel (a floor plus the lowest tripod height)
  std::vector<int> candidate_panel;       // per heat-map position, its panel
  std::vector<double> floor_m;            // the floor (top, m) under each panel: its z less the lowest tripod height
  double x0 = 0, y0 = 0, x1 = 1, y1 = 1;  // footprint: candidates, stations and every panel's slice
};

// The lowest and highest of the plan's tripod heights (m).
double LowestTripodHeight(const PlanResult& r);
double HighestTripodHeight(const PlanResult& r);

// Panels: positions grouped by height (a gap over 0.5 m starts a new group), and the footprint;
// `pad_m` is the margin around each candidate and station (half a heat-map cell).
Floors ComputeFloors(const PlanResult& r, double pad_m);

// Bit p set: a voxel centred at height `z` belongs to panel p's slice (at least a quarter of a voxel
// above its floor's top and at most the highest tripod height above it).
unsigned SlicePanels(const Floors& floors, const PlanResult& r, double z);

// The panel whose representative z lies nearest to `z` (m).
int NearestPanel(const Floors& floors, double z);

// A keep-out zone's outline in the local frame (m): x1, y1, x2, y2, ... (a box's four corners).
std::vector<double> ZoneOutlineLocal(const PlanResult& r, const KeepOutZone& zone);

// True when the zone's z range meets panel p's slice (its floor up to the highest tripod height),
// so the panel draws it.
bool ZoneOnPanel(const Floors& floors, const PlanResult& r, const KeepOutZone& zone, int panel);

// Each of `stations`' panel, in their order: the panel nearest to its height (fieldsheet.pdf's page
// and report.html's floor).
std::vector<int> StationPanels(const Floors& floors, const PlanResult& r, const std::vector<FieldStation>& stations);

// Each panel's name as fieldsheet.pdf titles its page: the floor label (FieldStation::floor, "L0", ...)
// of its first station in `stations` that has one, else the panel's number from 1 ("2").
std::vector<std::string> PanelNames(const Floors& floors, const std::vector<FieldStation>& stations,
                                    const std::vector<int>& station_panel);

// Grey level of a slice column whose highest voxel stands `above` m over the floor, `top` the
// highest tripod height: 175 for low objects down to 40 for what reaches the tripod (walls).
uint8_t SliceGrey(double above, double top);

}  // namespace vc::floor_plan
