// vc-validate-bench: how well today's selection tests predict what a scanner captures (issue 34;
// docs/VISIBILITY.md "Measured against captured points", docs/BENCHMARKS.md). Prints, for each
// selection test (surface, compatibility, subvoxel), ValidateAgainstScans' recall and precision, with no slack and with
// one voxel of slack, on: simulated planes tilted 0-60 deg to the lattice (with and without 1 cm range noise), two
// simulated stations in RoomWithClutterScene (all round, and 150 deg scans predicted with and without their field of
// view), the real hall scan and the two real room scans. Figures only, no assertions.
//
// Real scans: points nearer than the scanner's min_range_m to their own station are dropped (the
// room scans hold returns from the scanning platform within ~0.3 m, which would put the station in
// an occupied voxel); the room's second scan is moved into the first's frame by the estimated pose
// of ../shared/data/README.md (yaw +40.8 deg, translation (1.974, 0.058, 0.016) m), whose direction
// the tool checks by the overlap of the two scans. The hall scan covers -91..+91 deg of azimuth
// only: it is measured both all round (hfov 360) and with hfov 182 centred on its heading 0 (+x).
//
// --tests and --scenes pick what runs; --explain breaks the subvoxel test's misses down (the
// captured voxels by patch kind, incidence and distance with the share missed, each miss by its
// first blocker (flat patch or cube, how near) and whether the surface test or one voxel of slack
// has it), for the scans predicted all round.
#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "vc/scene/occupancy_grid.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/surface_patches.h"
#include "vc/synth/scanner_sim.h"
#include "vc/visibility/subvoxel.h"
#include "vc/visibility/validation.h"

namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct BenchOptions {
  double resolution_m = vc::kDefaultResolutionM;
  double step_deg = 0.1;
  double noise_m = 0.01;
  int threads = 0;
  std::string data_dir = "../shared/data";
  // The selection tests measured (--tests).
  std::vector<vc::SelectionTest> tests = {vc::SelectionTest::kSurfaceVisibility, vc::SelectionTest::kCompatibility,
                                          vc::SelectionTest::kSubvoxel};
  // Which groups of scenes run (--scenes): planes, room, partial, real.
  std::vector<std::string> scenes = {"planes", "room", "partial", "real"};
  // Break the subvoxel test's misses down by category (--explain).
  bool explain = false;
  // Voxels of faces seen by the corner rule also count as predicted (--faces, --face-set).
  vc::ValidationOptions::FaceRule count_faces = vc::ValidationOptions::FaceRule::kNone;
  vc::FaceSet count_faces_of = vc::FaceSet::kAll;
};

int ExplainMisses(const std::string& label, const std::vector<vc::CapturedScan>& scans, const BenchOptions& bench,
                  const vc::ScannerModel& scanner);

bool Runs(const BenchOptions& bench, const std::string& group) {
  return std::find(bench.scenes.begin(), bench.scenes.end(), group) != bench.scenes.end();
}

void PrintHeader() {
  std::printf("%-34s %-13s %-6s %9s %9s %9s %7s %7s %7s %7s\n", "scene", "test", "scan", "captured", "predicted",
              "both", "recall", "prec", "recall1", "prec1");
}

// Runs every selection test on `scans` with `scanner`'s limits and prints one line per test and scan.
int Report(const std::string& label, const std::vector<vc::CapturedScan>& scans, const BenchOptions& bench,
           const vc::ScannerModel& scanner = {}) {
  for (const vc::SelectionTest test : bench.tests) {
    vc::ValidationOptions options;
    options.scanner = scanner;
    options.resolution_m = bench.resolution_m;
    options.selection_test = test;
    options.threads = bench.threads;
    options.count_faces = bench.count_faces;
    options.count_faces_of = bench.count_faces_of;
    auto report = vc::ValidateAgainstScans(scans, options);
    if (!report.ok()) return std::fprintf(stderr, "%s: %s\n", label.c_str(), report.status().ToString().c_str()), 1;
    for (const vc::ScanAgreement& a : report->scans) {
      char precision[16], precision_slack[16];
      std::snprintf(precision, sizeof precision, "%.3f", a.precision);
      std::snprintf(precision_slack, sizeof precision_slack, "%.3f", a.precision_slack);
      std::printf("%-34s %-13s %-6s %9llu %9llu %9llu %7.3f %7s %7.3f %7s%s\n", label.c_str(),
                  std::string(vc::SelectionTestName(test)).c_str(), a.name.c_str(), (unsigned long long)a.captured,
                  (unsigned long long)a.predicted, (unsigned long long)a.both, a.recall,
                  report->precision_meaningful ? precision : "-", a.recall_slack,
                  report->precision_meaningful ? precision_slack : "-",
                  a.position_occupied ? "  (station in an occupied voxel)" : "");
    }
  }
  const bool subvoxel =
      std::find(bench.tests.begin(), bench.tests.end(), vc::SelectionTest::kSubvoxel) != bench.tests.end();
  if (bench.explain && subvoxel && !scanner.HasHorizontalFieldOfView())
    return ExplainMisses(label, scans, bench, scanner);
  return 0;
}

