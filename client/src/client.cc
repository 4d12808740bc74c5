#include "vc/client/client.h"

#include <grpcpp/grpcpp.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include "grpc/health/v1/health.grpc.pb.h"
#include "vc/base/crc32c.h"
#include "vc/v1/planner.grpc.pb.h"
#include "vc/wire/sha256.h"
#include "vc/wire/status_mapping.h"

namespace vc::client {
namespace {

Result<std::string> ReadFile(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError("cannot read " + what + " '" + path + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return NotFoundError("error while reading " + what + " '" + path + "'");
  return ss.str();
}

v1::UploadSpec MakeUploadSpec(const Upload& upload) {
  v1::UploadSpec spec;
  spec.set_format(v1::INPUT_FORMAT_UNSPECIFIED);  // the server detects it from the content
  spec.set_total_size_bytes(upload.bytes.size());
  spec.set_crc32c(ComputeCrc32c(upload.bytes));
  spec.set_source_name(upload.source_name);
  spec.set_units(upload.units);
  return spec;
}

const Upload kNoData;

// Streams the spec and the chunks, half-closes. Stops early when the server has ended the call
// (a write fails); the status then comes from Finish.
template <typename Request, typename Stream>
void SendUpload(Stream& stream, Request spec_request, const Upload& upload, size_t chunk_bytes) {
  if (!stream.Write(spec_request)) return;
  const std::string_view bytes(upload.bytes);
  for (size_t off = 0; off < bytes.size(); off += chunk_bytes) {
    Request r;
    r.mutable_chunk()->set_data(std::string(bytes.substr(off, chunk_bytes)));
    if (!stream.Write(r)) return;
  }
  stream.WritesDone();
}

// A stream that does not add up: DATA_LOSS stays, anything else is INTERNAL.
Status Local(const Status& s) {
  return Status(s.code() == StatusCode::kDataLoss ? StatusCode::kDataLoss : StatusCode::kInternal, s.message());
}

}  // namespace

namespace {

bool Contains(const std::string& text, std::string_view part) { return text.find(part) != std::string::npos; }

// The host of "host:port", "[v6]:port" or "dns:///host:port".
std::string HostOf(std::string server) {
  if (const size_t scheme = server.find(":///"); scheme != std::string::npos) server.erase(0, scheme + 4);
  if (server.starts_with("[")) return server.substr(1, server.find(']') - 1);
  const size_t colon = server.rfind(':');
  return colon == std::string::npos ? server : server.substr(0, colon);
}

bool UsesTls(const ConnectionOptions& o) { return o.tls || !o.tls_ca_file.empty() || !o.tls_cert_file.empty(); }

}  // namespace

std::optional<Status> PermanentConnectionError(const Status& s, const ConnectionOptions& options) {
  if (s.code() != StatusCode::kUnavailable) return std::nullopt;
  const std::string& m = s.message();
  if (Contains(m, "DNS resolution failed")) {
    return UnavailableError("cannot resolve host " + HostOf(options.server) +
                            ": check the name in --server (or VC_SERVER) [" + m + "]");
  }
  if (!UsesTls(options)) return std::nullopt;
  if (Contains(m, "WRONG_VERSION_NUMBER") || Contains(m, "wrong version number")) {
    return UnavailableError("the server does not speak TLS: drop --tls (and --tls-ca, --tls-cert) [" + m + "]");
  }
  if (Contains(m, "CERTIFICATE_VERIFY_FAILED") || Contains(m, "certificate verify failed")) {
    return UnavailableError(
        "the server's TLS certificate is not trusted: give its CA with --tls-ca, or the name in it with "
        "--tls-server-name [" +
        m + "]");
  }
  return std::nullopt;
}

Result<Upload> ReadUpload(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return InvalidArgumentError("the scene file " + path + " is a directory; give the file in it");
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const std::string why = errno != 0 ? std::strerror(errno) : "cannot open it";
    return NotFoundError("cannot read the scene file " + path + ": " + why);
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return NotFoundError("cannot read the scene file " + path + ": read error");
  std::string bytes = std::move(ss).str();
  if (bytes.empty()) {
    return InvalidArgumentError("the scene file " + path +
                                " is empty (0 bytes): nothing to upload; export the scene again");
  }
  const auto slash = path.find_last_of('/');
  return Upload{std::move(bytes), slash == std::string::npos ? path : path.substr(slash + 1), ""};
}

Result<std::unique_ptr<Client>> Client::Create(const ConnectionOptions& options) {
  std::unique_ptr<Client> c(new Client());
  c->options_ = options;
  std::shared_ptr<grpc::ChannelCredentials> creds;
  const bool tls = options.tls || !options.tls_ca_file.empty() || !options.tls_cert_file.empty();
  if (tls) {
    grpc::SslCredentialsOptions ssl;
    if (!options.tls_ca_file.empty()) {
      VC_ASSIGN_OR_RETURN(ssl.pem_root_certs, ReadFile(options.tls_ca_file, "the CA file (--tls-ca)"));
    }
    if (options.tls_cert_file.empty() != options.tls_key_file.empty()) {
      return InvalidArgumentError("--tls-cert and --tls-key must be given together");
    }
    if (!options.tls_cert_file.empty()) {
      VC_ASSIGN_OR_RETURN(ssl.pem_cert_chain, ReadFile(options.tls_cert_file, "the client certificate (--tls-cert)"));
      VC_ASSIGN_OR_RETURN(ssl.pem_private_key, ReadFile(options.tls_key_file, "the client key (--tls-key)"));
    }
    creds = grpc::SslCredentials(ssl);
  } else {
    creds = grpc::InsecureChannelCredentials();
  }
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(16 << 20);
  if (!options.tls_server_name.empty()) args.SetSslTargetNameOverride(options.tls_server_name);
  c->credentials_ = creds;
  c->channel_ = grpc::CreateCustomChannel(options.server, creds, args);
  return c;
}

void Client::Prepare(grpc::ClientContext* ctx) const {
  if (!options_.token.empty()) ctx->AddMetadata("authorization", "Bearer " + options_.token);
  if (options_.gzip) ctx->set_compression_algorithm(GRPC_COMPRESS_GZIP);
  if (options_.timeout.count() > 0) ctx->set_deadline(std::chrono::system_clock::now() + options_.timeout);
}

template <typename Fn>
Status Client::WithRetries(const JobObserver& observer, Fn&& attempt) {
  auto backoff = options_.initial_backoff;
  for (int i = 1;; ++i) {
    bool accepted = false;
    Status s = attempt(&accepted);
    if (s.code() != StatusCode::kUnavailable || accepted) return s;
    if (std::optional<Status> permanent = PermanentConnectionError(s, options_)) return *permanent;
    if (i >= options_.max_attempts) return s;
    if (observer.on_retry) observer.on_retry(s, backoff);
    std::this_thread::sleep_for(backoff);
    backoff *= 2;
  }
}

Status Client::WithSceneCache(const Upload& upload, v1::UploadSpec* spec, const std::function<Status(bool)>& call) {
  last_upload_ = {};
  if (options_.scene_cache) {
    spec->set_scene_sha256(wire::Sha256Hex(upload.bytes));
    last_upload_.scene_sha256 = spec->scene_sha256();
    spec->set_from_cache(true);
    const Status s = call(true);
    // NOT_FOUND means a cache miss only before a job was accepted (after, it is a lost job).
    if (s.code() != StatusCode::kNotFound || !last_job_.job_id.empty()) {
      last_upload_.from_cache = s.ok();
      return s;
    }
    spec->set_from_cache(false);
  }
  last_upload_.bytes_sent = upload.bytes.size();
  return call(false);
}

namespace {

void NoteAccepted(const v1::Accepted& a, const JobObserver& observer, JobTicket* ticket) {
  ticket->job_id = a.job_id();
  ticket->attach_address = a.attach_address();
  ticket->detach_grace_s = a.detach_grace_s();
  if (observer.on_accepted) observer.on_accepted(a.job_id(), a.queue_position());
  if (observer.on_job) observer.on_job(*ticket);
}

// Reads a Plan event stream (Plan's or AttachPlan's) to its end and its status.
template <typename Stream>
Status FollowPlan(Stream& stream, const JobObserver& observer, JobTicket* ticket, bool* accepted, PlanResult* out) {
  wire::PlanResultAssembler assembler;
  std::optional<v1::PlanResult> summary;
  Status broken;
  v1::PlanResponse r;
  while (stream.Read(&r)) {
    switch (r.event_case()) {
      case v1::PlanResponse::kAccepted:
        *accepted = true;
        NoteAccepted(r.accepted(), observer, ticket);
        break;
      case v1::PlanResponse::kProgress:
        if (observer.on_progress) observer.on_progress(wire::FromProto(r.progress()));
        break;
      case v1::PlanResponse::kStation:
        if (observer.on_station) observer.on_station(wire::FromProto(r.station().station()), r.station().index());
        break;
      case v1::PlanResponse::kFinalStations:
        if (observer.on_final_stations) {
          std::vector<PlannedStation> stations;
          for (const auto& s : r.final_stations().stations()) stations.push_back(wire::FromProto(s));
          observer.on_final_stations(stations);
        }
        break;
      case v1::PlanResponse::kHeatMap:
        if (broken.ok()) broken = assembler.AddHeatMap(r.heat_map());
        if (broken.ok() && observer.on_heat_map &&
            assembler.heat_map().positions.size() == r.heat_map().total_candidates()) {
          observer.on_heat_map(assembler.heat_map());
        }
        break;
      case v1::PlanResponse::kVoxels:
        if (broken.ok()) broken = assembler.AddVoxels(r.voxels());
        break;
      case v1::PlanResponse::kResult:
        summary = r.result();
        break;
      default:
        break;
    }
  }
  VC_RETURN_IF_ERROR(wire::FromGrpcStatus(stream.Finish()));
  if (!broken.ok()) return Local(broken);
  if (!summary) return InternalError("the server ended the plan without a result");
  auto result = std::move(assembler).Finish(*summary);
  if (!result.ok()) return Local(result.status());
  *out = std::move(result).value();
  return Status::Ok();
}

// Reads an Evaluate event stream (Evaluate's or AttachEvaluate's) to its end and its status.
template <typename Stream>
Status FollowEvaluate(Stream& stream, const JobObserver& observer, JobTicket* ticket, bool* accepted,
                      EvaluateJobResult* out) {
  wire::EvaluateResultAssembler assembler;
  std::optional<v1::EvaluateResult> summary;
  Status broken;
  v1::EvaluateResponse r;
  while (stream.Read(&r)) {
    switch (r.event_case()) {
      case v1::EvaluateResponse::kAccepted:
        *accepted = true;
        NoteAccepted(r.accepted(), observer, ticket);
        break;
      case v1::EvaluateResponse::kProgress:
        if (observer.on_progress) observer.on_progress(wire::FromProto(r.progress()));
        break;
      case v1::EvaluateResponse::kVoxels:
        if (broken.ok()) broken = assembler.AddVoxels(r.voxels());
        break;
      case v1::EvaluateResponse::kSeenSet:
        if (broken.ok()) broken = assembler.AddSeenSet(r.seen_set());
        break;
      case v1::EvaluateResponse::kResult:
        summary = r.result();
        break;
      default:
        break;
    }
  }
  VC_RETURN_IF_ERROR(wire::FromGrpcStatus(stream.Finish()));
  if (!broken.ok()) return Local(broken);
  if (!summary) return InternalError("the server ended the evaluation without a result");
  auto result = std::move(assembler).Finish(*summary);
  if (!result.ok()) return Local(result.status());
  *out = std::move(result).value();
  return Status::Ok();
}

}  // namespace

std::shared_ptr<grpc::Channel> Client::AttachChannel(const JobTicket& ticket) {
  if (ticket.attach_address.empty() || ticket.attach_address == options_.server) return channel_;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(16 << 20);
  if (!options_.tls_server_name.empty()) args.SetSslTargetNameOverride(options_.tls_server_name);
  return grpc::CreateCustomChannel(ticket.attach_address, credentials_, args);
}

template <typename Fn>
Status Client::Reattach(const Status& broken, const JobObserver& observer, Fn&& attach) {
  if (broken.code() != StatusCode::kUnavailable || last_job_.job_id.empty() || last_job_.detach_grace_s == 0) {
    return broken;
  }
  // Keep trying while the job may still be alive: within its grace of the moment the stream was
  // last alive (the server grants a fresh grace at every break), from 1 s up to 30 s apart.
  using Clock = std::chrono::steady_clock;
  const auto grace = std::chrono::seconds(last_job_.detach_grace_s);
  auto give_up = Clock::now() + grace;
  auto backoff = std::max(options_.initial_backoff, std::chrono::milliseconds(0));
  Status s = broken;
  while (s.code() == StatusCode::kUnavailable && Clock::now() + backoff < give_up) {
    if (observer.on_reattach) observer.on_reattach(last_job_, s, backoff);
    std::this_thread::sleep_for(backoff);
    backoff = std::min(std::max(backoff * 2, std::chrono::milliseconds(1000)), std::chrono::milliseconds(30000));
    bool followed = false;
    s = attach(&followed);
    if (followed) {  // it was attached again, then broke again: a new grace, a fresh backoff
      give_up = Clock::now() + grace;
      backoff = std::max(options_.initial_backoff, std::chrono::milliseconds(0));
    }
  }
  return s;
}

Result<PlanResult> Client::Plan(const Upload& upload, const PlanOptions& options, const JobObserver& observer) {
  auto stub = v1::StationPlanner::NewStub(channel_);
  v1::PlanRequest spec;
  *spec.mutable_spec()->mutable_upload() = MakeUploadSpec(upload);
  *spec.mutable_spec()->mutable_parameters() = wire::ToProto(options);
  spec.mutable_spec()->mutable_control()->set_detach_grace_s(options_.detach_grace_s);
  last_job_ = {};
  PlanResult out;
  const Status status = WithSceneCache(upload, spec.mutable_spec()->mutable_upload(), [&](bool from_cache) {
    return WithRetries(observer, [&](bool* accepted) -> Status {
      grpc::ClientContext ctx;
      Prepare(&ctx);
      auto stream = stub->Plan(&ctx);
      SendUpload(*stream, spec, from_cache ? kNoData : upload, options_.chunk_bytes);
      const Status s = FollowPlan(*stream, observer, &last_job_, accepted, &out);
      return Reattach(s, observer, [&](bool* followed) { return AttachPlanOnce(observer, &out, followed); });
    });
  });
  if (!status.ok()) return status;
  return out;
}

Result<EvaluateJobResult> Client::Evaluate(const Upload& upload, const EvaluateJobOptions& options,
                                           const JobObserver& observer) {
  auto stub = v1::StationPlanner::NewStub(channel_);
  v1::EvaluateRequest spec;
  *spec.mutable_spec()->mutable_upload() = MakeUploadSpec(upload);
  *spec.mutable_spec()->mutable_parameters() = wire::ToProto(options);
  spec.mutable_spec()->mutable_control()->set_detach_grace_s(options_.detach_grace_s);
  last_job_ = {};
  EvaluateJobResult out;
  const Status status = WithSceneCache(upload, spec.mutable_spec()->mutable_upload(), [&](bool from_cache) {
    return WithRetries(observer, [&](bool* accepted) -> Status {
      grpc::ClientContext ctx;
      Prepare(&ctx);
      auto stream = stub->Evaluate(&ctx);
      SendUpload(*stream, spec, from_cache ? kNoData : upload, options_.chunk_bytes);
      const Status s = FollowEvaluate(*stream, observer, &last_job_, accepted, &out);
      return Reattach(s, observer, [&](bool* followed) { return AttachEvaluateOnce(observer, &out, followed); });
    });
  });
  if (!status.ok()) return status;
  return out;
}

Status Client::AttachPlanOnce(const JobObserver& observer, PlanResult* out, bool* followed) {
  auto stub = v1::StationPlanner::NewStub(AttachChannel(last_job_));
  grpc::ClientContext ctx;
  Prepare(&ctx);
  v1::AttachRequest request;
  request.set_job_id(last_job_.job_id);
  auto stream = stub->AttachPlan(&ctx, request);
  return FollowPlan(*stream, observer, &last_job_, followed, out);
}

Status Client::AttachEvaluateOnce(const JobObserver& observer, EvaluateJobResult* out, bool* followed) {
  auto stub = v1::StationPlanner::NewStub(AttachChannel(last_job_));
  grpc::ClientContext ctx;
  Prepare(&ctx);
  v1::AttachRequest request;
  request.set_job_id(last_job_.job_id);
  auto stream = stub->AttachEvaluate(&ctx, request);
  return FollowEvaluate(*stream, observer, &last_job_, followed, out);
}

Status Client::FollowPlanJob(const std::string& job_id, const JobObserver& observer, PlanResult* out, bool* accepted) {
  last_job_ = {job_id, "", 0};
  const auto once = [&](bool* followed) {
    const Status s = AttachPlanOnce(observer, out, followed);
    *accepted = *accepted || *followed;
    return s;
  };
  return Reattach(WithRetries(observer, once), observer, once);
}

Result<PlanResult> Client::AttachPlan(const std::string& job_id, const JobObserver& observer) {
  PlanResult out;
  bool accepted = false;
  const Status s = FollowPlanJob(job_id, observer, &out, &accepted);
  if (!s.ok()) return s;
  return out;
}

Result<EvaluateJobResult> Client::AttachEvaluate(const std::string& job_id, const JobObserver& observer) {
  last_job_ = {job_id, "", 0};
  EvaluateJobResult out;
  const auto once = [&](bool* followed) { return AttachEvaluateOnce(observer, &out, followed); };
  const Status s = Reattach(WithRetries(observer, once), observer, once);
  if (!s.ok()) return s;
  return out;
}

Result<AttachedJob> Client::Attach(const std::string& job_id, const JobObserver& observer) {
  AttachedJob job;
  bool is_plan = false;  // AttachPlan replayed the job's Accepted event: the job is a plan
  const Status plan = FollowPlanJob(job_id, observer, &job.plan, &is_plan);
  if (plan.ok()) return job;
  if (is_plan || plan.code() != StatusCode::kFailedPrecondition) return plan;
  VC_ASSIGN_OR_RETURN(job.evaluation, AttachEvaluate(job_id, observer));
  job.kind = AttachedJob::Kind::kEvaluation;
  return job;
}

Result<std::string> CancelDetachedJob(ConnectionOptions options, const JobTicket& ticket) {
  options.max_attempts = 1;
  options.timeout = std::chrono::seconds(3);
  if (!ticket.attach_address.empty()) options.server = ticket.attach_address;
  VC_ASSIGN_OR_RETURN(std::unique_ptr<Client> client, Client::Create(options));
  return client->CancelJob(ticket.job_id);
}

Result<std::string> Client::CancelJob(const std::string& job_id) {
  auto stub = v1::StationPlanner::NewStub(channel_);
  std::string outcome;
  const Status status = WithRetries({}, [&](bool*) -> Status {
    grpc::ClientContext ctx;
    Prepare(&ctx);
    v1::CancelJobRequest request;
    request.set_job_id(job_id);
    v1::CancelJobResponse response;
    VC_RETURN_IF_ERROR(wire::FromGrpcStatus(stub->CancelJob(&ctx, request, &response)));
    outcome = response.outcome();
    return Status::Ok();
  });
  if (!status.ok()) return status;
  return outcome;
}

Result<std::string> Client::Health(const std::string& service) {
  auto stub = grpc::health::v1::Health::NewStub(channel_);
  grpc::health::v1::HealthCheckRequest req;
  req.set_service(service);
  std::string out;
  const Status status = WithRetries({}, [&](bool*) -> Status {
    grpc::ClientContext ctx;
    if (!options_.token.empty()) ctx.AddMetadata("authorization", "Bearer " + options_.token);
    ctx.set_deadline(std::chrono::system_clock::now() +
                     (options_.timeout.count() > 0 ? options_.timeout : std::chrono::milliseconds(5000)));
    grpc::health::v1::HealthCheckResponse resp;
    VC_RETURN_IF_ERROR(wire::FromGrpcStatus(stub->Check(&ctx, req, &resp)));
    out = grpc::health::v1::HealthCheckResponse::ServingStatus_Name(resp.status());
    if (resp.status() != grpc::health::v1::HealthCheckResponse::SERVING) {
      return UnavailableError("the server is " + out);
    }
    return Status::Ok();
  });
  if (!status.ok()) return status;
  return out;
}

}  // namespace vc::client
