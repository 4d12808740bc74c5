#include "vc/client/plan_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vc::client {
namespace {

// printf into a std::string.
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

// "[1 2 5]" from 0-based station indices.
std::string Group(const std::vector<int>& stations) {
  std::string out = "[";
  for (size_t k = 0; k < stations.size(); ++k) {
    if (k > 0) out += ' ';
    out += std::to_string(stations[k] + 1);
  }
  return out + "]";
}

std::string ScanGraphLine(const PlanResult& r) {
  const ScanGraph& g = r.scan_graph;
  if (r.stations.size() < 2) return "";
  const double threshold = g.min_overlap > 0 ? g.min_overlap : 0.3;
  size_t strong = 0;
  for (const ScanGraph::Edge& e : g.edges) strong += e.overlap >= threshold;
  std::string line = Format("scan graph: %zu pairs overlap by %.0f%% or more", strong, 100 * threshold);
  if (g.min_overlap > 0) {
    if (g.connected) {
      line += ", connected";
    } else {
      line += Format(", %zu groups no chain links:", g.components.size());
      for (const std::vector<int>& c : g.components) {
        line += ' ';
        line += Group(c);
      }
    }
    if (r.connecting_stations > 0) line += Format(" (%d connecting station(s))", r.connecting_stations);
  } else {
    line += " (registration not required: --min-overlap 0)";
  }
  return line + "\n";
}

// A local position of `r` in the input's frame, as stations.csv writes it (a zero origin keeps the bits).
WorldPoint InputFrame(const PlanResult& r, const WorldPoint& local) {
  return r.frame_origin_m.isZero() ? local : WorldPoint(local + r.frame_origin_m);
}

std::string RouteLines(const PlanResult& r) {
  const WalkingRoute& route = r.route;
  if (route.order.empty()) return "";
  std::string line = "route:";
  if (route.start) {
    const WorldPoint start = InputFrame(r, *route.start);
    line += Format(" start (%.2f, %.2f) ->", start.x(), start.y());
  }
  for (size_t k = 0; k < route.order.size(); ++k) {
    if (k > 0) line += k < route.legs_m.size() && std::isnan(route.legs_m[k]) ? " //" : " ->";
    line += ' ';
    line += std::to_string(route.order[k] + 1);
  }
  line += Format("\n  walking %.1f m", route.length_m);
  if (route.parts > 1) line += Format(" in %d parts no walkable path links (// above)", route.parts);
  return line + "\n";
}

std::string FieldTimeLine(const PlanResult& r) {
  const FieldTime& t = r.field_time;
  std::string line = "field time: " + FormatDuration(t.total_s) + " (set-up " + FormatDuration(t.setup_s) + ", scans " +
                     FormatDuration(t.scan_s) + ", walking " + FormatDuration(t.walk_s) + ")";
  if (t.scan_seconds_per_station <= 0) line += "; no scan time known: pass --scan-seconds or --scanner";
  return line + "\n";
}

// The optimality line: proven optimal, a bound, or none.
std::string OptimalityBoundLine(const PlanResult& r) {
  const planner::Optimality& o = r.optimality;
  if (o.solver == "greedy" && o.status == planner::OptimalityStatus::kHeuristic && o.note.empty()) return "";
  if (r.options.max_stations > 0 && o.status != planner::OptimalityStatus::kHeuristic) {
    if (o.status == planner::OptimalityStatus::kOptimal) {
      return Format("optimal: the most coverage %d station(s) reach, proven\n", o.stations);
    }
    return Format("%d station(s), coverage at most %.1f%% below the optimum\n", o.stations, 100.0 * o.gap);
  }
  switch (o.status) {
    case planner::OptimalityStatus::kOptimal:
      return Format("optimal: %d stations, proven\n", o.stations);
    case planner::OptimalityStatus::kFeasible: {
      const int bound = static_cast<int>(std::ceil(o.lower_bound - 1e-9));
      return Format("%d stations, at most %d more than the optimum (bound %d)\n", o.stations, o.stations - bound,
                    bound);
    }
    case planner::OptimalityStatus::kHeuristic:
      break;
  }
  return Format("%d stations (%s), no bound on the optimum\n", o.stations, o.solver.c_str());
}

}  // namespace

