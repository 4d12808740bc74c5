// A coordinate reference system the user names for the input's frame (vc-client --crs), checked
// and used through PROJ (Debian's libproj-dev): it labels the outputs (plan.json's `crs`, the
// stations.csv units line) and places them on the earth (stations.geojson, true north on a field
// sheet). docs/PLANNING.md, "A CRS for the outputs".
//
// Only a projected CRS is a site frame: its axes are lengths, so a scan's x, y, z can be in it. A
// geographic CRS (degrees) is refused, and so is one PROJ cannot tie to the earth. x is the
// easting and y the northing whatever axis order the CRS declares (the order of every point cloud
// and of GIS programs). Positions are given in metres, as every vc output holds them (a file in the
// CRS's feet was scaled to metres on reading), and converted back to the CRS's unit here.
//
// PROJ's objects are not thread-safe: one Crs is used by one thread at a time (each has its own
// PROJ context, so different Crs objects may be used concurrently).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "vc/base/status.h"

namespace vc {

// What a CRS is, as plan.json's `crs` object says it.
struct CrsInfo {
  std::string definition;      // the user's string (e.g. "EPSG:25832", WKT or a PROJ string)
  std::string name;            // PROJ's name of the CRS (e.g. "ETRS89 / UTM zone 32N")
  std::optional<int> epsg;     // its EPSG code when PROJ knows one
  std::string axis_unit;       // the unit of its horizontal axes, as PROJ names it ("metre", "US survey foot")
  double metres_per_unit = 1;  // metres in that unit
  std::string units;           // that unit as vc-client --units names it (MetresPerUnit): "m", "ft", "us-ft", ...;
                               // empty when vc reads no file in it
};

// A point on the WGS 84 ellipsoid (degrees).
struct LonLat {
  double lon_deg = 0;
  double lat_deg = 0;
};

// A checked projected CRS and its transformation to WGS 84 longitude/latitude.
class Crs {
 public:
  // The CRS `definition` names (anything PROJ accepts: "EPSG:25832", WKT, "+proj=utm +zone=32
  // +type=crs"); of a compound CRS (e.g. "EPSG:25832+5783") its horizontal part. INVALID_ARGUMENT
  // with PROJ's message when PROJ does not know it, for a geographic CRS (saying to give the
  // projected one, e.g. the UTM zone), or for a CRS that is not projected.
  [[nodiscard]] static Result<Crs> Create(std::string_view definition);
  Crs(Crs&&) noexcept;
  Crs& operator=(Crs&&) noexcept;
  ~Crs();

  // What the CRS is.
  const CrsInfo& info() const { return info_; }

  // The WGS 84 longitude and latitude (RFC 7946's) of the point at easting `x_m`, northing `y_m`
  // (metres, the input's frame). INVALID_ARGUMENT when PROJ cannot transform it (far outside the
  // CRS's area of use).
  [[nodiscard]] Result<LonLat> ToLonLat(double x_m, double y_m) const;

  // The angle from grid north (the frame's +y) to true north at easting `x_m`, northing `y_m`
  // (metres), in radians, counter-clockwise positive (true north west of grid north, as east of a
  // UTM zone's central meridian in the northern hemisphere): PROJ's meridian convergence
  // (proj_factors). INVALID_ARGUMENT when PROJ cannot compute it there.
  [[nodiscard]] Result<double> TrueNorthFromGridNorthRad(double x_m, double y_m) const;

 private:
  struct Proj;
  Crs(CrsInfo info, std::unique_ptr<Proj> proj);
  CrsInfo info_;
  std::unique_ptr<Proj> proj_;
};

}  // namespace vc
