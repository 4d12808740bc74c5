// PeerFanOut: a coordinating replica's side of scaling out (docs/DEPLOY.md, "Scaling out").
//
// A plan's visibility stage is split into shards of --shard-candidates viewpoints. This replica
// computes shards itself and, at the same time, one lane per peer sends shards to that peer
// (ComputeShard, after PeerHello and, if the peer lacks the scene, ShareScene). Every lane takes
// the next shard nobody has; when none is left, an idle lane starts again a shard that has run
// far longer than the shards finished so far (a slow or hung peer); the first answer wins. A lane
// whose peer fails is retired and its shard goes back to the others, so a peer that dies costs
// time, not the plan: this replica alone can always finish. The sets are the same whoever
// computes them (the computation is deterministic, and each peer's voxelization is checked
// against this replica's by SceneFingerprint), so the plan is the single-replica plan. The rules
// for shards and lanes are ShardBoard's and LaneRetryPolicy's (shard_board.h); peers.cc holds the
// gRPC lanes, the DNS lookup and the glue.
//
// Peers are --peers addresses and every address --peers-dns resolves to, resolved again for each
// plan; a peer whose PeerHello answers with this replica's own id is this replica and is skipped.
// Channels are kept per address. Thread-safe: several plans may fan out at once.
#pragma once

#include <grpcpp/grpcpp.h>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/planner.h"
#include "vc/server/server_options.h"
#include "vc/v1/planner.grpc.pb.h"

namespace vc::server {

template <class T>
struct FanOutResult;  // peers.cc

// One station's face values from a shard, and its figures when asked for and given with the join
// state (EvaluateOptions::keep_sparse_join_state).
struct StationFaceValues {
  SparseFaceValues values;
  std::optional<VisibilityFigures> figures;
};

// Viewpoints per shard of a fan-out of `viewpoints` (--shard-candidates = `shard_candidates`): that
// many for visibility sets. A station's face values cost several sets' worth and a reduction batch
// holds tens to hundreds of stations, so those are cut into at least kMinFaceValueShards shards
// where the stations allow, of at least kMinFaceValueShardStations (a small plan's few stations stay
// on the coordinator) and at most shard_candidates stations. (fr_campus's first reduction batch of
// 61 stations was one shard of 128, evaluated on the coordinator alone while the peers waited.)
inline constexpr size_t kMinFaceValueShards = 12;
inline constexpr size_t kMinFaceValueShardStations = 4;
[[nodiscard]] size_t ShardViewpoints(v1::ShardKind kind, size_t viewpoints, int shard_candidates);

class PeerFanOut {
 public:
  // The scene as peers get it: by hash from their cache, or these bytes.
  struct SceneRef {
    std::string sha256;
    std::shared_ptr<const std::string> bytes;
    std::string source_name;
    std::string units;  // UploadSpec.units: the peer reads the bytes in them (the same local frame)
  };

  // INVALID_ARGUMENT / NOT_FOUND for an unreadable TLS file. `self_id` is this replica's PeerHello id.
  static Result<std::unique_ptr<PeerFanOut>> Create(const ServerOptions& options, std::string self_id);

  // The sets of `viewpoints` on `scene` (which `parameters` voxelized from `ref`), exactly as
  // ComputeVisibilitySets(scene, viewpoints, options, ctx); CANCELLED / DEADLINE_EXCEEDED from ctx.
  // Peers' failures are warnings, not errors. `what` names the call in logs and warnings (a
  // string literal: VisibilitySetsFn).
  Result<DistributedSets> Compute(const SceneRef& ref, const v1::PlanParameters& parameters, const VoxelScene& scene,
                                  const std::vector<WorldPoint>& viewpoints, const VisibilitySetsOptions& options,
                                  const JobContext& ctx, const char* what);

  // The faces with V > 0 of each of `stations` on `scene`, exactly as vc::Evaluate(scene, stations,
  // options, ctx) with keep_sparse_per_viewpoint_values gives them (the reduction's evaluation);
  // `options` must be planner::ReductionEvaluateOptions of the plan's options (peers rebuild them
  // from `parameters`), with keep_sparse_join_state where the caller joins the values into an
  // evaluation (then DistributedFaceValues::figures, unless a peer is too old to give them).
  Result<DistributedFaceValues> ComputeFaceValues(const SceneRef& ref, const v1::PlanParameters& parameters,
                                                  const VoxelScene& scene, const std::vector<WorldPoint>& stations,
                                                  const EvaluateOptions& options, const JobContext& ctx);

  // The peers' addresses now (--peers, then what --peers-dns resolves to); `warnings` gets a
  // name that does not resolve.
  std::vector<std::string> Addresses(std::vector<std::string>* warnings) const;

 private:
  PeerFanOut(const ServerOptions& options, std::string self_id, std::shared_ptr<grpc::ChannelCredentials> creds)
      : options_(options), self_id_(std::move(self_id)), creds_(std::move(creds)) {}
  std::shared_ptr<v1::StationPlanner::Stub> StubFor(const std::string& address);

  // One kind of shard: what peers are asked for, how decoded sets are kept, and for progress and
  // messages, the stage and its name.
  struct ShardSpec {
    v1::ShardKind kind;
    double compact_gain;
    Stage stage;
    const char* what;
    bool join_state = false;  // face values: ask for their join state too
  };
  template <class T>
  using LocalShard = std::function<Result<std::vector<T>>(const std::vector<WorldPoint>&, const JobContext&)>;
  // The fan-out itself, for either kind: shards of `viewpoints` to the peers' lanes and this
  // replica's own, which computes with `local`.
  template <class T>
  Result<FanOutResult<T>> FanOut(const SceneRef& ref, const v1::PlanParameters& parameters, const VoxelScene& scene,
                                 const std::vector<WorldPoint>& viewpoints, const ShardSpec& spec,
                                 const LocalShard<T>& local, const JobContext& ctx);

  const ServerOptions options_;
  const std::string self_id_;
  const std::shared_ptr<grpc::ChannelCredentials> creds_;
  std::mutex mu_;
  std::map<std::string, std::shared_ptr<v1::StationPlanner::Stub>> stubs_;
};

}  // namespace vc::server
