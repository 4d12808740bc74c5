// What a file holds, for `vc-client inspect` and the README's first command.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/e57.h"
#include "vc/scene/scene_input.h"

namespace vc {

struct SceneSummary {
  std::string format;       // InputFormatName
  std::string compression;  // CompressionName
  std::string detail;
  uint64_t points = 0;             // points read (0 for octrees)
  uint64_t dropped_nonfinite = 0;  // points dropped for NaN/inf coordinates
  uint64_t scans = 0;              // scan origins (.graph)
  uint64_t octree_leaves = 0;      // occupied leaves of an input octree (0 for clouds)
  double octree_resolution_m = 0;  // input octree's own resolution (0 for clouds)
  WorldPoint bbox_min{0, 0, 0};    // of the points, or of the occupied leaves' cubes, in metres, input frame
  WorldPoint bbox_max{0, 0, 0};
  WorldPoint frame_origin_m{0, 0, 0};  // the local frame's origin, input frame (SceneInput::frame_origin_m)
  double resolution_m = 0;             // working resolution used for the voxel count
  uint64_t occupied_voxels = 0;        // at resolution_m
  std::vector<E57Scan> e57_scans;      // E57 only, set by the caller from ReadE57Scans: each scan and its pose
};

// Summarises `input`, counting occupied voxels at `resolution_m` (0 = the default working
// resolution). Errors as Voxelize.
Result<SceneSummary> Summarize(const SceneInput& input, double resolution_m, uint64_t memory_budget_bytes,
                               const JobContext& ctx = {});

// One JSON object with the keys format, compression, detail, points, dropped_nonfinite, scans,
// octree_leaves, octree_resolution_m, bbox_min, bbox_max, frame_origin_m, resolution_m,
// occupied_voxels, and for E57
// e57_scans: [{name, guid, points, translation_m: [x, y, z], rotation_wxyz: [w, x, y, z]}, ...].
std::string SummaryToJson(const SceneSummary& s);
// Human-readable multi-line text; E57 scans one line each (name, points, translation, rotation); the
// frame origin only when it is not zero.
std::string SummaryToText(const SceneSummary& s, const std::string& source);

}  // namespace vc
