// Number formatting for the planner's messages and warnings. Private to vc::plan.
#pragma once

#include <cstdio>
#include <string>

namespace vc::planner {

// `v` with printf's %g ("0.2", "1e+06").
inline std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

// `fraction` as a percentage with one decimal ("98.7 %").
inline std::string Percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f %%", 100.0 * fraction);
  return buf;
}

}  // namespace vc::planner
