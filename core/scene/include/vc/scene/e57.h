// The scans of an ASTM E57 file (ASTM E2807, "E57 1.0") and their poses, without their points.
//
// ReadScene (scene_input.h) reads the points of every scan into the world frame; this header is for
// callers that want the scans themselves: a plan that continues from stations already scanned
// (vc-client --fixed-stations FILE.e57) or a listing (vc-client inspect). It reads only the file
// header and the XML section, verifying the CRC-32C of every page it reads. Thread-safe: no shared
// state.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"

namespace vc {

// One /data3D child of an E57 file.
struct E57Scan {
  // The scan's `name` and `guid` strings; empty when the file has none.
  std::string name;
  std::string guid;
  // The pose: world = rotation * scanner + translation_m. Identity when the file has no pose.
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // Unit quaternion (w, x, y, z).
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();       // The scanner's origin, world frame.
  // Records the file declares for the scan (its `points` recordCount), valid or not.
  uint64_t point_count = 0;
};

// True if `bytes` starts with the E57 signature "ASTM-E57".
bool LooksLikeE57(std::string_view bytes);

// The scans of the E57 file `bytes`, in file order. `source` labels messages. INVALID_ARGUMENT for a
// bad header, a page whose checksum does not match, XML that does not parse or lacks a required
// element; each message names the section and byte offset.
Result<std::vector<E57Scan>> ReadE57Scans(std::string_view bytes, std::string_view source);

}  // namespace vc
