// What `vc-client submit` and `evaluate` send for a scene file (docs/PROTOCOL.md, "Compact
// uploads"): by default a point cloud's occupied voxels at the working resolution as a vc-voxels
// stream (vc/scene/voxel_stream.h), voxelised here by the server's own function, so the plan is
// the one the raw cloud gives while the upload shrinks (the 0.02 m hall: 121.7 MiB of PLY to
// under 1 MiB, docs/BENCHMARKS.md); the file's bytes as they are otherwise.
#pragma once

#include <string>
#include <utility>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/client/client.h"
#include "vc/report/plan_report.h"

namespace vc::client {

struct PreparedUpload {
  Upload upload;          // what to send
  UploadSummary summary;  // what was chosen and why (plan.json `upload`)
};

// The upload for `file` at `resolution_m` (0: vc's default for point clouds, 0.1 m). Raw when
// `raw` (--raw-upload), for octrees (already voxels, and their free space matters), for inputs
// that carry scan origins (.graph, E57: a stream would drop them), when the compact stream is not
// smaller, and when the file cannot be read or voxelised here (the server then reads it and says
// what is wrong, with its own limits). A compact upload reads the file in file.units here and is
// sent in metres (no units); a raw one keeps file.units for the server. Never fails.
PreparedUpload PrepareUpload(Upload file, double resolution_m, bool raw, const JobContext& ctx = {});

// One line for people: "compact upload: 131,705 voxels of 0.1 m, 212 KB instead of 4.6 MB" or
// "raw upload (an octree is uploaded as it is): 1.2 MB".
std::string DescribeUpload(const UploadSummary& summary);

}  // namespace vc::client
