// OBJ files written as text for the CLI tests.
#pragma once
#include <cmath>
#include <string>

namespace pt::test {

// `faces` copies of one convex polygon face with n vertices on the unit circle (z = 0): tinyobjloader
// triangulates each by ear clipping, which is what the loader's face-size limit bounds.
inline std::string polygon_obj(int n, int faces = 1) {
  std::string text;
  for (int i = 0; i < n; ++i) {
    double a = 2 * M_PI * i / n;
    text += "v ";
    text += std::to_string(std::cos(a));
    text += ' ';
    text += std::to_string(std::sin(a));
    text += " 0\n";
  }
  std::string face = "f";
  for (int i = 1; i <= n; ++i) {
    face += ' ';  // appended: GCC 12 warns falsely (-Wrestrict) on " " + std::string
    face += std::to_string(i);
  }
  for (int k = 0; k < faces; ++k) text += face + "\n";
  return text;
}

}  // namespace pt::test
