// vc-bench: one run, one scene, the same rays for OctoMap and for vc.
//
// Prints: OctoMap castRay rays/s (on a subsample) and ours on identical rays with an identity
// check and the per-core ratio; the full visibility-set computation (both selection tests); the
// end-to-end plan per stage; peak RSS; and scaling tables against footprint and candidate
// spacing. No assertions on time: figures are printed for docs/BENCHMARKS.md. `--quick` runs a
// small scene in seconds so CI keeps the tool building and running. `--bar` runs the bar
// method instead: the whole plan against OctoMap castRay on the plan's compatibility rays.
#include <hwy/targets.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <utility>

#include "bench_scene.h"
#include "vc/plan/candidates.h"
#include "vc/plan/planner.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/scene/octomap_adapter.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/synth/synth.h"
#include "vc/visibility/scanner_limits.h"
#include "vc/visibility/visibility.h"

namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); }

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// CPU seconds of this process so far (all threads).
double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

using vc::bench::LoadScene;
using vc::bench::PeakRssMiB;

// The two costliest stages on their own, for A/B runs of two builds (docs/BENCHMARKS.md, "The
// machine"): the grouped surface-visibility sets of every `every`-th candidate of the plan's
// grid, and the exact evaluation of 15 evenly spaced candidates keeping every station's face
// values (what the reduction does). Each round's seconds, the best, and a check value.
// `test` names the selection test of the sets ("surface", "subvoxel": the patches come from the
// input's points; "subvoxel-per-voxel" and "surface-per-voxel": the per-ray engines); `sets_only`
// skips the evaluation.
int VisibilityOnly(const vc::SceneInput& input, const vc::VoxelScene& s, double grid, int every, int threads,
                   int repeat, const std::string& test, bool sets_only) {
  vc::planner::CandidateOptions co;
  co.grid_spacing_m = grid;
  auto candidates = vc::planner::GenerateCandidates(s, co);
  if (!candidates.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", candidates.status().ToString().c_str());
    return 2;
  }
  const std::vector<vc::WorldPoint>& all = candidates->positions;
  std::vector<vc::WorldPoint> some, fifteen;
  for (size_t i = 0; i < all.size(); i += size_t(every)) some.push_back(all[i]);
  for (size_t i = 0; i < 15 && !all.empty(); ++i) fifteen.push_back(all[i * all.size() / 15]);
  // Wall seconds per round and the best; also the least CPU seconds of the process in a round: on
  // a loaded machine the wall time of a run depends on what else runs beside it, its CPU time much
  // less (docs/BENCHMARKS.md, "The paired method").
  auto rounds = [&](const char* what, auto&& run) {
    std::printf("%s:", what);
    double best = 1e300, best_cpu = 1e300;
    std::string check;
    for (int r = 0; r < repeat; ++r) {
      const auto t0 = Clock::now();
      const double c0 = ProcessCpuSeconds();
      check = run();
      const double t = Seconds(t0);
      best = std::min(best, t);
      best_cpu = std::min(best_cpu, ProcessCpuSeconds() - c0);
      std::printf(" %.3f", t);
    }
    std::printf(" s; best %.3f s; cpu %.3f s at least; %s\n", best, best_cpu, check.c_str());
  };
  const bool subvoxel = test.rfind("subvoxel", 0) == 0;
  const bool per_voxel = test.find("per-voxel") != std::string::npos;
  std::vector<vc::SurfacePatch> patches;
  if (subvoxel) patches = vc::ComputeSurfacePatches(s, input.points);
  char title[200];
  std::snprintf(title, sizeof title, "visibility sets (%s), %zu of %zu candidates, %d threads", test.c_str(),
                some.size(), all.size(), threads);
  rounds(title, [&] {
    vc::VisibilitySetsOptions o;
    o.threads = threads;
    o.per_voxel = per_voxel;
    if (subvoxel) {
      o.test = vc::SelectionTest::kSubvoxel;
      o.surface_patches = patches;
    }
    auto sets = vc::ComputeVisibilitySets(s, some, o);
    if (!sets.ok()) return sets.status().ToString();
    size_t visible = 0;
    uint64_t hash = 1469598103934665603ull;  // FNV-1a over the sets' ids
    for (const auto& set : *sets) {
      visible += set.count();
      set.ForEach([&](uint32_t id) { hash = (hash ^ id) * 1099511628211ull; });
      hash = (hash ^ 0xffffffffull) * 1099511628211ull;
    }
    char line[96];
    std::snprintf(line, sizeof line, "%zu visible, hash %016llx", visible, (unsigned long long)hash);
    return std::string(line);
  });
  if (sets_only) return 0;
  std::snprintf(title, sizeof title, "exact evaluation of %zu candidates, per-station values kept, %d threads",
                fifteen.size(), threads);
  rounds(title, [&] {
    vc::EvaluateOptions o;
    o.threads = threads;
    o.keep_face_values = true;
    o.keep_per_viewpoint_values = true;
    auto ev = vc::Evaluate(s, fifteen, o);
    char g[64];
    std::snprintf(g, sizeof g, "G = %.6f", ev->overall.global_visibility);
    return std::string(g);
  });
  return 0;
}

