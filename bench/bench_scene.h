// What the benchmark tools share: the scene to measure (a synthetic spec or a file, optionally
// copied side by side into a larger site) and the peak memory.
#pragma once

#include <sys/resource.h>

#include <cmath>
#include <string>

#include "vc/scene/scene_input.h"
#include "vc/synth/synth.h"

namespace vc::bench {

// Peak resident memory of this process so far, MiB.
inline double PeakRssMiB() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;
}

// A file path (contains '/' or '.') or a synthetic scene spec sampled at `spacing` m; with
// copies > 1, that many copies of the point cloud side by side, 2 m apart, in a grid of
// ceil(sqrt(copies)) columns (2: along x; 4: 2 x 2; 16: 4 x 4) — a larger site of the same kind.
inline Result<SceneInput> LoadScene(const std::string& scene, double spacing, int copies) {
  SceneInput input;
  if (scene.find('/') != std::string::npos || scene.find('.') != std::string::npos) {
    VC_ASSIGN_OR_RETURN(input, ReadSceneFile(scene));
  } else {
    SynthOptions so;
    so.spacing_m = spacing;
    VC_ASSIGN_OR_RETURN(input.points, GenerateScene(scene, so));
  }
  if (copies <= 1) return input;
  if (input.octree) return InvalidArgumentError("copies of a scene need a point cloud scene");
  Eigen::Vector3f lo = input.points.front(), hi = lo;
  for (const auto& p : input.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3f step = (hi - lo) + Eigen::Vector3f(2.0f, 2.0f, 0.0f);
  const int cols = int(std::ceil(std::sqrt(double(copies)) - 1e-9));
  const size_t n = input.points.size();
  input.points.reserve(n * size_t(copies));
  for (int t = 1; t < copies; ++t) {
    const Eigen::Vector3f shift(step.x() * float(t % cols), step.y() * float(t / cols), 0.0f);
    for (size_t i = 0; i < n; ++i) input.points.push_back(input.points[i] + shift);
  }
  return input;
}

}  // namespace vc::bench
