// A small ASTM E57 1.0 writer for tests and fuzz seeds: valid files in the layouts real writers use
// (libE57Format's XML tree, one compressedVector binary section per scan, 1024-byte pages with a
// big-endian CRC-32C), with knobs to make them lie. Not a general E57 library: it writes what the
// reader under test must accept, and the defects it must refuse.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vc::testing {

// How a scan's coordinates are stored.
enum class E57Coordinates { kCartesian, kSpherical };
// The E57 type of the coordinate fields.
enum class E57ValueType { kInteger, kScaledInteger, kFloatSingle, kFloatDouble };

struct E57ScanSpec {
  std::string name = "scan";
  std::string guid = "{5C2F6E9A-0000-4000-8000-000000000001}";
  bool write_pose = true;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  E57Coordinates coordinates = E57Coordinates::kCartesian;
  E57ValueType type = E57ValueType::kFloatDouble;
  // kScaledInteger: value = raw * scale + offset.
  double scale = 0.001;
  double offset = 0.25;
  // In the scanner's frame: (x, y, z) in metres, or (range m, azimuth rad, elevation rad).
  std::vector<Eigen::Vector3d> points;
  // Empty: no invalid-state field; else one state per point (0 valid, 1 direction only, 2 invalid).
  std::vector<int> invalid_state;
  // Adds an Integer intensity field (0..4095) before the coordinates.
  bool intensity = false;
  // recordCount written in the XML = points.size() + this (a lying count when non-zero).
  int64_t record_count_delta = 0;
  // Data packets to split the bytestreams over (values then straddle packet boundaries).
  int packets = 2;
  // Writes an empty packet (type 2) and an index packet (type 0) among the data packets.
  bool extra_packets = false;
};

struct E57Spec {
  std::vector<E57ScanSpec> scans;
  // Called with the XML section before it is written, to damage it.
  std::function<void(std::string&)> edit_xml;
};

// A whole E57 file.
std::string WriteE57(const E57Spec& spec);

// Recomputes the checksum of every whole page, after a test edited the bytes.
void FixE57Checksums(std::string* file);

// Physical offset of logical (checksum-free) offset `logical`.
uint64_t E57PhysicalOffset(uint64_t logical);

}  // namespace vc::testing
