// Shape statistics of a scene's triangles, printed by `pt bench rays` so that a throughput figure
// comes with what kind of mesh it was measured on (BVHs do worst on long thin triangles).
#pragma once
#include <cstddef>
#include <string>

#include "core/geometry/mesh.h"

namespace pt {

struct Quantiles {
  double median = 0, p90 = 0, p99 = 0, max = 0;
};

struct TriangleStats {
  size_t triangles = 0, degenerate = 0;  // degenerate: zero area (aspect ratio infinite)
  Quantiles edge;    // longest edge, in units of the mesh's bounding-box diagonal
  Quantiles area;    // in units of the median area
  Quantiles aspect;  // longest edge^2 * sqrt(3) / (4 * area): 1 for equilateral, large for slivers
  double aspect_over_10 = 0, aspect_over_100 = 0;  // fractions of the non-degenerate triangles
};

TriangleStats triangle_stats(const Mesh& mesh);
std::string format_triangle_stats(const TriangleStats& s);

}  // namespace pt
