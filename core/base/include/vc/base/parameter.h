// Parameters declared once. A parameter table is an X-macro of rows
//
//   X(type, name, default_value, unit, flag, check, help)
//
// e.g. `X(double, grid_spacing_m, 1.0, "m", "grid-spacing", kPositive, "candidate grid spacing")`.
// The options struct declares its fields from the table (VC_DECLARE_PARAMETER), and every place
// that must list the parameters expands the same table: validation (CheckParameter), the proto
// conversion (proto/src/convert.cc: the generated `set_<name>` / `has_<name>` accessors, so a
// row without a proto field does not compile), vc-client's flags (client/src/parameter_flags.cc)
// and plan.json's `parameters` (core/report). Adding a parameter is one row plus its doc line in
// docs/PLANNING.md; tests/client/parameter_flags_test.cc fails when a row is missing from a derived
// place, or a proto field has no row.
//
// Why an X-macro rather than a constexpr table of member pointers or proto field options: the
// struct, its defaults and the metadata are then literally one line per parameter, and each
// derived place is checked by the compiler (a typed accessor per field), with no reflection at
// run time. Rows hold only scalar parameters (numbers, bools, enums); lists (candidates,
// viewpoints) and nested models (the scanner) are written out where they are used.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>

#include "vc/base/status.h"

namespace vc {

// What values a parameter accepts (checked by CheckParameter). Numbers must also be finite.
enum class ParamCheck : uint8_t {
  kAny,             // any finite value
  kNonNegative,     // >= 0
  kPositive,        // > 0
  kFraction,        // in (0, 1]
  kUnitInterval,    // in [0, 1] (0 = off, for a fraction that can be switched off)
  kElevationDeg,    // in [-90, 90] (degrees)
  kIncidenceDeg,    // in (0, 90] (degrees)
  kAzimuthSpanDeg,  // in (0, 360] (degrees)
};

// A parameter's metadata, from its table row.
struct ParamInfo {
  std::string_view name;  // field name, as in the struct, the proto and plan.json ("grid_spacing_m")
  std::string_view unit;  // "m", "bytes", "voxels", ... or "" when unitless
  std::string_view flag;  // vc-client flag without the dashes ("grid-spacing")
  ParamCheck check = ParamCheck::kAny;
  std::string_view help;  // one line for --help and docs
};

// INVALID_ARGUMENT "<prefix><name> must be <requirement> <unit>, got <value>" when `value` fails
// info.check ("scanner.max_range_m must be > 0 m, got -5"); the unit is left out where the
// requirement says it ("fraction", "x") and for kAny ("must be a finite number").
Status CheckParameter(const ParamInfo& info, double value, std::string_view prefix = "");
Status CheckParameter(const ParamInfo& info, int64_t value, std::string_view prefix = "");
Status CheckParameter(const ParamInfo& info, uint64_t value, std::string_view prefix = "");
inline Status CheckParameter(const ParamInfo& info, int32_t value, std::string_view prefix = "") {
  return CheckParameter(info, int64_t{value}, prefix);
}
// Parameters that take any value of their type: bools and enums.
template <typename T>
concept UncheckedParameter = std::is_enum_v<T> || std::is_same_v<T, bool>;
template <UncheckedParameter T>
Status CheckParameter(const ParamInfo&, T, std::string_view = "") {
  return Status::Ok();
}

// How validation messages name a field: given its path as the proto and plan.json name it
// ("grid_spacing_m", "scanner.max_range_m", "keep_out[2]", "tripod_heights_m[0]"), the name to
// show. Empty shows the path (the server). vc-client shows its flags ("--max-range", "--keep-out
// line 4"; PlanFlagNamer in client/src/parameter_flags.cc), so the client and the server apply the
// same rules and only the names differ.
using FieldNamer = std::function<std::string(std::string_view path)>;

// `path` as `namer` shows it.
[[nodiscard]] std::string NameOf(const FieldNamer& namer, std::string_view path);

// CheckParameter naming the field `prefix` + info.name as `namer` shows it.
template <typename T>
Status CheckNamedParameter(ParamInfo info, T value, const FieldNamer& namer, std::string_view prefix = "") {
  const std::string shown = NameOf(namer, std::string(prefix) + std::string(info.name));
  info.name = shown;
  return CheckParameter(info, value);
}

}  // namespace vc

// Expands a row into a field with its default.
#define VC_DECLARE_PARAMETER(type, name, default_value, unit, flag, check, help) type name = default_value;
// Expands a row into its ParamInfo.
#define VC_PARAMETER_INFO(type, name, default_value, unit, flag, check, help) \
  ::vc::ParamInfo { #name, unit, flag, ::vc::ParamCheck::check, help }
