#include "vc/plan/coverage_curve.h"

#include <algorithm>

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

void AddBestCoverage(std::vector<CoveragePoint>& curve, const std::vector<std::optional<BestCoverage>>& best) {
  for (size_t k = 0; k < curve.size() && k < best.size(); ++k) {
    if (!best[k]) continue;
    CoveragePoint& p = curve[k];
    p.best_voxels_upper_bound = best[k]->upper_bound_voxels;  // >= covered_voxels: the plan's k are k stations
    p.best_voxels = std::max(best[k]->best_voxels, p.covered_voxels);
    p.best_voxels_optimal = *p.best_voxels == *p.best_voxels_upper_bound;
  }
}

std::vector<CoverageMilestone> CoverageMilestones(const std::vector<CoveragePoint>& curve, uint64_t coverable_voxels,
                                                  const std::vector<double>& levels) {
  std::vector<CoverageMilestone> out;
  out.reserve(levels.size());
  for (double level : levels) {
    CoverageMilestone m{level, std::nullopt, std::nullopt};
    const auto reaches = [&](uint64_t voxels) {
      return coverable_voxels > 0 && static_cast<double>(voxels) >= level * static_cast<double>(coverable_voxels);
    };
    for (const CoveragePoint& p : curve) {
      if (!m.fewest_possible_stations && p.best_voxels_upper_bound && reaches(*p.best_voxels_upper_bound)) {
        m.fewest_possible_stations = p.stations;
      }
      if (reaches(p.covered_voxels)) {
        m.reached = p;
        break;
      }
    }
    out.push_back(m);
  }
  return out;
}

}  // namespace vc
