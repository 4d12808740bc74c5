// Small vc.v1 messages for the outbox and kept-jobs tests (no gRPC).
#pragma once

#include <cstddef>
#include <string>

#include "vc/v1/planner.pb.h"

namespace vc::testing {

inline v1::PlanResponse AcceptedMessage(const std::string& id) {
  v1::PlanResponse m;
  m.mutable_accepted()->set_job_id(id);
  return m;
}

inline v1::PlanResponse ProgressMessage(double fraction) {
  v1::PlanResponse m;
  m.mutable_progress()->set_fraction(fraction);
  return m;
}

// A voxels chunk of about `bytes` (a bulk message).
inline v1::PlanResponse BulkMessage(size_t bytes) {
  v1::PlanResponse m;
  m.mutable_voxels()->mutable_centers_xyz_m()->Resize(int(bytes / sizeof(float)), 0.f);
  return m;
}

}  // namespace vc::testing
