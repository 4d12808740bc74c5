#include "vc/plan/plan_options.h"

#include <string>

#include "format.h"

namespace vc {

using planner::Num;

Status PlanOptions::Validate() const {
#define VC_CHECK_ROW(type, name, ...) \
  VC_RETURN_IF_ERROR(CheckParameter(VC_PARAMETER_INFO(type, name, __VA_ARGS__), name));
  VC_PLAN_PARAMETERS(VC_CHECK_ROW)
#undef VC_CHECK_ROW
  VC_RETURN_IF_ERROR(scanner.Validate());
  if (clearance_m >= tripod_height_m) {
    return InvalidArgumentError("clearance_m (" + Num(clearance_m) + " m) must be smaller than tripod_height_m (" +
                                Num(tripod_height_m) + " m): the scanner would touch the floor");
  }
  if (refine && refine_step_m > refine_radius_m) {
    return InvalidArgumentError("refine_step_m (" + Num(refine_step_m) + " m) must not exceed refine_radius_m (" +
                                Num(refine_radius_m) + " m)");
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (!candidates[i].allFinite()) return InvalidArgumentError("candidates[" + std::to_string(i) + "] is not finite");
  }
  return Status::Ok();
}

}  // namespace vc
