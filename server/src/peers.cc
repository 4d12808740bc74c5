#include "vc/server/peers.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netdb.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <optional>
#include <set>
#include <thread>

#include "vc/server/server.h"
#include "vc/server/upload_assembler.h"
#include "vc/server/voxelized_scenes.h"
#include "vc/wire/convert.h"
#include "vc/wire/face_values_codec.h"
#include "vc/wire/status_mapping.h"
#include "vc/wire/voxel_set_codec.h"

namespace vc::server {

// What a fan-out collects: the items of every viewpoint in order (visibility sets or face values),
// how they were spread, and the warnings.
template <class T>
struct FanOutResult {
  std::vector<T> items;
  Distribution distribution;
  std::vector<std::string> warnings;
};

namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kSceneChunkBytes = size_t{1} << 20;
constexpr auto kHelloDeadline = std::chrono::seconds(10);
// A lane retires after this many failed calls in a row (a peer that is gone fails at once).
constexpr int kMaxLaneFailures = 2;
// A shard running longer than this many times the mean of the finished ones (and at least
// kMinSlowSeconds) is started again by an idle lane.
constexpr double kSlowFactor = 3.0;
constexpr double kMinSlowSeconds = 2.0;
constexpr double kSlowWithoutMeasure = 30.0;
constexpr int kMaxRestartsPerShard = 2;
// A peer that answers "busy" (RESOURCE_EXHAUSTED) this many times in a row is left out.
constexpr int kMaxBusyAnswers = 20;
const std::string kSelf = "this replica";

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

std::string GrpcError(const grpc::Status& s) { return wire::FromGrpcStatus(s).ToString(); }

// One fan-out's shards, shared by its lanes; T is what a viewpoint yields.
template <class T>
class ShardBoard {
 public:
  ShardBoard(size_t viewpoints, size_t per_shard) {
    for (size_t b = 0; b < viewpoints; b += per_shard) {
      Shard s;
      s.begin = b;
      s.end = std::min(viewpoints, b + per_shard);
      shards_.push_back(s);
    }
    results_.resize(shards_.size());
  }
  size_t size() const { return shards_.size(); }
  std::pair<size_t, size_t> range(size_t k) const { return {shards_[k].begin, shards_[k].end}; }

