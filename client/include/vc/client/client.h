// vc::client::Client: the typed client of vc.v1.StationPlanner and of the gRPC health service.
//
// Uploads a scene in chunks (with its CRC32C), follows the event stream, and returns the core
// types (vc::PlanResult, vc::EvaluateJobResult) rebuilt by vc::wire, ready for vc::WritePlanOutputs.
// Failures are vc::Status values: the call's gRPC status mapped by vc::wire::FromGrpcStatus (same
// google.rpc.Code, same message), or DATA_LOSS / INTERNAL for a stream that does not add up.
// Transient UNAVAILABLE failures before the server accepted the job are retried with exponential
// backoff; permanent ones (PermanentConnectionError: an unknown host, TLS against a server that
// does not speak it) are returned at once, explained; every other status is returned as it came. Not thread-safe; use
// one per thread.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/planner.h"
#include "vc/visibility/visibility.h"
#include "vc/wire/convert.h"

namespace grpc {
class Channel;
class ChannelCredentials;
class ClientContext;
}  // namespace grpc

namespace vc::client {

struct ConnectionOptions {
  // host:port of vc-server.
  std::string server = "localhost:50051";
  // TLS: on when `tls` or any file below is set. CA file (PEM) verifying the server; empty = the
  // system roots. Client certificate and key (PEM) for mutual TLS.
  bool tls = false;
  std::string tls_ca_file;
  std::string tls_cert_file;
  std::string tls_key_file;
  // Name to verify the server certificate against, when it differs from the host in `server`.
  std::string tls_server_name;
  // Sent as "authorization: Bearer <token>" when non-empty.
  std::string token;
  // gzip-compress requests.
  bool gzip = true;
  // Attempts for transient UNAVAILABLE (connection refused, server restarting); 1 = no retry.
  int max_attempts = 5;
  std::chrono::milliseconds initial_backoff{200};
  // Per-call deadline; 0 = none.
  std::chrono::milliseconds timeout{0};
  // Bytes per upload chunk (well under the 4 MiB message limit).
  size_t chunk_bytes = size_t{256} << 10;
  // Name the scene by its SHA-256 first and upload it only when the server does not hold it
  // (docs/PROTOCOL.md, "The scene cache").
  bool scene_cache = true;
  // Detachable jobs (docs/PROTOCOL.md, "Detachable jobs"): seconds the job may run on without this
  // client (0 = it ends with the stream). With a grace, a stream that breaks after the job was
  // accepted is re-attached (AttachPlan / AttachEvaluate) up to `max_attempts` times with backoff.
  uint32_t detach_grace_s = 0;
};

// Where a job runs, once accepted: what a client needs to re-attach to it.
struct JobTicket {
  std::string job_id;
  std::string attach_address;  // empty = the server the job was submitted to
  uint32_t detach_grace_s = 0;
};

// A re-attached job's outcome: a plan or an evaluation, whichever kind the job is.
struct AttachedJob {
  enum class Kind { kPlan, kEvaluation };
  Kind kind = Kind::kPlan;
  PlanResult plan;               // when kind is kPlan
  EvaluateJobResult evaluation;  // when kind is kEvaluation
};

// How the last Plan or Evaluate call got its scene to the server.
struct UploadOutcome {
  std::string scene_sha256;  // empty without the scene cache
  bool from_cache = false;   // the server had it: no byte was sent
  uint64_t bytes_sent = 0;
};

// What the caller sees while a job runs; every member optional. Called on the calling thread.
struct JobObserver {
  std::function<void(const std::string& job_id, uint32_t queue_position)> on_accepted;
  std::function<void(const ProgressEvent&)> on_progress;
  // The heat map, once, when the candidates' visibility is known.
  std::function<void(const HeatMap&)> on_heat_map;
  // Provisional: a station as the greedy selection picks it (refinement and reduction may still
  // move or drop it); `index` in greedy order.
  std::function<void(const PlannedStation&, int index)> on_station;
  // Final: the stations that stand, once, after refinement and reduction (as in the PlanResult).
  std::function<void(const std::vector<PlannedStation>&)> on_final_stations;
  // Called before each retry, with the failed attempt's status (UNAVAILABLE) and the wait.
  std::function<void(const Status&, std::chrono::milliseconds)> on_retry;
  // Called when a job is accepted (after on_accepted, and again on each re-attach's replay) with
  // what it takes to re-attach: the id, the replica's address, the grace the server granted.
  std::function<void(const JobTicket&)> on_job;
  // Called before each re-attach to a detached job, with the status that broke the stream.
  std::function<void(const JobTicket&, const Status&, std::chrono::milliseconds)> on_reattach;
};

// A scene to upload: its bytes, a label for error messages (the file name), and the unit of its
// coordinates (--units: "m", "cm", "mm", "ft", "us-ft"; empty = metres), sent as UploadSpec.units.
struct Upload {
  std::string bytes;
  std::string source_name;
  std::string units;
};

// A connection failure that retrying cannot mend, explained, still UNAVAILABLE: a host name that
// does not resolve ("cannot resolve host nosuch.example: check the name in --server ..."), and,
// with TLS on, a server that does not speak TLS ("the server does not speak TLS: drop --tls ...")
// or a certificate the client does not trust; gRPC's own words follow in [...]. nullopt for any
// other status (connection refused, a server restarting: transient, retried).
[[nodiscard]] std::optional<Status> PermanentConnectionError(const Status& s, const ConnectionOptions& options);

// Reads a scene file into an Upload, before any connection. NOT_FOUND when it cannot be read
// ("cannot read the scene file x.ply: Permission denied"); INVALID_ARGUMENT when it is empty or a
// directory.
Result<Upload> ReadUpload(const std::string& path);

// Cancels `ticket`'s job the way a client about to exit does: on the replica running it (its
// attach_address, else options.server), in one attempt with a 3 s deadline. "cancelled" or
// "discarded"; the call's failure otherwise (the job may then run on for its grace).
Result<std::string> CancelDetachedJob(ConnectionOptions options, const JobTicket& ticket);

class Client {
 public:
  // Reads the TLS files and makes the channel (connecting lazily). NOT_FOUND for a missing file.
  static Result<std::unique_ptr<Client>> Create(const ConnectionOptions& options);

