#include "vc/plan/reduction.h"

#include <algorithm>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>

#include "progress_pacer.h"
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
  // Per chunk: G, the n singles, and the pair corrections of the pairs that are some face's two
  // best (few: a chunk is a run of neighbouring voxels), each summed in face order; the chunks are
  // then added in chunk order, so the sums do not depend on the threads. (A dense n x n block per
  // chunk, as before sparse sets, took gigabytes at hundreds of stations.)
  struct Partial {
    double g = 0;
    std::vector<double> singles;
    std::unordered_map<uint64_t, double> pairs;  // key a * n + z, a < z
  };
  std::vector<Partial> partial(chunks);
  const Status st = ParallelChunks(top3.size(), kChunk, threads, {}, [&](uint64_t c, uint64_t b, uint64_t e) {
    Partial& p = partial[c];
    p.singles.assign(n, 0.0);
    uint64_t last_key = ~uint64_t{0};
    double* last = nullptr;  // the last pair's sum: neighbouring faces mostly share their two best
    for (uint64_t f = b; f < e; ++f) {
      const FaceTop3& t = top3[f];
      if (t.s[0] < 0) continue;
      p.g += t.v[0];
      p.singles[t.s[0]] += static_cast<double>(t.v[0]) - t.v[1];
      if (t.s[1] >= 0) {
        const uint64_t key = static_cast<uint64_t>(std::min(t.s[0], t.s[1])) * n + std::max(t.s[0], t.s[1]);
        if (key != last_key) last = &p.pairs[key], last_key = key;
        *last += static_cast<double>(t.v[1]) - t.v[2];
      }
    }
  });
  (void)st;  // no token: cannot fail
  double g = 0;
  std::vector<double> singles(n, 0.0), pairs(n * n, 0.0);
  for (const Partial& p : partial) {
    g += p.g;
    for (size_t k = 0; k < n; ++k) singles[k] += p.singles[k];
    for (const auto& [key, v] : p.pairs) pairs[key] += v;
  }
  const double inv = 1.0 / static_cast<double>(faces_total);
  m.global_visibility = g * inv;
  for (size_t i = 0; i < n; ++i) m.loss[i * n + i] = singles[i] * inv;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      // Summed in the same order on both sides, so a zero-loss pair is exactly 0.
      const double v = (singles[i] + singles[j] + pairs[i * n + j]) * inv;
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

// Rebuilds the top-3 of every face that names a station just removed, from the active stations'
// cached values (inserted in ascending station order, as the first build did).
Status RefillFromCache(const std::vector<SparseFaceValues>& cache, const std::vector<int>& active,
                       const std::vector<bool>& removed_now, int threads, const JobContext& ctx,
                       std::vector<FaceTop3>& top3) {
  std::vector<uint8_t> affected(top3.size(), 0);
  std::vector<uint8_t> chunk_affected((top3.size() + kChunk - 1) / kChunk, 0);
  VC_RETURN_IF_ERROR(ParallelChunks(top3.size(), kChunk, threads, ctx, [&](uint64_t c, uint64_t b, uint64_t e) {
    for (uint64_t f = b; f < e; ++f) {
      FaceTop3& t = top3[f];
      bool hit = false;
      for (int k = 0; k < 3; ++k) hit |= t.s[k] >= 0 && removed_now[t.s[k]];
      if (!hit) continue;
      t = FaceTop3{};
      affected[f] = 1;
      chunk_affected[c] = 1;
    }
  }));
  return ParallelChunks(top3.size(), kChunk, threads, ctx, [&](uint64_t c, uint64_t b, uint64_t e) {
    if (!chunk_affected[c]) return;
    for (int s : active) {
      const SparseFaceValues& v = cache[s];
      auto it = std::lower_bound(v.faces.begin(), v.faces.end(), static_cast<uint32_t>(b));
      for (; it != v.faces.end() && *it < e; ++it) {
        if (affected[*it]) InsertTop3(top3[*it], v.values[it - v.faces.begin()], s);
      }
    }
  });
}

// Whether `v` lists faces in ascending order below faces_total, with a value for each.
Status CheckFaceValues(const SparseFaceValues& v, int station, uint64_t faces_total) {
  bool ok = v.values.size() == v.faces.size();
  for (size_t k = 0; ok && k < v.faces.size(); ++k) {
    ok = v.faces[k] < faces_total && (k == 0 || v.faces[k - 1] < v.faces[k]);
  }
  if (ok) return Status::Ok();
  return InternalError("station " + std::to_string(station) + ": face values not ascending within the " +
                       std::to_string(faces_total) + " faces");
}

}  // namespace

