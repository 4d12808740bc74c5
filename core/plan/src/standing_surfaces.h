// Standing surfaces of a voxel column, shared by candidate generation (candidates.cc) and the
// walking route (route.cc). Internal to the plan layer.
#pragma once

#include <vector>

#include "vc/scene/occupancy_grid.h"

namespace vc::planner::internal {

struct Surface {
  int z;           // index of the top voxel of an occupied run
  int free_above;  // free voxels above it (INT_MAX up to the top of the grid)
  bool covered;    // another occupied run above it in the column
  bool has_below;  // another occupied run below it in the column
  int run;         // the run's number from the top of the column
  // The outside of a ceiling: nothing above, a room below.
  bool roof() const { return !covered && has_below; }
};

// Voxels of free space needed above a floor to stand `height_m` plus `clearance_m` on it (at least 1).
int FreeVoxelsNeeded(double resolution_m, double height_m, double clearance_m);

// Standing surfaces of column (x, y) (voxel indices), top to bottom: the top voxel of each occupied
// run with at least `free_needed` free voxels above it. Outside the box is free. Replaces `out`.
void ColumnSurfaces(const OccupancyGrid& grid, int x, int y, int free_needed, std::vector<Surface>& out);

}  // namespace vc::planner::internal
