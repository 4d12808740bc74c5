// Keep-out zones: places no station may stand in (a doorway, a machine, a road), as axis-aligned
// boxes or as polygons in x, y extruded over a z range, in metres, in the frame the caller holds
// (PlanOptions: the input's frame; Plan moves them to the local frame, InLocalFrame). The planner
// drops generated and user candidates and refinement's trial positions inside a zone, and refuses
// fixed stations inside one (docs/PLANNING.md, "Keep-out zones"). ParseKeepOutCsv reads the CSV
// format documented there. Zones are closed: a point on a zone's boundary is inside it.
// Thread-compatible: plain values and pure functions.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"

namespace vc {

enum class KeepOutShape : uint8_t {
  kBox,      // the box [min, max]
  kPolygon,  // the polygon's interior in x, y, for z in [min.z, max.z]
};

struct KeepOutZone {
  KeepOutShape shape = KeepOutShape::kBox;
  // Box: its corners (m). Polygon: min.z / max.z are its z range; min/max x, y are its vertices'
  // bounding box (KeepOutPolygon computes them).
  WorldPoint min{0, 0, 0};
  WorldPoint max{0, 0, 0};
  std::vector<double> polygon_xy_m;  // polygon: x1, y1, x2, y2, ... (m), at least 3 vertices; empty for a box
};

// The box [min, max].
[[nodiscard]] KeepOutZone KeepOutBox(const WorldPoint& min, const WorldPoint& max);
// The polygon with vertices `xy_m` (x1, y1, x2, y2, ...) between z_min_m and z_max_m.
[[nodiscard]] KeepOutZone KeepOutPolygon(double z_min_m, double z_max_m, std::vector<double> xy_m);

// INVALID_ARGUMENT starting with `name` (e.g. "keep_out[2]" or "zones.csv:7") when a coordinate is
// not finite, a minimum exceeds its maximum, or a polygon has fewer than 3 vertices or an odd
// number of coordinates.
[[nodiscard]] Status ValidateKeepOutZone(const KeepOutZone& zone, std::string_view name);

// True if p lies in the zone (boundary included). The zone must be valid.
[[nodiscard]] bool KeepOutContains(const KeepOutZone& zone, const WorldPoint& p);
// Index of the first zone containing p, or -1.
[[nodiscard]] int KeepOutZoneContaining(const std::vector<KeepOutZone>& zones, const WorldPoint& p);

// A keep-out CSV's zones, each with the line (from 1) it was read from.
struct KeepOutFile {
  std::vector<KeepOutZone> zones;
  std::vector<size_t> lines;  // lines[i]: the line of zones[i]
};

// Parses the keep-out CSV (docs/PLANNING.md): one zone per line, `box,xmin,ymin,zmin,xmax,ymax,zmax`,
// `xmin,ymin,zmin,xmax,ymax,zmax` (a box without its kind) or `polygon,zmin,zmax,x1,y1,x2,y2,x3,
// y3,...`; the first line is a header, and skipped, when none of its fields is a number or a kind
// (`kind,xmin,ymin,...`); `#` starts a comment; blank lines are skipped; fields may carry spaces; a
// UTF-8 byte-order mark is skipped. INVALID_ARGUMENT naming `source:line` and what is wrong (an
// unknown kind, a wrong number of fields, a field that is not a number, NaN or infinity,
// min > max, fewer than 3 polygon vertices).
[[nodiscard]] Result<KeepOutFile> ParseKeepOutFile(std::string_view text, std::string_view source);
// ParseKeepOutFile's zones.
[[nodiscard]] Result<std::vector<KeepOutZone>> ParseKeepOutCsv(std::string_view text, std::string_view source);

// One line of that CSV for `zone` (no newline); ParseKeepOutCsv reads it back exactly (%.17g).
[[nodiscard]] std::string KeepOutCsvLine(const KeepOutZone& zone);

}  // namespace vc