Result<ReductionRun> RunReduction(int num_stations, uint64_t faces_total, const StationFaceValuesFn& values,
                                  const ReductionRunOptions& options, const JobContext& ctx) {
  ReductionRun run;
  if (num_stations <= 0) return run;
  // Every station's values are kept while they fit the budget (decided as they arrive: sparse
  // values take what each station sees); past it, each removal recomputes them.
  bool use_cache = true;
  uint64_t cache_bytes = 0;
  std::vector<SparseFaceValues> cache(num_stations);
  std::vector<FaceTop3> top3 = vc::internal::FilledOnHugePages(faces_total, FaceTop3{});
  // Stations per call: at most batch_stations, and as many as keep the batch in flight within the
  // cache budget too — first for the worst case (every face seen: 8 bytes a face), then for what
  // the stations asked so far saw on average.
  const size_t most = static_cast<size_t>(std::max(options.batch_stations, 1));
  auto batch_for = [&](uint64_t bytes_per_station) {
    return static_cast<size_t>(
        std::clamp<uint64_t>(options.cache_budget_bytes / std::max<uint64_t>(bytes_per_station, 1), 1, most));
  };
  size_t batch = batch_for(faces_total * (sizeof(uint32_t) + sizeof(float)));
  uint64_t bytes_seen = 0, stations_seen = 0;

  // Stations evaluated of those a build streams, with the time left at the rate so far, at most
  // once per pacer interval (and at every batch's end); the evaluation may report from its workers.
  internal::ProgressPacer build_pacer;
  std::mutex build_pacer_mutex;
  auto report_build = [&](double fraction, uint64_t done, uint64_t total, bool due) {
    if (!ctx.progress) return;
    std::lock_guard<std::mutex> lock(build_pacer_mutex);
    if (!(due || build_pacer.Due())) return;
    std::string note = "face values of the stations";
    if (const std::string left = build_pacer.TimeLeft(done, total); !left.empty()) note += ", " + left;
    ctx.progress(ProgressEvent{Stage::kReduction, fraction, std::move(note), done, total, "stations evaluated"});
  };

  // Streams every active station's values into a fresh top-3 table, a batch at a time.
  auto build = [&](const std::vector<int>& stations, double progress_from, double progress_to) -> Status {
    std::fill(top3.begin(), top3.end(), FaceTop3{});
    build_pacer.Restart();
    for (size_t first = 0; first < stations.size();) {
      const std::vector<int> part(stations.begin() + first,
                                  stations.begin() + std::min(first + batch, stations.size()));
      JobContext sub = ctx;
      const double lo = progress_from + (progress_to - progress_from) * first / stations.size();
      const double hi = progress_from + (progress_to - progress_from) * (first + part.size()) / stations.size();
      sub.progress = [&, lo, hi, first, part_size = part.size(), total = stations.size()](const ProgressEvent& e) {
        const double f = std::clamp(e.fraction, 0.0, 1.0);
        report_build(lo + (hi - lo) * f, first + static_cast<uint64_t>(f * double(part_size)), total, false);
      };
      if (!ctx.progress) sub.progress = nullptr;
      Result<std::vector<SparseFaceValues>> v = values(part, sub);
      if (!v.ok()) return v.status();
      if (v->size() != part.size()) {
        return InternalError(std::to_string(v->size()) + " stations' face values for " + std::to_string(part.size()) +
                             " stations");
      }
      for (size_t k = 0; k < part.size(); ++k) {
        const int s = part[k];
        SparseFaceValues& vals = (*v)[k];
        VC_RETURN_IF_ERROR(CheckFaceValues(vals, s, faces_total));
        bytes_seen += vals.MemoryBytes();
        ++stations_seen;
        // One station's faces are distinct, so its entries go in in parallel.
        VC_RETURN_IF_ERROR(
            ParallelChunks(vals.size(), kChunk, options.threads, ctx, [&](uint64_t, uint64_t b, uint64_t e) {
              for (uint64_t j = b; j < e; ++j) InsertTop3(top3[vals.faces[j]], vals.values[j], s);
            }));
        if (use_cache) {
          cache_bytes += vals.MemoryBytes();
          if (cache_bytes <= options.cache_budget_bytes) {
            cache[s] = std::move(vals);
          } else {
            use_cache = false;
            cache = {};
          }
        }
      }
      first += part.size();
      report_build(hi, first, stations.size(), true);
      batch = batch_for(bytes_seen / stations_seen);
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
  // Removals so far of the most there can be (all stations but one, or down to reduce_to).
  const uint64_t most_removals = static_cast<uint64_t>(std::max(num_stations - std::max(options.reduce_to, 1), 0));
  internal::ProgressPacer removal_pacer;
  while (true) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("reduction"));
    const uint64_t removed = run.removed.size();
    const double fraction = 0.8 + 0.2 * double(removed) / double(std::max<uint64_t>(most_removals, 1));
    if (ctx.progress && removal_pacer.Due()) {
      std::string note = std::to_string(active.size()) + " stations left";
      if (const std::string left = removal_pacer.TimeLeft(removed, most_removals); !left.empty())
        note += ", at most " + left;
      ctx.progress(ProgressEvent{Stage::kReduction, fraction, std::move(note), removed, most_removals,
                                 "stations removed (at most)"});
    }
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
      VC_RETURN_IF_ERROR(build(active, fraction, fraction));
    }
    current = ComputeReductionMatrix(top3, num_stations, faces_total, options.threads);
    run.global_visibility_after = current.global_visibility;
  }
  ctx.Report(Stage::kReduction, 1.0);
  return run;
}

}  // namespace vc::planner
