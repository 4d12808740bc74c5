// Stations already scanned, read from whatever file the user has: a stations CSV (vc's own
// stations.csv, or a pose table with a header such as 3DTK's "x,y,z,roll,pitch,yaw"), an E57 file
// (its scans' poses), an OctoMap scan graph (.graph: its nodes' poses) or a PCD file (its VIEWPOINT).
//
// The format is sniffed from the content (E57 signature, PCD header keywords, text vs binary), the
// ".graph" extension deciding only between a scan graph and binary of another kind. Every error
// names the file and the line (text) or the scan (binary), quotes the offending token with
// non-printable bytes escaped, and refuses NaN and infinite values. Thread-safe: no shared state.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"

namespace vc {

// One station read from a file, in the file's frame.
struct KnownStation {
  WorldPoint position_m;              // The scanner's origin (m).
  std::optional<double> heading_rad;  // Yaw about +z, counter-clockwise from +x; absent when the file has none.
  std::string name;                   // The CSV's name/id column, or the E57 scan's name; may be empty.
  std::string source;                 // Where it was read: "file:line", "file, scan 3" (scans count from 0).
};

// The stations of `bytes`, in file order. `source` (the file name) labels messages and each
// station's `source`. CSV and whitespace text: an optional header line whose columns name x, y, z
// (any order, case-insensitive; a "_m" suffix allowed), and optionally yaw or heading (degrees;
// "yaw_rad"/"heading_rad" for radians), roll and pitch (read, checked, not kept), and a name (a
// "name" column, else "id" or "station"); other columns are ignored, so a plan's own stations.csv
// reads back with its names. Without a header each line is "x y z [more...]". Fields split at ';', else
// ',', else whitespace; '#' starts a comment; a UTF-8 byte-order mark is skipped.
// INVALID_ARGUMENT naming file:line (text) or file and scan (binary) for a malformed or non-finite
// value, a file without stations, or binary content that is none of the formats above.
Result<std::vector<KnownStation>> ParseStationFile(std::string_view bytes, std::string_view source);

// ParseStationFile on the file at `path`; NOT_FOUND when it cannot be read.
Result<std::vector<KnownStation>> ReadStationFile(const std::string& path);

}  // namespace vc
