// ApplyServerLimits: what every job (Plan, Evaluate, a peer's shard) gets of this server.
#include "vc/server/server_options.h"

#include <gtest/gtest.h>

namespace vc::server {
namespace {

ServerOptions Server() {
  ServerOptions o;
  o.max_memory_budget_bytes = uint64_t{1} << 30;
  o.threads_per_job = 4;
  return o;
}

EvaluateJobOptions OneViewpoint() {
  EvaluateJobOptions o;
  o.viewpoints.emplace_back(1, 1, 1);
  return o;
}

TEST(ApplyServerLimits, CapsTheMemoryBudget) {
  PlanOptions big;
  big.memory_budget_bytes = uint64_t{8} << 30;
  const Result<PlanOptions> capped = ApplyServerLimits(Server(), big);
  ASSERT_TRUE(capped.ok()) << capped.status().ToString();
  EXPECT_EQ(capped->memory_budget_bytes, uint64_t{1} << 30);
  PlanOptions small;
  small.memory_budget_bytes = 1000;
  const Result<PlanOptions> kept = ApplyServerLimits(Server(), small);
  ASSERT_TRUE(kept.ok()) << kept.status().ToString();
  EXPECT_EQ(kept->memory_budget_bytes, 1000u);
}

TEST(ApplyServerLimits, ThreadsAreTheShareOrFewer) {
  for (const auto& [requested, expected] : {std::pair{0, 4}, std::pair{2, 2}, std::pair{4, 4}, std::pair{9, 4}}) {
    PlanOptions plan;
    plan.threads = requested;
    const Result<PlanOptions> p = ApplyServerLimits(Server(), plan);
    ASSERT_TRUE(p.ok()) << p.status().ToString();
    EXPECT_EQ(p->threads, expected) << "plan asked for " << requested;
    EvaluateJobOptions evaluate = OneViewpoint();
    evaluate.threads = requested;
    const Result<EvaluateJobOptions> e = ApplyServerLimits(Server(), evaluate);
    ASSERT_TRUE(e.ok()) << e.status().ToString();
    EXPECT_EQ(e->threads, expected) << "evaluation asked for " << requested;
  }
}

TEST(ApplyServerLimits, NegativeThreadsAreRefusedBeforeAnyOtherParameter) {
  PlanOptions plan;
  plan.threads = -2;
  plan.resolution_m = -1;
  const Result<PlanOptions> p = ApplyServerLimits(Server(), plan);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.status(), InvalidArgumentError("threads must be >= 0 (0 = the server's share)"));
  EvaluateJobOptions evaluate;  // no viewpoint either
  evaluate.threads = -1;
  const Result<EvaluateJobOptions> e = ApplyServerLimits(Server(), evaluate);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status(), InvalidArgumentError("threads must be >= 0 (0 = the server's share)"));
}

TEST(ApplyServerLimits, TheCappedOptionsAreValidated) {
  PlanOptions plan;
  plan.resolution_m = -1;
  EXPECT_EQ(ApplyServerLimits(Server(), plan).status().code(), StatusCode::kInvalidArgument);
  PlanOptions no_budget;
  no_budget.memory_budget_bytes = 0;
  EXPECT_EQ(ApplyServerLimits(Server(), no_budget).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ApplyServerLimits(Server(), EvaluateJobOptions{}).status().code(), StatusCode::kInvalidArgument)
      << "an evaluation without viewpoints";
}

}  // namespace
}  // namespace vc::server
