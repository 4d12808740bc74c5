#include "vc/client/plan_file.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace vc::client {
namespace {

using Json = nlohmann::json;

Status Refuse(const std::string& source, const std::string& what) {
  return InvalidArgumentError(source + ": " + what + " (expected a plan.json written by vc-client submit)");
}

// The finite number at `j`[key], named `field` in messages.
Result<double> Number(const Json& j, const char* key, const std::string& field, const std::string& source) {
  if (!j.contains(key)) return Refuse(source, "no " + field);
  const Json& v = j.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>())) return Refuse(source, field + " is not a number");
  return v.get<double>();
}

Result<std::vector<WorldPoint>> Stations(const Json& plan, const std::string& source) {
  if (!plan.contains("viewpoints") || !plan["viewpoints"].is_array()) return Refuse(source, "no viewpoints array");
  const Json& viewpoints = plan["viewpoints"];
  if (viewpoints.empty()) return Refuse(source, "viewpoints is empty: the plan has no station to evaluate");
  std::vector<WorldPoint> stations;
  for (size_t i = 0; i < viewpoints.size(); ++i) {
    const std::string at = "viewpoints[" + std::to_string(i) + "]";
    if (!viewpoints[i].is_object()) return Refuse(source, at + " is not an object");
    double p[3];
    for (int a = 0; a < 3; ++a) {
      const char key[2] = {char('x' + a), '\0'};
      VC_ASSIGN_OR_RETURN(p[a], Number(viewpoints[i], key, at + "." + key, source));
    }
    stations.emplace_back(p[0], p[1], p[2]);
  }
  return stations;
}

// parameters.scanner: a null row is a limit that is off, which is the row's default.
Result<ScannerModel> Scanner(const Json& plan, const std::string& source) {
  const Json* scanner = nullptr;
  if (plan.contains("parameters") && plan["parameters"].is_object() && plan["parameters"].contains("scanner")) {
    scanner = &plan["parameters"]["scanner"];
  }
  if (scanner == nullptr || !scanner->is_object()) return Refuse(source, "no parameters.scanner object");
  ScannerModel model;
#define VC_ROW_FROM_PLAN(type, name, ...)                                                          \
  if (!scanner->contains(#name)) return Refuse(source, "no parameters.scanner." #name);            \
  if (!(*scanner)[#name].is_null()) {                                                              \
    VC_ASSIGN_OR_RETURN(model.name, Number(*scanner, #name, "parameters.scanner." #name, source)); \
  }
  VC_SCANNER_PARAMETERS(VC_ROW_FROM_PLAN)
#undef VC_ROW_FROM_PLAN
  if (scanner->contains("name") && (*scanner)["name"].is_string()) model.name = (*scanner)["name"].get<std::string>();
  return model;
}

std::string Metres(double v, std::string_view unit) {
  char text[64];
  std::snprintf(text, sizeof text, "%g%s%.*s", v, unit.empty() ? "" : " ", int(unit.size()), unit.data());
  return text;
}

}  // namespace

Result<PlanForEvaluation> ParsePlanForEvaluation(std::string_view text, const std::string& source) {
  const Json plan = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (plan.is_discarded()) return Refuse(source, "not JSON");
  if (!plan.is_object()) return Refuse(source, "not a JSON object");
  if (!plan.contains("schema") || plan["schema"] != "vc.plan/1") return Refuse(source, "schema is not \"vc.plan/1\"");
  PlanForEvaluation out;
  VC_ASSIGN_OR_RETURN(out.stations, Stations(plan, source));
  VC_ASSIGN_OR_RETURN(out.scanner, Scanner(plan, source));
  VC_ASSIGN_OR_RETURN(out.resolution_m, Number(plan, "resolution_m", "resolution_m", source));
  if (out.resolution_m <= 0) return Refuse(source, "resolution_m is not positive");
  if (plan.contains("crs") && plan["crs"].is_object()) {
    const Json& crs = plan["crs"];
    if (!crs.contains("definition") || !crs["definition"].is_string())
      return Refuse(source, "crs.definition is not a string");
    out.crs_definition = crs["definition"].get<std::string>();
  }
  return out;
}

Result<PlanForEvaluation> LoadPlanForEvaluation(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError("cannot read the plan file " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return ParsePlanForEvaluation(text.str(), path);
}

std::vector<std::string> TakeScannerFromPlan(const CLI::App& command, const ScannerModel& plan_scanner,
                                             ScannerModel* scanner) {
  std::vector<std::string> differ;
  const bool preset = command.get_option("--scanner")->count() > 0;
  const std::string preset_note = preset ? "--scanner " + scanner->name + ": " : "";
#define VC_ROW_TAKE(type, name, default_value, unit, flag, ...)                                                    \
  if (command.get_option("--" flag)->count() == 0 && !preset) {                                                    \
    scanner->name = plan_scanner.name;                                                                             \
  } else if (scanner->name != plan_scanner.name) {                                                                 \
    differ.push_back((command.get_option("--" flag)->count() == 0 ? preset_note : std::string()) + "--" flag " " + \
                     Metres(scanner->name, unit) + " (the plan: " + Metres(plan_scanner.name, unit) + ")");        \
  }
  VC_SCANNER_PARAMETERS(VC_ROW_TAKE)
#undef VC_ROW_TAKE
  if (!preset) scanner->name = plan_scanner.name;
  return differ;
}

std::vector<std::string> TakeResolutionFromPlan(const CLI::App& command, double plan_resolution_m,
                                                double* resolution_m) {
  if (command.get_option("--resolution")->count() == 0) {
    *resolution_m = plan_resolution_m;
    return {};
  }
  if (*resolution_m == plan_resolution_m) return {};
  return {"--resolution " + Metres(*resolution_m, "m") + " (the plan: " + Metres(plan_resolution_m, "m") + ")"};
}

}  // namespace vc::client
