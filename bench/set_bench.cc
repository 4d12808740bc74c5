// vc-set-bench: dense bitsets against Roaring bitmaps for a plan's visibility sets (docs/BENCHMARKS.md,
// "Visibility sets: dense or Roaring"). Computes every candidate's set as the planner does, then
// prints, per representation: the bytes of all sets, the time to encode and decode them (the form
// they travel in between replicas, wire/voxel_set_codec.h), the union of all (selection's coverable
// set) and the intersection counts of every pair among the first --pairs candidates (the overlap
// matrix of registration). A site larger than the synthetic scenes: --tiles K copies the scene
// K x K side by side (2 m apart); --max-range makes each station's view local, as on a campus.
#include <roaring/roaring.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "bench_scene.h"
#include "vc/plan/planner.h"
#include "vc/plan/stages.h"
#include "vc/scene/scene_input.h"
#include "vc/synth/synth.h"
#include "vc/wire/voxel_set_codec.h"

namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
using vc::bench::PeakRssMiB;

// The scene, tiles x tiles copies of it.
vc::Result<vc::SceneInput> Load(const std::string& scene, double spacing, int tiles) {
  return vc::bench::LoadScene(scene, spacing, tiles * tiles);
}

int PlanEndToEnd(const std::string& scene, double spacing, int tiles, double resolution, double grid, double max_range,
                 int threads, const std::string& solver, double sparse_gain, uint64_t budget, bool consolidate,
                 bool reduce) {
  auto t = Clock::now();
  auto input = Load(scene, spacing, tiles);
  if (!input.ok()) return std::fprintf(stderr, "%s\n", input.status().ToString().c_str()), 1;
  std::printf("scene %s x%d: %zu points, loaded in %.1f s\n", scene.c_str(), tiles * tiles, input->points.size(),
              Since(t));
  vc::PlanOptions options;
  options.resolution_m = resolution;
  options.grid_spacing_m = grid;
  options.scanner.max_range_m = max_range;
  options.threads = threads;
  options.sparse_set_gain = sparse_gain;
  options.memory_budget_bytes = budget;
  options.consolidate = consolidate;
  options.reduce = reduce;
  options.solver = solver == "greedy"  ? vc::SelectionSolver::kGreedy
                   : solver == "exact" ? vc::SelectionSolver::kExact
                                       : vc::SelectionSolver::kAuto;
  vc::JobContext ctx;
  int last = -1;
  ctx.progress = [&](const vc::ProgressEvent& e) {
    const int pct = int(e.fraction * 10);
    if (pct == last) return;
    last = pct;
    std::fprintf(stderr, "  %s %3.0f %%%s%s\n", std::string(vc::StageName(e.stage)).c_str(), 100 * e.fraction,
                 e.message.empty() ? "" : ": ", e.message.c_str());
  };
  t = Clock::now();
  auto result = vc::Plan(*input, options, ctx);
  if (!result.ok()) {
    std::printf("plan failed after %.1f s: %s (peak RSS %.0f MiB)\n", Since(t), result.status().ToString().c_str(),
                PeakRssMiB());
    return 1;
  }
  std::printf("greedy picks %d, consolidation saved %d\n", result->greedy_stations, result->consolidated);
  std::printf(
      "plan: %zu stations, coverage %.4f of %llu coverable voxels (%llu occupied), G %.4f, %llu candidates, "
      "%s (bound %.0f)\n",
      result->stations.size(), double(result->covered_voxels) / double(result->coverable_voxels),
      (unsigned long long)result->coverable_voxels, (unsigned long long)result->occupied_voxels,
      result->evaluation.overall.global_visibility, (unsigned long long)result->candidate_count,
      result->optimality.solver.c_str(), result->optimality.lower_bound);
  for (const auto& st : result->timings) {
    std::printf("  %-11s %8.1f s\n", std::string(vc::StageName(st.stage)).c_str(), st.seconds);
  }
  std::printf("total %.1f s, peak RSS %.0f MiB (budget %.1f GiB)\n", result->total_seconds, PeakRssMiB(),
              double(budget) / 1073741824.0);
  for (const std::string& w : result->warnings) std::printf("warning: %s\n", w.c_str());
  return 0;
}