  // The next shard for a lane: one nobody runs, else one that runs too long; nullopt when every
  // shard is done or the board is stopped, or after `wait` (the caller checks Finished()). With
  // `defer`, a shard nobody runs is taken only once no peer lane is left (the coordinator's own
  // lane with --local-shards=false).
  std::optional<size_t> Take(Clock::duration wait, bool defer = false) {
    std::unique_lock lock(mu_);
    const auto until = Clock::now() + wait;
    while (true) {
      if (stopped_ || done_ == shards_.size()) return std::nullopt;
      // Deferring ends when no peer lane is left or one of them has stalled on a shard.
      if (std::optional<size_t> k = !defer || lanes_ == 0 || Stalled() ? Pick() : std::nullopt) {
        Shard& s = shards_[*k];
        if (s.running > 0) ++s.restarts;
        ++s.running;
        ++s.attempts;
        s.started = Clock::now();
        return k;
      }
      // Nothing now; something may turn slow, or come back, before long.
      if (cv_.wait_until(lock, std::min(until, Clock::now() + std::chrono::milliseconds(200))) ==
              std::cv_status::timeout &&
          Clock::now() >= until) {
        return std::nullopt;
      }
    }
  }
  // An attempt of shard k ended with these items (from `who`); the first answer is kept.
  void Deliver(size_t k, const std::string& who, std::vector<T> items, double seconds) {
    std::lock_guard lock(mu_);
    Shard& s = shards_[k];
    --s.running;
    if (s.done) return;
    s.done = true;
    results_[k] = std::move(items);
    ++done_;
    contributors_.insert(who);
    finished_seconds_ += seconds;
    cv_.notify_all();
  }
  // An attempt of shard k failed; the shard is free for any lane again.
  void Release(size_t k) {
    std::lock_guard lock(mu_);
    --shards_[k].running;
    cv_.notify_all();
  }
  // Peer lanes running (started, not yet ended).
  void LaneStarted() {
    std::lock_guard lock(mu_);
    ++lanes_;
  }
  void LaneEnded() {
    std::lock_guard lock(mu_);
    --lanes_;
    cv_.notify_all();
  }
  void Stop() {
    std::lock_guard lock(mu_);
    stopped_ = true;
    cv_.notify_all();
  }
  bool Finished() const {
    std::lock_guard lock(mu_);
    return stopped_ || done_ == shards_.size();
  }
  // Waits up to `d` or until the board stops (for a lane's back-off).
  void Sleep(Clock::duration d) {
    std::unique_lock lock(mu_);
    cv_.wait_for(lock, d, [&] { return stopped_ || done_ == shards_.size(); });
  }
  size_t done() const {
    std::lock_guard lock(mu_);
    return done_;
  }
  void Warn(std::string w) {
    std::lock_guard lock(mu_);
    warnings_.push_back(std::move(w));
  }
  void AddBytes(uint64_t b) {
    std::lock_guard lock(mu_);
    bytes_ += b;
  }
  // A lane's call in flight, cancelled when the board stops (TryCancel).
  bool SetLive(size_t lane, grpc::ClientContext* c) {
    std::lock_guard lock(mu_);
    if (c != nullptr && stopped_) return false;
    live_[lane] = c;
    return true;
  }
  void CancelLive() {
    std::lock_guard lock(mu_);
    for (auto& [lane, c] : live_) {
      if (c != nullptr) c->TryCancel();
    }
  }

  // Once the lanes are joined.
  FanOutResult<T> Collect() && {
    FanOutResult<T> out;
    for (std::vector<T>& r : results_) {
      for (T& s : r) out.items.push_back(std::move(s));
    }
    out.distribution.replicas = int(contributors_.size());
    out.distribution.shards = int(shards_.size());
    for (const Shard& s : shards_) out.distribution.retried += std::max(0, s.attempts - 1);
    out.distribution.bytes_exchanged = bytes_;
    out.warnings = std::move(warnings_);
    return out;
  }

