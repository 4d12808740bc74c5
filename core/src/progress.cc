#include "vc/core/progress.h"

namespace vc {

bool CancelToken::cancelled() const {
  if (cancelled_.load(std::memory_order_relaxed)) return true;
  return deadline_ && std::chrono::steady_clock::now() >= *deadline_;
}

Status CancelToken::Check(const char* what) const {
  if (cancelled_.load(std::memory_order_relaxed)) {
    return CancelledError(std::string(what) + " was cancelled");
  }
  if (deadline_ && std::chrono::steady_clock::now() >= *deadline_) {
    return DeadlineExceededError(std::string(what) + " ran past the deadline");
  }
  return Status::Ok();
}

}  // namespace vc