// The fine-evaluation target: a 10-station plan of the hall (planned at 0.1 m) evaluated
// at 0.01 m, where the scene comes from the hall sampled at 0.005 m (about 1.7e8 points, streamed
// into a voxel accumulator), by sampling faces until the 95 % interval of G is within +-0.5 %.
int FineEvaluation(int threads) {
  const auto start = Clock::now();
  vc::SynthOptions coarse;
  coarse.spacing_m = 0.05;
  auto usual = vc::GenerateScene("hall", coarse);
  if (!usual.ok()) return 2;
  vc::SceneInput input;
  input.points = std::move(*usual);
  vc::PlanOptions po;
  po.resolution_m = 0.1;
  po.max_stations = 10;
  po.threads = threads;
  auto t = Clock::now();
  auto plan = vc::Plan(input, po);
  if (!plan.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", plan.status().ToString().c_str());
    return 2;
  }
  std::vector<vc::WorldPoint> stations;
  for (const auto& st : plan->stations) stations.push_back(st.position);
  std::printf("## Fine evaluation\nplan at 0.1 m: %zu stations in %.1f s (not part of the figure)\n", stations.size(),
              Seconds(t));

  const auto figure_start = Clock::now();
  vc::SynthOptions fine;
  fine.spacing_m = 0.005;
  vc::VoxelAccumulator acc(0.01, uint64_t{3} << 30);
  t = Clock::now();
  const vc::Status st = vc::ForEachScenePoint("hall", fine, [&](const Eigen::Vector3f& p) { acc.Add(p); });
  auto scene = acc.Finish();
  if (!st.ok() || !scene.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", (st.ok() ? scene.status() : st).ToString().c_str());
    return 2;
  }
  std::printf("hall sampled at 0.005 m: %llu points -> %zu voxels at 0.01 m in %.1f s\n",
              (unsigned long long)acc.points_added(), scene->occupied.size(), Seconds(t));
  vc::EvaluateOptions eo;
  eo.threads = threads;
  eo.sample_faces = 20000;
  double eval_s = 0;
  vc::Result<vc::Evaluation> ev = vc::InternalError("not run");
  for (int round = 0; round < 4; ++round) {
    t = Clock::now();
    ev = vc::Evaluate(*scene, stations, eo);
    eval_s += Seconds(t);
    if (!ev.ok()) {
      std::fprintf(stderr, "vc-bench: %s\n", ev.status().ToString().c_str());
      return 2;
    }
    std::printf("evaluation: %llu sampled faces x %zu stations in %.1f s: G = %.4f +- %.4f (95 %%)\n",
                (unsigned long long)eo.sample_faces, stations.size(), Seconds(t), ev->overall.global_visibility,
                ev->global_visibility_ci95);
    if (ev->global_visibility_ci95 <= 0.005) break;
    // The interval shrinks as 1/sqrt(n): ask for enough faces, with 10 % to spare.
    const double scale = ev->global_visibility_ci95 / 0.005;
    eo.sample_faces = uint64_t(double(eo.sample_faces) * scale * scale * 1.1) + 1;
  }
  std::printf(
      "| figure | seconds |\n|---|---|\n| stream and voxelise 0.005 m -> 0.01 m | %.1f |\n"
      "| sampled evaluation, 10 stations | %.1f |\n| **total** | **%.1f** |\n",
      Seconds(figure_start) - eval_s, eval_s, Seconds(figure_start));
  std::printf("peak RSS: %.1f MiB (whole run %.1f s)\n", PeakRssMiB(), Seconds(start));
  return ev->global_visibility_ci95 <= 0.005 ? 0 : 1;
}

struct Ray {
  Eigen::Vector3d origin;     // world, m
  Eigen::Vector3d direction;  // unit, as OctoMap normalises it (float)
};

// The command line.
struct BenchOptions {
  std::string scene = "hall";
  double spacing = 0.05, resolution = 0.1, grid = 1.0;
  int rays = 200000, octomap_rays = 20000, threads = 2, repeat = 5;
  bool quick = false, scaling = true, rays_only = false, fine_eval = false, all_targets = false, sets = true;
  bool visibility_only = false, candidates_only = false;
  bool bar = false;               // --bar: the bar method (docs/BENCHMARKS.md, "The bar method")
  int bar_rays = 400000;          // --bar: the compatibility rays sampled for OctoMap
  bool spacing_given = false;     // --spacing on the command line (--bar: 0.02 m otherwise)
  bool resolution_given = false;  // --resolution on the command line: an OctoMap is resampled to it
  int every = 4;
  std::string test = "surface";  // --visibility-only's selection test
  bool test_given = false;       // --test on the command line: the sets only
};

// The working resolution for `input`: an OctoMap's own unless --resolution was given.
double WorkingResolution(const vc::SceneInput& input, const BenchOptions& o) {
  return input.octree && !o.resolution_given ? 0.0 : o.resolution;
}

