// evaluate --export-sets DIR (docs/VISIBILITY.md, "Checking a prediction: evaluate --export-sets"): each viewpoint's
// seen set under the evaluation's selection test as DIR/station_<n>.xyz, so that anyone can check the prediction with
// their own tools. A file holds the centres of the voxels the test counts as seen from viewpoint n (1-based, in the
// order the viewpoints were given), one "x y z" line each, in metres in the input's own frame (the scene's local frame
// plus its origin), to the millimetre, in voxel id order. A viewpoint that sees nothing gets an empty file.
#pragma once

#include <string>
#include <vector>

#include "vc/base/status.h"
#include "vc/plan/evaluate_job.h"

namespace vc::client {

// Makes `dir` ready for the files, before anything is sent: creates it (and its parents) when
// missing. INVALID_ARGUMENT when it is not a directory, or holds anything and `force` is false;
// with `force`, the station_*.xyz files already in it are removed (other files stay).
// PERMISSION_DENIED when it cannot be created or written. Each message names `dir`.
[[nodiscard]] Status PrepareExportDir(const std::string& dir, bool force);

// DIR/station_<n>.xyz for each of result.seen_sets; the paths written, in order. PERMISSION_DENIED
// when a file cannot be written; FAILED_PRECONDITION when the result holds no seen sets.
[[nodiscard]] Result<std::vector<std::string>> WriteSeenSets(const EvaluateJobResult& result, const std::string& dir);

// The line of one voxel centre (local frame) in the input's frame: "x y z" in metres, 3 decimals.
[[nodiscard]] std::string SeenVoxelLine(const WorldPoint& center_local_m, const WorldPoint& frame_origin_m);

}  // namespace vc::client
