#include "vc/plan/reduction.h"

#include <algorithm>
#include <string>
#include <utility>

#include "vc/base/huge_pages.h"
#include "vc/base/parallel.h"

namespace vc::planner {

namespace {
constexpr uint64_t kChunk = 1 << 15;  // faces per chunk (fixed: sums do not depend on threads)
}  // namespace

void InsertTop3(FaceTop3& t, float value, int32_t station) {
  if (!(value > 0.f)) return;
  if (value > t.v[0]) {
    t.v[2] = t.v[1], t.s[2] = t.s[1];
    t.v[1] = t.v[0], t.s[1] = t.s[0];
    t.v[0] = value, t.s[0] = station;
  } else if (value > t.v[1]) {
    t.v[2] = t.v[1], t.s[2] = t.s[1];
    t.v[1] = value, t.s[1] = station;
  } else if (value > t.v[2]) {
    t.v[2] = value, t.s[2] = station;
  }
}

ReductionMatrix ComputeReductionMatrix(const std::vector<FaceTop3>& top3, int num_stations, uint64_t faces_total,
                                       int threads) {
  ReductionMatrix m;
  m.size = num_stations;
  const size_t n = static_cast<size_t>(num_stations);
  m.loss.assign(n * n, 0.0);
  if (top3.empty() || n == 0 || faces_total == 0) return m;
  const uint64_t chunks = (top3.size() + kChunk - 1) / kChunk;
  // Per chunk: G sum, then n singles, then n*n pair corrections (upper triangle used).
  std::vector<std::vector<double>> partial(chunks);
  const Status st = ParallelChunks(top3.size(), kChunk, threads, {}, [&](uint64_t c, uint64_t b, uint64_t e) {
    std::vector<double> acc(1 + n + n * n, 0.0);
    for (uint64_t f = b; f < e; ++f) {
      const FaceTop3& t = top3[f];
      if (t.s[0] < 0) continue;
      acc[0] += t.v[0];
      acc[1 + t.s[0]] += static_cast<double>(t.v[0]) - t.v[1];
      if (t.s[1] >= 0) {
        const int a = std::min(t.s[0], t.s[1]), z = std::max(t.s[0], t.s[1]);
        acc[1 + n + static_cast<size_t>(a) * n + z] += static_cast<double>(t.v[1]) - t.v[2];
      }
    }
    partial[c] = std::move(acc);
  });
  (void)st;  // no token: cannot fail
  std::vector<double> total(1 + n + n * n, 0.0);
  for (const auto& p : partial) {
    for (size_t k = 0; k < total.size(); ++k) total[k] += p[k];
  }
  const double inv = 1.0 / static_cast<double>(faces_total);
  m.global_visibility = total[0] * inv;
  for (size_t i = 0; i < n; ++i) m.loss[i * n + i] = total[1 + i] * inv;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      // Summed in the same order on both sides, so a zero-loss pair is exactly 0.
      const double v = (total[1 + i] + total[1 + j] + total[1 + n + i * n + j]) * inv;
      m.loss[i * n + j] = v;
      m.loss[j * n + i] = v;
    }
  }
  return m;
}

std::vector<int> ChooseRemoval(const ReductionMatrix& m, const std::vector<int>& active, int reduce_to,
                               const std::vector<bool>& fixed, const RemovalCheck& keeps) {
  const int count = static_cast<int>(active.size());
  if (count <= 1) return {};
  auto kept = [&](int a) { return static_cast<size_t>(active[a]) < fixed.size() && fixed[active[a]]; };
  // Whether removing positions a (and b, if >= 0) of `active` leaves stations `keeps` accepts.
  auto allowed = [&](int a, int b) {
    if (!keeps) return true;
    std::vector<int> remaining;
    for (int k = 0; k < count; ++k) {
      if (k != a && k != b) remaining.push_back(active[k]);
    }
    return keeps(remaining);
  };
  // Zero loss: a pair first (keeping at least one station), else a single; the latest first.
  if (count >= 3) {
    for (int b = count - 1; b >= 1; --b) {
      if (kept(b)) continue;
      for (int a = b - 1; a >= 0; --a) {
        if (!kept(a) && m.at(active[a], active[b]) == 0.0 && allowed(a, b)) return {active[a], active[b]};
      }
    }
  }
  for (int a = count - 1; a >= 0; --a) {
    if (!kept(a) && m.at(active[a], active[a]) == 0.0 && allowed(a, -1)) return {active[a]};
  }
  if (reduce_to <= 0 || count <= reduce_to) return {};
  // Lowest loss per removed station; ties: a pair, then the latest in greedy order.
  const bool pairs = count - reduce_to >= 2;
  std::vector<int> best;
  double best_per = 0;
  auto consider = [&](std::vector<int> t, double per, int a, int b) {
    const bool better = best.empty() || per < best_per ||
                        (per == best_per && (t.size() > best.size() || (t.size() == best.size() && t > best)));
    if (better && allowed(a, b)) {
      best = std::move(t);
      best_per = per;
    }
  };
  for (int a = 0; a < count; ++a) {
    if (kept(a)) continue;
    consider({active[a]}, m.at(active[a], active[a]), a, -1);
    if (!pairs) continue;
    for (int b = a + 1; b < count; ++b) {
      if (!kept(b)) consider({active[a], active[b]}, m.at(active[a], active[b]) / 2, a, b);
    }
  }
  return best;
}

