#include "vc/server/voxelized_scenes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "vc/base/crc32c.h"

namespace vc::server {

uint32_t SceneFingerprint(const VoxelScene& scene) {
  Crc32c crc;
  char resolution[sizeof(double)];
  std::memcpy(resolution, &scene.resolution_m, sizeof(double));
  crc.Update(std::string_view(resolution, sizeof(resolution)));
  if (!scene.frame_origin_m.isZero()) {  // the local frame (SceneInput::frame_origin_m) is part of the scene
    char origin[3 * sizeof(double)];
    std::memcpy(origin, scene.frame_origin_m.data(), sizeof(origin));
    crc.Update(std::string_view(origin, sizeof(origin)));
  }
  for (const VoxelKey& k : scene.occupied) {
    const char key[6] = {char(k.x & 0xff), char(k.x >> 8),   char(k.y & 0xff),
                         char(k.y >> 8),   char(k.z & 0xff), char(k.z >> 8)};
    crc.Update(std::string_view(key, sizeof(key)));
  }
  return crc.value();
}

std::string VoxelizedSceneKey(const std::string& sha256, double resolution_m, const std::string& units) {
  return fmt::format("{}@{:a}/{}", sha256, resolution_m, units.empty() ? "m" : units);
}

Result<VoxelizedScenes::Scene> VoxelizedScenes::Get(const std::string& key, const MakeFn& make) {
  std::promise<Result<Scene>> promise;
  std::shared_future<Result<Scene>> existing;
  uint64_t mine = 0;
  {
    std::lock_guard lock(mu_);
    const auto it = std::find_if(lru_.begin(), lru_.end(), [&](const Entry& e) { return e.key == key; });
    if (it != lru_.end()) {
      lru_.splice(lru_.begin(), lru_, it);
      existing = it->scene;
    } else {
      mine = ++next_id_;
      lru_.push_front({key, mine, promise.get_future().share()});
      while (lru_.size() > capacity_) lru_.pop_back();
    }
  }
  if (existing.valid()) return existing.get();
  Result<VoxelScene> made = InternalError("voxelizing the scene failed");
  try {
    made = make();
  } catch (const std::bad_alloc&) {
    made = ResourceExhaustedError("this replica ran out of memory voxelizing the scene");
  } catch (const std::exception& e) {
    made = InternalError(std::string("voxelizing the scene failed: ") + e.what());
  }
  Result<Scene> result =
      made.ok() ? Result<Scene>(std::make_shared<const VoxelScene>(std::move(*made))) : Result<Scene>(made.status());
  promise.set_value(result);
  if (!result.ok()) {
    std::lock_guard lock(mu_);
    lru_.remove_if([&](const Entry& e) { return e.id == mine; });
  }
  return result;
}

size_t VoxelizedScenes::size() const {
  std::lock_guard lock(mu_);
  return lru_.size();
}

}  // namespace vc::server
