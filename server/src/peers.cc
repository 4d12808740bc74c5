#include "vc/server/peers.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netdb.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <optional>
#include <thread>
#include <type_traits>

#include "vc/server/server.h"
#include "vc/server/shard_board.h"
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

using Attempt = ShardBoard::Attempt;

// ShareScene sends the scene in chunks of this many bytes.
constexpr size_t kSceneChunkBytes = size_t{1} << 20;
constexpr auto kHelloDeadline = std::chrono::seconds(10);
constexpr auto kShareSceneDeadline = std::chrono::minutes(10);
// A peer lane waits this long for a shard at a time; it ends only when the board finishes.
constexpr auto kPeerLaneWait = std::chrono::hours(1);
// This replica's own lane checks cancellation and reports progress this often while it waits.
constexpr auto kOwnLaneWait = std::chrono::milliseconds(200);
const std::string kSelf = "this replica";

std::string GrpcError(const grpc::Status& s) { return wire::FromGrpcStatus(s).ToString(); }

// The bearer token this replica presents to its peers: --peer-token, else its first --token.
std::string PeerToken(const ServerOptions& options) {
  if (!options.peer_token.empty()) return options.peer_token;
  return options.tokens.empty() ? std::string() : options.tokens.front();
}

// What a peer needs of the plan's parameters (RunShard in peer_service.cc): the voxelization
// (resolution, memory budget), the selection test, the scanner and the sets' form. The others keep
// their defaults there (the peer computes with its own thread share), and the lists (candidates,
// keep-out zones, fixed stations), which may be long, are not sent.
v1::PlanParameters ShardParameters(const v1::PlanParameters& plan) {
  v1::PlanParameters shard;
  if (plan.has_resolution_m()) shard.set_resolution_m(plan.resolution_m());
  if (plan.has_memory_budget_bytes()) shard.set_memory_budget_bytes(plan.memory_budget_bytes());
  if (plan.has_selection_test()) shard.set_selection_test(plan.selection_test());
  if (plan.has_scanner()) *shard.mutable_scanner() = plan.scanner();
  if (plan.has_sparse_set_gain()) shard.set_sparse_set_gain(plan.sparse_set_gain());
  return shard;
}

// Everything one peer lane needs.
struct LaneJob {
  const PeerFanOut::SceneRef& ref;
  const v1::PlanParameters& parameters;
  const std::vector<WorldPoint>& viewpoints;
  uint64_t occupied_voxels;
  uint32_t fingerprint;
  const std::string& token;
  const std::string& self_id;
  std::chrono::milliseconds shard_deadline;
  v1::ShardKind kind;
  double compact_gain;  // the sets arrive sparse where the plan keeps them sparse
  const char* what;     // the stage, for messages
  bool join_state;      // face values: ask for their join state (ShardRequest.keep_join_state)
};

// `count` items decoded one by one from `encoded` with `decode`; DATA_LOSS saying `mismatch(n)`
// when a peer answered n items instead.
template <class T, class Encoded, class Decode, class Mismatch>
Result<std::vector<T>> DecodeEach(const google::protobuf::RepeatedPtrField<Encoded>& encoded, size_t count,
                                  const Decode& decode, const Mismatch& mismatch) {
  if (size_t(encoded.size()) != count) return DataLossError(mismatch(encoded.size()));
  std::vector<T> items;
  items.reserve(count);
  for (const Encoded& e : encoded) {
    VC_ASSIGN_OR_RETURN(T item, decode(e));
    items.push_back(std::move(item));
  }
  return items;
}