  Result<PlanResult> Plan(const Upload& upload, const PlanOptions& options, const JobObserver& observer = {});
  // The evaluation with its voxels (vc::EvaluateJobResult, rebuilt from the stream's chunks).
  Result<EvaluateJobResult> Evaluate(const Upload& upload, const EvaluateJobOptions& options,
                                     const JobObserver& observer = {});
  // Re-attaches to a detachable job by id (docs/PROTOCOL.md, "Detachable jobs"): the events so far
  // are replayed, then the job is followed to its end. FAILED_PRECONDITION when the job is of the
  // other kind; NOT_FOUND when the server does not hold it (any more).
  Result<PlanResult> AttachPlan(const std::string& job_id, const JobObserver& observer = {});
  Result<EvaluateJobResult> AttachEvaluate(const std::string& job_id, const JobObserver& observer = {});
  // Re-attaches to a job of either kind: AttachPlan, then AttachEvaluate when the server refuses it
  // with FAILED_PRECONDITION before any event (the job is an Evaluate job); a plan job's own
  // failure is returned as it is. NOT_FOUND when the server does not hold the job.
  Result<AttachedJob> Attach(const std::string& job_id, const JobObserver& observer = {});
  // Cancels a detachable job, or discards its kept result: "cancelled" or "discarded".
  Result<std::string> CancelJob(const std::string& job_id);
  // grpc.health.v1.Health/Check of `service` ("" = the whole server). The value is the serving
  // status name ("SERVING"); a server that is not serving gives UNAVAILABLE.
  Result<std::string> Health(const std::string& service = "");
  const UploadOutcome& last_upload() const { return last_upload_; }
  // The last Plan or Evaluate job accepted (job_id empty when none was).
  const JobTicket& last_job() const { return last_job_; }

 private:
  Client() = default;
  // Runs `call(from_cache)`: first naming the scene by its hash only (when the scene cache is on),
  // then, when the server does not hold it (NOT_FOUND), uploading it; notes the outcome.
  Status WithSceneCache(const Upload& upload, v1::UploadSpec* spec, const std::function<Status(bool)>& call);
  UploadOutcome last_upload_;
  JobTicket last_job_;
  void Prepare(grpc::ClientContext* ctx) const;
  // The channel to re-attach through: this client's, or one to the ticket's attach_address.
  std::shared_ptr<grpc::Channel> AttachChannel(const JobTicket& ticket);
  // One AttachPlan / AttachEvaluate call to last_job_, followed to its end; `followed` says
  // whether the job's events came (the stream was alive) before it ended.
  Status AttachPlanOnce(const JobObserver& observer, PlanResult* out, bool* followed);
  Status AttachEvaluateOnce(const JobObserver& observer, EvaluateJobResult* out, bool* followed);
  // AttachPlan's calls to `job_id`, retried and re-attached, into `out`; `accepted` says whether
  // the job's Accepted event came (the server holds it as a plan job).
  Status FollowPlanJob(const std::string& job_id, const JobObserver& observer, PlanResult* out, bool* accepted);
  // After a broken stream: re-attaches with `attach(bool* followed)` while the failure is
  // UNAVAILABLE and the job may still be alive (its grace since the stream was last alive), with
  // backoff; the original status when the job is not detachable.
  template <typename Fn>
  Status Reattach(const Status& broken, const JobObserver& observer, Fn&& attach);
  template <typename Fn>
  Status WithRetries(const JobObserver& observer, Fn&& attempt);

  ConnectionOptions options_;
  std::shared_ptr<grpc::ChannelCredentials> credentials_;
  std::shared_ptr<grpc::Channel> channel_;
};

}  // namespace vc::client