void AddFlags(CLI::App& app, BenchOptions* o) {
  app.add_option("--scene", o->scene, "synthetic scene spec (hall, box, comb:5, ...) or a file path");
  app.add_option("--spacing", o->spacing, "point spacing of synthetic scenes, m");
  app.add_option("--resolution", o->resolution, "working resolution, m (an OctoMap: its own unless given)");
  app.add_option("--grid", o->grid, "candidate grid spacing, m");
  app.add_option("--rays", o->rays, "rays for our traversal");
  app.add_option("--octomap-rays", o->octomap_rays, "rays (a prefix of ours) for OctoMap castRay");
  app.add_option("--threads", o->threads, "worker threads for the plan");
  app.add_option("--repeat", o->repeat, "interleaved timing rounds of the ray engines (medians are printed)")
      ->check(CLI::Range(1, 1000));
  app.add_flag("--quick", o->quick, "small scene, few rays, no scaling tables (CI)");
  app.add_flag("!--no-scaling", o->scaling, "skip the scaling tables");
  app.add_flag("!--no-sets", o->sets, "skip the three full visibility-set computations after the plan");
  app.add_flag("--rays-only", o->rays_only, "only the ray comparison with OctoMap");
  app.add_flag("--visibility-only", o->visibility_only,
               "only the grouped visibility sets of every --every-th candidate and the exact evaluation of 15 "
               "candidates, best of --repeat rounds (A/B runs of two builds)");
  app.add_flag("--candidates-only", o->candidates_only,
               "only the candidate stage under each ground model (auto, terrain, floors): counts, floor levels, "
               "the terrain's ground, seconds; then terrain and floors with doorway candidates (docs/PLANNING.md, "
               "\"Terrain\")");
  app.add_option("--every", o->every, "with --visibility-only: every how many candidates")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--test", o->test,
                 "with --visibility-only: the sets' selection test (surface, subvoxel, or either with -per-voxel "
                 "for the per-ray engine); given, only the sets are timed")
      ->check(CLI::IsMember({"surface", "subvoxel", "surface-per-voxel", "subvoxel-per-voxel"}));
  app.add_flag("--bar", o->bar,
               "only the bar method: the plan of the scene (default hall at --spacing 0.02) twice, the second "
               "timed, against OctoMap castRay on a sample of the compatibility rays of the plan's candidates, "
               "extrapolated to all of them (docs/BENCHMARKS.md, \"The bar method\")");
  app.add_option("--bar-rays", o->bar_rays, "with --bar: the compatibility rays sampled for OctoMap")
      ->check(CLI::Range(1000, 100000000));
  app.add_flag("--all-targets", o->all_targets, "also time the SIMD batch kernel on every other instruction set");
  app.add_flag("--fine-eval", o->fine_eval,
               "only the fine evaluation: the hall sampled at 0.005 m, a 10-station plan evaluated at 0.01 m "
               "by sampling to a 95 % interval of +-0.5 %");
}

// --quick: a small scene, few rays, one round, no scaling tables.
void ApplyQuick(BenchOptions* o) {
  o->scene = "rooms:3";
  o->rays = 20000;
  o->octomap_rays = 2000;
  o->scaling = false;
  o->repeat = 1;
}

// The scene as read and as voxelised for the benchmarks.
struct LoadedScene {
  vc::SceneInput input;
  vc::VoxelizeOptions voxelize;
  vc::VoxelScene voxels;
};

// Loads and voxelises the scene and prints its size and the seconds each step took.
vc::Result<LoadedScene> LoadAndVoxelize(const BenchOptions& o) {
  auto t0 = Clock::now();
  VC_ASSIGN_OR_RETURN(vc::SceneInput input, LoadScene(o.scene, o.spacing, 1));
  const double load_s = Seconds(t0);
  vc::VoxelizeOptions vo;
  vo.resolution_m = WorkingResolution(input, o);
  t0 = Clock::now();
  VC_ASSIGN_OR_RETURN(vc::VoxelScene s, vc::Voxelize(input, vo));
  const double vox_s = Seconds(t0);
  std::printf("scene: %zu points, %zu occupied voxels at %.3f m, grid %.1f MiB; load %.2f s, voxelise %.2f s\n",
              input.points.size(), s.occupied.size(), s.resolution_m, double(s.grid.memory_bytes()) / (1 << 20), load_s,
              vox_s);
  return LoadedScene{std::move(input), vo, std::move(s)};
}

// `count` rays from random free points of the scene's bounds to random occupied voxel centres
// (the same rays on every run).
std::vector<Ray> MakeRays(const vc::VoxelScene& s, int count) {
  const vc::WorldPoint lo = s.BoundsMin(), hi = s.BoundsMax();
  std::mt19937_64 rng(2014);
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), uz(lo.z(), hi.z());
  std::uniform_int_distribution<size_t> pick(0, s.occupied.size() - 1);
  std::vector<Ray> ray_set;
  ray_set.reserve(count);
  while (int(ray_set.size()) < count) {
    const Eigen::Vector3f o(float(ux(rng)), float(uy(rng)), float(uz(rng)));
    if (s.grid.Occupied(s.grid.WorldToIndex(o.cast<double>()))) continue;
    const Eigen::Vector3f target = s.Center(pick(rng)).cast<float>();
    Eigen::Vector3f d = target - o;
    if (d.norm() < 1e-3f) continue;
    // OctoMap normalises in float; both sides use exactly that direction.
    d /= d.norm();
    ray_set.push_back({o.cast<double>(), d.cast<double>()});
  }
  return ray_set;
}

// Each ray as an index-space segment of `length_m`, the input of both of our kernels.
struct Segments {
  std::vector<Eigen::Vector3d> a, b;
};

Segments ToSegments(const vc::VoxelScene& s, const std::vector<Ray>& ray_set, double length_m) {
  Segments seg{std::vector<Eigen::Vector3d>(ray_set.size()), std::vector<Eigen::Vector3d>(ray_set.size())};
  for (size_t i = 0; i < ray_set.size(); ++i) {
    seg.a[i] = ray_set[i].origin * s.grid.inv_resolution();
    seg.b[i] = (ray_set[i].origin + ray_set[i].direction * length_m) * s.grid.inv_resolution();
  }
  return seg;
}

// What the three ray engines found, and their rates (rays/s) and ratios to OctoMap per round.
struct RayRounds {
  std::vector<vc::CastRayOutcome> theirs;  // the first `m` rays only
  std::vector<std::optional<vc::VoxelIndex>> ours, batch;
  size_t rechecked = 0;
  std::string batch_target;
  std::vector<double> theirs_r, ours_r, batch_r, ours_x, batch_x;
};

