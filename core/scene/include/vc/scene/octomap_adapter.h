// The one place that talks to OctoMap. Everything else in vc sees VoxelKey, WorldPoint and Status.
//
// OctoMap squeezes several outcomes into a bool (castRay), prints errors to stderr and uses float
// points; this adapter turns those into explicit results. Thread-safety: functions taking a const
// tree may run concurrently on the same tree; OctoMap's own tree classes are not thread-safe for
// writing.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"

namespace octomap {
class OcTree;
}

namespace vc {

// Bytes OctoMap takes per tree node, as ReadOctree* estimate it (a 16-byte node, an eighth of an
// inner node's 64-byte child array, allocator overhead).
inline constexpr uint64_t kOctreeNodeBytes = 48;

// Parses an OctoMap binary stream (.bt). INVALID_ARGUMENT naming `source` when malformed;
// RESOURCE_EXHAUSTED, before OctoMap allocates, when the tree would take more than
// `max_tree_bytes` (kOctreeNodeBytes per node).
Result<std::shared_ptr<octomap::OcTree>> ReadOctreeBinary(std::string_view bytes, std::string_view source,
                                                          uint64_t max_tree_bytes = UINT64_MAX);

// Parses an OctoMap full stream (.ot) holding an OcTree. INVALID_ARGUMENT when malformed or when
// the stream holds another tree type (e.g. ColorOcTree is accepted only as its occupancy).
// RESOURCE_EXHAUSTED as ReadOctreeBinary.
Result<std::shared_ptr<octomap::OcTree>> ReadOctreeText(std::string_view bytes, std::string_view source,
                                                        uint64_t max_tree_bytes = UINT64_MAX);

// A scan graph (.graph): every node's points transformed to the world frame, and each node's pose.
struct ScanGraphData {
  // Every point in metres, in the local frame: world minus frame_origin_m (scene_input.h).
  std::vector<Eigen::Vector3f> points;
  // The local frame's origin in the world frame, in metres (docs/PLANNING.md "Coordinates").
  Eigen::Vector3d frame_origin_m = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> origins;              // Each node's origin (m), world frame (not local).
  std::vector<Eigen::Quaterniond> origin_rotations;  // Each node's rotation (unit), scanner to world.
  uint64_t dropped_nonfinite = 0;
};
// Reads a scan graph whose coordinates are in units of `metres_per_unit` metres (1: metres).
// INVALID_ARGUMENT naming the byte when malformed.
Result<ScanGraphData> ReadScanGraph(std::string_view bytes, std::string_view source, double metres_per_unit = 1.0);

// Resolution of a tree, in metres.
double OctreeResolution(const octomap::OcTree& tree);

// Number of occupied leaves of the tree (at any depth), as OctoMap counts them.
size_t CountOccupiedLeaves(const octomap::OcTree& tree);

// Calls fn(min_corner, edge_m) for every occupied leaf: the leaf's cube in world coordinates.
void ForEachOccupiedLeaf(const octomap::OcTree& tree,
                         const std::function<void(const WorldPoint& min_corner, double edge_m)>& fn);

// Whether the tree knows p (world, m) to be free: p lies in a leaf the scanner's rays observed as
// free (not occupied, and not unknown: no leaf at all).
bool IsKnownFree(const octomap::OcTree& tree, const WorldPoint& p);

// Metric bounding box of the tree's occupied leaves. Empty tree: min > max.
void OccupiedBoundingBox(const octomap::OcTree& tree, WorldPoint* min, WorldPoint* max);

// Builds an OcTree of `resolution_m` with exactly `occupied` as occupied voxels (others unknown),
// pruned. The key numbers are the same at equal resolution.
std::shared_ptr<octomap::OcTree> BuildOctree(double resolution_m, const std::vector<VoxelKey>& occupied);

// What octomap::OcTree::castRay reported, made explicit.
struct CastRayOutcome {
  enum class Kind { kHitOccupied, kNoHit };
  Kind kind = Kind::kNoHit;
  VoxelKey hit;  // valid when kind == kHitOccupied
};
// octomap::OcTree::castRay from `origin` along `direction` up to `max_range_m`, unknown cells free.
CastRayOutcome OctomapCastRay(const octomap::OcTree& tree, const WorldPoint& origin, const Eigen::Vector3d& direction,
                              double max_range_m);

}  // namespace vc
