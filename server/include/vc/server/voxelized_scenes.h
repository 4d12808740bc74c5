// VoxelizedScenes: the scenes a replica has voxelized for its peers' shards (docs/DEPLOY.md,
// "Scaling out"), so that the many shards of one plan read and voxelize the scene once.
//
// Keyed by the scene's SHA-256, the working resolution and the input's units (ShardRequest.units); the few most
// recently used are kept (a replica serves one or two plans' shards at a time). Two shards asking for the same scene at
// once share one voxelization; a failed one is not kept. Thread-safe.
#pragma once

#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <string>

#include "vc/base/status.h"
#include "vc/scene/voxel_scene.h"

namespace vc::server {

// CRC32C of the scene's resolution, its frame's origin (when not zero) and occupied keys, in order: a coordinator
// checks with it that a peer's voxelization is its own (same build, same input).
uint32_t SceneFingerprint(const VoxelScene& scene);

// The key of a shared scene's voxelization: its SHA-256, the working resolution and the input's
// units (UploadSpec.units), which change the scene's scale and local frame as the resolution does.
std::string VoxelizedSceneKey(const std::string& sha256, double resolution_m, const std::string& units);

class VoxelizedScenes {
 public:
  using Scene = std::shared_ptr<const VoxelScene>;
  using MakeFn = std::function<Result<VoxelScene>()>;

  explicit VoxelizedScenes(size_t capacity) : capacity_(capacity) {}

  // The scene under `key`, made by `make` (on this thread) if no one has or is making it.
  Result<Scene> Get(const std::string& key, const MakeFn& make);
  size_t size() const;

 private:
  struct Entry {
    std::string key;
    uint64_t id = 0;  // tells a failed entry from a later retry's
    std::shared_future<Result<Scene>> scene;
  };
  const size_t capacity_;
  mutable std::mutex mu_;
  uint64_t next_id_ = 0;
  std::list<Entry> lru_;  // most recently used first
};

}  // namespace vc::server