// The three engines are timed in `repeat` interleaved rounds (OctoMap, FirstOccupied, the batch
// kernel, then again), so that a slow spell of this shared machine hits all of them alike; each
// rate is the median over the rounds, and so is the ratio of each round's rates.
RayRounds TimeRayEngines(const vc::VoxelScene& s, const octomap::OcTree& tree, const std::vector<Ray>& ray_set,
                         const Segments& seg, int m, double length_m, int repeat) {
  RayRounds r;
  r.ours.resize(ray_set.size());
  r.batch.resize(ray_set.size());
  r.theirs.resize(m);
  for (int round = 0; round < repeat; ++round) {
    auto t0 = Clock::now();
    for (int i = 0; i < m; ++i)
      r.theirs[i] = vc::OctomapCastRay(tree, ray_set[i].origin, ray_set[i].direction, length_m);
    r.theirs_r.push_back(double(m) / Seconds(t0));
    t0 = Clock::now();
    for (size_t i = 0; i < ray_set.size(); ++i) r.ours[i] = vc::FirstOccupied(s.grid, seg.a[i], seg.b[i]);
    r.ours_r.push_back(double(ray_set.size()) / Seconds(t0));
    // The same segments through the SIMD batch kernel (one ray per lane, target chosen at run time).
    t0 = Clock::now();
    r.batch_target = vc::FirstOccupiedBatch(s.grid, seg.a, seg.b, r.batch, vc::BatchKernel::kAuto, &r.rechecked);
    r.batch_r.push_back(double(ray_set.size()) / Seconds(t0));
    r.ours_x.push_back(r.ours_r.back() / r.theirs_r.back());
    r.batch_x.push_back(r.batch_r.back() / r.theirs_r.back());
  }
  return r;
}

// The lanes kernel on every instruction set compiled in and supported here, forced through
// Highway's test mock: what the lanes would give on a CPU without the best one. The best one is
// skipped when the rounds already used its lanes. Prints a table row each; returns how many differ.
int TimeForcedTargets(const vc::VoxelScene& s, const Segments& seg, const RayRounds& r, double theirs_rps) {
  int forced_differ = 0;
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  for (size_t k = r.batch_target.ends_with(" lanes") ? 1 : 0; k < targets.size(); ++k) {
    hwy::SetSupportedTargetsForTest(targets[k]);
    std::vector<std::optional<vc::VoxelIndex>> forced(seg.a.size());
    const auto t0 = Clock::now();
    const std::string name = vc::FirstOccupiedBatch(s.grid, seg.a, seg.b, forced, vc::BatchKernel::kLanes);
    const double rps = double(seg.a.size()) / Seconds(t0);
    const bool same = forced == r.ours;
    std::printf("| vc FirstOccupiedBatch (%s, forced) | %zu | %.0f | %.1fx | one round |%s\n", name.c_str(),
                seg.a.size(), rps, rps / theirs_rps, same ? "" : " DIFFERENT");
    forced_differ += !same;
  }
  hwy::SetSupportedTargetsForTest(0);
  return forced_differ;
}

// OctoMap castRay, FirstOccupied and the batch kernel on identical rays: prints the rates and the
// identity checks; returns the number of rays where the engines disagree.
int CompareRays(const vc::VoxelScene& s, const octomap::OcTree& tree, const BenchOptions& o) {
  const double length = (s.BoundsMax() - s.BoundsMin()).norm();
  const std::vector<Ray> ray_set = MakeRays(s, o.rays);
  const Segments seg = ToSegments(s, ray_set, length);
  const int m = std::min<int>(o.octomap_rays, int(ray_set.size()));
  const RayRounds r = TimeRayEngines(s, tree, ray_set, seg, m, length, o.repeat);
  size_t batch_differ = 0;
  for (size_t i = 0; i < r.batch.size(); ++i) batch_differ += r.batch[i] != r.ours[i];
  int mismatches = 0, hits = 0;
  for (int i = 0; i < m; ++i) {
    const bool hit = r.theirs[i].kind == vc::CastRayOutcome::Kind::kHitOccupied;
    hits += hit;
    if (hit != r.ours[i].has_value() || (hit && vc::IndexToKey(*r.ours[i]) != r.theirs[i].hit)) ++mismatches;
  }
  const double theirs_rps = Median(r.theirs_r);
  std::printf("\n## Rays (single core, identical rays; first occupied voxel; median of %d interleaved rounds)\n",
              o.repeat);
  std::printf("| engine | rays | rays/s | ratio per core | ratio, lowest-highest round |\n|---|---|---|---|---|\n");
  std::printf("| OctoMap castRay | %d | %.0f | 1.0 | |\n", m, theirs_rps);
  std::printf("| vc FirstOccupied | %zu | %.0f | %.1fx | %.1f-%.1fx |\n", ray_set.size(), Median(r.ours_r),
              Median(r.ours_x), *std::min_element(r.ours_x.begin(), r.ours_x.end()),
              *std::max_element(r.ours_x.begin(), r.ours_x.end()));
  std::printf("| vc FirstOccupiedBatch (%s) | %zu | %.0f | %.1fx | %.1f-%.1fx |\n", r.batch_target.c_str(),
              ray_set.size(), Median(r.batch_r), Median(r.batch_x),
              *std::min_element(r.batch_x.begin(), r.batch_x.end()),
              *std::max_element(r.batch_x.begin(), r.batch_x.end()));
  const int forced_differ = o.all_targets ? TimeForcedTargets(s, seg, r, theirs_rps) : 0;
  std::printf("identity check on the %d shared rays: %d mismatches (%d hits) -> %s\n", m, mismatches, hits,
              mismatches == 0 ? "IDENTICAL" : "DIFFERENT");
  std::printf("batch: %zu of %zu rays had a near-tie (crossings within 2^-20) and were walked by FirstOccupied\n",
              r.rechecked, ray_set.size());
  std::printf("batch against FirstOccupied on all %zu rays: %zu differ -> %s\n", ray_set.size(), batch_differ,
              batch_differ == 0 ? "IDENTICAL" : "DIFFERENT");
  return mismatches + int(batch_differ) + forced_differ;
}

