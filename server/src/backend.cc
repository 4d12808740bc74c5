#include "vc/server/backend.h"

namespace vc::server {

Backend Backend::Default() {
  Backend b;
  b.read_scene = [](std::string_view bytes, std::string_view source, const ReadOptions& o) {
    return ReadScene(bytes, source, o);
  };
  b.plan = [](const SceneInput& in, const PlanOptions& o, const JobContext& ctx, const PlanCallbacks& cb) {
    return Plan(in, o, ctx, cb);
  };
  b.evaluate = [](const SceneInput& in, const EvaluateJobOptions& o, const JobContext& ctx) {
    return RunEvaluation(in, o, ctx);
  };
  return b;
}

}  // namespace vc::server
