#include "vc/client/parameter_flags.h"

#include <map>
#include <string>

namespace vc::client {
namespace {

std::string Help(const ParamInfo& info) {
  std::string help(info.help);
  if (!info.unit.empty()) help += " (" + std::string(info.unit) + ")";
  return help;
}

std::string Flag(const ParamInfo& info) { return "--" + std::string(info.flag); }

template <typename T>
void AddFlag(CLI::App* app, const ParamInfo& info, T* value) {
  app->add_option(Flag(info), *value, Help(info))->capture_default_str();
}

void AddFlag(CLI::App* app, const ParamInfo& info, bool* value) {
  app->add_flag(Flag(info) + ",!--no-" + std::string(info.flag), *value, Help(info))->capture_default_str();
}

// An enum flag that takes the value's name.
template <typename E>
void AddEnumFlag(CLI::App* app, const ParamInfo& info, E* value, const std::map<std::string, E>& names) {
  std::string shown, choices;
  for (const auto& [name, v] : names) {
    if (v == *value) shown = name;
    choices += (choices.empty() ? "" : "|") + name;
  }
  app->add_option(Flag(info), *value, Help(info))
      ->transform(CLI::CheckedTransformer(names, CLI::ignore_case).description(""))
      ->type_name(choices)
      ->default_str(shown);
}

void AddFlag(CLI::App* app, const ParamInfo& info, SelectionTest* value) {
  AddEnumFlag(app, info, value,
              {{"surface", SelectionTest::kSurfaceVisibility}, {"compatibility", SelectionTest::kCompatibility}});
}

void AddFlag(CLI::App* app, const ParamInfo& info, FaceSet* value) {
  AddEnumFlag(app, info, value, {{"all", FaceSet::kAll}, {"exposed", FaceSet::kExposed}});
}

#define VC_ROW_FLAG(type, name, ...) AddFlag(command, VC_PARAMETER_INFO(type, name, __VA_ARGS__), &o->name);

void AddScannerFlags(CLI::App* command, ScannerModel* o) { VC_SCANNER_PARAMETERS(VC_ROW_FLAG) }

}  // namespace

void AddPlanFlags(CLI::App* command, PlanOptions* o) {
  VC_PLAN_PARAMETERS(VC_ROW_FLAG)
  AddScannerFlags(command, &o->scanner);
}

void AddEvaluateFlags(CLI::App* command, EvaluateJobOptions* o) {
  VC_EVALUATE_PARAMETERS(VC_ROW_FLAG)
  AddScannerFlags(command, &o->scanner);
}

#undef VC_ROW_FLAG

}  // namespace vc::client
