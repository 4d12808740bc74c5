// vc-route-bench: the walking route stage alone (route.h) on a scene, with the planner's settings
// (RunRouteStage), through stations taken from the scene's own candidates: every k-th of them,
// k chosen so that about --stations remain. No plan is needed, so a campus-scale route can be
// timed in seconds where the whole plan takes hours.
//
// Prints the walk grid (cells, nodes, bridged nodes), the route (parts, length, warnings), the
// seconds of each phase (Route::seconds), the peak RSS, a hash of the route (order, legs to the
// millimetre, parts) to compare two builds, and, with --baseline NAME=SECONDS, the ratio of this
// run's route seconds to that baseline's. Figures only, no assertions (docs/BENCHMARKS.md, "The
// walking route at campus scale"). `--quick` routes a small synthetic scene so CI keeps it running.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_scene.h"
#include "vc/plan/candidates.h"
#include "vc/plan/plan_options.h"
#include "vc/plan/stages.h"
#include "vc/scene/voxel_scene.h"

namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); }

struct RouteBenchOptions {
  std::string scene = "rooms:3";
  double spacing = 0.05, resolution = 0, grid = 1.0;
  int stations = 300, threads = 2;
  std::string ground = "auto";  // the candidates' ground model
  std::string baseline;         // NAME=SECONDS
  bool warnings = false;
};

// FNV-1a over the route's order, legs (mm) and parts: equal routes, equal hashes.
uint64_t RouteHash(const vc::planner::Route& r) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](int64_t v) {
    for (int b = 0; b < 8; ++b) {
      h ^= uint64_t(v >> (8 * b)) & 0xff;
      h *= 1099511628211ull;
    }
  };
  for (int s : r.order) mix(s);
  for (double l : r.legs_m) mix(std::isnan(l) ? -1 : std::llround(l * 1000));
  mix(r.parts);
  return h;
}

// The baseline's name and seconds from NAME=SECONDS; false when malformed.
bool ParseBaseline(const std::string& text, std::string* name, double* seconds) {
  const size_t eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0) return false;
  char* end = nullptr;
  *seconds = std::strtod(text.c_str() + eq + 1, &end);
  *name = text.substr(0, eq);
  return end != text.c_str() + eq + 1 && *end == '\0' && *seconds > 0 && std::isfinite(*seconds);
}

