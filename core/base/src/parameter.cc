#include "vc/base/parameter.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace vc {
namespace {

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

// Units a bound reads well with ("> 0 m", ">= 0 stations"); a fraction's interval and a ratio's
// "x" say what they are without one.
bool UnitFollowsBound(std::string_view unit) { return !unit.empty() && unit != "fraction" && unit != "x"; }

// "must be > 0 m, got -5" for the row's check and unit.
Status Refuse(const ParamInfo& info, std::string_view prefix, const char* requirement, const std::string& got) {
  std::string m = std::string(prefix) + std::string(info.name) + " must be " + requirement;
  if (info.check != ParamCheck::kAny && UnitFollowsBound(info.unit)) {
    m += ' ';
    m += info.unit;
  }
  return InvalidArgumentError(m + ", got " + got);
}

}  // namespace

std::string NameOf(const FieldNamer& namer, std::string_view path) { return namer ? namer(path) : std::string(path); }

Status CheckParameter(const ParamInfo& info, double v, std::string_view prefix) {
  switch (info.check) {
    case ParamCheck::kAny:
      if (!std::isfinite(v)) return Refuse(info, prefix, "a finite number", Num(v));
      break;
    case ParamCheck::kNonNegative:
      if (!std::isfinite(v) || v < 0) return Refuse(info, prefix, ">= 0", Num(v));
      break;
    case ParamCheck::kPositive:
      if (!std::isfinite(v) || v <= 0) return Refuse(info, prefix, "> 0", Num(v));
      break;
    case ParamCheck::kFraction:
      if (!std::isfinite(v) || v <= 0 || v > 1) return Refuse(info, prefix, "in (0, 1]", Num(v));
      break;
    case ParamCheck::kUnitInterval:
      if (!std::isfinite(v) || v < 0 || v > 1) return Refuse(info, prefix, "in [0, 1]", Num(v));
      break;
    case ParamCheck::kElevationDeg:
      if (!std::isfinite(v) || v < -90 || v > 90) return Refuse(info, prefix, "in [-90, 90]", Num(v));
      break;
    case ParamCheck::kIncidenceDeg:
      if (!std::isfinite(v) || v <= 0 || v > 90) return Refuse(info, prefix, "in (0, 90]", Num(v));
      break;
    case ParamCheck::kAzimuthSpanDeg:
      if (!std::isfinite(v) || v <= 0 || v > 360) return Refuse(info, prefix, "in (0, 360]", Num(v));
      break;
  }
  return Status::Ok();
}

Status CheckParameter(const ParamInfo& info, int64_t v, std::string_view prefix) {
  switch (info.check) {
    case ParamCheck::kAny:
      break;
    case ParamCheck::kNonNegative:
      if (v < 0) return Refuse(info, prefix, ">= 0", std::to_string(v));
      break;
    case ParamCheck::kPositive:
      if (v <= 0) return Refuse(info, prefix, "> 0", std::to_string(v));
      break;
    case ParamCheck::kFraction:
      if (v <= 0 || v > 1) return Refuse(info, prefix, "in (0, 1]", std::to_string(v));
      break;
    case ParamCheck::kUnitInterval:
      if (v < 0 || v > 1) return Refuse(info, prefix, "in [0, 1]", std::to_string(v));
      break;
    case ParamCheck::kElevationDeg:
      if (v < -90 || v > 90) return Refuse(info, prefix, "in [-90, 90]", std::to_string(v));
      break;
    case ParamCheck::kIncidenceDeg:
      if (v <= 0 || v > 90) return Refuse(info, prefix, "in (0, 90]", std::to_string(v));
      break;
    case ParamCheck::kAzimuthSpanDeg:
      if (v <= 0 || v > 360) return Refuse(info, prefix, "in (0, 360]", std::to_string(v));
      break;
  }
  return Status::Ok();
}

Status CheckParameter(const ParamInfo& info, uint64_t v, std::string_view prefix) {
  if ((info.check == ParamCheck::kPositive || info.check == ParamCheck::kFraction) && v == 0) {
    return Refuse(info, prefix, info.check == ParamCheck::kPositive ? "> 0" : "in (0, 1]", "0");
  }
  if (info.check == ParamCheck::kFraction && v > 1) return Refuse(info, prefix, "in (0, 1]", std::to_string(v));
  if (info.check == ParamCheck::kUnitInterval && v > 1) return Refuse(info, prefix, "in [0, 1]", std::to_string(v));
  return Status::Ok();
}

}  // namespace vc
