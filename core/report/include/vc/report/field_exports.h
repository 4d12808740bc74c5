// What a survey crew takes to the field from a plan: the station table (stations.csv and the
// station fields of plan.json: number and name in walking order, floor, tripod height above that
// floor, existing or new) and stations.dxf for CAD and field software (docs/PLANNING.md,
// "stations.csv" and "stations.dxf").
//
// stations.dxf is DXF R12 text written here, not through Debian's libdxflib: dxflib is GPL-2.0
// (or a commercial licence), which would bind vc-client and vc-server, which link this layer, and
// the four entity kinds needed (POINT, TEXT, POLYLINE/VERTEX, the LAYER table) are a few dozen
// lines of group codes. R12 is the one DXF every CAD program and field controller still imports.
// Pure functions of their arguments: thread-safe (StationsGeoJson as far as its Crs is: one thread
// at a time per Crs).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"
#include "vc/plan/planner.h"
#include "vc/report/crs.h"

namespace vc {

// One station as the crew sees it; every position and height in the input's own frame (m).
struct FieldStation {
  int number = 0;    // 1..N in walking order (the route's order, then unrouted stations in selection order)
  std::string name;  // the fixed station's own name, else "S01", "S02", ... (unique within the plan)
  size_t index = 0;  // into PlanResult::stations (selection order)
  WorldPoint position_m{0, 0, 0};  // the instrument's optical centre
  std::string floor;               // level label, "L0" = the lowest level; empty when nothing lies below the station
  double floor_z_m = 0;            // top of the floor under the station; NaN when none
  double tripod_height_m = 0;      // optical centre above that floor; NaN when there is no floor
  bool fixed = false;              // an existing station (PlanOptions::fixed_stations)
  int route_order = 0;             // place in the walking route (1 = first), 0 when the route leaves it out
  uint64_t gain_voxels = 0;        // voxels it adds to the stations picked before it (selection order)
  // covered / coverable once it and those before it in selection order are scanned; NaN (and
  // gain_voxels 0) for a station that was not selected: an evaluation's (EvaluationAsPlan)
  double cumulative_coverage = 0;
};

// The stations of `result` in walking order. `fixed_station_names`: names of
// PlanOptions::fixed_stations in that order (KnownStation::name); missing or empty ones, and names
// another station already holds, get generated names. Names keep printable ASCII other than
// ',', ';', '#' and '"' (others become '_'), so both CSV readers read them back.
std::vector<FieldStation> FieldStations(const PlanResult& result,
                                        const std::vector<std::string>& fixed_station_names = {});

// stations.csv: a '#' line naming units and orders, a header line, one row per station in walking
// order: station,name,x_m,y_m,z_m,floor,floor_z_m,tripod_height_m,fixed,route_order,
// selection_order,gain_voxels,cumulative_coverage (x, y, z to the micrometre; fixed "existing" or
// "new"; empty cells where a station has no floor). ParseStationsCsv and ParseStationFile read it.
// With `crs`, the '#' line names the CRS the input's frame is in.
std::string FieldStationsCsv(const std::vector<FieldStation>& stations, const CrsInfo* crs = nullptr);

// stations.dxf (DXF R12, metres, the input's frame): layer STATIONS a POINT per optical centre,
// LABELS a TEXT "name h=1.60" beside each, ROUTE one 3D polyline per walkable part of the route
// (its paths over the floors, as plan.json's route.polyline), KEEP_OUT each zone's outline as a
// closed 3D polyline at the zone's lowest z.
std::string StationsDxf(const PlanResult& result, const std::vector<FieldStation>& stations);

// stations.geojson (RFC 7946: WGS 84 longitude, latitude in degrees, 9 decimals): a FeatureCollection
// of a Point per station in walking order (properties kind "station", station, name, tripod_height_m,
// floor, fixed, route_order, z_m), a LineString per walkable part of the route (kind "route", part),
// and a Polygon per keep-out zone's footprint (kind "keep_out", zone, z_min_m, z_max_m; closed ring,
// counter-clockwise), the input's frame being in `crs`. INVALID_ARGUMENT when PROJ cannot place a
// point.
Result<std::string> StationsGeoJson(const PlanResult& result, const std::vector<FieldStation>& stations,
                                    const Crs& crs);

}  // namespace vc