// A plan and its wall seconds (voxelisation included).
struct TimedPlan {
  std::optional<vc::PlanResult> plan;  // empty when it failed
  double seconds = -1;                 // -1 when it failed
};

// Plans `in` with the candidate grid `grid_m`; prints "plan failed" when it fails.
TimedPlan RunPlan(const vc::SceneInput& in, const BenchOptions& o, double grid_m) {
  vc::PlanOptions po;
  po.resolution_m = WorkingResolution(in, o);
  po.grid_spacing_m = grid_m;
  po.threads = o.threads;
  const auto start = Clock::now();
  auto plan = vc::Plan(in, po);
  const double total = Seconds(start);
  if (!plan.ok()) {
    std::printf("plan failed: %s\n", plan.status().ToString().c_str());
    return {};
  }
  return {std::move(plan).value(), total};
}

void PrintPlan(const vc::PlanResult& plan, double wall_s, int threads) {
  std::printf("\n## End-to-end plan (%d threads)\n| stage | seconds |\n|---|---|\n", threads);
  for (const auto& t : plan.timings)
    std::printf("| %s | %.3f |\n", std::string(vc::StageName(t.stage)).c_str(), t.seconds);
  std::printf("| total | %.3f |\n", plan.total_seconds);
  std::printf("| **total (wall, incl. voxelise)** | **%.3f** |\n", wall_s);
  std::printf("%zu stations from %llu candidates; %llu occupied, %llu coverable, %llu covered voxels; G = %.4f\n",
              plan.stations.size(), (unsigned long long)plan.candidate_count, (unsigned long long)plan.occupied_voxels,
              (unsigned long long)plan.coverable_voxels, (unsigned long long)plan.covered_voxels,
              plan.evaluation.overall.global_visibility);
  std::printf("route %.1f m in %d part(s); ground: %s\n", plan.route.length_m, plan.route.parts,
              plan.ground.reason.c_str());
}

// The candidate stage alone under each ground model (docs/PLANNING.md, "Terrain"): seconds,
// candidates, cells, floor levels, the terrain's ground columns and auto's reason; for floors, how
// many candidates stand in a cell where the terrain has none, or more than 1 m above its ground.
int CandidatesOnly(const vc::VoxelScene& s, double grid) {
  std::map<std::pair<long, long>, double> terrain_floor;  // per cell centre (mm): the terrain's floor
  for (vc::GroundModel g : {vc::GroundModel::kAuto, vc::GroundModel::kTerrain, vc::GroundModel::kFloors}) {
    vc::planner::CandidateOptions co;
    co.grid_spacing_m = grid;
    co.ground = g;
    const auto t0 = Clock::now();
    auto c = vc::planner::GenerateCandidates(s, co);
    const double seconds = Seconds(t0);
    if (!c.ok()) {
      std::fprintf(stderr, "vc-bench: %s\n", c.status().ToString().c_str());
      return 2;
    }
    uint64_t no_terrain = 0, above_terrain = 0;
    for (size_t i = 0; i < c->positions.size(); ++i) {
      const std::pair<long, long> cell{std::lround(c->positions[i].x() * 1000),
                                       std::lround(c->positions[i].y() * 1000)};
      if (g == vc::GroundModel::kTerrain) {
        terrain_floor[cell] = c->floor_z_m[i];
      } else if (g == vc::GroundModel::kFloors) {
        const auto it = terrain_floor.find(cell);
        if (it == terrain_floor.end()) {
          ++no_terrain;
        } else if (c->floor_z_m[i] > it->second + 1.0) {
          ++above_terrain;
        }
      }
    }
    std::string levels;
    for (const vc::planner::FloorLevel& l : c->levels) levels += " " + std::to_string(l.z_m).substr(0, 6);
    std::printf(
        "%s: %.2f s, %zu candidates of %llu cells (%llu without floor, %llu failing clearance); levels:%s; "
        "terrain ground %llu columns; %s\n",
        std::string(vc::GroundModelName(g)).c_str(), seconds, c->positions.size(),
        static_cast<unsigned long long>(c->cells), static_cast<unsigned long long>(c->rejected_no_floor),
        static_cast<unsigned long long>(c->rejected_clearance), levels.empty() ? " none" : levels.c_str(),
        static_cast<unsigned long long>(c->ground_columns), c->ground.reason.c_str());
    if (g == vc::GroundModel::kFloors) {
      std::printf("floors: %llu candidates in cells where the terrain has none, %llu more than 1 m above its ground\n",
                  static_cast<unsigned long long>(no_terrain), static_cast<unsigned long long>(above_terrain));
    }
  }
  // The plan's default adds doorway candidates (PlanOptions::doorway_candidates), on terrain too.
  for (vc::GroundModel g : {vc::GroundModel::kTerrain, vc::GroundModel::kFloors}) {
    vc::planner::CandidateOptions co;
    co.grid_spacing_m = grid;
    co.ground = g;
    co.doorway_candidates = true;
    const auto t0 = Clock::now();
    auto c = vc::planner::GenerateCandidates(s, co);
    if (!c.ok()) {
      std::fprintf(stderr, "vc-bench: %s\n", c.status().ToString().c_str());
      return 2;
    }
    std::printf("%s with doorway candidates: %.2f s, %zu candidates, %llu of them in passages\n",
                std::string(vc::GroundModelName(g)).c_str(), Seconds(t0), c->positions.size(),
                static_cast<unsigned long long>(c->passage_candidates));
  }
  return 0;
}