std::string CoverageTable(const PlanResult& r) {
  if (r.coverage_curve.empty()) return "";
  // "any plan": the smallest k whose per-k bound reaches the level (no plan of fewer stations can);
  // the column is there only when the curve carries the bound (from k = F with F fixed stations).
  const bool bound = std::any_of(r.coverage_curve.begin(), r.coverage_curve.end(),
                                 [](const CoveragePoint& p) { return p.best_voxels_upper_bound.has_value(); });
  std::string out = Format("  %8s %7s %9s", "coverage", "scene", "stations");
  if (bound) out += Format(" %10s", "any plan");
  out += "  field time (set-up and scans)\n";
  const std::vector<double> levels(std::begin(kCoverageMilestones), std::end(kCoverageMilestones));
  for (const CoverageMilestone& m : CoverageMilestones(r.coverage_curve, r.coverable_voxels, levels)) {
    const std::string fewest = !bound ? ""
                               : m.fewest_possible_stations
                                   ? Format(" %10s", (">= " + std::to_string(*m.fewest_possible_stations)).c_str())
                                   : Format(" %10s", "-");
    if (!m.reached) {
      out += Format("  %6.0f %% %7s %9s%s  not reached by this plan\n", 100.0 * m.coverable_fraction, "-", "-",
                    fewest.c_str());
      continue;
    }
    out += Format("  %6.0f %% %6.1f%% %9d%s  %s\n", 100.0 * m.coverable_fraction, 100.0 * m.reached->scene_fraction,
                  m.reached->stations, fewest.c_str(), FormatDuration(m.reached->setup_scan_s).c_str());
  }
  if (bound) out += "  (any plan: no plan over these candidates reaches the level with fewer stations)\n";
  return out;
}

std::string StopLine(const PlanResult& r) {
  const PlanOptions& o = r.options;
  switch (r.stop_reason) {
    case StopReason::kExhausted:
      return "stopped: every voxel some candidate sees is covered\n";
    case StopReason::kTargetReached:
      return Format("stopped: target coverage %g %% reached (--target-coverage)\n", 100.0 * o.target_coverage);
    case StopReason::kMaxStations:
      return Format("stopped: %d stations (--max-stations)\n", o.max_stations);
    case StopReason::kMinGain:
      return Format("stopped: no candidate adds %llu voxels or more (--min-gain; candidates exhausted)\n",
                    static_cast<unsigned long long>(o.min_marginal_gain_voxels));
    case StopReason::kGainRule: {
      const double minutes = (o.setup_seconds + r.field_time.scan_seconds_per_station) / 60.0;
      const std::optional<GainRule> rule = GainRuleOf(o, r.resolution_m);
      if (!rule) return "stopped: gain rule\n";
      const double voxels = rule->voxels_per_minute * minutes;
      if (o.min_gain_voxels_per_minute > 0) {
        return Format(
            "stopped: gain rule, the next station adds under %.0f voxels for its %s of set-up and scan "
            "(--min-gain-voxels-per-minute %g)\n",
            voxels, FormatDuration(60.0 * minutes).c_str(), rule->value);
      }
      return Format(
          "stopped: gain rule, the next station adds under %.3g m2 of surface (%.0f voxels at %g m) for its %s of "
          "set-up and scan (--min-gain-m2-per-minute %g)\n",
          rule->value * minutes, voxels, r.resolution_m, FormatDuration(60.0 * minutes).c_str(), rule->value);
    }
  }
  return "";
}

std::string OptimalityLine(const PlanResult& r) {
  const planner::Optimality& o = r.optimality;
  std::string local;
  if (const planner::LocalCandidatesReport& l = o.local_candidates; !l.stations_per_solve.empty()) {
    std::string counts;
    for (int n : l.stations_per_solve) counts += (counts.empty() ? "" : " -> ") + std::to_string(n);
    local = Format("local candidates: %d position(s) in %d round(s); stations per selection %s\n", l.added, l.rounds,
                   counts.c_str());
    if (!l.coarse_to_fine.empty()) local += l.coarse_to_fine + "\n";
  }
  return local + OptimalityBoundLine(r);
}

std::string DistributionLine(const PlanResult& r) {
  const Distribution& d = r.distribution;
  if (d.shards == 0) return "";
  return Format("fanned out: %d shard(s) on %d replica(s), %d retried, %.1f MiB exchanged\n", d.shards, d.replicas,
                d.retried, double(d.bytes_exchanged) / 1048576.0);
}

std::string TimingLine(const PlanResult& r) {
  if (r.timings.empty()) return "";
  std::string out = "stages:";
  for (size_t i = 0; i < r.timings.size(); ++i) {
    const StageTiming& t = r.timings[i];
    out += Format("%s %s %.2f s", i ? "," : "", std::string(StageName(t.stage)).c_str(), t.seconds);
    if (t.peak_rss_bytes > 0) out += Format(" (peak %.0f MiB)", double(t.peak_rss_bytes) / 1048576.0);
  }
  return out + Format("; total %.2f s\n", r.total_seconds);
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  if (s < 60) return std::to_string(s) + " s";
  const long minutes = std::lround(seconds / 60.0);
  if (minutes < 60) return std::to_string(minutes) + " min";
  return Format("%ld h %02ld min", minutes / 60, minutes % 60);
}

