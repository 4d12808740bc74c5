// vc-area-bench: how many square metres of surface an occupied voxel stands for, measured on point
// clouds (figures only, no assertions; docs/PLANNING.md, "The gain rule").
//
// The area gain rule (--min-gain-m2-per-minute) counts resolution^2 per surface voxel. A plane
// with unit normal n crosses about area x |n|_1 / resolution^2 voxels (|n|_1 = |nx| + |ny| + |nz|,
// 1 for a wall along an axis, up to sqrt(3) diagonally), so the surface a voxel holds is
// resolution^2 / |n|_1 by the voxel's own plane (vc/scene/surface_patches.h). This prints, per
// cloud, the occupied voxels x resolution^2 against the sum of that planar area (voxels without a
// plane counted at resolution^2; "ratio"), the same over the voxels with a plane only ("planes"),
// and, for a vc-synth cloud sampled at --spacing, the sampled surface (points x spacing^2).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "vc/scene/scene_input.h"
#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"

namespace {

int Measure(const std::string& path, double resolution_m, double spacing_m) {
  vc::Result<vc::SceneInput> input = vc::ReadSceneFile(path);
  if (!input.ok()) return std::fprintf(stderr, "%s: %s\n", path.c_str(), input.status().ToString().c_str()), 1;
  vc::VoxelizeOptions options;
  options.resolution_m = resolution_m;
  vc::Result<vc::VoxelScene> scene = vc::Voxelize(*input, options);
  if (!scene.ok()) return std::fprintf(stderr, "%s: %s\n", path.c_str(), scene.status().ToString().c_str()), 1;
  const std::vector<vc::SurfacePatch> patches = vc::ComputeSurfacePatches(*scene, input->points);
  const double cell_m2 = scene->resolution_m * scene->resolution_m;
  double planar_m2 = 0;     // over all voxels, res^2 where there is no plane
  double on_planes_m2 = 0;  // over the voxels with a plane only
  size_t with_plane = 0;
  for (const vc::SurfacePatch& p : patches) {
    if (p.flat || p.borrowed) {
      on_planes_m2 += cell_m2 / p.normal.cast<double>().lpNorm<1>();
      ++with_plane;
    } else {
      planar_m2 += cell_m2;
    }
  }
  planar_m2 += on_planes_m2;
  const double voxel_m2 = cell_m2 * static_cast<double>(patches.size());
  std::printf("%-40s %9zu %9zu %6.3f %10.0f %10.0f %6.3f %6.3f", path.c_str(), input->points.size(), patches.size(),
              static_cast<double>(with_plane) / static_cast<double>(patches.size()), voxel_m2, planar_m2,
              planar_m2 / voxel_m2, on_planes_m2 / (cell_m2 * static_cast<double>(with_plane)));
  if (spacing_m > 0) {
    const double sampled_m2 = spacing_m * spacing_m * static_cast<double>(input->points.size());
    std::printf(" %10.0f %6.3f", sampled_m2, sampled_m2 / voxel_m2);
  }
  std::printf("\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"surface area per occupied voxel of point clouds: voxels x resolution^2 against the voxels' planes"};
  std::vector<std::string> files;
  double resolution_m = 0.1;
  double spacing_m = 0;
  app.add_option("files", files, "point clouds (any format vc reads)")->required();
  app.add_option("--resolution", resolution_m, "voxel edge, m")->capture_default_str();
  app.add_option("--spacing", spacing_m, "the clouds' sample spacing (vc-synth --spacing), m; 0 = not sampled");
  CLI11_PARSE(app, argc, argv);
  std::printf("%-40s %9s %9s %6s %10s %10s %6s %6s%s\n", "file", "points", "voxels", "plane", "voxel_m2", "planar_m2",
              "ratio", "planes", spacing_m > 0 ? "  sampled_m2  ratio" : "");
  for (const std::string& f : files) {
    if (Measure(f, resolution_m, spacing_m) != 0) return 1;
  }
  return 0;
}