bool HasMemberWithinOneVoxel(const vc::VoxelScene& model, const vc::VoxelSet& set, size_t id);

// Captured voxels and the subvoxel test's misses among them, by category (--explain).
class Tally {
 public:
  void Add(const std::string& category, bool missed) {
    auto& [captured, misses] = rows_[category];
    ++captured;
    misses += missed;
  }
  void Print(const std::string& label, const std::string& scan, uint64_t all_misses) const {
    for (const auto& [category, row] : rows_) {
      std::printf("# explain %-34s scan %-3s %-44s voxels %7llu missed %7llu (%5.3f of them, %5.3f of all)\n",
                  label.c_str(), scan.c_str(), category.c_str(), (unsigned long long)row.first,
                  (unsigned long long)row.second, row.first ? double(row.second) / double(row.first) : 0.0,
                  all_misses ? double(row.second) / double(all_misses) : 0.0);
    }
  }

 private:
  std::map<std::string, std::pair<uint64_t, uint64_t>> rows_;
};

const char* Bin(double x, std::initializer_list<std::pair<double, const char*>> bins, const char* last) {
  for (const auto& [bound, name] : bins) {
    if (x < bound) return name;
  }
  return last;
}

std::string PatchKind(const vc::SurfacePatch& p) {
  if (p.flat) return p.borrowed ? "borrowed flat" : "flat";
  return p.points < vc::kFlatMinPoints ? "not flat, < 3 points" : "not flat";
}