 private:
  struct Shard {
    size_t begin = 0, end = 0;
    bool done = false;
    int running = 0;   // attempts in flight
    int attempts = 0;  // attempts started
    int restarts = 0;  // attempts started while another still ran (a slow shard)
    Clock::time_point started;
  };
  // Under mu_: the first shard nobody runs, else the longest-running slow one.
  std::optional<size_t> Pick() const {
    for (size_t k = 0; k < shards_.size(); ++k) {
      if (!shards_[k].done && shards_[k].running == 0) return k;
    }
    return Slowest();
  }
  // Under mu_: whether some shard has run longer than the slow threshold.
  bool Stalled() const {
    const double slow_s = SlowSeconds();
    const auto now = Clock::now();
    for (const Shard& s : shards_) {
      if (!s.done && s.running > 0 && Seconds(now - s.started) >= slow_s) return true;
    }
    return false;
  }
  double SlowSeconds() const {
    return done_ == 0 ? kSlowWithoutMeasure
                      : std::max(kMinSlowSeconds, kSlowFactor * finished_seconds_ / double(done_));
  }
  // Under mu_: the longest-running shard among those running longer than kSlowFactor times the
  // mean finished shard (kSlowWithoutMeasure before any finished), run once and not too often.
  std::optional<size_t> Slowest() const {
    const double slow_s = SlowSeconds();
    std::optional<size_t> best;
    const auto now = Clock::now();
    for (size_t k = 0; k < shards_.size(); ++k) {
      const Shard& s = shards_[k];
      if (s.done || s.running != 1 || s.restarts >= kMaxRestartsPerShard) continue;
      if (Seconds(now - s.started) < slow_s) continue;
      if (!best || s.started < shards_[*best].started) best = k;
    }
    return best;
  }

  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Shard> shards_;
  std::vector<std::vector<T>> results_;
  size_t done_ = 0;
  int lanes_ = 0;
  bool stopped_ = false;
  double finished_seconds_ = 0;
  std::set<std::string> contributors_;
  std::vector<std::string> warnings_;
  uint64_t bytes_ = 0;
  std::map<size_t, grpc::ClientContext*> live_;
};

// Everything one peer lane needs.
struct LaneJob {
  const PeerFanOut::SceneRef& ref;
  const v1::PlanParameters& parameters;
  const std::vector<WorldPoint>& viewpoints;
  uint64_t occupied_voxels;
  uint32_t fingerprint;
  const std::string& token;
  const std::string& self_id;
  Clock::duration shard_deadline;
  v1::ShardKind kind;
  double compact_gain;  // the sets arrive sparse where the plan keeps them sparse
  const char* what;     // the stage, for messages
};

// A shard's items from a peer's answer (its voxelization already checked).
template <class T>
Result<std::vector<T>> DecodeItems(const v1::ShardResponse& resp, size_t count, const LaneJob& job);
template <>
Result<std::vector<VoxelSet>> DecodeItems(const v1::ShardResponse& resp, size_t count, const LaneJob& job) {
  if (size_t(resp.sets_size()) != count) {
    return DataLossError(fmt::format("it answered {} sets for {} viewpoints", resp.sets_size(), count));
  }
  std::vector<VoxelSet> sets;
  sets.reserve(count);
  for (const std::string& b : resp.sets()) {
    VC_ASSIGN_OR_RETURN(VoxelSet s, wire::DecodeVoxelSet(b, job.occupied_voxels, job.compact_gain));
    sets.push_back(std::move(s));
  }
  return sets;
}
template <>
Result<std::vector<SparseFaceValues>> DecodeItems(const v1::ShardResponse& resp, size_t count, const LaneJob& job) {
  if (size_t(resp.face_values_size()) != count) {
    return DataLossError(fmt::format("it answered face values of {} stations for {}", resp.face_values_size(), count));
  }
  std::vector<SparseFaceValues> values;
  values.reserve(count);
  for (const v1::FaceValues& m : resp.face_values()) {
    VC_ASSIGN_OR_RETURN(SparseFaceValues v, wire::DecodeFaceValues(m, job.occupied_voxels * kFacesPerVoxel));
    values.push_back(std::move(v));
  }
  return values;
}

template <class T>
class PeerLane {
 public:
  PeerLane(size_t index, std::string address, std::shared_ptr<v1::StationPlanner::Stub> stub, const LaneJob& job,
           ShardBoard<T>& board)
      : index_(index), address_(std::move(address)), stub_(std::move(stub)), job_(job), board_(board) {}

  void Run() {
    try {
      RunLane();
    } catch (const std::exception& e) {
      if (held_) board_.Release(*held_);
      board_.Warn(fmt::format("replica {} was left out of the plan: {}", address_, e.what()));
    }
    board_.LaneEnded();
  }

 private:
  void Prepare(grpc::ClientContext& c, Clock::duration deadline) const {
    c.set_deadline(std::chrono::system_clock::now() + deadline);
    if (!job_.token.empty()) c.AddMetadata("authorization", "Bearer " + job_.token);
  }
  // While alive, `c` is the lane's call the board cancels when it stops (exception-safe: the
  // board never sees a context that is gone).
  class LiveCall {
   public:
    LiveCall(ShardBoard<T>& board, size_t lane, grpc::ClientContext& c)
        : board_(board), lane_(lane), live_(board.SetLive(lane, &c)) {}
    ~LiveCall() {
      if (live_) board_.SetLive(lane_, nullptr);
    }
    bool live() const { return live_; }

