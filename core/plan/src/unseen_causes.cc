#include "vc/plan/unseen_causes.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "vc/base/parallel.h"
#include "vc/scene/occupancy_grid.h"

namespace vc {
namespace {

constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

// The storey of height z: the index of the highest floor level at or below z, or -1.
int StoreyOf(const std::vector<double>& floor_levels_m, double z_m) {
  const auto above = std::upper_bound(floor_levels_m.begin(), floor_levels_m.end(), z_m);
  return static_cast<int>(above - floor_levels_m.begin()) - 1;
}

constexpr std::array<std::array<int, 3>, 6> kFaceNormals{
    {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

// The voxel's faces toward empty space (bit k: kFaceNormals[k]); 0 for a voxel inside solid matter.
unsigned OpenFaces(const OccupancyGrid& grid, const VoxelIndex& v) {
  unsigned open = 0;
  for (size_t k = 0; k < kFaceNormals.size(); ++k) {
    const auto& n = kFaceNormals[k];
    if (!grid.Occupied(v.x + n[0], v.y + n[1], v.z + n[2])) open |= 1u << k;
  }
  return open;
}

// Whether a face in `open` faces a scanner at `to_scanner` (from the voxel's centre): the scanner
// lies beyond the face's plane, half a voxel out.
bool FacesScanner(unsigned open, const WorldPoint& to_scanner, double half_voxel_m) {
  for (size_t k = 0; k < kFaceNormals.size(); ++k) {
    if (!(open >> k & 1u)) continue;
    const auto& n = kFaceNormals[k];
    if (n[0] * to_scanner.x() + n[1] * to_scanner.y() + n[2] * to_scanner.z() > half_voxel_m) return true;
  }
  return false;
}

enum Cause : int {
  kInterior,
  kInKeepOut,
  kNoCandidateOnFloor,
  kOutOfRange,
  kOutsideFieldOfView,
  kFacesAway,
  kHidden,
  kCauses
};

struct Classifier {
  const UnseenCausesInput& in;
  std::vector<bool> storey_has_candidate;

  Cause Classify(size_t id) const {
    const VoxelScene& scene = in.scene;
    const unsigned open = OpenFaces(scene.grid, KeyToIndex(scene.occupied[id]));
    if (open == 0) return kInterior;
    const WorldPoint c = scene.Center(id);
    if (KeepOutZoneContaining(in.keep_out, c) >= 0) return kInKeepOut;
    // The floor voxel whose top is a level belongs to the storey above it.
    const int storey = StoreyOf(in.floor_levels_m, c.z() + 0.5 * scene.resolution_m);
    if (storey >= 0 && !storey_has_candidate[storey]) return kNoCandidateOnFloor;
    Cause cause = kOutOfRange;
    const double min_range2 = in.scanner.min_range_m * in.scanner.min_range_m;
    const double max_range2 = in.scanner.max_range_m * in.scanner.max_range_m;
    const bool limited_view = in.scanner.HasVerticalFieldOfView();
    for (const WorldPoint& p : in.candidates) {
      const WorldPoint d = c - p;
      const double range2 = d.squaredNorm();
      if (range2 < min_range2 || range2 > max_range2) continue;
      cause = std::max(cause, kOutsideFieldOfView);
      if (limited_view) {
        const double elevation_deg = std::atan2(d.z(), d.head<2>().norm()) * kDegreesPerRadian;
        if (elevation_deg < in.scanner.vfov_min_deg || elevation_deg > in.scanner.vfov_max_deg) continue;
      }
      cause = kFacesAway;
      if (FacesScanner(open, -d, 0.5 * scene.resolution_m)) return kHidden;
    }
    return cause;
  }
};

}  // namespace

Result<UnseenCauses> CountUnseenCauses(const UnseenCausesInput& in, int threads, const JobContext& ctx) {
  Classifier classifier{in, std::vector<bool>(in.floor_levels_m.size(), false)};
  for (const WorldPoint& p : in.candidates) {
    const int storey = StoreyOf(in.floor_levels_m, p.z());
    if (storey >= 0) classifier.storey_has_candidate[storey] = true;
  }
  const uint64_t n = in.scene.occupied.size();
  std::array<std::atomic<uint64_t>, kCauses> counts{};
  VC_RETURN_IF_ERROR(ParallelChunks(
      n, 4096, threads, ctx,
      [&](uint64_t, uint64_t begin, uint64_t end) {
        std::array<uint64_t, kCauses> local{};
        for (uint64_t id = begin; id < end; ++id) {
          if (!in.coverable.test(id)) ++local[classifier.Classify(id)];
        }
        for (int k = 0; k < kCauses; ++k) counts[k].fetch_add(local[k], std::memory_order_relaxed);
      },
      "counting why voxels are unseen"));
  UnseenCauses out;
  out.interior = counts[kInterior];
  out.in_keep_out = counts[kInKeepOut];
  out.no_candidate_on_floor = counts[kNoCandidateOnFloor];
  out.out_of_range = counts[kOutOfRange];
  out.outside_field_of_view = counts[kOutsideFieldOfView];
  out.faces_away = counts[kFacesAway];
  out.hidden = counts[kHidden];
  return out;
}

}  // namespace vc
