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

// A coordinate for people: %g as Num for small ones, to the millimetre (%.3f) from 100 km on, so a
// survey coordinate (5612330.123) keeps its digits.
inline std::string Coordinate(double v) {
  if (!(v > -1e5 && v < 1e5)) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.3f", v);
    return buf;
  }
  return Num(v);
}

// `fraction` as a percentage with one decimal ("98.7 %").
inline std::string Percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f %%", 100.0 * fraction);
  return buf;
}

}  // namespace vc::planner
