#include "vc/scene/scene_summary.h"

#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "vc/scene/octomap_adapter.h"
#include "vc/scene/voxel_scene.h"

namespace vc {

Result<SceneSummary> Summarize(const SceneInput& input, double resolution_m, uint64_t memory_budget_bytes,
                               const JobContext& ctx) {
  SceneSummary s;
  s.format = std::string(InputFormatName(input.format));
  s.compression = std::string(CompressionName(input.compression));
  s.detail = input.detail;
  s.points = input.points.size();
  s.dropped_nonfinite = input.dropped_nonfinite;
  s.scans = input.scan_origins.size();
  if (input.octree) {
    s.octree_leaves = CountOccupiedLeaves(*input.octree);
    s.octree_resolution_m = OctreeResolution(*input.octree);
    OccupiedBoundingBox(*input.octree, &s.bbox_min, &s.bbox_max);
  } else if (!input.points.empty()) {
    s.bbox_min = s.bbox_max = input.points.front().cast<double>();
    for (const Eigen::Vector3f& p : input.points) {
      s.bbox_min = s.bbox_min.cwiseMin(p.cast<double>());
      s.bbox_max = s.bbox_max.cwiseMax(p.cast<double>());
    }
    s.frame_origin_m = input.frame_origin_m;
    s.bbox_min += s.frame_origin_m;
    s.bbox_max += s.frame_origin_m;
  }
  VoxelizeOptions vo;
  vo.resolution_m = resolution_m;
  vo.memory_budget_bytes = memory_budget_bytes;
  s.resolution_m = WorkingResolution(input, vo);
  VC_ASSIGN_OR_RETURN(
      const uint64_t occupied,
      CatchOutOfMemory("voxelising at " + std::to_string(s.resolution_m) + " m", [&]() -> Result<uint64_t> {
        VC_ASSIGN_OR_RETURN(std::vector<VoxelKey> keys, OccupiedKeys(input, s.resolution_m, memory_budget_bytes, ctx));
        return uint64_t{keys.size()};
      }));
  s.occupied_voxels = occupied;
  return s;
}

std::string SummaryToJson(const SceneSummary& s) {
  nlohmann::ordered_json j;
  j["format"] = s.format;
  j["compression"] = s.compression;
  j["detail"] = s.detail;
  j["points"] = s.points;
  j["dropped_nonfinite"] = s.dropped_nonfinite;
  j["scans"] = s.scans;
  j["octree_leaves"] = s.octree_leaves;
  j["octree_resolution_m"] = s.octree_resolution_m;
  j["bbox_min"] = {s.bbox_min.x(), s.bbox_min.y(), s.bbox_min.z()};
  j["bbox_max"] = {s.bbox_max.x(), s.bbox_max.y(), s.bbox_max.z()};
  j["frame_origin_m"] = {s.frame_origin_m.x(), s.frame_origin_m.y(), s.frame_origin_m.z()};
  j["resolution_m"] = s.resolution_m;
  j["occupied_voxels"] = s.occupied_voxels;
  if (!s.e57_scans.empty()) {
    nlohmann::ordered_json scans = nlohmann::ordered_json::array();
    for (const E57Scan& e : s.e57_scans) {
      nlohmann::ordered_json scan;
      scan["name"] = e.name;
      scan["guid"] = e.guid;
      scan["points"] = e.point_count;
      scan["translation_m"] = {e.translation_m.x(), e.translation_m.y(), e.translation_m.z()};
      scan["rotation_wxyz"] = {e.rotation.w(), e.rotation.x(), e.rotation.y(), e.rotation.z()};
      scans.push_back(std::move(scan));
    }
    j["e57_scans"] = std::move(scans);
  }
  return j.dump();
}

std::string SummaryToText(const SceneSummary& s, const std::string& source) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(3);
  os << source << "\n";
  os << "  format:            " << s.format;
  if (!s.detail.empty()) os << " (" << s.detail << ")";
  if (s.compression != "none") os << ", " << s.compression << "-compressed";
  os << "\n";
  if (s.octree_leaves > 0 || s.octree_resolution_m > 0) {
    os << "  octree:            " << s.octree_leaves << " occupied leaves at " << s.octree_resolution_m << " m\n";
  } else {
    os << "  points:            " << s.points << "\n";
    os << "  dropped (NaN/inf): " << s.dropped_nonfinite << "\n";
  }
  if (s.scans > 0) os << "  scans:             " << s.scans << " (with scanner origins)\n";
  for (size_t i = 0; i < s.e57_scans.size(); ++i) {
    const E57Scan& e = s.e57_scans[i];
    const Eigen::Quaterniond& q = e.rotation;
    os << "    " << i << " \"" << e.name << "\": " << e.point_count << " points, at (" << e.translation_m.x() << ", "
       << e.translation_m.y() << ", " << e.translation_m.z() << ") m, rotation (w, x, y, z) (" << std::setprecision(4)
       << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << ")\n"
       << std::setprecision(3);
  }
  os << "  bounding box:      [" << s.bbox_min.x() << ", " << s.bbox_min.y() << ", " << s.bbox_min.z() << "] .. ["
     << s.bbox_max.x() << ", " << s.bbox_max.y() << ", " << s.bbox_max.z() << "] m\n";
  if (!s.frame_origin_m.isZero()) {
    os << "  frame origin:      (" << s.frame_origin_m.x() << ", " << s.frame_origin_m.y() << ", "
       << s.frame_origin_m.z() << ") m; the scene is planned relative to it\n";
  }
  const WorldPoint e = s.bbox_max - s.bbox_min;
  os << "  extent:            " << e.x() << " x " << e.y() << " x " << e.z() << " m\n";
  os << "  occupied voxels:   " << s.occupied_voxels << " at " << s.resolution_m << " m\n";
  return os.str();
}

}  // namespace vc
