#include "vc/client/client.h"

#include <grpcpp/grpcpp.h>

#include <fstream>
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

Result<Upload> ReadUpload(const std::string& path) {
  VC_ASSIGN_OR_RETURN(std::string bytes, ReadFile(path, "the scene file"));
  const auto slash = path.find_last_of('/');
  return Upload{std::move(bytes), slash == std::string::npos ? path : path.substr(slash + 1)};
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
    if (s.code() != StatusCode::kUnavailable || accepted || i >= options_.max_attempts) return s;
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
    if (s.code() != StatusCode::kNotFound) {
      last_upload_.from_cache = s.ok();
      return s;
    }
    spec->set_from_cache(false);
  }
  last_upload_.bytes_sent = upload.bytes.size();
  return call(false);
}

Result<PlanResult> Client::Plan(const Upload& upload, const PlanOptions& options, const JobObserver& observer) {
  auto stub = v1::StationPlanner::NewStub(channel_);
  v1::PlanRequest spec;
  *spec.mutable_spec()->mutable_upload() = MakeUploadSpec(upload);
  *spec.mutable_spec()->mutable_parameters() = wire::ToProto(options);
  PlanResult out;
  const Status status = WithSceneCache(upload, spec.mutable_spec()->mutable_upload(), [&](bool from_cache) {
    return WithRetries(observer, [&](bool* accepted) -> Status {
      grpc::ClientContext ctx;
      Prepare(&ctx);
      auto stream = stub->Plan(&ctx);
      SendUpload(*stream, spec, from_cache ? kNoData : upload, options_.chunk_bytes);
      wire::PlanResultAssembler assembler;
      std::optional<v1::PlanResult> summary;
      Status broken;
      v1::PlanResponse r;
      while (stream->Read(&r)) {
        switch (r.event_case()) {
          case v1::PlanResponse::kAccepted:
            *accepted = true;
            if (observer.on_accepted) observer.on_accepted(r.accepted().job_id(), r.accepted().queue_position());
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
      VC_RETURN_IF_ERROR(wire::FromGrpcStatus(stream->Finish()));
      if (!broken.ok()) return Local(broken);
      if (!summary) return InternalError("the server ended the plan without a result");
      auto result = std::move(assembler).Finish(*summary);
      if (!result.ok()) return Local(result.status());
      out = std::move(result).value();
      return Status::Ok();
    });
  });
  if (!status.ok()) return status;
  return out;
}

Result<Evaluation> Client::Evaluate(const Upload& upload, const EvaluateJobOptions& options,
                                    const JobObserver& observer) {
  auto stub = v1::StationPlanner::NewStub(channel_);
  v1::EvaluateRequest spec;
  *spec.mutable_spec()->mutable_upload() = MakeUploadSpec(upload);
  *spec.mutable_spec()->mutable_parameters() = wire::ToProto(options);
  Evaluation out;
  const Status status = WithSceneCache(upload, spec.mutable_spec()->mutable_upload(), [&](bool from_cache) {
    return WithRetries(observer, [&](bool* accepted) -> Status {
      grpc::ClientContext ctx;
      Prepare(&ctx);
      auto stream = stub->Evaluate(&ctx);
      SendUpload(*stream, spec, from_cache ? kNoData : upload, options_.chunk_bytes);
      std::optional<v1::EvaluateResult> result;
      v1::EvaluateResponse r;
      while (stream->Read(&r)) {
        switch (r.event_case()) {
          case v1::EvaluateResponse::kAccepted:
            *accepted = true;
            if (observer.on_accepted) observer.on_accepted(r.accepted().job_id(), r.accepted().queue_position());
            break;
          case v1::EvaluateResponse::kProgress:
            if (observer.on_progress) observer.on_progress(wire::FromProto(r.progress()));
            break;
          case v1::EvaluateResponse::kResult:
            result = r.result();
            break;
          default:
            break;
        }
      }
      VC_RETURN_IF_ERROR(wire::FromGrpcStatus(stream->Finish()));
      if (!result) return InternalError("the server ended the evaluation without a result");
      out = wire::FromProto(result->evaluation());
      return Status::Ok();
    });
  });
  if (!status.ok()) return status;
  return out;
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
