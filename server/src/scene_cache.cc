#include "vc/server/scene_cache.h"

namespace vc::server {

SceneCache::Bytes SceneCache::Get(const std::string& sha256) {
  std::lock_guard lock(mu_);
  const auto it = index_.find(sha256);
  if (it == index_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->bytes;
}

bool SceneCache::Put(const std::string& sha256, Bytes bytes) {
  if (!bytes || bytes->size() > capacity_bytes_) return false;
  std::lock_guard lock(mu_);
  if (const auto it = index_.find(sha256); it != index_.end()) {
    lru_.splice(lru_.begin(), lru_, it->second);
    return true;
  }
  while (!lru_.empty() && bytes_ + bytes->size() > capacity_bytes_) {
    bytes_ -= lru_.back().bytes->size();
    index_.erase(lru_.back().sha256);
    lru_.pop_back();
  }
  bytes_ += bytes->size();
  lru_.push_front({sha256, std::move(bytes)});
  index_[sha256] = lru_.begin();
  return true;
}

uint64_t SceneCache::bytes() const {
  std::lock_guard lock(mu_);
  return bytes_;
}

size_t SceneCache::scenes() const {
  std::lock_guard lock(mu_);
  return lru_.size();
}

}  // namespace vc::server