// The full visibility-set computation for both tests, on the plan's candidates; the surface test
// also per voxel (no face groups), the baseline of the grouped method.
void TimeVisibilitySets(const vc::VoxelScene& s, const std::vector<vc::WorldPoint>& candidates, int threads) {
  for (int run = 0; run < 3; ++run) {
    vc::VisibilitySetsOptions vo;
    vo.test = run == 2 ? vc::SelectionTest::kCompatibility : vc::SelectionTest::kSurfaceVisibility;
    vo.per_voxel = run == 1;
    vo.threads = threads;
    const auto c0 = Clock::now();
    auto sets = vc::ComputeVisibilitySets(s, candidates, vo);
    std::printf("visibility sets (%s%s): %zu candidates x %zu voxels in %.3f s\n",
                std::string(vc::SelectionTestName(vo.test)).c_str(), run == 1 ? ", per voxel" : "", candidates.size(),
                s.occupied.size(), Seconds(c0));
  }
}

// Plan seconds against the footprint (1, 2 and 4 copies of the scene) and the candidate spacing.
void PrintScaling(const LoadedScene& scene, const BenchOptions& o) {
  std::printf(
      "\n## Scaling: footprint (candidate grid %.2f m)\n| footprint | occupied voxels | plan s |\n|---|---|---|\n",
      o.grid);
  for (int tiles : {1, 2, 4}) {
    auto in = LoadScene(o.scene, o.spacing, tiles);
    if (!in.ok()) continue;
    auto v = vc::Voxelize(*in, scene.voxelize);
    const double secs = RunPlan(*in, o, o.grid).seconds;
    std::printf("| %dx | %zu | %.2f |\n", tiles, v.ok() ? v->occupied.size() : size_t{0}, secs);
  }
  std::printf("\n## Scaling: candidate spacing (footprint 1x)\n| spacing m | plan s |\n|---|---|\n");
  for (double g : {2.0, 1.0, 0.5}) std::printf("| %.2f | %.2f |\n", g, RunPlan(scene.input, o, g).seconds);
}

// The compatibility rays of a plan (ALGORITHM.md section 3, docs/VISIBILITY.md "Compatibility"):
// for every candidate that can be a viewpoint (in range, not inside an occupied voxel) and every
// occupied voxel with a free 6-neighbour whose centre passes the scanner's limits, the segment from
// the candidate to the voxel's centre; the voxel is compatible iff it is the first occupied voxel on
// it. (A voxel whose 6 neighbours are all occupied is never compatible, so neither method casts to
// it.) `count` is exact; `sample` holds `sample_size` of them drawn uniformly with replacement.
struct CompatibilityRays {
  uint64_t count = 0, all_pairs = 0;  // the rays; every candidate x every occupied voxel
  size_t valid_candidates = 0, testable_voxels = 0;
  std::vector<std::pair<uint32_t, uint32_t>> sample;  // (candidate, voxel id)
};

CompatibilityRays CountCompatibilityRays(const vc::VoxelScene& s, const std::vector<vc::WorldPoint>& candidates,
                                         const vc::ScannerModel& scanner, size_t sample_size) {
  const vc::OccupancyGrid& g = s.grid;
  CompatibilityRays r;
  r.all_pairs = uint64_t(candidates.size()) * s.occupied.size();
  std::vector<vc::VoxelIndex> index(s.occupied.size());
  std::vector<uint32_t> testable;
  for (size_t i = 0; i < s.occupied.size(); ++i) {
    index[i] = g.WorldToIndex(s.Center(i));
    const vc::VoxelIndex& v = index[i];
    const bool enclosed = g.Occupied(v.x - 1, v.y, v.z) && g.Occupied(v.x + 1, v.y, v.z) &&
                          g.Occupied(v.x, v.y - 1, v.z) && g.Occupied(v.x, v.y + 1, v.z) &&
                          g.Occupied(v.x, v.y, v.z - 1) && g.Occupied(v.x, v.y, v.z + 1);
    if (!enclosed) testable.push_back(uint32_t(i));
  }
  r.testable_voxels = testable.size();
  std::vector<uint32_t> valid;
  std::vector<vc::ScannerLimits> limits;
  for (size_t k = 0; k < candidates.size(); ++k) {
    if (!vc::ViewpointInRange(candidates[k], g.resolution_m()) || g.Occupied(g.WorldToIndex(candidates[k]))) continue;
    valid.push_back(uint32_t(k));
    limits.emplace_back(scanner, g.resolution_m(), g.WorldToIndexSpace(candidates[k]));
  }
  r.valid_candidates = valid.size();
  auto passes = [&](size_t j, uint32_t id) {
    const vc::ScannerLimits& l = limits[j];
    if (!l.active()) return true;
    const vc::VoxelIndex& v = index[id];
    int axis = 0, sign = 1;
    if (l.JudgesFace()) l.EntryFace(v, &axis, &sign);
    return l.Passes(Eigen::Vector3d(v.x + 0.5, v.y + 0.5, v.z + 0.5), axis, sign);
  };
  for (size_t j = 0; j < valid.size(); ++j) {
    if (!limits[j].active()) {
      r.count += testable.size();
      continue;
    }
    for (uint32_t id : testable) r.count += passes(j, id);
  }
  // Uniform over the rays: a uniform (candidate, testable voxel) pair, kept if it passes.
  std::mt19937_64 rng(2014);
  std::uniform_int_distribution<size_t> pick_c(0, valid.empty() ? 0 : valid.size() - 1);
  std::uniform_int_distribution<size_t> pick_v(0, testable.empty() ? 0 : testable.size() - 1);
  while (r.count > 0 && r.sample.size() < sample_size) {
    const size_t j = pick_c(rng);
    const uint32_t id = testable[pick_v(rng)];
    if (passes(j, id)) r.sample.emplace_back(valid[j], id);
  }
  return r;
}