// A shard's items from a peer's answer (its voxelization already checked).
template <class T>
Result<std::vector<T>> DecodeItems(const v1::ShardResponse& resp, size_t count, const LaneJob& job) {
  if constexpr (std::is_same_v<T, VoxelSet>) {
    return DecodeEach<VoxelSet>(
        resp.sets(), count,
        [&](const std::string& b) { return wire::DecodeVoxelSet(b, job.occupied_voxels, job.compact_gain); },
        [&](int n) { return fmt::format("it answered {} sets for {} viewpoints", n, count); });
  } else {
    static_assert(std::is_same_v<T, StationFaceValues>);
    return DecodeEach<StationFaceValues>(
        resp.face_values(), count,
        [&](const v1::FaceValues& m) -> Result<StationFaceValues> {
          VC_ASSIGN_OR_RETURN(SparseFaceValues v, wire::DecodeFaceValues(m, job.occupied_voxels * kFacesPerVoxel));
          StationFaceValues out{std::move(v), std::nullopt};
          // An older replica ignores keep_join_state and answers without figures (or join state).
          if (job.join_state && m.has_figures() && out.values.HasJoinState()) {
            const VisibilityFigures f = wire::FromProto(m.figures());
            for (const double x : {f.global_visibility, f.fully_visible_fraction, f.mean_full_visibility,
                                   f.partially_visible_fraction}) {
              // Each figure is a mean of values in [0, 1] or a share of F; anything else is not Evaluate's.
              if (!(x >= 0 && x <= 1))
                return DataLossError(fmt::format(
                    "a station's figures (G {}, fully visible {}, mean full V {}, partially visible {}) are not "
                    "all finite and within [0, 1]",
                    f.global_visibility, f.fully_visible_fraction, f.mean_full_visibility,
                    f.partially_visible_fraction));
            }
            out.figures = f;
          }
          return out;
        },
        [&](int n) { return fmt::format("it answered face values of {} stations for {}", n, count); });
  }
}

// One peer's lane: PeerHello, ShareScene if the peer lacks the scene, then ComputeShard for one
// shard after another from the board, until the board finishes or the peer is retired
// (LaneRetryPolicy). Answers go into `results`, by shard.
template <class T>
class PeerLane {
 public:
  PeerLane(size_t index, std::string address, std::shared_ptr<v1::StationPlanner::Stub> stub, const LaneJob& job,
           ShardBoard& board, std::vector<std::vector<T>>& results)
      : index_(index),
        address_(std::move(address)),
        stub_(std::move(stub)),
        job_(job),
        board_(board),
        results_(results) {}

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
  void Prepare(grpc::ClientContext& c, std::chrono::milliseconds deadline) const {
    c.set_deadline(std::chrono::system_clock::now() + deadline);
    if (!job_.token.empty()) c.AddMetadata("authorization", "Bearer " + job_.token);
  }
  // While alive, `c` is the lane's call the board cancels when it stops (exception-safe: the
  // board never sees a context that is gone).
  class LiveCall {
   public:
    LiveCall(ShardBoard& board, size_t lane, grpc::ClientContext& c)
        : board_(board), lane_(lane), live_(board.SetLive(lane, [&c] { c.TryCancel(); })) {}
    ~LiveCall() {
      if (live_) board_.SetLive(lane_, nullptr);
    }
    bool live() const { return live_; }

   private:
    ShardBoard& board_;
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
    Prepare(c, kShareSceneDeadline);
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

  // ComputeShard for the attempt's viewpoints; nullopt when the board has stopped.
  std::optional<grpc::Status> ComputeShard(const Attempt& a, v1::ShardResponse* resp) {
    v1::ShardRequest req;
    req.set_scene_sha256(job_.ref.sha256);
    req.set_source_name(job_.ref.source_name);
    req.set_units(job_.ref.units);
    *req.mutable_parameters() = job_.parameters;
    req.set_first_index(a.begin);
    req.set_kind(job_.kind);
    req.set_keep_join_state(job_.join_state);
    for (size_t i = a.begin; i < a.end; ++i) *req.add_viewpoints() = wire::ToProto(job_.viewpoints[i]);
    grpc::ClientContext c;
    Prepare(c, job_.shard_deadline);
    const auto s = Call(c, [&] { return stub_->ComputeShard(&c, req, resp); });
    if (s) board_.AddBytes(req.ByteSizeLong() + resp->ByteSizeLong());
    return s;
  }