// Why the subvoxel test misses captured voxels of `scans` (all round, `scanner`'s limits): each
// captured voxel by its patch, incidence and distance; each miss by its first blocker, and whether
// the surface test or one voxel of slack would have had it.
int ExplainMisses(const std::string& label, const std::vector<vc::CapturedScan>& scans, const BenchOptions& bench,
                  const vc::ScannerModel& scanner) {
  vc::ValidationOptions options;
  options.scanner = scanner;
  options.resolution_m = bench.resolution_m;
  options.selection_test = vc::SelectionTest::kSubvoxel;
  options.threads = bench.threads;
  options.keep_sets = true;
  auto report = vc::ValidateAgainstScans(scans, options);
  if (!report.ok()) return std::fprintf(stderr, "%s: %s\n", label.c_str(), report.status().ToString().c_str()), 1;
  const vc::VoxelScene& model = report->model;
  vc::SurfacePatchBuilder builder(model);
  for (const vc::CapturedScan& scan : scans) {
    for (const auto& p : scan.points_m) builder.Add(p);
  }
  const std::vector<vc::SurfacePatch> patches = builder.Finish();
  const double r = model.resolution_m;
  for (size_t i = 0; i < scans.size(); ++i) {
    const vc::ScanAgreement& a = report->scans[i];
    const vc::WorldPoint& o = scans[i].position_m;
    Tally tally;
    const uint64_t misses = a.captured - a.both;
    a.captured_set.ForEach([&](size_t id) {
      const bool missed = !a.predicted_set.test(id);
      const vc::SurfacePatch& p = patches[id];
      const vc::WorldPoint c = p.centroid_m.cast<double>();
      const std::string kind = PatchKind(p);
      tally.Add("target: " + kind, missed);
      if (p.flat) {
        const double cos_in = std::abs(p.normal.cast<double>().dot((o - c).normalized()));
        const double incidence_deg = std::acos(std::min(1.0, cos_in)) * 180.0 / std::numbers::pi;
        tally.Add(std::string("flat target, incidence ") +
                      Bin(incidence_deg, {{45, "0-45"}, {70, "45-70"}, {80, "70-80"}}, "80-90") + " deg",
                  missed);
      }
      tally.Add(std::string("distance ") + Bin((o - c).norm(), {{3, "0-3"}, {6, "3-6"}, {12, "6-12"}}, "12+") + " m",
                missed);
      if (!missed) return;
      const vc::SubvoxelRay ray = vc::ExplainSubvoxel(model, patches, o, id, scanner);
      std::string why = "miss: ";
      if (ray.outcome == vc::SubvoxelRay::Outcome::kOutsideLimits) {
        why += "outside the limits";
      } else if (ray.outcome != vc::SubvoxelRay::Outcome::kBlocked) {
        why += "explained as seen (engine and query disagree)";
      } else {
        const vc::SurfacePatch& w = patches[size_t(ray.first_blocker)];
        const vc::VoxelIndex vi = vc::KeyToIndex(model.occupied[id]);
        const vc::VoxelIndex wi = vc::KeyToIndex(model.occupied[size_t(ray.first_blocker)]);
        const int chebyshev = std::max({std::abs(vi.x - wi.x), std::abs(vi.y - wi.y), std::abs(vi.z - wi.z)});
        const double behind_edges = (1 - ray.blocker_s) * (o - c).norm() / r;
        why += std::string("blocked by a ") + (w.flat ? "flat patch" : "box (not flat)") + ", " +
               (chebyshev <= 1   ? "adjacent"
                : chebyshev <= 3 ? "2-3 voxels away"
                                 : "farther") +
               ", hit " + Bin(behind_edges, {{0.5, "<0.5"}, {1, "0.5-1"}, {2, "1-2"}}, "2+") + " edges before the aim";
        if (p.flat && w.flat) {
          const double cos_n = std::abs(p.normal.dot(w.normal));
          why += cos_n >= std::cos(vc::kSameSurfaceMaxAngleDeg * std::numbers::pi / 180) ? ", normals agree"
                                                                                         : ", normals differ";
        }
      }
      tally.Add(why, true);
      if (ray.outcome == vc::SubvoxelRay::Outcome::kBlocked) {
        const double blocker_m = ray.blocker_s * (o - c).norm();
        tally.Add(std::string("miss, first blocker ") + Bin(blocker_m, {{1, "< 1"}, {2, "1-2"}}, ">= 2") +
                      " m from the station",
                  true);
      }
      const bool surface = vc::IsSurfaceVisible(model.grid, o, vc::KeyToIndex(model.occupied[id]), scanner);
      tally.Add(std::string("miss, surface test ") + (surface ? "sees it" : "misses it too") + ", " +
                    (HasMemberWithinOneVoxel(model, a.predicted_set, id) ? "slack recovers it" : "not within slack"),
                true);
    });
    tally.Print(label, a.name, misses);
    // Over-predictions: voxels predicted for this scan that it did not capture (another scan did).
    Tally over;
    const uint64_t overs = a.predicted - a.both;
    a.predicted_set.ForEach([&](size_t id) {
      if (a.captured_set.test(id)) return;
      const vc::SurfacePatch& p = patches[id];
      const vc::WorldPoint c = p.centroid_m.cast<double>();
      over.Add("over: target " + PatchKind(p), true);
      over.Add(
          std::string("over: target of ") + Bin(p.points, {{3, "1-2"}, {10, "3-9"}, {30, "10-29"}}, "30+") + " points",
          true);
      if (p.flat) {
        const double cos_in = std::abs(p.normal.cast<double>().dot((o - c).normalized()));
        const double incidence_deg = std::acos(std::min(1.0, cos_in)) * 180.0 / std::numbers::pi;
        over.Add(std::string("over: flat target, incidence ") +
                     Bin(incidence_deg, {{45, "0-45"}, {70, "45-70"}, {80, "70-80"}}, "80-90") + " deg",
                 true);
      }
      over.Add(
          std::string("over: distance ") + Bin((o - c).norm(), {{3, "0-3"}, {6, "3-6"}, {12, "6-12"}}, "12+") + " m",
          true);
      const vc::SubvoxelRay ray = vc::ExplainSubvoxel(model, patches, o, id, scanner);
      std::string why = "over: seen ";
      if (ray.outcome == vc::SubvoxelRay::Outcome::kClear) {
        why += "clear (no blocker)";
      } else if (ray.outcome == vc::SubvoxelRay::Outcome::kSameSurface) {
        const vc::VoxelIndex vi = vc::KeyToIndex(model.occupied[id]);
        const vc::VoxelIndex wi = vc::KeyToIndex(model.occupied[size_t(ray.first_blocker)]);
        const int chebyshev = std::max({std::abs(vi.x - wi.x), std::abs(vi.y - wi.y), std::abs(vi.z - wi.z)});
        why += std::string("past the same surface, blocker ") + (chebyshev <= 1 ? "adjacent" : "farther");
      } else {
        why += "by a face of its box";
      }
      over.Add(why, true);
      const bool surface = vc::IsSurfaceVisible(model.grid, o, vc::KeyToIndex(model.occupied[id]), scanner);
      over.Add(std::string("over: surface test ") + (surface ? "predicts it too" : "does not") + ", " +
                   (HasMemberWithinOneVoxel(model, a.captured_set, id) ? "a captured voxel within one voxel"
                                                                       : "none within one voxel"),
               true);
    });
    over.Print(label, a.name, overs);
  }
  return 0;
}

