// Server: a running vc-server (the StationPlanner service, the standard gRPC health service and
// server reflection) on a listening port, in-process. main.cc and the tests both use it.
#pragma once

#include <chrono>
#include <memory>

#include "vc/base/status.h"
#include "vc/server/backend.h"
#include "vc/server/server_options.h"
#include "vc/server/worker_pool.h"

namespace grpc {
class Server;
}

namespace vc::server {

class StationPlannerService;

class Server {
 public:
  // Validates `options`, reads the TLS files and starts listening. INVALID_ARGUMENT for bad options,
  // NOT_FOUND for an unreadable TLS file, UNAVAILABLE-like INTERNAL when the address cannot be bound.
  static Result<std::unique_ptr<Server>> Start(const ServerOptions& options, Backend backend = Backend::Default());
  // Shutdown(0) if not shut down yet.
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // The bound port (the real one when `listen` asked for port 0).
  int port() const { return port_; }
  // After the grace, how long cancelled jobs get to reach a cancellation point and send their
  // CANCELLED status before gRPC cancels the calls itself (the core polls at least every second).
  static constexpr std::chrono::milliseconds kCancelWindow{5000};
  // After the last call ended, how long the connections stay open for its last bytes.
  static constexpr std::chrono::milliseconds kFlushLinger{500};

  // Reports NOT_SERVING and refuses new calls with UNAVAILABLE; running and queued calls get `grace`
  // to finish, then their jobs are cancelled and end with CANCELLED (within about a second). Then
  // gRPC shuts down. Returns when every call has ended.
  void Shutdown(std::chrono::milliseconds grace);
  const WorkerPool& pool() const;

 private:
  Server() = default;
  std::unique_ptr<StationPlannerService> service_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;
  bool shut_down_ = false;
};

// Reads a whole file. NOT_FOUND naming `what` and the path if it cannot be read.
Result<std::string> ReadTextFile(const std::string& path, const std::string& what);

}  // namespace vc::server
