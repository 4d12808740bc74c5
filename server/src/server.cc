#include "vc/server/server.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "vc/server/service.h"

namespace vc::server {

Result<std::string> ReadTextFile(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError("cannot read the " + what + " file '" + path + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

Result<std::shared_ptr<grpc::ServerCredentials>> Credentials(const ServerOptions& o) {
  if (o.tls_cert_file.empty()) return grpc::InsecureServerCredentials();
  VC_ASSIGN_OR_RETURN(std::string cert, ReadTextFile(o.tls_cert_file, "TLS certificate (--tls-cert)"));
  VC_ASSIGN_OR_RETURN(std::string key, ReadTextFile(o.tls_key_file, "TLS key (--tls-key)"));
  grpc::SslServerCredentialsOptions ssl(o.tls_client_ca_file.empty()
                                            ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                                            : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  if (!o.tls_client_ca_file.empty()) {
    VC_ASSIGN_OR_RETURN(ssl.pem_root_certs, ReadTextFile(o.tls_client_ca_file, "client CA (--tls-client-ca)"));
  }
  ssl.pem_key_cert_pairs.push_back({std::move(key), std::move(cert)});
  return grpc::SslServerCredentials(ssl);
}

}  // namespace

Result<std::unique_ptr<Server>> Server::Start(const ServerOptions& options, Backend backend) {
  VC_RETURN_IF_ERROR(options.Validate());
  VC_ASSIGN_OR_RETURN(auto credentials, Credentials(options));
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  std::unique_ptr<Server> s(new Server());
  const std::string replica_id = [] {
    std::random_device rd;
    return fmt::format("{:08x}{:08x}", rd(), rd());
  }();
  std::unique_ptr<PeerFanOut> fan_out;
  if (options.HasPeers()) {
    VC_ASSIGN_OR_RETURN(fan_out, PeerFanOut::Create(options, replica_id));
  }
  s->service_ = std::make_unique<StationPlannerService>(options, std::move(backend), replica_id, std::move(fan_out));
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options.listen, credentials, &s->port_);
  builder.RegisterService(s->service_.get());
  builder.SetMaxReceiveMessageSize(4 << 20);
  s->server_ = builder.BuildAndStart();
  if (!s->server_ || s->port_ == 0) {
    s->service_.reset();
    return InternalError("cannot listen on " + options.listen +
                         ": the address is in use or not local; choose another --listen");
  }
  s->server_->GetHealthCheckService()->SetServingStatus(true);
  spdlog::info(
      "vc-server listening on {} (port {}), {} workers x {} threads, queue {}, tls={}, tokens={}, replica {}{}",
      options.listen, s->port_, options.EffectiveWorkers(), options.EffectiveThreadsPerJob(), options.queue,
      options.tls_cert_file.empty() ? "off" : (options.tls_client_ca_file.empty() ? "on" : "mutual"),
      options.tokens.empty() ? "off" : std::to_string(options.tokens.size()), replica_id,
      options.HasPeers() ? fmt::format(", peers {}{}{} in shards of {}", fmt::join(options.peers, ","),
                                       options.peers.empty() || options.peers_dns.empty() ? "" : ",", options.peers_dns,
                                       options.shard_candidates)
                         : std::string());
  return s;
}

Server::~Server() { Shutdown(std::chrono::milliseconds(0)); }

void Server::Shutdown(std::chrono::milliseconds grace) {
  if (shut_down_ || !server_) return;
  shut_down_ = true;
  server_->GetHealthCheckService()->SetServingStatus(false);
  // Our own drain first, gRPC's shutdown only once every call has ended: gRPC closes a connection
  // as soon as its last stream ends while it shuts down, which reset connections whose clients had
  // not yet read their results (scripts/load/sigterm.sh). So: refuse new calls (UNAVAILABLE, retried
  // elsewhere), give the running and queued ones the grace, cancel what is left (each ends with its
  // own CANCELLED), and give those kCancelWindow to end.
  using Clock = std::chrono::steady_clock;
  service_->Drain();
  const bool had_calls = !service_->WaitForCalls(Clock::now());
  if (!service_->WaitForCalls(Clock::now() + grace)) {
    spdlog::info("vc-server: the {:.1f} s grace is over; cancelling the jobs still running or queued",
                 std::chrono::duration<double>(grace).count());
    service_->CancelAll();
    service_->WaitForCalls(Clock::now() + kCancelWindow);
  }
  // The last results were handed to the transport; let them reach their clients before the
  // connections close.
  if (had_calls) std::this_thread::sleep_for(kFlushLinger);
  server_->Shutdown(std::chrono::system_clock::now() + kFlushLinger);
  server_->Wait();
  service_.reset();  // joins the workers; every job has ended with its call
}

const WorkerPool& Server::pool() const { return service_->pool(); }

}  // namespace vc::server
