// Shared by the server and client tests: an in-process vc-server on a free loopback port, a
// backend whose plan blocks until cancelled, a tiny box-room PLY, and a raw stream driver that
// sends arbitrary (also malformed) request sequences.
#pragma once

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "vc/base/crc32c.h"
#include "vc/server/server.h"
#include "vc/v1/planner.grpc.pb.h"

namespace vc::testing {

// A closed box room (walls, floor, ceiling) of size_m, as an ASCII PLY, points every spacing_m.
std::string BoxRoomPly(const Eigen::Vector3d& size_m = {4, 3, 2.5}, double spacing_m = 0.1);

// A one-shot latch with a timeout, for awaiting events from other threads.
class Latch {
 public:
  void Set() {
    std::lock_guard lock(mu_);
    set_ = true;
    cv_.notify_all();
  }
  bool WaitFor(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return set_; });
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  bool set_ = false;
};

// A backend that never touches the core: read_scene returns an empty input; plan and evaluate
// block until the job's token is cancelled (recording when and with which status), unless
// `block` is false, in which case plan returns `plan_result` at once.
struct BlockingBackend {
  std::atomic<bool> block{true};
  PlanResult plan_result;
  Latch started;
  Latch returned;
  std::mutex mu;
  Status returned_status;
  std::chrono::steady_clock::time_point returned_at;

  server::Backend Make();
};

// Starts a server on 127.0.0.1:0 (options.listen is overwritten). Fails the test if it cannot.
std::unique_ptr<server::Server> StartServer(server::ServerOptions options,
                                            server::Backend backend = server::Backend::Default());
std::string Address(const server::Server& s);

// An UploadSpec for `bytes` with the right size and CRC32C.
v1::UploadSpec SpecFor(const std::string& bytes);
// Spec then the bytes in chunks of `chunk` bytes.
std::vector<v1::PlanRequest> PlanRequests(const std::string& bytes, const v1::PlanParameters& params = {},
                                          size_t chunk = 64 << 10);

template <typename Response>
struct RawCall {
  grpc::Status status;
  std::vector<Response> responses;
  std::multimap<std::string, std::string> trailers;
};

// Sends `requests` on a Plan stream, half-closes, reads everything and finishes.
RawCall<v1::PlanResponse> RawPlan(const std::string& address, const std::vector<v1::PlanRequest>& requests,
                                  const std::string& token = "");
RawCall<v1::EvaluateResponse> RawEvaluate(const std::string& address, const std::vector<v1::EvaluateRequest>& requests);

}  // namespace vc::testing