// Evaluates `count` candidates spread over the site (every k-th), all in one vc::Evaluate and each
// alone (the reduction's per-station evaluation), and prints the time per station and G.
int EvaluateStations(const vc::VoxelScene& s, const std::vector<vc::WorldPoint>& candidates, size_t count,
                     const vc::PlanOptions& options) {
  std::vector<vc::WorldPoint> stations;
  const size_t step = std::max<size_t>(1, candidates.size() / std::max<size_t>(count, 1));
  for (size_t k = 0; k < candidates.size() && stations.size() < count; k += step) stations.push_back(candidates[k]);
  vc::EvaluateOptions eval;
  eval.scanner = options.scanner;
  eval.threads = options.threads;
  auto t = Clock::now();
  auto all = vc::Evaluate(s, stations, eval);
  if (!all.ok()) return std::fprintf(stderr, "%s\n", all.status().ToString().c_str()), 1;
  const double together_s = Since(t);
  t = Clock::now();
  const size_t alone = std::min<size_t>(stations.size(), 4);
  for (size_t k = 0; k < alone; ++k) {
    auto one = vc::Evaluate(s, {stations[k]}, eval);
    if (!one.ok()) return std::fprintf(stderr, "%s\n", one.status().ToString().c_str()), 1;
    if (std::abs(all->per_viewpoint[k].global_visibility - one->overall.global_visibility) > 1e-12) {
      std::printf("station %zu: G together %.12f, alone %.12f\n", k, all->per_viewpoint[k].global_visibility,
                  one->overall.global_visibility);
    }
  }
  const double alone_s = Since(t);
  std::printf("evaluate %zu stations: together %.3f s (%.1f ms each), the first %zu alone %.1f ms each; G %.9f\n",
              stations.size(), together_s, 1e3 * together_s / double(stations.size()), alone,
              1e3 * alone_s / double(alone), all->overall.global_visibility);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene = "hall";
  double spacing = 0.05, resolution = 0.1, grid = 1.0, max_range = 75.0;
  int tiles = 1, threads = 0;
  size_t pairs = 300;
  CLI::App app{"vc-set-bench: dense bitsets against Roaring bitmaps for a plan's visibility sets"};
  app.add_option("--scene", scene, "synthetic scene spec (hall, comb:5, ...) or a file path")->capture_default_str();
  app.add_option("--spacing", spacing, "point spacing of synthetic scenes, m")->capture_default_str();
  app.add_option("--resolution", resolution, "working resolution, m")->capture_default_str();
  app.add_option("--grid", grid, "candidate grid spacing, m")->capture_default_str();
  app.add_option("--max-range", max_range, "scanner range, m")->capture_default_str();
  app.add_option("--tiles", tiles, "copies of the scene, K x K")->capture_default_str();
  app.add_option("--pairs", pairs, "intersection counts among the first N candidates")->capture_default_str();
  app.add_option("--threads", threads, "threads for the visibility sets (0 = all)")->capture_default_str();
  bool plan = false;
  std::string solver = "auto";
  double sparse_gain = 4.0;
  uint64_t budget = uint64_t{4} << 30;
  app.add_flag("--plan", plan,
               "instead: plan the scene end to end (vc::Plan, default parameters but these) and print the stages' "
               "times, the plan and the peak memory");
  app.add_option("--solver", solver, "with --plan: greedy, exact or auto")->capture_default_str();
  app.add_option("--sparse-set-gain", sparse_gain, "with --plan: PlanOptions::sparse_set_gain")->capture_default_str();
  app.add_option("--memory-budget-bytes", budget, "with --plan: the plan's memory budget")->capture_default_str();
  bool no_consolidate = false, no_reduce = false;
  app.add_flag("--no-consolidate", no_consolidate, "with --plan: no consolidation after greedy");
  app.add_flag("--no-reduce", no_reduce, "with --plan: no reduction");
  size_t evaluate = 0;
  app.add_option("--evaluate", evaluate,
                 "instead: time vc::Evaluate of this many candidates spread over the site, together and alone");
  CLI11_PARSE(app, argc, argv);
  if (plan) {
    return PlanEndToEnd(scene, spacing, tiles, resolution, grid, max_range, threads, solver, sparse_gain, budget,
                        !no_consolidate, !no_reduce);
  }

  auto input = Load(scene, spacing, tiles);
  if (!input.ok()) {
    std::fprintf(stderr, "vc-set-bench: %s\n", input.status().ToString().c_str());
    return 1;
  }
  vc::PlanOptions options;
  options.resolution_m = resolution;
  options.grid_spacing_m = grid;
  options.scanner.max_range_m = max_range;
  options.threads = threads;
  options.memory_budget_bytes = uint64_t{16} << 30;
  options.sparse_set_gain = 0;  // the dense sets, to compare with their Roaring form
  auto voxelized = vc::planner::RunVoxelizeStage({*input}, options, {});
  if (!voxelized.ok()) return std::fprintf(stderr, "%s\n", voxelized.status().ToString().c_str()), 1;
  const vc::VoxelScene& s = voxelized->scene;
  auto candidates = vc::planner::RunCandidatesStage({s}, options, {});
  if (!candidates.ok()) return std::fprintf(stderr, "%s\n", candidates.status().ToString().c_str()), 1;
  const size_t n = candidates->positions.size(), voxels = s.occupied.size();
  if (evaluate > 0) return EvaluateStations(s, candidates->positions, evaluate, options);
  auto t = Clock::now();
  auto sets = vc::ComputeVisibilitySets(s, candidates->positions, vc::planner::VisibilitySetsOptionsFor(options));
  if (!sets.ok()) return std::fprintf(stderr, "%s\n", sets.status().ToString().c_str()), 1;
  const double visibility_s = Since(t);
  uint64_t seen = 0, dense_bytes = 0;
  for (const vc::VoxelSet& v : *sets) {
    seen += v.count();
    dense_bytes += v.words().size() * 8;
  }
  std::printf(
      "scene %s x%d at %.2f m, range %.0f m: %zu voxels, %zu candidates, each sees %.1f %% (visibility %.1f s)\n",
      scene.c_str(), tiles * tiles, s.resolution_m, max_range, voxels, n, 100.0 * double(seen) / double(n * voxels),
      visibility_s);

  // Encode and decode (the wire form), and the Roaring bitmaps for the set operations.
  t = Clock::now();
  std::vector<std::string> encoded;
  uint64_t roaring_bytes = 0;
  for (const vc::VoxelSet& v : *sets) {
    encoded.push_back(vc::wire::EncodeVoxelSet(v));
    roaring_bytes += encoded.back().size();
  }
  const double encode_s = Since(t);
  t = Clock::now();
  for (const std::string& e : encoded) (void)vc::wire::DecodeVoxelSet(e, voxels);
  const double decode_s = Since(t);
  std::vector<roaring_bitmap_t*> bitmaps;
  for (const std::string& e : encoded) bitmaps.push_back(roaring_bitmap_portable_deserialize_safe(e.data(), e.size()));

  t = Clock::now();
  vc::VoxelSet dense_union(voxels);
  for (const vc::VoxelSet& v : *sets) dense_union.Union(v);
  const double dense_union_s = Since(t);
  t = Clock::now();
  roaring_bitmap_t* roaring_union =
      roaring_bitmap_or_many(bitmaps.size(), const_cast<const roaring_bitmap_t**>(bitmaps.data()));
  const double roaring_union_s = Since(t);
  const bool same_union = roaring_bitmap_get_cardinality(roaring_union) == dense_union.count();
  roaring_bitmap_free(roaring_union);

  const size_t m = std::min(pairs, n);
  uint64_t dense_sum = 0, roaring_sum = 0;
  t = Clock::now();
  for (size_t i = 0; i < m; ++i) {
    for (size_t j = i + 1; j < m; ++j) dense_sum += (*sets)[i].CountAnd((*sets)[j]);
  }
  const double dense_pairs_s = Since(t);
  t = Clock::now();
  for (size_t i = 0; i < m; ++i) {
    for (size_t j = i + 1; j < m; ++j) roaring_sum += roaring_bitmap_and_cardinality(bitmaps[i], bitmaps[j]);
  }
  const double roaring_pairs_s = Since(t);
  for (roaring_bitmap_t* b : bitmaps) roaring_bitmap_free(b);

  std::printf("| representation | bytes of all sets | union of all | %zu pairs' intersections |\n", m * (m - 1) / 2);
  std::printf("|---|---|---|---|\n");
  std::printf("| dense | %.1f MiB | %.3f s | %.3f s |\n", double(dense_bytes) / 1048576.0, dense_union_s,
              dense_pairs_s);
  std::printf("| Roaring | %.1f MiB (%.2fx smaller) | %.3f s | %.3f s |\n", double(roaring_bytes) / 1048576.0,
              double(dense_bytes) / double(roaring_bytes), roaring_union_s, roaring_pairs_s);
  std::printf("encode %.2f ms per set, decode %.2f ms per set; results agree: %s; peak RSS %.0f MiB\n",
              1e3 * encode_s / double(n), 1e3 * decode_s / double(n),
              same_union && dense_sum == roaring_sum ? "yes" : "NO", PeakRssMiB());
  return same_union && dense_sum == roaring_sum ? 0 : 1;
}
