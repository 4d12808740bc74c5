// The scanner model on the wire (vc/wire/convert.h): ScannerModel.name selects an instrument preset
// (vc/visibility/scanner_presets.h), the fields that are set override it, and an unknown name is
// INVALID_ARGUMENT naming scanner.name.
#include <gtest/gtest.h>

#include <string>

#include "vc/visibility/scanner_presets.h"
#include "vc/wire/convert.h"

namespace vc {
namespace {

#define VC_EXPECT_ROW_EQ(type, name, ...) EXPECT_EQ(got.name, want.name) << #name;

void ExpectSameModel(const ScannerModel& got, const ScannerModel& want) {
  EXPECT_EQ(got.name, want.name);
  VC_SCANNER_PARAMETERS(VC_EXPECT_ROW_EQ)
}

TEST(ScannerConvertTest, APresetNameAloneGivesThePresetsValues) {
  for (const ScannerPreset& preset : ScannerPresets()) {
    SCOPED_TRACE(std::string(preset.name));
    v1::PlanParameters plan;
    plan.mutable_scanner()->set_name(std::string(preset.name));
    const Result<PlanOptions> p = wire::FromProto(plan);
    ASSERT_TRUE(p.ok()) << p.status().ToString();
    ExpectSameModel(p->scanner, preset.model);

    v1::EvaluateParameters eval;
    eval.mutable_scanner()->set_name(std::string(preset.name));
    const Result<EvaluateJobOptions> e = wire::FromProto(eval);
    ASSERT_TRUE(e.ok()) << e.status().ToString();
    ExpectSameModel(e->scanner, preset.model);
  }
}

TEST(ScannerConvertTest, APresetModelRoundTrips) {
  PlanOptions o;
  o.scanner = *ScannerFromPreset("zf-imager-5016");
  const Result<PlanOptions> back = wire::FromProto(wire::ToProto(o));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ExpectSameModel(back->scanner, o.scanner);
}

TEST(ScannerConvertTest, AnExplicitFieldOverridesThePreset) {
  v1::PlanParameters plan;
  plan.mutable_scanner()->set_name("leica-rtc360");
  plan.mutable_scanner()->set_max_range_m(40.0);
  plan.mutable_scanner()->set_max_incidence_deg(70.0);
  const Result<PlanOptions> p = wire::FromProto(plan);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ScannerModel want = *ScannerFromPreset("leica-rtc360");
  want.max_range_m = 40.0;
  want.max_incidence_deg = 70.0;
  ExpectSameModel(p->scanner, want);
}

TEST(ScannerConvertTest, AModelWithoutANameIsCustom) {
  v1::PlanParameters plan;
  plan.mutable_scanner()->set_max_range_m(40.0);
  const Result<PlanOptions> p = wire::FromProto(plan);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ScannerModel want;
  want.max_range_m = 40.0;
  ExpectSameModel(p->scanner, want);
  EXPECT_TRUE(p->scanner.name.empty());
}

TEST(ScannerConvertTest, AnUnknownPresetIsInvalidArgumentNamingScannerName) {
  v1::EvaluateParameters eval;
  eval.mutable_scanner()->set_name("leica-p50");
  const Result<EvaluateJobOptions> e = wire::FromProto(eval);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(e.status().message().find("scanner.name"), std::string::npos) << e.status().message();
  EXPECT_NE(e.status().message().find("leica-p50"), std::string::npos) << e.status().message();
  EXPECT_NE(e.status().message().find("leica-rtc360"), std::string::npos) << e.status().message();
}

#undef VC_EXPECT_ROW_EQ

}  // namespace
}  // namespace vc