  // Decodes and checks a peer's answer for the attempt's viewpoints.
  Result<std::vector<T>> Decode(const v1::ShardResponse& resp, const Attempt& a) const {
    if (resp.occupied_voxels() != job_.occupied_voxels || resp.scene_crc32c() != job_.fingerprint) {
      return FailedPreconditionError(fmt::format(
          "its voxelization differs from this replica's ({} voxels, CRC32C {:08x}, against {} and {:08x}): is it "
          "another version of vc-server?",
          resp.occupied_voxels(), resp.scene_crc32c(), job_.occupied_voxels, job_.fingerprint));
    }
    return DecodeItems<T>(resp, a.end - a.begin, job_);
  }

  // The attempt failed: its shard goes back to the board.
  void ReleaseHeld() {
    board_.Release(*held_);
    held_.reset();
  }

  // One attempt on the peer; false when the lane ends.
  bool RunAttempt(const Attempt a) {
    v1::ShardResponse resp;
    const std::optional<grpc::Status> s = ComputeShard(a, &resp);
    if (!s) {
      ReleaseHeld();
      return false;
    }
    if (s->ok()) {
      Result<std::vector<T>> items = Decode(resp, a);
      if (!items.ok()) {
        ReleaseHeld();
        Retire(items.status().message());
        return false;
      }
      const bool first = board_.Deliver(a, address_);
      held_.reset();
      if (first) results_[a.shard] = std::move(*items);
      policy_.OnAnswer();
      return true;
    }
    ReleaseHeld();
    if (board_.Finished()) return false;
    const LaneRetryPolicy::Decision d = policy_.OnFailure(wire::FromGrpcStatus(*s));
    switch (d.action) {
      case LaneRetryPolicy::Action::kRetry:
        return true;
      case LaneRetryPolicy::Action::kShareSceneAgain:
        return Share();
      case LaneRetryPolicy::Action::kBackOff:
        board_.Sleep(kBusyBackOff);
        return true;
      case LaneRetryPolicy::Action::kRetire:
        Retire(d.retire_reason);
        return false;
    }
    return false;
  }

  void RunLane() {
    bool has_scene = false;
    if (!Hello(&has_scene)) return;
    if (!has_scene && !Share()) return;
    while (true) {
      held_ = board_.Take(kPeerLaneWait);
      if (!held_) {
        if (board_.Finished()) return;
        continue;
      }
      if (!RunAttempt(*held_)) return;
    }
  }

  const size_t index_;
  const std::string address_;
  const std::shared_ptr<v1::StationPlanner::Stub> stub_;
  const LaneJob& job_;
  ShardBoard& board_;
  std::vector<std::vector<T>>& results_;
  LaneRetryPolicy policy_;
  std::optional<Attempt> held_;  // the attempt this lane runs, released if the lane throws
};

// The peer lanes' threads. Every way out of a fan-out (an exception included) stops the board and
// joins them first: they hold references to the board, the job and the results.
class LaneThreads {
 public:
  explicit LaneThreads(ShardBoard& board) : board_(board) {}
  LaneThreads(const LaneThreads&) = delete;
  LaneThreads& operator=(const LaneThreads&) = delete;
  ~LaneThreads() { StopAndJoin(); }

  void Start(std::function<void()> run) { threads_.emplace_back(std::move(run)); }
  void StopAndJoin() {
    board_.Stop();
    for (std::thread& t : threads_) {
      if (t.joinable()) t.join();
    }
  }