vc::Result<vc::CapturedScan> Simulate(const vc::AnalyticScene& scene, vc::SimulatedScanner scanner, std::string name) {
  VC_ASSIGN_OR_RETURN(vc::SimulatedScan scan, vc::SimulateScan(scene, scanner));
  return vc::CapturedScan{std::move(name), scanner.position_m, std::move(scan.points_m)};
}

int TiltedPlanes(const BenchOptions& bench) {
  for (const double distance_m : {3.0, 3.05}) {
    for (const double noise_m : {0.0, bench.noise_m}) {
      for (const double tilt_deg : {0.0, 15.0, 30.0, 45.0, 60.0}) {
        auto scene = vc::TiltedPlaneScene(tilt_deg, distance_m);
        if (!scene.ok()) return std::fprintf(stderr, "%s\n", scene.status().ToString().c_str()), 1;
        vc::SimulatedScanner scanner;
        scanner.hfov_deg = 100.0;
        scanner.vfov_min_deg = -45.0;
        scanner.vfov_max_deg = 45.0;
        scanner.horizontal_step_deg = scanner.vertical_step_deg = bench.step_deg;
        scanner.range_noise_sigma_m = noise_m;
        auto scan = Simulate(*scene, scanner, "1");
        if (!scan.ok()) return std::fprintf(stderr, "%s\n", scan.status().ToString().c_str()), 1;
        char label[64];
        std::snprintf(label, sizeof label, "plane %2.0f deg at %.2f m, noise %.0f cm", tilt_deg, distance_m,
                      100 * noise_m);
        if (Report(label, {*scan}, bench) != 0) return 1;
      }
    }
  }
  return 0;
}

int Room(const BenchOptions& bench) {
  const vc::AnalyticScene scene = vc::RoomWithClutterScene();
  for (const double noise_m : {0.0, bench.noise_m}) {
    std::vector<vc::CapturedScan> scans;
    int index = 0;
    for (const vc::WorldPoint& station : {vc::kRoomWithClutterStationM, vc::WorldPoint(6.5, 3.0, 1.2)}) {
      vc::SimulatedScanner scanner;
      scanner.position_m = station;
      scanner.horizontal_step_deg = scanner.vertical_step_deg = bench.step_deg;
      scanner.range_noise_sigma_m = noise_m;
      scanner.seed = uint64_t(++index);
      auto scan = Simulate(scene, scanner, std::to_string(index));
      if (!scan.ok()) return std::fprintf(stderr, "%s\n", scan.status().ToString().c_str()), 1;
      scans.push_back(std::move(*scan));
    }
    char label[64];
    std::snprintf(label, sizeof label, "room with clutter, noise %.0f cm", 100 * noise_m);
    if (Report(label, scans, bench) != 0) return 1;
  }
  return 0;
}