// CPU seconds (user and system) this process has used so far.
double CpuSeconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// OctoMap castRay on the sampled rays with `threads` threads (each a contiguous share), each ray
// from the candidate along the direction to the voxel's centre (normalised in float, as OctoMap
// does), as far as the scene's diagonal (its first occupied voxel is the ray's answer: the voxel is
// compatible iff it is that voxel). Then our FirstOccupied on the same segments: how many first hits differ
// (the identity check), and how many rays' voxels are compatible. Returns castRay's rays/s.
struct OctomapCompatibility {
  double rays_per_s = 0;
  double cpu_s_per_ray = 0;  // this process's CPU seconds over the rays cast
  size_t differ = 0, compatible = 0;
};

OctomapCompatibility TimeOctomapCompatibility(const vc::VoxelScene& s, const octomap::OcTree& tree,
                                              const std::vector<vc::WorldPoint>& candidates, const CompatibilityRays& r,
                                              int threads) {
  const size_t m = r.sample.size();
  std::vector<Ray> rays(m);
  std::vector<double> length(m);
  const double diagonal_m = (s.BoundsMax() - s.BoundsMin()).norm();
  for (size_t i = 0; i < m; ++i) {
    const Eigen::Vector3f o = candidates[r.sample[i].first].cast<float>();  // OctoMap's point3d is float
    const Eigen::Vector3f d = s.Center(r.sample[i].second).cast<float>() - o;
    length[i] = diagonal_m;
    rays[i] = {o.cast<double>(), (d / d.norm()).cast<double>()};
  }
  std::vector<vc::CastRayOutcome> theirs(m);
  const double cpu0 = CpuSeconds();
  const auto t0 = Clock::now();
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      for (size_t i = m * t / threads; i < m * (t + 1) / threads; ++i)
        theirs[i] = vc::OctomapCastRay(tree, rays[i].origin, rays[i].direction, length[i]);
    });
  }
  for (std::thread& t : pool) t.join();
  OctomapCompatibility out;
  out.rays_per_s = double(m) / Seconds(t0);
  out.cpu_s_per_ray = (CpuSeconds() - cpu0) / double(m);
  const Segments seg = [&] {
    Segments all{std::vector<Eigen::Vector3d>(m), std::vector<Eigen::Vector3d>(m)};
    for (size_t i = 0; i < m; ++i) {
      all.a[i] = rays[i].origin * s.grid.inv_resolution();
      all.b[i] = (rays[i].origin + rays[i].direction * length[i]) * s.grid.inv_resolution();
    }
    return all;
  }();
  for (size_t i = 0; i < m; ++i) {
    const auto ours = vc::FirstOccupied(s.grid, seg.a[i], seg.b[i]);
    const bool hit = theirs[i].kind == vc::CastRayOutcome::Kind::kHitOccupied;
    out.differ += hit != ours.has_value() || (hit && vc::IndexToKey(*ours) != theirs[i].hit);
    out.compatible += hit && theirs[i].hit == s.occupied[r.sample[i].second];
  }
  return out;
}

// vc::Plan of `input`, timed (wall and this process's CPU seconds); prints the error if it fails.
std::optional<std::pair<TimedPlan, double>> TimedPlanRun(const vc::SceneInput& input, const vc::PlanOptions& po) {
  const double cpu0 = CpuSeconds();
  const auto t0 = Clock::now();
  auto plan = vc::Plan(input, po);
  if (!plan.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", plan.status().ToString().c_str());
    return std::nullopt;
  }
  const double wall = Seconds(t0);
  return std::make_pair(TimedPlan{std::move(plan).value(), wall}, CpuSeconds() - cpu0);
}