 private:
  ShardBoard& board_;
  std::vector<std::thread> threads_;
};

// How this replica's own lane runs: for progress and messages, the stage, its name and the
// number of peers; whether it leaves fresh shards to the peers (--local-shards=false).
struct OwnLane {
  Stage stage;
  const char* what;
  size_t peers;
  bool defer;
};

// This replica's own lane, on the plan's thread (progress and cancellation are checked here):
// shards computed with `local` until the board finishes. CANCELLED / DEADLINE_EXCEEDED from ctx,
// and `local`'s errors.
template <class T, class Local>
Status RunOwnLane(ShardBoard& board, const std::vector<WorldPoint>& viewpoints, const Local& local, const OwnLane& lane,
                  std::vector<std::vector<T>>& results, const JobContext& ctx) {
  JobContext quiet = ctx;
  quiet.progress = nullptr;
  while (true) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled(lane.what));
    ctx.ReportCount(lane.stage, board.done(), board.size(), "shards", fmt::format("{} peers", lane.peers));
    const std::optional<Attempt> a = board.Take(kOwnLaneWait, lane.defer);
    if (!a) {
      if (board.Finished()) return Status::Ok();
      continue;
    }
    const std::vector<WorldPoint> slice(viewpoints.begin() + std::ptrdiff_t(a->begin),
                                        viewpoints.begin() + std::ptrdiff_t(a->end));
    const auto started = std::chrono::steady_clock::now();
    Result<std::vector<T>> items = local(slice, quiet);
    // As a peer logs its ComputeShard, so that every shard's compute time is in the logs.
    spdlog::info("fan-out: {}: own shard viewpoints={}+{} elapsed={:.3f}s", lane.what, a->begin, slice.size(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    if (items.ok() && items->size() != slice.size()) {
      items = InternalError(fmt::format("{}: {} results for {} viewpoints", lane.what, items->size(), slice.size()));
    }
    if (!items.ok()) {
      board.Release(*a);
      return items.status();
    }
    if (board.Deliver(*a, kSelf)) results[a->shard] = std::move(*items);
  }
}

// The shards' items, in viewpoint order.
template <class T>
std::vector<T> Concatenate(std::vector<std::vector<T>>& results) {
  std::vector<T> items;
  for (std::vector<T>& r : results) {
    for (T& item : r) items.push_back(std::move(item));
  }
  return items;
}

std::string JoinHostPort(const sockaddr* sa, const std::string& port) {
  char host[INET6_ADDRSTRLEN] = {};
  if (sa->sa_family == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(sa)->sin_addr, host, sizeof(host));
    return std::string(host) + ":" + port;
  }
  inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(sa)->sin6_addr, host, sizeof(host));
  std::string joined = "[";
  joined += host;
  joined += "]:";
  joined += port;
  return joined;
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

size_t ShardViewpoints(v1::ShardKind kind, size_t viewpoints, int shard_candidates) {
  const size_t most = size_t(std::max(shard_candidates, 1));
  if (kind != v1::SHARD_KIND_FACE_VALUES) return most;
  const size_t spread = (viewpoints + kMinFaceValueShards - 1) / kMinFaceValueShards;
  return std::min(most, std::max(spread, kMinFaceValueShardStations));
}

template <class T>
Result<FanOutResult<T>> PeerFanOut::FanOut(const SceneRef& ref, const v1::PlanParameters& parameters,
                                           const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                           const ShardSpec& spec, const LocalShard<T>& local, const JobContext& ctx) {
  ShardBoard board(viewpoints.size(), ShardViewpoints(spec.kind, viewpoints.size(), options_.shard_candidates));
  std::vector<std::vector<T>> results(board.size());
  std::vector<std::string> warnings;
  const std::vector<std::string> addresses = board.size() > 1 ? Addresses(&warnings) : std::vector<std::string>{};
  for (std::string& w : warnings) board.Warn(std::move(w));
  const std::string token = PeerToken(options_);
  const v1::PlanParameters shard_parameters = ShardParameters(parameters);
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
                    spec.what,
                    spec.join_state};
  std::vector<std::unique_ptr<PeerLane<T>>> lanes;
  LaneThreads threads(board);  // declared after what the lanes use, so joined before it goes
  for (size_t i = 0; i < addresses.size(); ++i) {
    lanes.push_back(std::make_unique<PeerLane<T>>(i, addresses[i], StubFor(addresses[i]), job, board, results));
    board.LaneStarted();
    threads.Start([lane = lanes.back().get()] { lane->Run(); });
  }
  const OwnLane own{spec.stage, spec.what, addresses.size(), !options_.local_shards};
  const Status status = RunOwnLane<T>(board, viewpoints, local, own, results, ctx);
  threads.StopAndJoin();
  VC_RETURN_IF_ERROR(status);
  FanOutResult<T> out{Concatenate(results), board.distribution(), board.TakeWarnings()};
  spdlog::info("fan-out: {}: {} viewpoints in {} shards over {} replicas, {} retried, {} exchanged", spec.what,
               viewpoints.size(), out.distribution.shards, out.distribution.replicas, out.distribution.retried,
               HumanBytes(out.distribution.bytes_exchanged));
  return out;
}