// Two simulated 150 deg scans of RoomWithClutterScene (headings 20 and -160 deg): predicted all
// round, then with hfov 150 centred on each scan's heading.
int PartialRoomScans(const BenchOptions& bench) {
  const vc::AnalyticScene scene = vc::RoomWithClutterScene();
  std::vector<vc::CapturedScan> scans;
  const std::pair<vc::WorldPoint, double> stations[] = {{vc::kRoomWithClutterStationM, 20.0},
                                                        {vc::WorldPoint(6.5, 3.0, 1.2), -160.0}};
  for (const auto& [position, heading_deg] : stations) {
    vc::SimulatedScanner scanner;
    scanner.position_m = position;
    scanner.heading_rad = heading_deg * std::numbers::pi / 180.0;
    scanner.hfov_deg = 150.0;
    scanner.horizontal_step_deg = scanner.vertical_step_deg = bench.step_deg;
    auto scan = Simulate(scene, scanner, std::to_string(scans.size() + 1));
    if (!scan.ok()) return std::fprintf(stderr, "%s\n", scan.status().ToString().c_str()), 1;
    scan->heading_deg = heading_deg;
    scans.push_back(std::move(*scan));
  }
  if (Report("room, 150 deg scans, hfov 360", scans, bench) != 0) return 1;
  vc::ScannerModel sector;
  sector.hfov_deg = 150.0;
  return Report("room, 150 deg scans, hfov 150", scans, bench, sector);
}

// A real scan's points (its own frame), those nearer than min_range_m to the origin dropped.
vc::Result<std::vector<Eigen::Vector3f>> ReadScan(const std::string& path, double min_range_m) {
  VC_ASSIGN_OR_RETURN(vc::SceneInput input, vc::ReadSceneFile(path));
  std::vector<Eigen::Vector3f> kept;
  kept.reserve(input.points.size());
  for (const auto& p : input.points) {
    if (p.cast<double>().norm() >= min_range_m) kept.push_back(p);
  }
  std::printf("# %s: %zu points, %zu nearer than %.2f m dropped\n", path.c_str(), input.points.size(),
              input.points.size() - kept.size(), min_range_m);
  return kept;
}

// Whether `set` holds voxel `id` of `model` or one of its 26 neighbours.
bool HasMemberWithinOneVoxel(const vc::VoxelScene& model, const vc::VoxelSet& set, size_t id) {
  const vc::VoxelIndex v = vc::KeyToIndex(model.occupied[id]);
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int64_t n = model.IdOf(vc::IndexToKey({v.x + dx, v.y + dy, v.z + dz}));
        if (n >= 0 && set.test(size_t(n))) return true;
      }
    }
  }
  return false;
}

// Share of `moved`'s voxels with a voxel of `fixed` within one voxel (a check of a relative pose).
double Overlap(const std::vector<Eigen::Vector3f>& fixed, const std::vector<Eigen::Vector3f>& moved,
               const BenchOptions& bench) {
  vc::ValidationOptions options;
  options.resolution_m = bench.resolution_m;
  options.keep_sets = true;
  options.threads = bench.threads;
  auto report = vc::ValidateAgainstScans({{"fixed", {0, 0, 0}, fixed}, {"moved", {0, 0, 0}, moved}}, options);
  if (!report.ok()) return -1;
  const vc::ScanAgreement& f = report->scans[0];
  const vc::ScanAgreement& m = report->scans[1];
  uint64_t near = 0;
  m.captured_set.ForEach([&](size_t id) { near += HasMemberWithinOneVoxel(report->model, f.captured_set, id); });
  return double(near) / double(m.captured);
}

int RealScans(const BenchOptions& bench) {
  const double min_range_m = vc::ScannerModel{}.min_range_m;
  auto hall = ReadScan(bench.data_dir + "/hall-scan/scan.dat.bz2", min_range_m);
  if (!hall.ok()) return std::fprintf(stderr, "%s\n", hall.status().ToString().c_str()), 1;
  std::printf("# the hall scan covers -91..+91 deg of azimuth: predicted all round, then with hfov 182, heading 0\n");
  if (Report("hall (real, one station)", {{"1", {0, 0, 0}, *hall}}, bench) != 0) return 1;
  vc::ScannerModel hall_scanner;
  hall_scanner.hfov_deg = 182.0;
  if (Report("hall (real, one station), hfov 182", {{"1", {0, 0, 0}, std::move(*hall), 0.0}}, bench, hall_scanner) != 0)
    return 1;

  auto room1 = ReadScan(bench.data_dir + "/room-2scans/room_scan1.pcd", min_range_m);
  auto room2 = ReadScan(bench.data_dir + "/room-2scans/room_scan2.pcd", min_range_m);
  if (!room1.ok() || !room2.ok()) return std::fprintf(stderr, "room scans unreadable\n"), 1;
  const Eigen::Matrix3f yaw =
      Eigen::AngleAxisf(float(40.8 * std::numbers::pi / 180.0), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  const Eigen::Vector3f t(1.974f, 0.058f, 0.016f);
  std::vector<Eigen::Vector3f> as_readme, inverse;
  for (const auto& p : *room2) {
    as_readme.push_back(yaw * p + t);
    inverse.push_back(yaw.transpose() * (p - t));
  }
  const double overlap_readme = Overlap(*room1, as_readme, bench);
  const double overlap_inverse = Overlap(*room1, inverse, bench);
  const bool use_readme = overlap_readme >= overlap_inverse;
  std::printf(
      "# room pose check: share of scan 2's voxels within one voxel of scan 1's: %.3f (p1 = R p2 + t, as "
      "README) vs %.3f (inverse); using %s\n",
      overlap_readme, overlap_inverse, use_readme ? "README's" : "the inverse");
  const Eigen::Vector3f station2 = use_readme ? t : Eigen::Vector3f(-(yaw.transpose() * t));
  return Report("room (real, two stations)",
                {{"1", {0, 0, 0}, std::move(*room1)}, {"2", station2.cast<double>(), use_readme ? as_readme : inverse}},
                bench);
}

}  // namespace

