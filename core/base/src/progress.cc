#include "vc/base/progress.h"

namespace vc {

std::string_view StageName(Stage stage) {
  switch (stage) {
    case Stage::kUnspecified:
      return "unspecified";
    case Stage::kRead:
      return "read";
    case Stage::kVoxelize:
      return "voxelize";
    case Stage::kCandidates:
      return "candidates";
    case Stage::kVisibility:
      return "visibility";
    case Stage::kSelection:
      return "selection";
    case Stage::kRefine:
      return "refine";
    case Stage::kReduction:
      return "reduction";
    case Stage::kEvaluation:
      return "evaluation";
    case Stage::kRoute:
      return "route";
  }
  return "unspecified";
}

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
