// Synthetic scenes whose answer is known: point clouds sampled on the surfaces of simple buildings
// (one room, an L-shaped room, a comb of dead-end bays, rooms along a corridor, a hub hall whose
// rooms are best seen from their doorways, a court hall with rooms on all sides behind off-centre
// doors, a square hall with rooms on three sides, two storeys, two
// rooms joined by a door, two storeys joined by a flight of steps, the chapel-like benchmark
// hall, and an open sloping site with buildings), for oracle tests of the planner and for benchmarks.
//
// Why the API is split: DescribeScene says what a scene is (its known optimum, the regions that each
// need their own station, its floors) without generating anything; ForEachScenePoint streams the
// points with O(1) memory in the number of points (the hall at 0.005 m is ~2e8 points);
// GenerateScene and WritePlyBinary are conveniences on top of the stream.
//
// Model: a scene is a union of axis-aligned free-space boxes ("air": rooms, doors, windows) minus
// axis-aligned solid boxes inside them (pillars, pews, beams, cornices). Points are sampled on the
// boundary of that free space, i.e. on the surfaces a scanner standing inside would record; the
// outside of the building is never sampled (it could not be covered, and it would tie the roof with
// the floor as the largest horizontal layer). An open site (slope, hillside) is the exception: there the
// faces on the air's bounding box, the sky and the site's edges, are not sampled. Every face is sampled on a grid whose
// lines include every box edge that crosses it, so the surface is watertight after voxelisation at any resolution
// >= 2 x spacing. The whole scene is shifted by kSceneOffsetM so no surface plane lies on a multiple
// of 0.1, 0.08, 0.05, 0.02 or 0.01 m. Details and dimensions: docs/SCENES.md.
//
// Thread-safety: all functions are pure and may be called concurrently.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"

namespace vc {

// Shift applied to every scene's design coordinates (m), so that surface planes avoid voxel borders.
inline const WorldPoint kSceneOffsetM{0.0137, 0.0213, 0.0071};

// GenerateScene refuses scenes with more points than this (12 bytes each, i.e. 240 MB).
inline constexpr uint64_t kMaxGeneratedPoints = 20'000'000;

struct SynthOptions {
  // Step of the sampling grid on every surface (m), in [0.005, 1]; actual steps are <= this.
  double spacing_m = 0.05;
  // Seed of the in-plane jitter (at most 10 % of the local spacing); same seed -> same points.
  uint64_t seed = 1;

  // INVALID_ARGUMENT if spacing_m is not finite or outside [0.005, 1].
  Status Validate() const;
};

// An axis-aligned box in the world frame (m).
struct AxisBox {
  WorldPoint min{0, 0, 0};
  WorldPoint max{0, 0, 0};
};

struct SceneInfo {
  // Canonical spec ("comb:3").
  std::string name;
  // One line describing the scene.
  std::string description;
  // Minimum number of stations that see every surface (surface visibility, ALGORITHM.md 3b);
  // 0 = unknown (the hall), in which case rooms.size() is a lower bound.
  int optimum_stations = 0;
  // Disjoint regions (world, m) that each need a station inside: every region holds at least one
  // station of any plan that sees every surface (and exactly one of an optimal plan).
  std::vector<AxisBox> rooms;
  // Heights of the floors a tripod stands on (world z of the floor surface, m), lowest first.
  std::vector<double> floor_heights_m;
  // The building's outer envelope (world, m); every point lies inside it.
  WorldPoint bounds_min{0, 0, 0};
  WorldPoint bounds_max{0, 0, 0};
};

// Names, descriptions and optima of the available scenes, one line each, for `vc-synth --list`.
std::string ListScenes();

// Describes the scene `spec` ("box", "lroom", "comb:K", "rooms:N", "hub:K", "court:K", "tee", "star:K", "atrium:K",
// "hall", "twofloor", "tworooms", "stairs", "slope", "hillside"; K and N in 1..50, star's K in 2..4, atrium's in
// 2..50). INVALID_ARGUMENT naming the valid specs for anything else.
Result<SceneInfo> DescribeScene(std::string_view spec);

// Calls fn once per point (world, m) of the scene, in a fixed order; memory does not grow with the
// number of points. INVALID_ARGUMENT for a bad spec or options.
Status ForEachScenePoint(std::string_view spec, const SynthOptions& options,
                         const std::function<void(const Eigen::Vector3f&)>& fn);

// Exact number of points ForEachScenePoint would produce, computed without generating them.
Result<uint64_t> CountScenePoints(std::string_view spec, const SynthOptions& options);

// All points of the scene, in ForEachScenePoint's order. RESOURCE_EXHAUSTED if there would be more
// than kMaxGeneratedPoints (use ForEachScenePoint or WritePlyBinary instead).
Result<std::vector<Eigen::Vector3f>> GenerateScene(std::string_view spec, const SynthOptions& options);

// Streams the scene to `path` as binary little-endian PLY (float x, y, z per vertex).
// INVALID_ARGUMENT for a bad spec or options; FAILED_PRECONDITION if the file cannot be written.
Status WritePlyBinary(const std::string& path, std::string_view spec, const SynthOptions& options);

}  // namespace vc
