// vc-server: flags and environment to ServerOptions, start, wait for SIGTERM/SIGINT, drain, exit 0.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdlib>
#include <iostream>

#include "vc/server/server.h"

int main(int argc, char** argv) {
  vc::server::ServerOptions o;
  double grace_s = std::chrono::duration<double>(o.shutdown_grace).count();
  std::string log_level = "info";
  CLI::App app{"vc-server: plans laser-scanner stations over gRPC (vc.v1.StationPlanner)"};
  app.add_option("--listen", o.listen, "host:port to listen on (port 0 = any free port)")
      ->envname("VC_LISTEN")
      ->capture_default_str();
  app.add_option("--workers", o.workers, "jobs running at once (0 = one per core)")
      ->envname("VC_WORKERS")
      ->capture_default_str();
  app.add_option("--queue", o.queue, "jobs that may wait for a worker; more get RESOURCE_EXHAUSTED")
      ->envname("VC_QUEUE")
      ->capture_default_str();
  app.add_option("--max-upload-bytes", o.max_upload_bytes, "largest upload accepted, in bytes")
      ->envname("VC_MAX_UPLOAD_BYTES")
      ->capture_default_str();
  app.add_option("--max-memory-budget-bytes", o.max_memory_budget_bytes,
                 "upper bound on a job's memory budget, in bytes")
      ->envname("VC_MAX_MEMORY_BUDGET_BYTES")
      ->capture_default_str();
  app.add_option("--scene-cache-bytes", o.scene_cache_bytes,
                 "bytes of uploaded scenes kept by their SHA-256 for clients that plan them again (0 = none)")
      ->envname("VC_SCENE_CACHE_BYTES")
      ->capture_default_str();
  app.add_option("--threads-per-job", o.threads_per_job, "threads per job (0 = cores / workers)")
      ->envname("VC_THREADS_PER_JOB")
      ->capture_default_str();
  app.add_option("--tls-cert", o.tls_cert_file, "server certificate chain (PEM); enables TLS")->envname("VC_TLS_CERT");
  app.add_option("--tls-key", o.tls_key_file, "server private key (PEM)")->envname("VC_TLS_KEY");
  app.add_option("--tls-client-ca", o.tls_client_ca_file, "CA (PEM) for client certificates; enables mutual TLS")
      ->envname("VC_TLS_CLIENT_CA");
  app.add_option("--token", o.tokens,
                 "require 'authorization: Bearer TOKEN' on vc.v1 calls; several tokens separated by commas (each "
                 "owns the detachable jobs submitted with it)")
      ->delimiter(',')
      ->envname("VC_TOKEN");
  double max_grace_s = std::chrono::duration<double>(o.max_detach_grace).count();
  double ttl_s = std::chrono::duration<double>(o.result_ttl).count();
  app.add_option("--max-detach-grace-seconds", max_grace_s,
                 "largest detach grace granted to a job (vc-client --detach-grace); 0 = no job outlives its stream")
      ->envname("VC_MAX_DETACH_GRACE_SECONDS")
      ->capture_default_str();
  app.add_option("--result-ttl-seconds", ttl_s,
                 "how long a detached job's result is kept for a client to attach after the job ended")
      ->envname("VC_RESULT_TTL_SECONDS")
      ->capture_default_str();
  app.add_option("--kept-results-bytes", o.kept_results_bytes,
                 "bytes of events and results all detached jobs together may keep")
      ->envname("VC_KEPT_RESULTS_BYTES")
      ->capture_default_str();
  app.add_option("--advertise-address", o.advertise_address,
                 "host:port clients re-attach to (sent in Accepted); set it to the replica's own address behind "
                 "a load balancer")
      ->envname("VC_ADVERTISE_ADDRESS");
  app.add_option("--peers", o.peers,
                 "host:port of replicas to fan each plan's visibility stage out to, separated by commas "
                 "(docs/DEPLOY.md, \"Scaling out\")")
      ->delimiter(',')
      ->envname("VC_PEERS");
  app.add_option("--peers-dns", o.peers_dns,
                 "NAME:PORT whose every address is a peer, resolved again for each plan (a Kubernetes headless "
                 "Service)")
      ->envname("VC_PEERS_DNS");
  app.add_option("--shard-candidates", o.shard_candidates, "candidates per shard sent to a peer")
      ->envname("VC_SHARD_CANDIDATES")
      ->capture_default_str();
  app.add_option("--local-shards", o.local_shards,
                 "whether this replica computes shards of its own plans too (false: only when its peers cannot)")
      ->envname("VC_LOCAL_SHARDS")
      ->capture_default_str();
  app.add_option("--peer-token", o.peer_token, "bearer token presented to peers (default: the first --token)")
      ->envname("VC_PEER_TOKEN");
  app.add_option("--peer-tls-ca", o.peer_tls_ca_file, "CA (PEM) that peers' certificates are checked against")
      ->envname("VC_PEER_TLS_CA");
  double shard_deadline_s = std::chrono::duration<double>(o.shard_deadline).count();
  app.add_option("--shard-deadline-seconds", shard_deadline_s,
                 "seconds a peer gets for one shard before it is computed elsewhere")
      ->envname("VC_SHARD_DEADLINE_SECONDS")
      ->capture_default_str();
  app.add_option("--shutdown-grace", grace_s, "seconds running jobs get after SIGTERM before they are cancelled")
      ->envname("VC_SHUTDOWN_GRACE")
      ->capture_default_str();
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")
      ->envname("VC_LOG_LEVEL")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  o.shutdown_grace = std::chrono::milliseconds(int64_t(grace_s * 1000));
  o.max_detach_grace = std::chrono::milliseconds(int64_t(max_grace_s * 1000));
  o.result_ttl = std::chrono::milliseconds(int64_t(ttl_s * 1000));
  o.shard_deadline = std::chrono::milliseconds(int64_t(shard_deadline_s * 1000));
  spdlog::set_level(spdlog::level::from_str(log_level));

  // Block the signals in every thread (gRPC's included); this thread waits for them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  auto server = vc::server::Server::Start(o);
  if (!server.ok()) {
    std::cerr << "vc-server: " << server.status().message() << "\n";
    return EXIT_FAILURE;
  }
  int sig = 0;
  sigwait(&signals, &sig);
  spdlog::info("vc-server: {} received; draining (grace {:.1f}s)", sig == SIGTERM ? "SIGTERM" : "SIGINT", grace_s);
  (*server)->Shutdown(o.shutdown_grace);
  spdlog::info("vc-server: stopped");
  return EXIT_SUCCESS;
}
