// vc-client: parses the command line, calls vc::client::Client or the core (inspect), prints.
// Exit status: 0 on success, else the gRPC status code number of the failure (3 invalid
// argument, 5 not found, 8 resource exhausted, 14 unavailable, 16 unauthenticated, ...; local
// errors use the same numbers); command-line mistakes give CLI11's codes (>= 100).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "vc/client/client.h"
#include "vc/client/compact_upload.h"
#include "vc/client/crs_flag.h"
#include "vc/client/did_you_mean.h"
#include "vc/client/export_sets.h"
#include "vc/client/parameter_flags.h"
#include "vc/client/plan_file.h"
#include "vc/client/plan_summary.h"
#include "vc/client/progress_display.h"
#include "vc/client/validate_command.h"
#include "vc/report/plan_report.h"
#include "vc/scene/e57.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/scene_summary.h"
#include "vc/scene/station_file.h"
#include "vc/wire/status_mapping.h"

namespace {

// A local failure; the exit status is its gRPC code number.
int Fail(const std::string& what, const vc::Status& s) {
  std::cerr << "vc-client: " << what << ": " << s.message() << "\n";
  return int(vc::wire::ToGrpcCode(s.code()));
}

// A local failure whose message says it all (it names the flag or the file), found before any
// connection; the exit status is its gRPC code number.
int Fail(const vc::Status& s) {
  std::cerr << "vc-client: " << s.message() << " (nothing was sent)\n";
  return int(vc::wire::ToGrpcCode(s.code()));
}

// A failed call to `server`; the exit status is its gRPC code number.
int FailCall(const std::string& what, const vc::Status& s, const std::string& server) {
  const int code = int(vc::wire::ToGrpcCode(s.code()));
  std::string msg = s.message();
  if (s.code() == vc::StatusCode::kUnavailable) msg = "cannot reach vc-server at " + server + " (" + msg + ")";
  std::cerr << "vc-client: " << what << " failed (" << code << "): " << msg << "\n";
  return code;
}

void PrintStations(const vc::PlanResult& r) { std::fputs(vc::client::PlanSummary(r).c_str(), stdout); }

// Says whether the server had the scene already, and keeps it for plan.json.
void NoteCache(const vc::client::UploadOutcome& outcome, vc::UploadSummary* summary,
               vc::client::ProgressDisplay& display) {
  summary->scene_hash = outcome.scene_sha256;
  summary->from_cache = outcome.from_cache;
  if (outcome.from_cache) {
    summary->bytes_sent = 0;
    display.Note("the server had the scene (" + outcome.scene_sha256.substr(0, 12) +
                 "...) in its cache: nothing uploaded");
  }
}

// Ctrl-C (SIGINT) or SIGTERM while a job runs: the job is cancelled on the server (CancelJob), so
// its worker is free at once, rather than left running detached as a dropped link would leave it.
// The signals are blocked in every thread (gRPC's too) and taken by one watcher thread.
class InterruptCancelsTheJob {
 public:
  explicit InterruptCancelsTheJob(vc::client::ConnectionOptions conn) : conn_(std::move(conn)) {
    sigemptyset(&signals_);
    sigaddset(&signals_, SIGINT);
    sigaddset(&signals_, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
    std::thread([this] { Watch(); }).detach();
  }
  void set_job(const vc::client::JobTicket& ticket) {
    std::lock_guard lock(mu_);
    job_ = ticket;
  }

 private:
  [[noreturn]] void Watch() {
    int sig = 0;
    sigwait(&signals_, &sig);
    vc::client::JobTicket job;
    {
      std::lock_guard lock(mu_);
      job = job_;
    }
    const std::string& id = job.job_id;
    if (!id.empty() && job.detach_grace_s > 0) {  // else the job ends with this process's stream
      const auto r = vc::client::CancelDetachedJob(conn_, job);
      std::fprintf(
          stderr, "\nvc-client: interrupted; job %s %s\n", id.c_str(),
          r.ok() ? (*r + " on the server").c_str()
                 : ("may still run on the server (" + r.status().message() + "): vc-client cancel " + id).c_str());
    } else {
      std::fprintf(stderr, "\nvc-client: interrupted\n");
    }
    std::_Exit(128 + sig);
  }
  vc::client::ConnectionOptions conn_;
  sigset_t signals_;
  std::mutex mu_;
  vc::client::JobTicket job_;
};

// Writes the evaluation's reports (stations.geojson and true north on the field sheet with a CRS;
// the field sheet's scan time from `scanner`, the job's, when known), prints G and the files written.
int WriteEvaluation(const vc::EvaluateJobResult& result, const std::string& out_dir, const std::string& paper,
                    const vc::Crs* crs = nullptr, const vc::ScannerModel& scanner = {}) {
  vc::FieldSheetOptions sheet;
  sheet.paper = paper == "a4" ? vc::PaperSize::kA4 : vc::PaperSize::kA3;
  vc::Status written = vc::WriteEvaluationOutputs(result, out_dir, crs, sheet, scanner);
  if (!written.ok()) return Fail("cannot write the reports", written);
  const vc::Evaluation& r = result.evaluation;
  const bool per_voxel = !r.best_face_values.empty();
  std::printf(
      "global visibility G = %.4f%s over %llu faces; wrote evaluation.json, stations.csv, stations.dxf, "
      "%sfieldsheet.pdf%s to %s\n",
      r.overall.global_visibility,
      r.sampled ? (" (+/- " + std::to_string(r.global_visibility_ci95) + ", sampled)").c_str() : "",
      static_cast<unsigned long long>(r.faces_evaluated), crs != nullptr ? "stations.geojson, " : "",
      per_voxel ? ", visibility.ply, heatmap.png (what the stations miss), report.html" : "", out_dir.c_str());
  if (!per_voxel) {
    std::printf("no visibility.ply, heatmap.png, report.html: a sampled evaluation has no per-voxel values\n");
  }
  if (crs == nullptr) {
    std::printf("no stations.geojson: name the scene's CRS (--crs EPSG:25832, say) for a map in longitude/latitude\n");
  }
  return 0;
}

vc::client::JobObserver Observe(vc::client::ProgressDisplay& display, InterruptCancelsTheJob* interrupt = nullptr) {
  vc::client::JobObserver o;
  o.on_accepted = [&display](const std::string& id, uint32_t pos) { display.Accepted(id, pos); };
  o.on_job = [&display, interrupt, noted = false](const vc::client::JobTicket& t) mutable {
    if (interrupt != nullptr) interrupt->set_job(t);
    if (t.detach_grace_s == 0 || noted) return;
    noted = true;  // once, not again on a re-attach's replay
    const std::string server = t.attach_address.empty() ? "" : " --server " + t.attach_address;
    display.Note("it runs on for " + std::to_string(t.detach_grace_s) + " s if the connection drops: vc-client" +
                 server + " attach " + t.job_id + " (or cancel " + t.job_id + ")");
  };
  o.on_progress = [&](const vc::ProgressEvent& e) { display.Update(e); };
  o.on_station = [&](const vc::PlannedStation& s, int i) { display.Station(s, i); };
  o.on_final_stations = [&](const std::vector<vc::PlannedStation>& s) { display.FinalStations(s); };
  o.on_heat_map = [&](const vc::HeatMap& h) {
    display.Note("heat map ready: " + std::to_string(h.positions.size()) + " candidate positions");
  };
  o.on_retry = [&](const vc::Status& s, std::chrono::milliseconds wait) {
    display.Note("server unavailable (" + s.message() + "); retrying in " + std::to_string(wait.count()) + " ms");
  };
  o.on_reattach = [&](const vc::client::JobTicket& t, const vc::Status& s, std::chrono::milliseconds wait) {
    display.Note("lost the stream of job " + t.job_id + " (" + s.message() + "); re-attaching in " +
                 std::to_string(wait.count()) + " ms");
  };
  return o;
}

// The names in the --fixed-stations file, in its order (LoadPlanFiles keeps the positions only);
// none without the file (attach: the names come from the file, which the job does not keep).
std::vector<std::string> FixedStationNames(const std::string& path) {
  std::vector<std::string> names;
  if (path.empty()) return names;
  auto stations = vc::ReadStationFile(path);
  if (!stations.ok()) return names;
  for (const vc::KnownStation& s : *stations) names.push_back(s.name);
  return names;
}

// Writes the plan's reports (stations.geojson and true north on the field sheet with a CRS) and
// prints its stations.
int WritePlan(const vc::PlanResult& r, const std::string& out_dir, const std::string& paper,
              const vc::UploadSummary* upload, const std::vector<std::string>& fixed_station_names = {},
              const vc::Crs* crs = nullptr) {
  vc::FieldSheetOptions sheet;
  sheet.paper = paper == "a4" ? vc::PaperSize::kA4 : vc::PaperSize::kA3;
  vc::Status written = vc::WritePlanOutputs(r, out_dir, upload, fixed_station_names, crs, sheet);
  if (!written.ok()) return Fail("cannot write the reports", written);
  PrintStations(r);
  std::printf(
      "wrote plan.json, stations.csv, stations.dxf, %sfieldsheet.pdf, visibility.ply, heatmap.png, reduction.png, "
      "report.html to %s\n",
      crs != nullptr ? "stations.geojson, " : "", out_dir.c_str());
  if (crs == nullptr) {
    std::printf("no stations.geojson: name the scene's CRS (--crs EPSG:25832, say) for a map in longitude/latitude\n");
  }
  return 0;
}

constexpr const char* kRawUploadHelp =
    "upload the file's bytes as they are, not a point cloud's voxels at the working resolution (vc-voxels)";
constexpr const char* kDetachHelp =
    "seconds the job runs on if this connection drops (re-attached automatically, or with vc-client attach); "
    "0 = the job ends with the connection";

constexpr const char* kUnitsHelp =
    "unit of the file's coordinates when the file does not say: m, cm, mm, ft (international foot), us-ft "
    "(US survey foot); default m (E57 and octrees are metres by their formats)";

constexpr const char* kCrsHelp =
    "CRS of the file's coordinates (EPSG:25832, WKT or a PROJ string; a projected CRS): labels plan.json and "
    "stations.csv and writes stations.geojson; without --units the file is read in the CRS's unit (an E57 or "
    "an octree in metres)";

// --units on `command`, checked here with the server's own list (MetresPerUnit).
void AddUnitsFlag(CLI::App* command, std::string* units) {
  command->add_option("--units", *units, kUnitsHelp)->check([](const std::string& unit) {
    const vc::Result<double> metres = vc::MetresPerUnit(unit);
    return metres.ok() ? std::string() : metres.status().message();
  });
}

// --paper: the paper fieldsheet.pdf is laid out for (landscape).
void AddPaperFlag(CLI::App* command, std::string* paper) {
  command->add_option("--paper", *paper, "paper of fieldsheet.pdf, landscape: a3 or a4")
      ->check(CLI::IsMember({"a3", "a4"}))
      ->capture_default_str();
}

// What the command line says; each subcommand reads its own fields.
struct CommandLine {
  vc::client::ConnectionOptions conn;
  double timeout_s = 0;
  std::string file;
  std::string out_dir = "./vc-out";
  bool raw_upload = false;
  std::string units;                     // submit, evaluate, inspect (--units; empty = metres)
  std::string crs;                       // submit, evaluate, attach (--crs; empty = none)
  std::string paper = "a3";              // submit, evaluate, attach: fieldsheet.pdf's paper (--paper)
  vc::PlanOptions plan;                  // submit
  vc::client::PlanFileFlags plan_files;  // submit
  vc::EvaluateJobOptions eval;           // evaluate
  std::string viewpoints_csv;            // evaluate
  std::string plan_json;                 // evaluate (--plan: stations, scanner and CRS from a plan.json)
  std::string export_dir;                // evaluate (--export-sets: each station's seen set as DIR/station_<n>.xyz)
  bool force = false;                    // evaluate (--force: write --export-sets into a non-empty DIR)
  std::string job_id;                    // attach, cancel
  std::string health_service;            // health
  double inspect_resolution = 0;         // inspect
  bool json = false;                     // inspect
};

// The subcommands, to tell which one was given.
struct Subcommands {
  CLI::App* submit;
  CLI::App* evaluate;
  CLI::App* attach;
  CLI::App* cancel;
  CLI::App* health;
  CLI::App* scanners;
  CLI::App* inspect;
};

void AddConnectionFlags(CLI::App& app, CommandLine* cl) {
  vc::client::ConnectionOptions& conn = cl->conn;
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
  app.add_flag("--scene-cache,!--no-scene-cache", conn.scene_cache,
               "name the scene by its SHA-256 first; upload it only when the server does not hold it")
      ->capture_default_str();
  app.add_option("--retries", conn.max_attempts, "attempts when the server is unavailable")->capture_default_str();
  app.add_option("--timeout", cl->timeout_s, "deadline per call in seconds (0 = none)")->capture_default_str();
}

// submit: every planning parameter's flag comes from the parameter table (parameter_flags.h).
CLI::App* AddSubmitCommand(CLI::App& app, CommandLine* cl) {
  auto* submit = app.add_subcommand("submit", "plan stations for a scene on the server; write the reports");
  submit->add_option("FILE", cl->file, "scene: PLY, PCD, XYZ, LAS, or OctoMap .bt/.ot/.graph")->required();
  submit->add_option("--out", cl->out_dir, "output directory")->capture_default_str();
  AddPaperFlag(submit, &cl->paper);
  submit->add_flag("--raw-upload", cl->raw_upload, kRawUploadHelp);
  AddUnitsFlag(submit, &cl->units);
  submit->add_option("--crs", cl->crs, kCrsHelp);
  cl->conn.detach_grace_s = 600;
  submit->add_option("--detach-grace", cl->conn.detach_grace_s, kDetachHelp)->capture_default_str();
  vc::client::AddPlanFileFlags(submit, &cl->plan_files);
  vc::client::AddPlanFlags(submit, &cl->plan);
  return submit;
}

CLI::App* AddEvaluateCommand(CLI::App& app, CommandLine* cl) {
  auto* evaluate = app.add_subcommand(
      "evaluate",
      "evaluate viewpoints or a plan on a scene on the server; write evaluation.json and submit's files for them "
      "(stations.csv, stations.dxf, fieldsheet.pdf, visibility.ply, heatmap.png of what they miss, report.html)");
  evaluate->add_option("FILE", cl->file, "scene file")->required();
  auto* viewpoints =
      evaluate->add_option("--viewpoints", cl->viewpoints_csv, "CSV of viewpoints x,y,z (e.g. stations.csv)");
  evaluate
      ->add_option("--plan", cl->plan_json,
                   "a plan.json from submit: its stations, its scanner (each scanner flag given overrides it) and "
                   "its CRS (unless --crs)")
      ->excludes(viewpoints);
  evaluate->add_option("--out", cl->out_dir, "output directory")->capture_default_str();
  evaluate->add_flag("--raw-upload", cl->raw_upload, kRawUploadHelp);
  AddUnitsFlag(evaluate, &cl->units);
  evaluate->add_option("--crs", cl->crs, kCrsHelp);
  evaluate->add_option("--detach-grace", cl->conn.detach_grace_s, kDetachHelp)->capture_default_str();
  AddPaperFlag(evaluate, &cl->paper);
  vc::client::AddEvaluateFlags(evaluate, &cl->eval);
  auto* export_sets = evaluate->add_option(
      "--export-sets", cl->export_dir,
      "also write, per station, the voxels --test counts as seen from it as DIR/station_<n>.xyz (voxel centres, "
      "the input's frame, metres; n from 1 in the stations' order): check the prediction with your own tools");
  export_sets->type_name("DIR");
  evaluate->add_flag("--force", cl->force, "write --export-sets into a directory that is not empty")
      ->needs(export_sets);
  return evaluate;
}

Subcommands AddCommands(CLI::App& app, CommandLine* cl) {
  AddConnectionFlags(app, cl);
  Subcommands sub;
  sub.submit = AddSubmitCommand(app, cl);
  sub.evaluate = AddEvaluateCommand(app, cl);

  sub.attach = app.add_subcommand(
      "attach", "re-attach to a detached job (plan or evaluation) by its id; write its reports like submit/evaluate");
  sub.attach->add_option("JOB_ID", cl->job_id, "the id submit printed (j-...)")->required();
  sub.attach->add_option("--out", cl->out_dir, "output directory")->capture_default_str();
  sub.attach->add_option("--crs", cl->crs,
                         "CRS the job's scene was submitted in (as submit --crs): labels the outputs");
  AddPaperFlag(sub.attach, &cl->paper);
  sub.cancel = app.add_subcommand("cancel", "cancel a detached job, or discard its kept result");
  sub.cancel->add_option("JOB_ID", cl->job_id, "the id submit printed (j-...)")->required();

  sub.health = app.add_subcommand("health", "check the server's gRPC health service");
  sub.health->add_option("--service", cl->health_service, "service name (empty = the whole server)");

  sub.scanners = app.add_subcommand("scanners", "list the instrument presets for --scanner (no server)");

  sub.inspect = app.add_subcommand("inspect", "describe a scene file locally (no server)");
  sub.inspect->add_option("FILE", cl->file, "scene file")->required();
  sub.inspect->add_option("--resolution", cl->inspect_resolution, "resolution in m for the voxel count (0 = default)")
      ->capture_default_str();
  sub.inspect->add_flag("--json", cl->json, "print JSON");
  AddUnitsFlag(sub.inspect, &cl->units);
  return sub;
}

int RunScanners() {
  std::cout << vc::client::ScannerPresetsTable();
  return 0;
}

int RunInspect(const CommandLine& cl) {
  const std::string& file = cl.file;
  // The limits vc-server applies with its defaults, so inspect accepts what a plan would.
  vc::ReadOptions read_options = vc::ReadLimits(vc::kDefaultMaxUploadBytes, vc::kDefaultMemoryBudgetBytes);
  if (!cl.units.empty()) read_options.metres_per_unit = *vc::MetresPerUnit(cl.units);  // checked by --units
  auto input = vc::ReadSceneFile(file, read_options);
  if (!input.ok()) return Fail("cannot read " + file, input.status());
  auto summary = vc::Summarize(*input, cl.inspect_resolution, vc::kDefaultMemoryBudgetBytes);
  if (!summary.ok()) return Fail("cannot summarise " + file, summary.status());
  if (input->format == vc::InputFormat::kE57 && input->compression == vc::Compression::kNone) {
    auto bytes = vc::client::ReadUpload(file);
    if (!bytes.ok()) return Fail("cannot read " + file, bytes.status());
    auto scans = vc::ReadE57Scans(bytes->bytes, file);
    if (!scans.ok()) return Fail("cannot list the scans of " + file, scans.status());
    summary->e57_scans = std::move(scans).value();
  }
  std::cout << (cl.json ? vc::SummaryToJson(*summary) : vc::SummaryToText(*summary, file)) << "\n";
  return 0;
}

int RunHealth(vc::client::Client& client, const CommandLine& cl) {
  auto r = client.Health(cl.health_service);
  if (!r.ok()) return FailCall("health check", r.status(), cl.conn.server);
  std::cout << *r << "\n";
  return 0;
}

int RunCancel(vc::client::Client& client, const CommandLine& cl) {
  auto r = client.CancelJob(cl.job_id);
  if (!r.ok()) return FailCall("cancel", r.status(), cl.conn.server);
  std::cout << "job " << cl.job_id << ": " << *r << "\n";
  return 0;
}

int RunAttach(vc::client::Client& client, const CommandLine& cl) {
  // The job's units are the server's to know: only the CRS itself is checked here.
  vc::Result<vc::client::CrsChoice> crs = vc::client::CheckCrsFlag(cl.crs, "");
  if (!crs.ok()) return Fail(crs.status());
  const vc::Crs* crs_ptr = crs->crs ? &*crs->crs : nullptr;
  vc::client::ProgressDisplay display(stderr, isatty(fileno(stderr)) != 0);
  auto job = client.Attach(cl.job_id, Observe(display));
  display.Done();
  if (!job.ok()) return FailCall("attach", job.status(), cl.conn.server);
  if (job->kind == vc::client::AttachedJob::Kind::kEvaluation) {
    return WriteEvaluation(job->evaluation, cl.out_dir, cl.paper, crs_ptr);
  }
  return WritePlan(job->plan, cl.out_dir, cl.paper, nullptr, {}, crs_ptr);
}

// The scene file's bytes, and the format they hold when that can be told here (else the reader's
// error comes with PrepareScene): --crs and --units depend on it (E57 holds metres; CheckCrsFlag).
struct SceneFile {
  vc::client::Upload bytes;
  std::optional<vc::InputFormat> format;
};

vc::Result<SceneFile> ReadSceneBytes(const CommandLine& cl) {
  SceneFile file;
  VC_ASSIGN_OR_RETURN(file.bytes, vc::client::ReadUpload(cl.file));
  const vc::ReadOptions limits = vc::ReadLimits(vc::kDefaultMaxUploadBytes, vc::kDefaultMemoryBudgetBytes);
  vc::Result<vc::InputFormat> format = vc::DetectSceneFormat(file.bytes.bytes, cl.file, limits);
  if (format.ok()) file.format = *format;
  return file;
}

// The scene file, read and checked here before any connection: refused when the server's reader
// would refuse it too (compact_upload.h); the upload for it in `units` at `resolution_m` otherwise.
// The subvoxel test needs the points: with it the file goes raw.
vc::Result<vc::client::PreparedUpload> PrepareScene(const CommandLine& cl, SceneFile file, const std::string& units,
                                                    double resolution_m, vc::SelectionTest test) {
  vc::client::Upload file_bytes = std::move(file.bytes);
  file_bytes.units = units;
  const bool needs_points = test == vc::SelectionTest::kSubvoxel && !cl.raw_upload;
  VC_ASSIGN_OR_RETURN(vc::client::PreparedUpload prepared,
                      vc::client::PrepareUpload(std::move(file_bytes), resolution_m, cl.raw_upload || needs_points));
  if (needs_points) prepared.summary.why_raw = "the subvoxel test needs the points";
  return prepared;
}

// Announces `prepared` on `display`.
void AnnounceUpload(const vc::client::PreparedUpload& prepared, const CommandLine& cl,
                    vc::client::ProgressDisplay& display) {
  if (!prepared.format_note.empty()) display.Note(prepared.format_note);
  display.Note(vc::client::DescribeUpload(prepared.summary));
  display.Uploading(prepared.upload.source_name, prepared.upload.bytes.size(), cl.conn.server);
}

// Everything submit checks before it connects: the parameters and the files they name (by the
// server's rules, named by flag), then the scene file.
struct CheckedSubmit {
  vc::PlanOptions plan;
  vc::client::CrsChoice crs;
  vc::client::PreparedUpload prepared;
  vc::client::PlanFileLines lines;  // where the files' entries were read, for the server's messages
};

vc::Result<CheckedSubmit> CheckSubmit(const CommandLine& cl) {
  CheckedSubmit checked{cl.plan, {}, {}, {}};
  vc::Result<SceneFile> file = ReadSceneBytes(cl);  // its error comes after the flags'
  VC_ASSIGN_OR_RETURN(checked.crs, vc::client::CheckCrsFlag(cl.crs, cl.units, file.ok() ? file->format : std::nullopt));
  VC_ASSIGN_OR_RETURN(checked.lines, vc::client::LoadPlanFiles(cl.plan_files, &checked.plan));
  VC_RETURN_IF_ERROR(checked.plan.Validate(vc::client::PlanFlagNamer(checked.lines)));
  if (!file.ok()) return file.status();
  VC_ASSIGN_OR_RETURN(checked.prepared, PrepareScene(cl, std::move(file).value(), checked.crs.units,
                                                     checked.plan.resolution_m, checked.plan.selection_test));
  return checked;
}

int RunSubmit(const CommandLine& cl, InterruptCancelsTheJob* interrupt) {
  vc::Result<CheckedSubmit> checked = CheckSubmit(cl);
  if (!checked.ok()) return Fail(checked.status());
  auto client = vc::client::Client::Create(cl.conn);
  if (!client.ok()) return Fail("cannot set up the connection", client.status());
  vc::client::ProgressDisplay display(stderr, isatty(fileno(stderr)) != 0);
  vc::client::PreparedUpload& prepared = checked->prepared;
  if (!checked->crs.note.empty()) display.Note(checked->crs.note);
  AnnounceUpload(prepared, cl, display);
  auto r = (*client)->Plan(prepared.upload, checked->plan, Observe(display, interrupt));
  display.Done();
  if (!r.ok()) {
    // The server names a file's entry by its place ("fixed_stations[2]"); the user gets its line.
    const vc::Status named(r.status().code(), vc::client::NameListEntries(r.status().message(),
                                                                          vc::client::PlanFlagNamer(checked->lines)));
    return FailCall("plan", named, cl.conn.server);
  }
  NoteCache((*client)->last_upload(), &prepared.summary, display);
  const std::optional<vc::Crs>& crs = checked->crs.crs;
  return WritePlan(*r, cl.out_dir, cl.paper, &prepared.summary, FixedStationNames(cl.plan_files.fixed_stations),
                   crs ? &*crs : nullptr);
}

// evaluate --export-sets: the files, and a line saying what they hold.
int WriteSeenSets(const vc::EvaluateJobResult& result, const std::string& dir) {
  vc::Result<std::vector<std::string>> files = vc::client::WriteSeenSets(result, dir);
  if (!files.ok()) return Fail("cannot write the seen sets", files.status());
  uint64_t voxels = 0;
  for (const vc::VoxelSet& s : result.seen_sets) voxels += s.count();
  const std::string names =
      files->size() == 1 ? "station_1.xyz" : "station_1.xyz .. station_" + std::to_string(files->size()) + ".xyz";
  std::printf("wrote %s (%llu seen voxels, %s test, voxel centres in the input's frame) to %s\n", names.c_str(),
              static_cast<unsigned long long>(voxels),
              std::string(vc::SelectionTestName(result.selection_test)).c_str(), dir.c_str());
  return 0;
}

// evaluate's counterpart of CheckSubmit.
struct CheckedEvaluate {
  vc::EvaluateJobOptions eval;
  vc::client::CrsChoice crs;
  vc::client::PreparedUpload prepared;
};

// --plan's stations and CRS into `checked`, and its scanner and resolution for the flags not given
// (each given flag that differs from the plan is noted on stderr).
vc::Status TakePlan(const CommandLine& cl, const CLI::App& evaluate, CheckedEvaluate* checked, std::string* crs) {
  VC_ASSIGN_OR_RETURN(vc::client::PlanForEvaluation plan, vc::client::LoadPlanForEvaluation(cl.plan_json));
  checked->eval.viewpoints = std::move(plan.stations);
  for (const std::string& flag : vc::client::TakeScannerFromPlan(evaluate, plan.scanner, &checked->eval.scanner)) {
    std::cerr << "vc-client: " << flag << " overrides " << cl.plan_json << "\n";
  }
  for (const std::string& flag :
       vc::client::TakeResolutionFromPlan(evaluate, plan.resolution_m, &checked->eval.resolution_m)) {
    std::cerr << "vc-client: " << flag << " overrides " << cl.plan_json << "\n";
  }
  if (checked->eval.scanner.HasHorizontalFieldOfView()) {
    return vc::InvalidArgumentError(cl.plan_json + "'s scanner sees " + std::to_string(int(plan.scanner.hfov_deg)) +
                                    " deg around its heading, and evaluate takes no headings: add --hfov 360 to "
                                    "evaluate its stations all round");
  }
  if (crs->empty()) {
    *crs = plan.crs_definition;
  } else if (!plan.crs_definition.empty() && *crs != plan.crs_definition) {
    std::cerr << "vc-client: --crs " << *crs << " overrides " << cl.plan_json << "'s " << plan.crs_definition << "\n";
  }
  return vc::Status::Ok();
}

vc::Result<CheckedEvaluate> CheckEvaluate(const CommandLine& cl, const CLI::App& evaluate) {
  CheckedEvaluate checked{cl.eval, {}, {}};
  std::string crs = cl.crs;
  if (!cl.plan_json.empty()) {
    VC_RETURN_IF_ERROR(TakePlan(cl, evaluate, &checked, &crs));
  } else if (cl.viewpoints_csv.empty()) {
    return vc::InvalidArgumentError("evaluate needs the stations: --viewpoints stations.csv or --plan plan.json");
  } else {
    VC_ASSIGN_OR_RETURN(checked.eval.viewpoints, vc::client::LoadViewpoints(cl.viewpoints_csv));
  }
  vc::Result<SceneFile> file = ReadSceneBytes(cl);  // its error comes after the flags'
  VC_ASSIGN_OR_RETURN(checked.crs, vc::client::CheckCrsFlag(crs, cl.units, file.ok() ? file->format : std::nullopt));
  VC_RETURN_IF_ERROR(checked.eval.Validate(vc::client::EvaluateFlagNamer()));
  if (evaluate.get_option("--test")->count() > 0 && cl.export_dir.empty()) {
    return vc::InvalidArgumentError("--test names the selection test of --export-sets' files; add --export-sets DIR");
  }
  checked.eval.export_sets = !cl.export_dir.empty();
  if (checked.eval.export_sets) VC_RETURN_IF_ERROR(vc::client::PrepareExportDir(cl.export_dir, cl.force));
  if (!file.ok()) return file.status();
  VC_ASSIGN_OR_RETURN(checked.prepared, PrepareScene(cl, std::move(file).value(), checked.crs.units,
                                                     checked.eval.resolution_m, checked.eval.test));
  return checked;
}

int RunEvaluate(const CommandLine& cl, const CLI::App& evaluate, InterruptCancelsTheJob* interrupt) {
  vc::Result<CheckedEvaluate> checked = CheckEvaluate(cl, evaluate);
  if (!checked.ok()) return Fail(checked.status());
  auto client = vc::client::Client::Create(cl.conn);
  if (!client.ok()) return Fail("cannot set up the connection", client.status());
  vc::client::ProgressDisplay display(stderr, isatty(fileno(stderr)) != 0);
  vc::client::PreparedUpload& prepared = checked->prepared;
  if (!checked->crs.note.empty()) display.Note(checked->crs.note);
  AnnounceUpload(prepared, cl, display);
  auto r = (*client)->Evaluate(prepared.upload, checked->eval, Observe(display, interrupt));
  display.Done();
  if (!r.ok()) return FailCall("evaluate", r.status(), cl.conn.server);
  NoteCache((*client)->last_upload(), &prepared.summary, display);
  for (const std::string& w : r->warnings) std::cerr << "vc-client: warning: " << w << "\n";
  const std::optional<vc::Crs>& crs = checked->crs.crs;
  const int written = WriteEvaluation(*r, cl.out_dir, cl.paper, crs ? &*crs : nullptr, checked->eval.scanner);
  if (written != 0 || !checked->eval.export_sets) return written;
  return WriteSeenSets(*r, cl.export_dir);
}

// Parses the command line; on a mistake prints CLI11's message and, for a misspelt flag or
// subcommand, the nearest known one. The exit status when the parse failed (or --help).
std::optional<int> Parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    if (code != 0) {
      const std::string hint = vc::client::CommandLineHint(app, std::vector<std::string>(argv + 1, argv + argc));
      if (!hint.empty()) std::cerr << "vc-client: " << hint << "\n";
    }
    return code;
  }
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vc-client: plan laser-scanner stations with vc-server, or inspect a scene locally"};
  app.require_subcommand(1);
  app.fallthrough();
  CommandLine cl;
  const Subcommands sub = AddCommands(app, &cl);
  vc::client::ValidateCommand validate;
  const CLI::App* validate_command = vc::client::AddValidateCommand(app, &validate);
  if (const std::optional<int> refused = Parse(app, argc, argv)) return *refused;
  cl.conn.timeout = std::chrono::milliseconds(int64_t(cl.timeout_s * 1000));

  if (*sub.scanners) return RunScanners();
  if (*sub.inspect) return RunInspect(cl);
  if (*validate_command) return vc::client::RunValidate(validate);

  // Before any gRPC thread exists, so that every thread inherits the blocked signals.
  InterruptCancelsTheJob* interrupt = nullptr;  // never freed: its watcher thread lives as long as the process
  // (attach leaves SIGINT as it is: interrupting it stops following, and the job runs on.)
  if (*sub.submit || *sub.evaluate) interrupt = new InterruptCancelsTheJob(cl.conn);
  if (*sub.submit) return RunSubmit(cl, interrupt);
  if (*sub.evaluate) return RunEvaluate(cl, *sub.evaluate, interrupt);
  auto client = vc::client::Client::Create(cl.conn);
  if (!client.ok()) return Fail("cannot set up the connection", client.status());
  if (*sub.health) return RunHealth(**client, cl);
  if (*sub.cancel) return RunCancel(**client, cl);
  return RunAttach(**client, cl);
}
