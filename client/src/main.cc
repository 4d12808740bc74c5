// vc-client: parses the command line, calls vc::client::Client or the core (inspect), prints.
// Exit status: 0 on success, else the gRPC status code number of the failure (3 invalid
// argument, 5 not found, 8 resource exhausted, 14 unavailable, 16 unauthenticated, ...; local
// errors use the same numbers); command-line mistakes give CLI11's codes (>= 100).
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <string>

#include "vc/client/client.h"
#include "vc/client/progress_display.h"
#include "vc/report/plan_report.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/scene_summary.h"
#include "vc/server/status_mapping.h"

namespace {

int Fail(const std::string& what, const vc::Status& s) {
  std::cerr << "vc-client: " << what << ": " << s.message() << "\n";
  return int(vc::server::ToGrpcCode(s.code()));
}

int Fail(const std::string& what, const grpc::Status& s, const std::string& server) {
  std::string msg = s.error_message();
  if (s.error_code() == grpc::StatusCode::UNAVAILABLE) msg = "cannot reach vc-server at " + server + " (" + msg + ")";
  std::cerr << "vc-client: " << what << " failed (" << int(s.error_code()) << "): " << msg << "\n";
  return int(s.error_code());
}

const std::vector<std::string> kSelectionTests = {"surface", "compatibility"};

void PrintStations(const vc::PlanResult& r) {
  std::printf("%zu station(s), coverage %.1f%% of %llu coverable voxels, global visibility G = %.3f\n",
              r.stations.size(), r.coverable_voxels ? 100.0 * double(r.covered_voxels) / double(r.coverable_voxels) : 0.0,
              static_cast<unsigned long long>(r.coverable_voxels), r.evaluation.overall.global_visibility);
  std::printf("  %3s %10s %10s %10s %12s %9s\n", "#", "x_m", "y_m", "z_m", "gain_voxels", "coverage");
  for (size_t i = 0; i < r.stations.size(); ++i) {
    const auto& s = r.stations[i];
    std::printf("  %3zu %10.3f %10.3f %10.3f %12llu %8.1f%%\n", i + 1, s.position.x(), s.position.y(), s.position.z(),
                static_cast<unsigned long long>(s.marginal_gain), 100.0 * s.cumulative_coverage);
  }
  for (const auto& w : r.warnings) std::printf("warning: %s\n", w.c_str());
}

vc::client::JobObserver Observe(vc::client::ProgressDisplay& display) {
  vc::client::JobObserver o;
  o.on_accepted = [&](const std::string& id, uint32_t pos) { display.Accepted(id, pos); };
  o.on_progress = [&](const vc::ProgressEvent& e) { display.Update(e); };
  o.on_station = [&](const vc::PlannedStation& s, int i) { display.Station(s, i); };
  // The server sends the heat map when it is ready and again with the final result; note it once.
  o.on_heat_map = [&display, shown = false](const vc::HeatMap& h) mutable {
    if (!shown) display.Note("heat map ready: " + std::to_string(h.positions.size()) + " candidate positions");
    shown = true;
  };
  o.on_retry = [&](const grpc::Status& s, std::chrono::milliseconds wait) {
    display.Note("server unavailable (" + s.error_message() + "); retrying in " + std::to_string(wait.count()) + " ms");
  };
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vc-client: plan laser-scanner stations with vc-server, or inspect a scene locally"};
  app.require_subcommand(1);
  app.fallthrough();

  vc::client::ConnectionOptions conn;
  double timeout_s = 0;
  app.add_option("--server", conn.server, "vc-server address host:port")->envname("VC_SERVER")->capture_default_str();
  app.add_flag("--tls", conn.tls, "use TLS with the system's root certificates")->envname("VC_TLS");
  app.add_option("--tls-ca", conn.tls_ca_file, "CA certificate (PEM) to verify the server; implies --tls")
      ->envname("VC_TLS_CA");
  app.add_option("--tls-cert", conn.tls_cert_file, "client certificate (PEM) for mutual TLS")->envname("VC_TLS_CERT");
  app.add_option("--tls-key", conn.tls_key_file, "client key (PEM) for mutual TLS")->envname("VC_TLS_KEY");
  app.add_option("--tls-server-name", conn.tls_server_name, "name to verify in the server certificate")
      ->envname("VC_TLS_SERVER_NAME");
  app.add_option("--token", conn.token, "bearer token for the server")->envname("VC_TOKEN");
  app.add_flag("--gzip,!--no-gzip", conn.gzip, "gzip-compress the upload")->capture_default_str();
  app.add_option("--retries", conn.max_attempts, "attempts when the server is unavailable")->capture_default_str();
  app.add_option("--timeout", timeout_s, "deadline per call in seconds (0 = none)")->capture_default_str();

  // submit
  const vc::PlanOptions defaults;
  vc::PlanOptions plan = defaults;
  std::string file, out_dir = "./vc-out", test_name = "surface", candidates_csv;
  auto* submit = app.add_subcommand("submit", "plan stations for a scene on the server; write the reports");
  submit->add_option("FILE", file, "scene: PLY, PCD, XYZ, LAS, or OctoMap .bt/.ot/.graph")->required();
  submit->add_option("--out", out_dir, "output directory")->capture_default_str();
  submit->add_option("--resolution", plan.resolution_m, "working resolution in m (0 = the octree's own, or 0.1 m)")
      ->capture_default_str();
  submit->add_option("--memory-budget-bytes", plan.memory_budget_bytes, "memory budget of the job in bytes")
      ->capture_default_str();
  submit->add_option("--test", test_name, "selection test")->check(CLI::IsMember(kSelectionTests))->capture_default_str();
  submit->add_option("--min-range", plan.scanner.min_range_m, "scanner minimum range in m")->capture_default_str();
  submit->add_option("--max-range", plan.scanner.max_range_m, "scanner maximum range in m")->capture_default_str();
  submit->add_option("--grid-spacing", plan.grid_spacing_m, "candidate grid spacing in m")->capture_default_str();
  submit->add_option("--tripod-height", plan.tripod_height_m, "scanner height above the floor in m")->capture_default_str();
  submit->add_option("--clearance", plan.clearance_m, "clearance around a candidate in m")->capture_default_str();
  submit->add_option("--candidates", candidates_csv, "CSV of candidate positions x,y,z (replaces the grid)");
  submit->add_option("--max-stations", plan.max_stations, "at most this many stations (0 = no limit)")->capture_default_str();
  submit->add_option("--min-gain", plan.min_marginal_gain_voxels, "stop when a station adds fewer voxels")
      ->capture_default_str();
  submit->add_option("--target-coverage", plan.target_coverage, "stop at this covered fraction (0..1]")->capture_default_str();
  submit->add_flag("--consolidate,!--no-consolidate", plan.consolidate,
                   "drop covered picks and merge pairs after greedy selection")->capture_default_str();
  submit->add_flag("--refine,!--no-refine", plan.refine, "refine each station on a local sub-grid")->capture_default_str();
  submit->add_option("--refine-radius", plan.refine_radius_m, "refinement radius in m")->capture_default_str();
  submit->add_option("--refine-step", plan.refine_step_m, "refinement step in m")->capture_default_str();
  submit->add_flag("--reduce,!--no-reduce", plan.reduce, "remove redundant stations")->capture_default_str();
  submit->add_option("--reduce-to", plan.reduce_to, "reduce to at most this many stations (0 = zero-loss only)")
      ->capture_default_str();
  submit->add_option("--threads", plan.threads, "threads for the job (0 = the server's share)")->capture_default_str();

  // evaluate
  vc::wire::EvaluateJobOptions eval;
  std::string viewpoints_csv, faces_name = "all";
  auto* evaluate = app.add_subcommand("evaluate", "evaluate viewpoints on a scene on the server; write evaluation.json");
  evaluate->add_option("FILE", file, "scene file")->required();
  evaluate->add_option("--viewpoints", viewpoints_csv, "CSV of viewpoints x,y,z (e.g. stations.csv)")->required();
  evaluate->add_option("--resolution", eval.voxelize.resolution_m, "working resolution in m (0 = default)")
      ->capture_default_str();
  evaluate->add_option("--sample", eval.evaluate.sample_faces, "evaluate a random sample of N faces (0 = all)")
      ->capture_default_str();
  evaluate->add_option("--seed", eval.evaluate.seed, "sampling seed")->capture_default_str();
  evaluate->add_option("--faces", faces_name, "faces counted in F")->check(CLI::IsMember(std::vector<std::string>{"all", "exposed"}))
      ->capture_default_str();
  evaluate->add_option("--min-range", eval.evaluate.scanner.min_range_m, "scanner minimum range in m")->capture_default_str();
  evaluate->add_option("--max-range", eval.evaluate.scanner.max_range_m, "scanner maximum range in m")->capture_default_str();
  evaluate->add_option("--memory-budget-bytes", eval.voxelize.memory_budget_bytes, "memory budget in bytes")
      ->capture_default_str();
  evaluate->add_option("--threads", eval.evaluate.threads, "threads (0 = the server's share)")->capture_default_str();
  evaluate->add_option("--out", out_dir, "output directory")->capture_default_str();

  // health
  std::string health_service;
  auto* health = app.add_subcommand("health", "check the server's gRPC health service");
  health->add_option("--service", health_service, "service name (empty = the whole server)");

  // inspect
  double inspect_resolution = 0;
  bool json = false;
  auto* inspect = app.add_subcommand("inspect", "describe a scene file locally (no server)");
  inspect->add_option("FILE", file, "scene file")->required();
  inspect->add_option("--resolution", inspect_resolution, "resolution in m for the voxel count (0 = default)")
      ->capture_default_str();
  inspect->add_flag("--json", json, "print JSON");

  CLI11_PARSE(app, argc, argv);
  conn.timeout = std::chrono::milliseconds(int64_t(timeout_s * 1000));

  if (*inspect) {
    // The limits vc-server applies with its defaults, so inspect accepts what a plan would.
    auto input = vc::ReadSceneFile(file, vc::ReadLimits(vc::kDefaultMaxUploadBytes, vc::kDefaultMemoryBudgetBytes));
    if (!input.ok()) return Fail("cannot read " + file, input.status());
    auto summary = vc::Summarize(*input, inspect_resolution, vc::kDefaultMemoryBudgetBytes);
    if (!summary.ok()) return Fail("cannot summarise " + file, summary.status());
    std::cout << (json ? vc::SummaryToJson(*summary) : vc::SummaryToText(*summary, file)) << "\n";
    return 0;
  }

  auto client = vc::client::Client::Create(conn);
  if (!client.ok()) return Fail("cannot set up the connection", client.status());

  if (*health) {
    auto r = (*client)->Health(health_service);
    if (!r.ok()) return Fail("health check", r.status, conn.server);
    std::cout << r.value << "\n";
    return 0;
  }

  auto upload = vc::client::ReadUpload(file);
  if (!upload.ok()) return Fail("cannot read the scene", upload.status());
  vc::client::ProgressDisplay display(stderr, isatty(fileno(stderr)) != 0);
  display.Uploading(upload->source_name, upload->bytes.size(), conn.server);

  if (*submit) {
    plan.test = test_name == "compatibility" ? vc::SelectionTest::kCompatibility : vc::SelectionTest::kSurfaceVisibility;
    if (!candidates_csv.empty()) {
      auto text = vc::client::ReadUpload(candidates_csv);
      if (!text.ok()) return Fail("cannot read the candidates", text.status());
      auto points = vc::ParseStationsCsv(text->bytes, candidates_csv);
      if (!points.ok()) return Fail("bad candidates file", points.status());
      plan.candidates = std::move(points).value();
    }
    auto r = (*client)->Plan(*upload, plan, Observe(display));
    display.Done();
    if (!r.ok()) return Fail("plan", r.status, conn.server);
    vc::Status written = vc::WritePlanOutputs(r.value, out_dir);
    if (!written.ok()) return Fail("cannot write the reports", written);
    PrintStations(r.value);
    std::printf("wrote plan.json, stations.csv, visibility.ply, heatmap.png, reduction.png to %s\n", out_dir.c_str());
    return 0;
  }

  // evaluate
  eval.evaluate.faces = faces_name == "exposed" ? vc::FaceSet::kExposed : vc::FaceSet::kAll;
  auto text = vc::client::ReadUpload(viewpoints_csv);
  if (!text.ok()) return Fail("cannot read the viewpoints", text.status());
  auto points = vc::ParseStationsCsv(text->bytes, viewpoints_csv);
  if (!points.ok()) return Fail("bad viewpoints file", points.status());
  eval.viewpoints = std::move(points).value();
  auto r = (*client)->Evaluate(*upload, eval, Observe(display));
  display.Done();
  if (!r.ok()) return Fail("evaluate", r.status, conn.server);
  vc::Status written = vc::WriteEvaluationOutputs(r.value, eval.viewpoints, out_dir);
  if (!written.ok()) return Fail("cannot write evaluation.json", written);
  std::printf("global visibility G = %.4f%s over %llu faces; wrote %s/evaluation.json\n",
              r.value.overall.global_visibility,
              r.value.sampled ? (" (+/- " + std::to_string(r.value.global_visibility_ci95) + ", sampled)").c_str() : "",
              static_cast<unsigned long long>(r.value.faces_evaluated), out_dir.c_str());
  return 0;
}
