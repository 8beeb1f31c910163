// Text for `pt info`'s material lines, shared by the models' describe().
#pragma once
#include <cstdio>
#include <string>

#include "core/math/vec.h"

namespace pt {

inline std::string describe_value(const char* label, float v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s %g", label, v);
  return buf;
}
inline std::string describe_colour(const char* label, const Spectrum& c, int texture = -1) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s (%g, %g, %g)%s", label, c.x, c.y, c.z, texture >= 0 ? " textured" : "");
  return buf;
}

}  // namespace pt
