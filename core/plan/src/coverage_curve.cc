#include "vc/plan/coverage_curve.h"

namespace vc {

std::vector<CoveragePoint> CoverageCurve(const std::vector<uint64_t>& marginal_gains_voxels, uint64_t occupied_voxels,
                                         uint64_t coverable_voxels, double station_seconds) {
  std::vector<CoveragePoint> curve;
  curve.reserve(marginal_gains_voxels.size());
  uint64_t covered = 0;
  for (size_t k = 0; k < marginal_gains_voxels.size(); ++k) {
    covered += marginal_gains_voxels[k];
    CoveragePoint p;
    p.stations = static_cast<int>(k) + 1;
    p.covered_voxels = covered;
    p.coverable_fraction = coverable_voxels ? double(covered) / double(coverable_voxels) : 0.0;
    p.scene_fraction = occupied_voxels ? double(covered) / double(occupied_voxels) : 0.0;
    p.setup_scan_s = static_cast<double>(p.stations) * station_seconds;
    curve.push_back(p);
  }
  return curve;
}

std::vector<CoverageMilestone> CoverageMilestones(const std::vector<CoveragePoint>& curve, uint64_t coverable_voxels,
                                                  const std::vector<double>& levels) {
  std::vector<CoverageMilestone> out;
  out.reserve(levels.size());
  for (double level : levels) {
    CoverageMilestone m{level, std::nullopt};
    for (const CoveragePoint& p : curve) {
      if (coverable_voxels > 0 &&
          static_cast<double>(p.covered_voxels) >= level * static_cast<double>(coverable_voxels)) {
        m.reached = p;
        break;
      }
    }
    out.push_back(m);
  }
  return out;
}

}  // namespace vc