namespace {

// Rebuilds every face's top-3 from the active stations' cached values.
Status RefillFromCache(const std::vector<std::vector<float>>& cache, const std::vector<int>& active,
                       const std::vector<bool>& removed_now, int threads, const JobContext& ctx,
                       std::vector<FaceTop3>& top3) {
  return ParallelChunks(top3.size(), kChunk, threads, ctx, [&](uint64_t, uint64_t b, uint64_t e) {
    for (uint64_t f = b; f < e; ++f) {
      FaceTop3& t = top3[f];
      bool affected = false;
      for (int k = 0; k < 3; ++k) affected |= t.s[k] >= 0 && removed_now[t.s[k]];
      if (!affected) continue;
      t = FaceTop3{};
      for (int s : active) InsertTop3(t, cache[s][f], s);
    }
  });
}

}  // namespace

Result<ReductionRun> RunReduction(int num_stations, uint64_t faces_total, const StationFaceValuesFn& values,
                                  const ReductionRunOptions& options, const JobContext& ctx) {
  ReductionRun run;
  if (num_stations <= 0) return run;
  const bool use_cache =
      static_cast<uint64_t>(num_stations) * faces_total * sizeof(float) <= options.cache_budget_bytes;
  std::vector<std::vector<float>> cache(use_cache ? num_stations : 0);
  std::vector<FaceTop3> top3 = internal::FilledOnHugePages(faces_total, FaceTop3{});

  // Streams every active station's values into a fresh top-3 table.
  auto build = [&](const std::vector<int>& stations, double progress_from, double progress_to) -> Status {
    std::fill(top3.begin(), top3.end(), FaceTop3{});
    for (size_t k = 0; k < stations.size(); ++k) {
      const int s = stations[k];
      JobContext sub = ctx;
      const double lo = progress_from + (progress_to - progress_from) * k / stations.size();
      const double hi = progress_from + (progress_to - progress_from) * (k + 1) / stations.size();
      sub.progress = [&ctx, lo, hi](const ProgressEvent& e) {
        ctx.Report(Stage::kReduction, lo + (hi - lo) * e.fraction);
      };
      if (!ctx.progress) sub.progress = nullptr;
      Result<std::vector<float>> v = values(s, sub);
      if (!v.ok()) return v.status();
      if (v->size() != faces_total) {
        return InternalError("station " + std::to_string(s) + ": " + std::to_string(v->size()) +
                             " face values, expected " + std::to_string(faces_total));
      }
      const std::vector<float>& vals = *v;
      VC_RETURN_IF_ERROR(
          ParallelChunks(faces_total, kChunk, options.threads, ctx, [&](uint64_t, uint64_t b, uint64_t e) {
            for (uint64_t f = b; f < e; ++f) InsertTop3(top3[f], vals[f], s);
          }));
      if (use_cache) cache[s] = std::move(*v);
      ctx.Report(Stage::kReduction, hi);
    }
    return Status::Ok();
  };

  std::vector<int> active(num_stations);
  for (int i = 0; i < num_stations; ++i) active[i] = i;
  VC_RETURN_IF_ERROR(build(active, 0.0, options.remove ? 0.8 : 1.0));
  run.initial = ComputeReductionMatrix(top3, num_stations, faces_total, options.threads);
  run.global_visibility_before = run.initial.global_visibility;
  run.global_visibility_after = run.initial.global_visibility;
  if (!options.remove) return run;

  ReductionMatrix current = run.initial;
  while (true) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("reduction"));
    std::vector<int> remove = ChooseRemoval(current, active, options.reduce_to, options.fixed, options.keeps);
    if (remove.empty()) break;
    const double loss = remove.size() == 1 ? current.at(remove[0], remove[0]) : current.at(remove[0], remove[1]);
    std::vector<bool> removed_now(num_stations, false);
    for (int s : remove) {
      removed_now[s] = true;
      run.removed.push_back(s);
    }
    run.steps.push_back({remove, loss});
    active.erase(std::remove_if(active.begin(), active.end(), [&](int s) { return removed_now[s]; }), active.end());
    if (use_cache) {
      VC_RETURN_IF_ERROR(RefillFromCache(cache, active, removed_now, options.threads, ctx, top3));
    } else {
      VC_RETURN_IF_ERROR(build(active, 0.8, 0.8));
    }
    current = ComputeReductionMatrix(top3, num_stations, faces_total, options.threads);
    run.global_visibility_after = current.global_visibility;
  }
  ctx.Report(Stage::kReduction, 1.0);
  return run;
}

}  // namespace vc::planner