int main(int argc, char** argv) {
  BenchOptions bench;
  bool simulated_only = false;
  CLI::App app{"vc-validate-bench: selection tests' recall and precision against captured points"};
  app.add_option("--resolution", bench.resolution_m, "voxel edge, m")->capture_default_str();
  app.add_option("--step", bench.step_deg, "simulated scanner's angular step, deg")->capture_default_str();
  app.add_option("--noise", bench.noise_m, "range noise of the noisy simulated scans, m")->capture_default_str();
  app.add_option("--threads", bench.threads, "threads for the visibility sets (0 = all)")->capture_default_str();
  app.add_option("--data", bench.data_dir, "folder of the real scans")->capture_default_str();
  app.add_flag("--simulated-only", simulated_only, "skip the real scans (as --scenes planes,room,partial)");
  std::vector<std::string> tests;
  app.add_option("--tests", tests, "selection tests measured (default: surface compatibility subvoxel)")
      ->check(CLI::IsMember({"surface", "compatibility", "subvoxel"}))
      ->delimiter(',');
  app.add_option("--scenes", bench.scenes, "groups of scenes (default: all)")
      ->check(CLI::IsMember({"planes", "room", "partial", "real"}))
      ->delimiter(',')
      ->capture_default_str();
  app.add_flag("--explain", bench.explain,
               "break the subvoxel test's misses down by patch, incidence, distance and first blocker "
               "(scans predicted all round)");
  std::string faces = "none", face_set = "all";
  app.add_option("--faces", faces,
                 "voxels that also count as predicted: none, those with a face fully visible (full), or at least "
                 "partially visible (partial), by the paper's corner rays")
      ->check(CLI::IsMember({"none", "full", "partial"}))
      ->capture_default_str();
  app.add_option("--face-set", face_set, "the faces --faces looks at: all six, or the exposed ones")
      ->check(CLI::IsMember({"all", "exposed"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  bench.count_faces = faces == "full"      ? vc::ValidationOptions::FaceRule::kFull
                      : faces == "partial" ? vc::ValidationOptions::FaceRule::kPartial
                                           : vc::ValidationOptions::FaceRule::kNone;
  bench.count_faces_of = face_set == "exposed" ? vc::FaceSet::kExposed : vc::FaceSet::kAll;
  if (!tests.empty()) {
    bench.tests.clear();
    for (const std::string& name : tests) {
      bench.tests.push_back(name == "surface"         ? vc::SelectionTest::kSurfaceVisibility
                            : name == "compatibility" ? vc::SelectionTest::kCompatibility
                                                      : vc::SelectionTest::kSubvoxel);
    }
  }
  if (simulated_only) std::erase(bench.scenes, std::string("real"));

  const auto start = Clock::now();
  std::printf(
      "# resolution %.3f m, simulated step %.2f deg; recall1 / prec1: with one voxel of slack; "
      "prec '-': one scan, so only recall is meaningful; faces counted too: %s (%s)\n",
      bench.resolution_m, bench.step_deg, faces.c_str(), face_set.c_str());
  PrintHeader();
  if ((Runs(bench, "planes") && TiltedPlanes(bench) != 0) || (Runs(bench, "room") && Room(bench) != 0) ||
      (Runs(bench, "partial") && PartialRoomScans(bench) != 0) || (Runs(bench, "real") && RealScans(bench) != 0))
    return 1;
  std::printf("# %.1f s\n", Since(start));
  return 0;
}
