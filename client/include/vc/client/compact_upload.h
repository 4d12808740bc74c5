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
  // When the name says another format than the content: "cloud.ply holds XYZ text, not PLY: read
  // as XYZ text"; empty otherwise.
  std::string format_note;
};

// The upload for `file` at `resolution_m` (0: vc's default for point clouds, 0.1 m). The file is
// read here first, by the server's own reader, so what the server would refuse is refused before
// anything is sent: INVALID_ARGUMENT for content that reader cannot read (malformed, truncated, no
// point). The format comes from the content, not the name (as on the server): a file named for
// another format is read as what it holds, with a format_note, or, when it cannot be, refused
// saying so ("cloud.ply is not a PLY file (it looks like XYZ text; rename it .xyz, or export it
// again as PLY): ..."). Why read, not refuse, a renamed file that reads: the server reads it the
// same way, and `inspect` does too, so refusing would make submit the one place that cares about
// the name. Raw when `raw` (--raw-upload: nothing is read here), for octrees (already voxels, and
// their free space matters), for inputs that carry scan origins (.graph, E57: a stream would drop
// them), when the compact stream is not smaller, and when the file is beyond the default limits
// or its units are unknown here (a server with larger limits or a newer list may still take it).
// A compact upload reads the file in file.units here and is sent in metres (no units); a raw one
// keeps file.units for the server.
[[nodiscard]] Result<PreparedUpload> PrepareUpload(Upload file, double resolution_m, bool raw,
                                                   const JobContext& ctx = {});

// One line for people: "compact upload: 131,705 voxels of 0.1 m, 212 KB instead of 4.6 MB" or
// "raw upload (an octree is uploaded as it is): 1.2 MB".
std::string DescribeUpload(const UploadSummary& summary);

}  // namespace vc::client