   private:
    ShardBoard<T>& board_;
    size_t lane_;
    bool live_;
  };
  // A call in flight that the board can cancel; nullopt when the board has stopped.
  template <class F>
  std::optional<grpc::Status> Call(grpc::ClientContext& c, F&& call) {
    LiveCall live(board_, index_, c);
    if (!live.live()) return std::nullopt;
    return call();
  }

  void Retire(const std::string& why) {
    if (board_.Finished()) return;  // the plan is done or cancelled: nothing to report
    board_.Warn(fmt::format("replica {} was left out of the rest of {} ({}); the other replicas computed its shards",
                            address_, job_.what, why));
    spdlog::warn("fan-out: replica {} retired: {}", address_, why);
  }

  // PeerHello; false when the lane should not run (unreachable, or this replica itself).
  bool Hello(bool* has_scene) {
    grpc::ClientContext c;
    Prepare(c, kHelloDeadline);
    v1::PeerHelloRequest req;
    req.set_scene_sha256(job_.ref.sha256);
    v1::PeerHelloResponse resp;
    const auto s = Call(c, [&] { return stub_->PeerHello(&c, req, &resp); });
    if (!s) return false;
    if (!s->ok()) {
      Retire("it did not answer PeerHello: " + GrpcError(*s));
      return false;
    }
    if (resp.replica_id() == job_.self_id) return false;  // this replica, listed among its peers
    *has_scene = resp.has_scene();
    return true;
  }

  bool Share() {
    grpc::ClientContext c;
    Prepare(c, std::chrono::minutes(10));
    LiveCall live(board_, index_, c);
    if (!live.live()) return false;
    v1::ShareSceneResponse resp;
    std::unique_ptr<grpc::ClientWriter<v1::SceneChunk>> w(stub_->ShareScene(&c, &resp));
    const std::string& bytes = *job_.ref.bytes;
    size_t sent = 0;
    bool first = true;
    while (first || sent < bytes.size()) {
      v1::SceneChunk chunk;
      if (first) {
        chunk.set_sha256(job_.ref.sha256);
        chunk.set_total_size_bytes(bytes.size());
      }
      const size_t n = std::min(kSceneChunkBytes, bytes.size() - sent);
      chunk.set_data(bytes.substr(sent, n));
      sent += n;
      first = false;
      if (!w->Write(chunk)) break;
    }
    w->WritesDone();
    const grpc::Status s = w->Finish();
    board_.AddBytes(sent);
    if (!s.ok()) {
      Retire("it could not take the scene: " + GrpcError(s));
      return false;
    }
    return true;
  }

  // Decodes and checks a peer's answer for shard k.
  Result<std::vector<T>> Decode(const v1::ShardResponse& resp, size_t begin, size_t end) const {
    if (resp.occupied_voxels() != job_.occupied_voxels || resp.scene_crc32c() != job_.fingerprint) {
      return FailedPreconditionError(fmt::format(
          "its voxelization differs from this replica's ({} voxels, CRC32C {:08x}, against {} and {:08x}): is it "
          "another version of vc-server?",
          resp.occupied_voxels(), resp.scene_crc32c(), job_.occupied_voxels, job_.fingerprint));
    }
    return DecodeItems<T>(resp, end - begin, job_);
  }

