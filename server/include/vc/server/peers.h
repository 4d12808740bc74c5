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
// against this replica's by SceneFingerprint), so the plan is the single-replica plan.
//
// Peers are --peers addresses and every address --peers-dns resolves to, resolved again for each
// plan; a peer whose PeerHello answers with this replica's own id is this replica and is skipped.
// Channels are kept per address. Thread-safe: several plans may fan out at once.
#pragma once

#include <grpcpp/grpcpp.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/planner.h"
#include "vc/server/server_options.h"
#include "vc/v1/planner.grpc.pb.h"

namespace vc::server {

class PeerFanOut {
 public:
  // The scene as peers get it: by hash from their cache, or these bytes.
  struct SceneRef {
    std::string sha256;
    std::shared_ptr<const std::string> bytes;
    std::string source_name;
  };

  // INVALID_ARGUMENT / NOT_FOUND for an unreadable TLS file. `self_id` is this replica's PeerHello id.
  static Result<std::unique_ptr<PeerFanOut>> Create(const ServerOptions& options, std::string self_id);

  // The sets of `viewpoints` on `scene` (which `parameters` voxelized from `ref`), exactly as
  // ComputeVisibilitySets(scene, viewpoints, options, ctx); CANCELLED / DEADLINE_EXCEEDED from ctx.
  // Peers' failures are warnings, not errors.
  Result<DistributedSets> Compute(const SceneRef& ref, const v1::PlanParameters& parameters, const VoxelScene& scene,
                                  const std::vector<WorldPoint>& viewpoints, const VisibilitySetsOptions& options,
                                  const JobContext& ctx);

  // The peers' addresses now (--peers, then what --peers-dns resolves to); `warnings` gets a
  // name that does not resolve.
  std::vector<std::string> Addresses(std::vector<std::string>* warnings) const;

 private:
  PeerFanOut(const ServerOptions& options, std::string self_id, std::shared_ptr<grpc::ChannelCredentials> creds)
      : options_(options), self_id_(std::move(self_id)), creds_(std::move(creds)) {}
  std::shared_ptr<v1::StationPlanner::Stub> StubFor(const std::string& address);

  const ServerOptions options_;
  const std::string self_id_;
  const std::shared_ptr<grpc::ChannelCredentials> creds_;
  std::mutex mu_;
  std::map<std::string, std::shared_ptr<v1::StationPlanner::Stub>> stubs_;
};

}  // namespace vc::server