// The bar method (docs/BENCHMARKS.md, "The bar method"): the whole vc::Plan of the scene twice
// (the second is the figure), and OctoMap castRay on a sample of the first plan's compatibility
// rays with as many threads as the plan, once between the two plans and once after the second;
// the faster of the two rates is extrapolated to all the rays. Prints both, the ratio and the
// second plan's stages.
int BarMethod(const BenchOptions& o) {
  std::printf("vc-bench --bar: scene %s at %.3f m spacing, plan defaults, %d threads (hardware: %u)\n", o.scene.c_str(),
              o.spacing, o.threads, std::thread::hardware_concurrency());
  auto t0 = Clock::now();
  auto input = LoadScene(o.scene, o.spacing, 1);
  if (!input.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", input.status().ToString().c_str());
    return 2;
  }
  std::printf("scene: %zu points, generated/read in %.2f s\n", input->points.size(), Seconds(t0));
  vc::PlanOptions po;
  po.threads = o.threads;
  const auto first = TimedPlanRun(*input, po);
  if (!first) return 2;
  std::printf("first plan (cold): %.3f s\n", first->first.seconds);
  const vc::PlanResult& cold = *first->first.plan;
  auto voxels = vc::Voxelize(*input, {cold.resolution_m, po.memory_budget_bytes});
  if (!voxels.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", voxels.status().ToString().c_str());
    return 2;
  }
  const std::vector<vc::WorldPoint>& candidates = cold.heat_map.positions;
  t0 = Clock::now();
  const CompatibilityRays rays = CountCompatibilityRays(*voxels, candidates, po.scanner, size_t(o.bar_rays));
  std::printf(
      "compatibility rays: %zu of %zu candidates valid x %zu of %zu occupied voxels testable (not enclosed), "
      "within the scanner's limits: %llu rays (every candidate x every voxel: %llu); counted in %.2f s\n",
      rays.valid_candidates, candidates.size(), rays.testable_voxels, voxels->occupied.size(),
      (unsigned long long)rays.count, (unsigned long long)rays.all_pairs, Seconds(t0));
  if (rays.count == 0) return 2;
  auto tree = input->octree ? std::const_pointer_cast<octomap::OcTree>(input->octree)
                            : vc::BuildOctree(voxels->resolution_m, voxels->occupied);
  OctomapCompatibility om[2];
  om[0] = TimeOctomapCompatibility(*voxels, *tree, candidates, rays, o.threads);
  const auto second = TimedPlanRun(*input, po);
  if (!second) return 2;
  om[1] = TimeOctomapCompatibility(*voxels, *tree, candidates, rays, o.threads);
  const vc::PlanResult& plan = *second->first.plan;
  const double plan_s = second->first.seconds;
  if (plan.heat_map.positions != candidates)
    std::printf("NOTE: the second plan's candidates differ from the first's\n");
  for (int r = 0; r < 2; ++r) {
    std::printf(
        "OctoMap castRay %s, %d threads: %zu sampled rays at %.0f rays/s, %zu of them to a compatible voxel; "
        "first hits against FirstOccupied on the same segments: %zu differ%s\n",
        r == 0 ? "before the second plan" : "after it", o.threads, rays.sample.size(), om[r].rays_per_s,
        om[r].compatible, om[r].differ,
        om[r].differ == 0 ? " (identical)"
                          : " (rays from the candidates' lattice points meet exact ties, which the two break either "
                            "way: docs/VISIBILITY.md, the tie rule)");
  }
  PrintPlan(plan, plan_s, o.threads);
  const double rate = std::max(om[0].rays_per_s, om[1].rays_per_s);
  const double octomap_s = double(rays.count) / rate;
  std::printf("\n| the bar method | seconds |\n|---|---|\n");
  std::printf(
      "| OctoMap castRay, the %llu compatibility rays at the faster round's %.0f rays/s (%d threads) | %.1f |\n",
      (unsigned long long)rays.count, rate, o.threads, octomap_s);
  std::printf("| vc::Plan, second run, %d threads (voxelise to route; this process's CPU: %.1f s) | %.3f |\n",
              o.threads, second->second, plan_s);
  std::printf("| **ratio** | **%.1fx** |\n", octomap_s / plan_s);
  // The same in CPU seconds (per core for both), which a loaded machine disturbs less than wall time.
  const double cpu_per_ray = std::min(om[0].cpu_s_per_ray, om[1].cpu_s_per_ray);
  std::printf("| CPU seconds: OctoMap %.1f (the faster round's %.3g s per ray), vc::Plan %.1f | ratio %.1fx |\n",
              double(rays.count) * cpu_per_ray, cpu_per_ray, second->second,
              double(rays.count) * cpu_per_ray / second->second);
  std::printf("peak RSS: %.1f MiB\n", PeakRssMiB());
  return 0;
}

// The rays, the plan and the scaling tables (as the flags select); 0 when the ray engines agree.
int RunBench(const BenchOptions& o) {
  std::printf("vc-bench: scene %s, resolution %.3f m, candidate grid %.2f m, %d threads (hardware: %u)\n",
              o.scene.c_str(), o.resolution, o.grid, o.threads, std::thread::hardware_concurrency());
  auto loaded = LoadAndVoxelize(o);
  if (!loaded.ok()) {
    std::fprintf(stderr, "vc-bench: %s\n", loaded.status().ToString().c_str());
    return 2;
  }
  const vc::SceneInput& input = loaded->input;
  const vc::VoxelScene& s = loaded->voxels;
  if (o.visibility_only) return VisibilityOnly(input, s, o.grid, o.every, o.threads, o.repeat, o.test, o.test_given);
  if (o.candidates_only) return CandidatesOnly(s, o.grid);

  auto tree = input.octree ? std::const_pointer_cast<octomap::OcTree>(input.octree)
                           : vc::BuildOctree(s.resolution_m, s.occupied);
  const int mismatches = CompareRays(s, *tree, o);
  if (o.rays_only) return mismatches == 0 ? 0 : 1;

  const TimedPlan timed = RunPlan(input, o, o.grid);
  if (timed.plan) {
    PrintPlan(*timed.plan, timed.seconds, o.threads);
    if (o.sets) TimeVisibilitySets(s, timed.plan->heat_map.positions, o.threads);
  }
  std::printf("\npeak RSS: %.1f MiB\n", PeakRssMiB());
  if (o.scaling && !input.octree) PrintScaling(*loaded, o);
  std::printf("\npeak RSS (all runs): %.1f MiB\n", PeakRssMiB());
  return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vc-bench: end-to-end and ray-casting benchmarks against OctoMap"};
  BenchOptions o;
  AddFlags(app, &o);
  CLI11_PARSE(app, argc, argv);
  o.test_given = app.count("--test") > 0;
  o.resolution_given = app.count("--resolution") > 0;
  o.spacing_given = app.count("--spacing") > 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // figures appear as they are measured
  if (o.fine_eval) return FineEvaluation(o.threads);
  if (o.bar) {
    if (!o.spacing_given) o.spacing = 0.02;
    return BarMethod(o);
  }
  if (o.quick) ApplyQuick(&o);
  return RunBench(o);
}
