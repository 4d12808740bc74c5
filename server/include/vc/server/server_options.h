// Configuration of vc-server (set by flags and VC_* environment variables in main.cc).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "vc/base/status.h"
#include "vc/plan/evaluate_job.h"
#include "vc/plan/plan_options.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"

namespace vc::server {

struct ServerOptions {
  // host:port to listen on; port 0 picks a free port (see Server::port()).
  std::string listen = "0.0.0.0:50051";
  // Worker threads running jobs; 0 = one per core.
  int workers = 0;
  // Jobs that may wait for a worker (beyond those running); more get RESOURCE_EXHAUSTED.
  int queue = 16;
  // Largest upload accepted, in bytes.
  uint64_t max_upload_bytes = kDefaultMaxUploadBytes;
  // Upper bound on a job's memory budget (PlanOptions::memory_budget_bytes), in bytes; requests
  // above it are capped to it.
  uint64_t max_memory_budget_bytes = kDefaultMemoryBudgetBytes;
  // Bytes of uploaded scenes kept for clients that name a scene by its SHA-256 (0 = no cache).
  uint64_t scene_cache_bytes = uint64_t{1} << 30;
  // Threads each job may use; 0 = cores / workers (at least 1).
  int threads_per_job = 0;
  // PEM files. With cert and key the server speaks TLS; with client_ca it also requires and
  // verifies client certificates (mutual TLS).
  std::string tls_cert_file;
  std::string tls_key_file;
  std::string tls_client_ca_file;
  // When non-empty, vc.v1 calls must carry "authorization: Bearer <token>" with one of these
  // tokens. Each token owns the detachable jobs submitted with it: only it may attach or cancel.
  std::vector<std::string> tokens;
  // Detachable jobs (docs/PROTOCOL.md, "Detachable jobs"): the largest detach grace granted (a
  // request asks for more is capped to it; 0 = no job is detachable), how long a finished job's
  // result waits for a client, and the bytes of events all detachable jobs together may keep.
  std::chrono::milliseconds max_detach_grace{std::chrono::hours(1)};
  std::chrono::milliseconds result_ttl{std::chrono::minutes(30)};
  uint64_t kept_results_bytes = uint64_t{1} << 30;
  // The address clients re-attach to, sent in Accepted.attach_address (e.g. the pod's own
  // address behind a load balancer); empty = the address the client used.
  std::string advertise_address;
  // Scaling out (docs/DEPLOY.md, "Scaling out"): the replicas a plan's visibility stage is fanned
  // out to, as host:port addresses and/or a DNS name (NAME:PORT, every address it resolves to,
  // re-resolved per plan: a Kubernetes headless Service). Empty: every plan runs here alone.
  std::vector<std::string> peers;
  std::string peers_dns;
  // Candidates per shard (the unit a peer computes, and retries).
  int shard_candidates = 128;
  // Whether this replica computes shards of its own plans too; false leaves them to the peers
  // while any is working (it still starts a slow shard again, and finishes alone if all fail).
  bool local_shards = true;
  // The bearer token this replica presents to its peers; empty = the first of `tokens` (replicas
  // of one deployment share them).
  std::string peer_token;
  // Peers speak TLS when this replica does (tls_cert_file), verified against this CA (PEM; empty =
  // the system's roots); with tls_client_ca_file (mutual TLS) this replica's own certificate and
  // key are presented to them.
  std::string peer_tls_ca_file;
  // A shard attempt a peer has not answered within this long is abandoned and computed elsewhere
  // (a slow one is started again elsewhere much sooner, see DEPLOY.md).
  std::chrono::milliseconds shard_deadline{std::chrono::minutes(10)};

  // On shutdown, running jobs get this long to finish before they are cancelled.
  std::chrono::milliseconds shutdown_grace{std::chrono::seconds(30)};

  // INVALID_ARGUMENT naming the first bad field.
  Status Validate() const;
  // Workers and per-job threads with the 0 defaults resolved.
  int EffectiveWorkers() const;
  int EffectiveThreadsPerJob() const;
  // Whether plans fan out (peers or peers_dns given).
  bool HasPeers() const { return !peers.empty() || !peers_dns.empty(); }
};

// A job's options within this server's limits: the memory budget capped at
// max_memory_budget_bytes, the threads at the per-job share (0 = the share); then validated.
// INVALID_ARGUMENT for negative threads (before any other check), or from options.Validate().
[[nodiscard]] Result<PlanOptions> ApplyServerLimits(const ServerOptions& server, PlanOptions options);
[[nodiscard]] Result<EvaluateJobOptions> ApplyServerLimits(const ServerOptions& server, EvaluateJobOptions options);

}  // namespace vc::server
