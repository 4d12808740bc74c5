// SceneCache: the scenes this server was sent lately, by the SHA-256 of their bytes, so that a
// client planning the same scene again (other parameters, another evaluation) sends only its hash
// (docs/PROTOCOL.md, "The scene cache").
//
// Bounded by bytes (--scene-cache-bytes), least recently used out first; a scene larger than the
// whole cache is not kept. Nothing in it is needed: a replica may lose it at any time and a client
// that asks for a scene it no longer holds is told NOT_FOUND and uploads it. Thread-safe.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace vc::server {

class SceneCache {
 public:
  using Bytes = std::shared_ptr<const std::string>;

  explicit SceneCache(uint64_t capacity_bytes) : capacity_bytes_(capacity_bytes) {}

  // The scene named `sha256` (and it becomes the most recently used), or null.
  Bytes Get(const std::string& sha256);
  // Keeps `bytes` under `sha256` (which the caller has checked), evicting the least recently used
  // scenes until it fits; a scene over the capacity is not kept. False when not kept.
  bool Put(const std::string& sha256, Bytes bytes);

  uint64_t capacity_bytes() const { return capacity_bytes_; }
  uint64_t bytes() const;
  size_t scenes() const;

 private:
  struct Entry {
    std::string sha256;
    Bytes bytes;
  };
  const uint64_t capacity_bytes_;
  mutable std::mutex mu_;
  std::list<Entry> lru_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> index_;
  uint64_t bytes_ = 0;
};

}  // namespace vc::server
