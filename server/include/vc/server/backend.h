// Backend: the core functions a job calls. The service calls them through this struct so tests
// can substitute a function that blocks until cancelled (to prove cancellation frees a worker);
// production uses the defaults, which are vc::ReadScene, vc::Plan and vc::RunEvaluation.
#pragma once

#include <functional>
#include <string_view>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/evaluate_job.h"
#include "vc/plan/planner.h"
#include "vc/scene/scene_input.h"
#include "vc/visibility/visibility.h"
#include "vc/wire/convert.h"

namespace vc::server {

struct Backend {
  std::function<Result<SceneInput>(std::string_view bytes, std::string_view source, const ReadOptions&)> read_scene;
  std::function<Result<PlanResult>(const SceneInput&, const PlanOptions&, const JobContext&, const PlanCallbacks&)>
      plan;
  std::function<Result<EvaluateJobResult>(const SceneInput&, const EvaluateJobOptions&, const JobContext&)> evaluate;

  // The production backend.
  static Backend Default();
};

}  // namespace vc::server
