// Micro-benchmarks of the hot kernels on a fixed synthetic scene (Google Benchmark).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <string>

#include "vc/plan/greedy.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/scene/voxel_scene.h"
#include "vc/synth/synth.h"
#include "vc/visibility/visibility.h"

namespace {

const vc::VoxelScene& Scene() {
  static const vc::VoxelScene scene = [] {
    vc::SceneInput in;
    vc::SynthOptions so;
    in.points = *vc::GenerateScene("rooms:4", so);
    vc::VoxelizeOptions vo;
    vo.resolution_m = 0.1;
    return *vc::Voxelize(in, vo);
  }();
  return scene;
}

void BM_FirstOccupied(benchmark::State& state) {
  const auto& s = Scene();
  std::mt19937_64 rng(1);
  const vc::WorldPoint lo = s.BoundsMin(), hi = s.BoundsMax();
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), uz(lo.z(), hi.z());
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays(4096);
  for (auto& r : rays)
    r = {vc::WorldPoint(ux(rng), uy(rng), uz(rng)) / s.resolution_m,
         vc::WorldPoint(ux(rng), uy(rng), uz(rng)) / s.resolution_m};
  size_t i = 0;
  for (auto _ : state) {
    const auto& r = rays[i++ & 4095];
    benchmark::DoNotOptimize(vc::FirstOccupied(s.grid, r.first, r.second));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FirstOccupied);

// The same segments through the SIMD batch kernel, 4096 per call; the label names the target.
void BM_FirstOccupiedBatch(benchmark::State& state) {
  const auto& s = Scene();
  std::mt19937_64 rng(1);
  const vc::WorldPoint lo = s.BoundsMin(), hi = s.BoundsMax();
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), uz(lo.z(), hi.z());
  std::vector<Eigen::Vector3d> a(4096), b(4096);
  for (size_t i = 0; i < a.size(); ++i) {
    a[i] = vc::WorldPoint(ux(rng), uy(rng), uz(rng)) / s.resolution_m;
    b[i] = vc::WorldPoint(ux(rng), uy(rng), uz(rng)) / s.resolution_m;
  }
  std::vector<std::optional<vc::VoxelIndex>> out(a.size());
  std::string target;
  for (auto _ : state) {
    target = vc::FirstOccupiedBatch(s.grid, a, b, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetLabel(target);
  state.SetItemsProcessed(state.iterations() * int64_t(a.size()));
}
BENCHMARK(BM_FirstOccupiedBatch);

void BM_VisibilitySets(benchmark::State& state) {
  const auto& s = Scene();
  const vc::WorldPoint c = (s.BoundsMin() + s.BoundsMax()) / 2;
  vc::VisibilitySetsOptions o;
  o.test = state.range(0) ? vc::SelectionTest::kCompatibility : vc::SelectionTest::kSurfaceVisibility;
  o.threads = 1;
  for (auto _ : state) benchmark::DoNotOptimize(vc::ComputeVisibilitySets(s, {c}, o));
  state.SetItemsProcessed(state.iterations() * int64_t(s.occupied.size()));
}
BENCHMARK(BM_VisibilitySets)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_EvaluateExact(benchmark::State& state) {
  const auto& s = Scene();
  const vc::WorldPoint c = (s.BoundsMin() + s.BoundsMax()) / 2;
  vc::EvaluateOptions o;
  o.threads = 1;
  for (auto _ : state) benchmark::DoNotOptimize(vc::Evaluate(s, {c}, o));
  state.SetItemsProcessed(state.iterations() * int64_t(s.occupied.size()) * 6);
}
BENCHMARK(BM_EvaluateExact)->Unit(benchmark::kMillisecond);

// A campus-like site for consolidation: a width x height voxel plane (400 x 200), a candidate every
// 4 voxels (5,000), each seeing the voxels within `radius` voxels of it (20) but a pseudo-random
// quarter (occlusion), so that greedy's many picks are mostly far apart and consolidation has many
// pairs to rule out.
std::vector<vc::VoxelSet> CampusSets(int width = 400, int height = 200, int radius = 20) {
  constexpr int kStep = 4;
  std::vector<vc::VoxelSet> sets;
  for (int cy = 0; cy < height; cy += kStep) {
    for (int cx = 0; cx < width; cx += kStep) {
      vc::VoxelSet s(size_t(width) * height);
      for (int y = std::max(0, cy - radius); y < std::min(height, cy + radius + 1); ++y) {
        for (int x = std::max(0, cx - radius); x < std::min(width, cx + radius + 1); ++x) {
          const uint32_t hash = uint32_t(x * 73856093) ^ uint32_t(y * 19349663) ^ uint32_t(sets.size() * 83492791);
          if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= radius * radius && hash % 4 != 0) {
            s.set(size_t(y) * width + size_t(x));
          }
        }
      }
      sets.push_back(std::move(s));
    }
  }
  return sets;
}

void BM_ConsolidatePicks(benchmark::State& state) {
  const std::vector<vc::VoxelSet> sets = CampusSets();
  vc::planner::GreedyOptions options;
  options.target_coverage = 0.99;
  const auto greedy = vc::planner::SelectGreedy(sets, options);
  std::vector<int> picks;
  for (const vc::planner::GreedyPick& p : greedy->picks) picks.push_back(p.candidate);
  size_t after = 0;
  for (auto _ : state) {
    const auto r = vc::planner::ConsolidatePicks(sets, picks, options);
    after = r->picks.size();
  }
  state.counters["greedy_picks"] = double(picks.size());
  state.counters["consolidated_picks"] = double(after);
}
BENCHMARK(BM_ConsolidatePicks)->Unit(benchmark::kMillisecond)->Iterations(1);

// Consolidation through many passes: greedy's picks (to 99 %) and every third candidate besides,
// most of them redundant, on a range(0) x range(1) plane with a view radius of range(2) voxels.
void BM_ConsolidatePicksManyPasses(benchmark::State& state) {
  const std::vector<vc::VoxelSet> sets = CampusSets(int(state.range(0)), int(state.range(1)), int(state.range(2)));
  vc::planner::GreedyOptions options;
  options.target_coverage = 0.99;
  const auto greedy = vc::planner::SelectGreedy(sets, options);
  std::vector<int> picks;
  for (const vc::planner::GreedyPick& p : greedy->picks) picks.push_back(p.candidate);
  for (size_t c = 0; c < sets.size(); c += 3) picks.push_back(int(c));
  int dropped = 0, merged = 0;
  size_t after = 0;
  for (auto _ : state) {
    const auto r = vc::planner::ConsolidatePicks(sets, picks, options);
    after = r->picks.size();
    dropped = r->dropped;
    merged = r->merged;
  }
  state.counters["picks"] = double(picks.size());
  state.counters["consolidated_picks"] = double(after);
  state.counters["dropped"] = dropped;
  state.counters["merged"] = merged;
}
BENCHMARK(BM_ConsolidatePicksManyPasses)
    ->Args({400, 200, 20})
    ->Args({600, 300, 15})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->MeasureProcessCPUTime();

}  // namespace