Result<DistributedSets> PeerFanOut::Compute(const SceneRef& ref, const v1::PlanParameters& parameters,
                                            const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints,
                                            const VisibilitySetsOptions& options, const JobContext& ctx,
                                            const char* what) {
  const ShardSpec spec{v1::SHARD_KIND_VISIBILITY_SETS, options.compact_gain, Stage::kVisibility, what, false};
  const LocalShard<VoxelSet> local = [&](const std::vector<WorldPoint>& slice, const JobContext& c) {
    return ComputeVisibilitySets(scene, slice, options, c);
  };
  VC_ASSIGN_OR_RETURN(FanOutResult<VoxelSet> got,
                      FanOut<VoxelSet>(ref, parameters, scene, viewpoints, spec, local, ctx));
  uint64_t set_bytes = 0;
  for (const VoxelSet& s : got.items) set_bytes += s.MemoryBytes();
  VC_RETURN_IF_ERROR(CheckSetBytes(set_bytes, viewpoints.size(), scene.occupied.size(), options.max_set_bytes));
  return DistributedSets{std::move(got.items), got.distribution, std::move(got.warnings)};
}

Result<DistributedFaceValues> PeerFanOut::ComputeFaceValues(const SceneRef& ref, const v1::PlanParameters& parameters,
                                                            const VoxelScene& scene,
                                                            const std::vector<WorldPoint>& stations,
                                                            const EvaluateOptions& options, const JobContext& ctx) {
  const ShardSpec spec{v1::SHARD_KIND_FACE_VALUES, 0, Stage::kReduction, "the reduction",
                       options.keep_sparse_join_state};
  const LocalShard<StationFaceValues> local = [&](const std::vector<WorldPoint>& slice,
                                                  const JobContext& c) -> Result<std::vector<StationFaceValues>> {
    VC_ASSIGN_OR_RETURN(Evaluation e, Evaluate(scene, slice, options, c));
    std::vector<StationFaceValues> out;
    out.reserve(slice.size());
    for (size_t k = 0; k < slice.size(); ++k) {
      out.push_back({std::move(e.per_viewpoint_sparse_values[k]), std::nullopt});
      if (options.keep_sparse_join_state) out.back().figures = e.per_viewpoint[k];
    }
    return out;
  };
  VC_ASSIGN_OR_RETURN(FanOutResult<StationFaceValues> got,
                      FanOut<StationFaceValues>(ref, parameters, scene, stations, spec, local, ctx));
  DistributedFaceValues out{{}, {}, got.distribution, std::move(got.warnings)};
  // The figures only when every station has them: one older replica's shard leaves the join out.
  bool joinable = options.keep_sparse_join_state;
  for (const StationFaceValues& s : got.items) joinable = joinable && s.figures.has_value();
  out.values.reserve(got.items.size());
  if (joinable) out.figures.reserve(got.items.size());
  for (StationFaceValues& s : got.items) {
    out.values.push_back(std::move(s.values));
    if (joinable) out.figures.push_back(*s.figures);
  }
  return out;
}

}  // namespace vc::server