  void RunLane() {
    bool has_scene = false;
    if (!Hello(&has_scene)) return;
    if (!has_scene && !Share()) return;
    bool shared_again = false;
    int failures = 0, busy = 0;
    while (true) {
      const std::optional<size_t> k = board_.Take(std::chrono::hours(1));
      if (!k) {
        if (board_.Finished()) return;
        continue;
      }
      held_ = k;
      const auto [begin, end] = board_.range(*k);
      v1::ShardRequest req;
      req.set_scene_sha256(job_.ref.sha256);
      req.set_source_name(job_.ref.source_name);
      *req.mutable_parameters() = job_.parameters;
      req.set_first_index(begin);
      req.set_kind(job_.kind);
      for (size_t i = begin; i < end; ++i) *req.add_viewpoints() = wire::ToProto(job_.viewpoints[i]);
      v1::ShardResponse resp;
      grpc::ClientContext c;
      Prepare(c, job_.shard_deadline);
      const auto t0 = Clock::now();
      const auto s = Call(c, [&] { return stub_->ComputeShard(&c, req, &resp); });
      if (!s) {
        board_.Release(*k);
        held_.reset();
        return;
      }
      board_.AddBytes(req.ByteSizeLong() + resp.ByteSizeLong());
      if (s->ok()) {
        Result<std::vector<T>> items = Decode(resp, begin, end);
        if (!items.ok()) {
          board_.Release(*k);
          held_.reset();
          Retire(items.status().message());
          return;
        }
        board_.Deliver(*k, address_, std::move(*items), Seconds(Clock::now() - t0));
        held_.reset();
        failures = busy = 0;
        continue;
      }
      board_.Release(*k);
      held_.reset();
      if (board_.Finished()) return;
      switch (s->error_code()) {
        case grpc::StatusCode::NOT_FOUND:  // the scene was evicted from its cache: share it once more
          if (shared_again || !Share()) {
            if (shared_again) Retire("it lost the scene twice: " + GrpcError(*s));
            return;
          }
          shared_again = true;
          break;
        case grpc::StatusCode::RESOURCE_EXHAUSTED:  // busy: the others take the shard meanwhile
          if (++busy >= kMaxBusyAnswers) {
            Retire(GrpcError(*s) + fmt::format(" ({} times in a row)", busy));
            return;
          }
          board_.Sleep(std::chrono::milliseconds(500));
          break;
        case grpc::StatusCode::UNAUTHENTICATED:
        case grpc::StatusCode::PERMISSION_DENIED:
        case grpc::StatusCode::INVALID_ARGUMENT:
        case grpc::StatusCode::FAILED_PRECONDITION:
        case grpc::StatusCode::UNIMPLEMENTED:
          Retire(GrpcError(*s));
          return;
        default:
          if (++failures >= kMaxLaneFailures) {
            Retire(GrpcError(*s));
            return;
          }
      }
    }
  }

  const size_t index_;
  const std::string address_;
  const std::shared_ptr<v1::StationPlanner::Stub> stub_;
  const LaneJob& job_;
  ShardBoard<T>& board_;
  std::optional<size_t> held_;  // the shard this lane runs, released if the lane throws
};

std::string JoinHostPort(const sockaddr* sa, const std::string& port) {
  char host[INET6_ADDRSTRLEN] = {};
  if (sa->sa_family == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(sa)->sin_addr, host, sizeof(host));
    return std::string(host) + ":" + port;
  }
  inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(sa)->sin6_addr, host, sizeof(host));
  return "[" + std::string(host) + "]:" + port;
}

}  // namespace

Result<std::unique_ptr<PeerFanOut>> PeerFanOut::Create(const ServerOptions& options, std::string self_id) {
  std::shared_ptr<grpc::ChannelCredentials> creds = grpc::InsecureChannelCredentials();
  if (!options.tls_cert_file.empty()) {
    grpc::SslCredentialsOptions ssl;
    if (!options.peer_tls_ca_file.empty()) {
      VC_ASSIGN_OR_RETURN(ssl.pem_root_certs, ReadTextFile(options.peer_tls_ca_file, "peer CA (--peer-tls-ca)"));
    }
    if (!options.tls_client_ca_file.empty()) {  // mutual TLS: peers require a client certificate
      VC_ASSIGN_OR_RETURN(ssl.pem_cert_chain, ReadTextFile(options.tls_cert_file, "TLS certificate (--tls-cert)"));
      VC_ASSIGN_OR_RETURN(ssl.pem_private_key, ReadTextFile(options.tls_key_file, "TLS key (--tls-key)"));
    }
    creds = grpc::SslCredentials(ssl);
  }
  return std::unique_ptr<PeerFanOut>(new PeerFanOut(options, std::move(self_id), std::move(creds)));
}

