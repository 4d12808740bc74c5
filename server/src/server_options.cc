#include "vc/server/server_options.h"

#include <algorithm>
#include <thread>
#include <utility>

namespace vc::server {
namespace {

int Cores() { return std::max(1, int(std::thread::hardware_concurrency())); }

template <class JobOptions>
Result<JobOptions> ApplyLimits(const ServerOptions& server, JobOptions options) {
  options.memory_budget_bytes = std::min(options.memory_budget_bytes, server.max_memory_budget_bytes);
  if (options.threads < 0) return InvalidArgumentError("threads must be >= 0 (0 = the server's share)");
  const int share = server.EffectiveThreadsPerJob();
  options.threads = options.threads == 0 ? share : std::min(options.threads, share);
  VC_RETURN_IF_ERROR(options.Validate());
  return options;
}

}  // namespace

Status ServerOptions::Validate() const {
  if (listen.empty() || listen.find(':') == std::string::npos) {
    return InvalidArgumentError("--listen '" + listen + "' is not host:port (e.g. 0.0.0.0:50051)");
  }
  if (workers < 0) return InvalidArgumentError("--workers must be >= 0 (0 = one per core)");
  if (queue < 0) return InvalidArgumentError("--queue must be >= 0");
  if (max_upload_bytes == 0) return InvalidArgumentError("--max-upload-bytes must be > 0");
  if (max_memory_budget_bytes == 0) return InvalidArgumentError("--max-memory-budget-bytes must be > 0");
  if (threads_per_job < 0) return InvalidArgumentError("--threads-per-job must be >= 0 (0 = cores / workers)");
  if (tls_cert_file.empty() != tls_key_file.empty()) {
    return InvalidArgumentError("--tls-cert and --tls-key must be given together");
  }
  if (!tls_client_ca_file.empty() && tls_cert_file.empty()) {
    return InvalidArgumentError("--tls-client-ca needs --tls-cert and --tls-key");
  }
  for (const std::string& t : tokens) {
    if (t.empty()) return InvalidArgumentError("--token: a token is empty (separate several with commas)");
  }
  if (max_detach_grace.count() < 0) return InvalidArgumentError("--max-detach-grace-seconds must be >= 0");
  if (result_ttl.count() < 0) return InvalidArgumentError("--result-ttl-seconds must be >= 0");
  if (shutdown_grace.count() < 0) return InvalidArgumentError("--shutdown-grace must be >= 0");
  for (const std::string& p : peers) {
    if (p.empty() || p.rfind(':') == std::string::npos || p.rfind(':') + 1 == p.size()) {
      return InvalidArgumentError("--peers: '" + p + "' is not host:port (separate several with commas)");
    }
  }
  if (!peers_dns.empty() &&
      (peers_dns.rfind(':') == std::string::npos || peers_dns.rfind(':') + 1 == peers_dns.size())) {
    return InvalidArgumentError("--peers-dns '" + peers_dns +
                                "' is not NAME:PORT (e.g. vc-server-peers.default.svc.cluster.local:50051)");
  }
  if (shard_candidates < 1) return InvalidArgumentError("--shard-candidates must be >= 1");
  if (shard_deadline.count() <= 0) return InvalidArgumentError("--shard-deadline-seconds must be > 0");
  if (!peer_tls_ca_file.empty() && tls_cert_file.empty()) {
    return InvalidArgumentError(
        "--peer-tls-ca needs --tls-cert and --tls-key (peers speak TLS when this replica does)");
  }
  return Status::Ok();
}

int ServerOptions::EffectiveWorkers() const { return workers > 0 ? workers : Cores(); }

int ServerOptions::EffectiveThreadsPerJob() const {
  return threads_per_job > 0 ? threads_per_job : std::max(1, Cores() / EffectiveWorkers());
}

Result<PlanOptions> ApplyServerLimits(const ServerOptions& server, PlanOptions options) {
  return ApplyLimits(server, std::move(options));
}

Result<EvaluateJobOptions> ApplyServerLimits(const ServerOptions& server, EvaluateJobOptions options) {
  return ApplyLimits(server, std::move(options));
}

}  // namespace vc::server