namespace {

// Why no candidate sees what it does not, the largest cause first, each with what would help; empty
// when nothing is unseen (or an older server sent no breakdown).
std::string UnseenCausesLine(const UnseenCauses& u) {
  const std::pair<uint64_t, const char*> causes[] = {
      {u.hidden, "hidden behind other surfaces from every candidate (a finer grid or your own candidates)"},
      {u.faces_away, "facing away from every candidate (undersides, outer walls: a station on that side)"},
      {u.interior, "inside solid matter, seen from nowhere"},
      {u.out_of_range, "out of every candidate's range"},
      {u.outside_field_of_view, "outside the vertical field of view (another tripod height)"},
      {u.no_candidate_on_floor, "on floors without candidates"},
      {u.in_keep_out, "in keep-out zones"},
  };
  std::vector<std::pair<uint64_t, const char*>> present;
  for (const auto& c : causes) {
    if (c.first > 0) present.push_back(c);
  }
  if (present.empty()) return "";
  std::stable_sort(present.begin(), present.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string out = "  unseen:";
  for (size_t i = 0; i < present.size(); ++i) {
    out += Format("%s %llu %s", i ? ";" : "", static_cast<unsigned long long>(present[i].first), present[i].second);
  }
  return out + "\n";
}

// The plan's first lines: the share of the whole scene covered first (what a crew reads first),
// then the share of what any candidate can see, and what no candidate sees. Older servers send no
// occupied count (0): then only the coverable share is known.
std::string HeadlineLines(const PlanResult& r) {
  const auto percent = [](uint64_t part, uint64_t whole) { return whole ? 100.0 * double(part) / double(whole) : 0.0; };
  const auto count = [](uint64_t n) { return static_cast<unsigned long long>(n); };
  if (r.occupied_voxels == 0) {
    return Format("%zu station(s), coverage %.1f%% of %llu coverable voxels, global visibility G = %.3f\n",
                  r.stations.size(), percent(r.covered_voxels, r.coverable_voxels), count(r.coverable_voxels),
                  r.evaluation.overall.global_visibility);
  }
  std::string out =
      Format("%zu station(s) see %.1f%% of the scene (%llu of %llu occupied voxels), global visibility G = %.3f\n",
             r.stations.size(), percent(r.covered_voxels, r.occupied_voxels), count(r.covered_voxels),
             count(r.occupied_voxels), r.evaluation.overall.global_visibility);
  out += Format("  %.1f%% of the %llu voxels some candidate can see", percent(r.covered_voxels, r.coverable_voxels),
                count(r.coverable_voxels));
  const uint64_t unseen = r.occupied_voxels - std::min(r.occupied_voxels, r.coverable_voxels);
  if (unseen > 0) {
    out += Format("; %llu (%.1f%% of the scene) no candidate sees at all (plan.json \"coverage\")", count(unseen),
                  percent(unseen, r.occupied_voxels));
  }
  return out + "\n" + UnseenCausesLine(r.unseen_causes);
}

}  // namespace

std::string PlanSummary(const PlanResult& r) {
  std::vector<int> route_position(r.stations.size(), 0);
  for (size_t k = 0; k < r.route.order.size(); ++k) {
    if (r.route.order[k] >= 0 && static_cast<size_t>(r.route.order[k]) < r.stations.size()) {
      route_position[r.route.order[k]] = static_cast<int>(k) + 1;
    }
  }
  std::string out = HeadlineLines(r);
  out += Format("  %3s %10s %10s %10s %12s %9s %6s\n", "#", "x_m", "y_m", "z_m", "gain_voxels", "coverage", "walk");
  for (size_t i = 0; i < r.stations.size(); ++i) {
    const PlannedStation& s = r.stations[i];
    const WorldPoint p = InputFrame(r, s.position);
    out += Format("  %3zu %10.3f %10.3f %10.3f %12llu %8.1f%% %6s%s\n", i + 1, p.x(), p.y(), p.z(),
                  static_cast<unsigned long long>(s.marginal_gain), 100.0 * s.cumulative_coverage,
                  route_position[i] ? std::to_string(route_position[i]).c_str() : "-", s.fixed ? "  fixed" : "");
  }
  out += CoverageTable(r);
  out += StopLine(r);
  out += OptimalityLine(r);
  out += DistributionLine(r);
  out += TimingLine(r);
  out += ScanGraphLine(r);
  if (r.ground.model != GroundModel::kAuto) out += "ground: " + r.ground.reason + " (--ground)\n";
  out += RouteLines(r);
  out += FieldTimeLine(r);
  for (const std::string& w : r.warnings) out += "warning: " + w + "\n";
  return out;
}

}  // namespace vc::client