std::vector<std::string> PeerFanOut::Addresses(std::vector<std::string>* warnings) const {
  std::vector<std::string> out = options_.peers;
  if (!options_.peers_dns.empty()) {
    const size_t colon = options_.peers_dns.rfind(':');
    const std::string host = options_.peers_dns.substr(0, colon);
    const std::string port = options_.peers_dns.substr(colon + 1);
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    const int rc = getaddrinfo(host.c_str(), port.c_str(), &hints, &found);
    if (rc != 0) {
      if (warnings) {
        warnings->push_back(fmt::format("--peers-dns {} did not resolve ({}); this plan ran without its replicas",
                                        options_.peers_dns, gai_strerror(rc)));
      }
    } else {
      for (addrinfo* a = found; a != nullptr; a = a->ai_next) out.push_back(JoinHostPort(a->ai_addr, port));
      freeaddrinfo(found);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::shared_ptr<v1::StationPlanner::Stub> PeerFanOut::StubFor(const std::string& address) {
  std::lock_guard lock(mu_);
  auto& stub = stubs_[address];
  if (!stub) {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(-1);  // a shard's sets (see --shard-candidates)
    stub = v1::StationPlanner::NewStub(grpc::CreateCustomChannel(address, creds_, args));
  }
  return stub;
}

template <class T>
Result<FanOutResult<T>> PeerFanOut::FanOut(const SceneRef& ref, const v1::PlanParameters& parameters,
                                           const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                           const ShardSpec& spec, const LocalShard<T>& local, const JobContext& ctx) {
  ShardBoard<T> board(viewpoints.size(), size_t(options_.shard_candidates));
  std::vector<std::string> warnings;
  const std::vector<std::string> addresses = board.size() > 1 ? Addresses(&warnings) : std::vector<std::string>{};
  for (std::string& w : warnings) board.Warn(std::move(w));
  const std::string token = !options_.peer_token.empty() ? options_.peer_token
                            : options_.tokens.empty()    ? std::string()
                                                         : options_.tokens.front();
  // What a peer needs of the plan's parameters: the voxelization, the selection test and the
  // scanner, not the lists (user candidates, keep-out zones, fixed stations), which may be long.
  v1::PlanParameters shard_parameters = parameters;
  shard_parameters.clear_candidates();
  shard_parameters.clear_keep_out();
  shard_parameters.clear_fixed_stations();
  shard_parameters.clear_tripod_heights_m();
  shard_parameters.clear_route_start();
  const LaneJob job{ref,
                    shard_parameters,
                    viewpoints,
                    scene.occupied.size(),
                    SceneFingerprint(scene),
                    token,
                    self_id_,
                    options_.shard_deadline,
                    spec.kind,
                    spec.compact_gain,
                    spec.what};
  std::vector<std::unique_ptr<PeerLane<T>>> lanes;
  std::vector<std::thread> threads;
  // Every way out of here (an exception included) stops the lanes and joins their threads first:
  // they hold references to `board` and `job`.
  struct Joiner {
    ShardBoard<T>& board;
    std::vector<std::thread>& threads;
    ~Joiner() {
      board.Stop();
      board.CancelLive();
      for (std::thread& t : threads) {
        if (t.joinable()) t.join();
      }
    }
  } joiner{board, threads};
  for (size_t i = 0; i < addresses.size(); ++i) {
    lanes.push_back(std::make_unique<PeerLane<T>>(i, addresses[i], StubFor(addresses[i]), job, board));
    board.LaneStarted();
    threads.emplace_back([lane = lanes.back().get()] { lane->Run(); });
  }
  // This replica's own lane, on the plan's thread: progress and cancellation are checked here.
  JobContext quiet = ctx;
  quiet.progress = nullptr;
  Status status;
  while (status.ok()) {
    status = ctx.CheckCancelled(spec.what);
    if (!status.ok()) break;
    ctx.ReportCount(spec.stage, board.done(), board.size(), "shards", fmt::format("{} peers", addresses.size()));
    const std::optional<size_t> k = board.Take(std::chrono::milliseconds(200), !options_.local_shards);
    if (!k) {
      if (board.Finished()) break;
      continue;
    }
    const auto [begin, end] = board.range(*k);
    const auto t0 = Clock::now();
    const std::vector<WorldPoint> slice(viewpoints.begin() + std::ptrdiff_t(begin),
                                        viewpoints.begin() + std::ptrdiff_t(end));
    Result<std::vector<T>> items = local(slice, quiet);
    if (items.ok() && items->size() != slice.size()) {
      items = InternalError(fmt::format("{}: {} results for {} viewpoints", spec.what, items->size(), slice.size()));
    }
    if (!items.ok()) {
      board.Release(*k);
      status = items.status();
      break;
    }
    board.Deliver(*k, kSelf, std::move(*items), Seconds(Clock::now() - t0));
  }
  board.Stop();
  board.CancelLive();
  for (std::thread& t : threads) t.join();
  VC_RETURN_IF_ERROR(status);
  FanOutResult<T> out = std::move(board).Collect();
  spdlog::info("fan-out: {}: {} viewpoints in {} shards over {} replicas, {} retried, {} exchanged", spec.what,
               viewpoints.size(), out.distribution.shards, out.distribution.replicas, out.distribution.retried,
               HumanBytes(out.distribution.bytes_exchanged));
  return out;
}

Result<DistributedSets> PeerFanOut::Compute(const SceneRef& ref, const v1::PlanParameters& parameters,
                                            const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                            const VisibilitySetsOptions& options, const JobContext& ctx) {
  const ShardSpec spec{v1::SHARD_KIND_VISIBILITY_SETS, options.compact_gain, Stage::kVisibility,
                       "the visibility stage"};
  const LocalShard<VoxelSet> local = [&](const std::vector<WorldPoint>& slice, const JobContext& c) {
    return ComputeVisibilitySets(scene, slice, options, c);
  };
  VC_ASSIGN_OR_RETURN(FanOutResult<VoxelSet> got,
                      FanOut<VoxelSet>(ref, parameters, scene, viewpoints, spec, local, ctx));
  DistributedSets out{std::move(got.items), got.distribution, std::move(got.warnings)};
  if (options.max_set_bytes > 0) {
    uint64_t bytes = 0;
    for (const VoxelSet& s : out.sets) bytes += s.MemoryBytes();
    if (bytes > options.max_set_bytes) {
      return ResourceExhaustedError("the visibility sets of " + std::to_string(viewpoints.size()) + " positions need " +
                                    HumanBytes(bytes) +
                                    ", over half the memory budget; raise grid_spacing_m or "
                                    "resolution_m, lower max_range_m, or raise the memory budget");
    }
  }
  return out;
}

Result<DistributedFaceValues> PeerFanOut::ComputeFaceValues(const SceneRef& ref, const v1::PlanParameters& parameters,
                                                            const VoxelScene& scene,
                                                            const std::vector<WorldPoint>& stations,
                                                            const EvaluateOptions& options, const JobContext& ctx) {
  const ShardSpec spec{v1::SHARD_KIND_FACE_VALUES, 0, Stage::kReduction, "the reduction"};
  const LocalShard<SparseFaceValues> local = [&](const std::vector<WorldPoint>& slice,
                                                 const JobContext& c) -> Result<std::vector<SparseFaceValues>> {
    VC_ASSIGN_OR_RETURN(Evaluation e, Evaluate(scene, slice, options, c));
    return std::move(e.per_viewpoint_sparse_values);
  };
  VC_ASSIGN_OR_RETURN(FanOutResult<SparseFaceValues> got,
                      FanOut<SparseFaceValues>(ref, parameters, scene, stations, spec, local, ctx));
  return DistributedFaceValues{std::move(got.items), got.distribution, std::move(got.warnings)};
}

}  // namespace vc::server