int Run(const RouteBenchOptions& o) {
  std::string baseline_name;
  double baseline_s = 0;
  if (!o.baseline.empty() && !ParseBaseline(o.baseline, &baseline_name, &baseline_s)) {
    std::fprintf(stderr, "vc-route-bench: --baseline wants NAME=SECONDS with SECONDS > 0, got '%s'\n",
                 o.baseline.c_str());
    return 2;
  }
  auto t0 = Clock::now();
  vc::Result<vc::SceneInput> input = vc::bench::LoadScene(o.scene, o.spacing, 1);
  if (!input.ok()) return std::fprintf(stderr, "vc-route-bench: %s\n", input.status().ToString().c_str()), 2;
  vc::VoxelizeOptions vo;
  vo.resolution_m = o.resolution;
  vc::Result<vc::VoxelScene> scene = vc::Voxelize(*input, vo);
  if (!scene.ok()) return std::fprintf(stderr, "vc-route-bench: %s\n", scene.status().ToString().c_str()), 2;
  const double load_s = Seconds(t0);
  vc::PlanOptions po;
  po.threads = o.threads;
  po.grid_spacing_m = o.grid;
  vc::planner::CandidateOptions co;
  co.grid_spacing_m = o.grid;
  co.walk_max_step_m = po.walk_max_step_m;
  co.ground = o.ground == "terrain"  ? vc::GroundModel::kTerrain
              : o.ground == "floors" ? vc::GroundModel::kFloors
                                     : vc::GroundModel::kAuto;
  t0 = Clock::now();
  vc::Result<vc::planner::CandidateGrid> c = vc::planner::GenerateCandidates(*scene, co);
  if (!c.ok()) return std::fprintf(stderr, "vc-route-bench: %s\n", c.status().ToString().c_str()), 2;
  const double candidates_s = Seconds(t0);
  const size_t every = std::max<size_t>(1, (c->positions.size() + size_t(o.stations) - 1) / size_t(o.stations));
  std::vector<vc::WorldPoint> stations;
  std::vector<double> floor_z;
  for (size_t i = 0; i < c->positions.size(); i += every) {
    stations.push_back(c->positions[i]);
    floor_z.push_back(c->floor_z_m[i]);
  }
  std::vector<double> levels;
  for (const vc::planner::FloorLevel& l : c->levels) levels.push_back(l.z_m);
  std::printf(
      "vc-route-bench: scene %s, %zu occupied voxels at %.3f m (load %.1f s); ground %s; %zu candidates "
      "(%.1f s), every %zu-th: %zu stations; %d threads\n",
      o.scene.c_str(), scene->occupied.size(), scene->resolution_m, load_s,
      std::string(vc::GroundModelName(c->ground.model)).c_str(), c->positions.size(), candidates_s, every,
      stations.size(), o.threads);
  t0 = Clock::now();
  vc::Result<vc::planner::RouteOutput> out =
      vc::planner::RunRouteStage({*input, *scene, stations, floor_z, levels}, po, {});
  const double route_s = Seconds(t0);
  if (!out.ok()) return std::fprintf(stderr, "vc-route-bench: %s\n", out.status().ToString().c_str()), 1;
  if (!out->route) {
    std::printf("no route: %s\n", out->unrouted_reason.c_str());
    return 1;
  }
  const vc::planner::Route& r = *out->route;
  const vc::planner::RouteSeconds& p = r.seconds;
  std::printf("walk grid: %llu cells of %.2f m, %llu nodes (%llu bridged)\n",
              static_cast<unsigned long long>(r.walk_cells), r.cell_m, static_cast<unsigned long long>(r.walk_nodes),
              static_cast<unsigned long long>(r.bridged_nodes));
  std::printf("route: %d part(s), %.1f m, %zu warning(s), hash %016llx\n", r.parts, r.length_m, r.warnings.size(),
              static_cast<unsigned long long>(RouteHash(r)));
  std::printf(
      "seconds: walk graph %.2f (bridging %.2f), distances %.2f, parts %.2f, order %.2f, legs %.2f; "
      "route %.2f; peak RSS %.0f MiB\n",
      p.walk_graph_s, p.bridging_s, p.distances_s, p.parts_s, p.order_s, p.legs_s, route_s, vc::bench::PeakRssMiB());
  if (baseline_s > 0) {
    std::printf("ratio to %s (%.2f s): %.4f (%.1fx faster)\n", baseline_name.c_str(), baseline_s, route_s / baseline_s,
                baseline_s / route_s);
  }
  for (size_t i = 0; i < r.warnings.size() && (o.warnings || i < 3); ++i) {
    std::printf("warning: %s\n", r.warnings[i].c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"the walking route stage alone, through every k-th candidate of a scene (docs/BENCHMARKS.md)"};
  RouteBenchOptions o;
  bool quick = false;
  app.add_option("--scene", o.scene, "synthetic scene spec (rooms:3, twofloor, ...) or a file path");
  app.add_option("--spacing", o.spacing, "point spacing of synthetic scenes, m");
  app.add_option("--resolution", o.resolution, "working resolution, m (0: an octree's own, 0.1 for points)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--grid", o.grid, "candidate grid spacing, m")->check(CLI::PositiveNumber);
  app.add_option("--stations", o.stations, "about this many stations, every k-th candidate")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_option("--ground", o.ground, "the candidates' ground model")
      ->check(CLI::IsMember({"auto", "terrain", "floors"}));
  app.add_option("--baseline", o.baseline, "NAME=SECONDS: print the route's seconds as a ratio to this baseline");
  app.add_flag("--warnings", o.warnings, "print every warning (default: the first 3)");
  app.add_flag("--quick", quick, "rooms:3 with 20 stations (CI)");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    o.scene = "rooms:3";
    o.stations = 20;
  }
  return Run(o);
}
