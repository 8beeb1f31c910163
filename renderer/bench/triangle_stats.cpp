#include "renderer/bench/triangle_stats.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace pt {
namespace {

// Quantiles by selection (nth_element); reorders `v`.
Quantiles quantiles(std::vector<double>& v) {
  Quantiles q;
  if (v.empty()) return q;
  auto at = [&](double f) {
    size_t k = std::min(v.size() - 1, static_cast<size_t>(f * static_cast<double>(v.size())));
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  };
  q.median = at(0.5);
  q.p90 = at(0.9);
  q.p99 = at(0.99);
  q.max = *std::max_element(v.begin(), v.end());
  return q;
}

}  // namespace

TriangleStats triangle_stats(const Mesh& mesh) {
  TriangleStats s;
  size_t n = mesh.triangle_count();
  s.triangles = n;
  if (n == 0) return s;
  std::vector<double> edge(n), area(n), aspect(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      // In double, so that slivers of float triangles get their true (tiny) area.
      double p[3][3];
      for (int c = 0; c < 3; ++c) {
        Vec3f v = mesh.vertex(t, c);
        p[c][0] = v.x;
        p[c][1] = v.y;
        p[c][2] = v.z;
      }
      double longest2 = 0, e[3][3];
      for (int c = 0; c < 3; ++c) {
        double l2 = 0;
        for (int a = 0; a < 3; ++a) {
          e[c][a] = p[(c + 1) % 3][a] - p[c][a];
          l2 += e[c][a] * e[c][a];
        }
        longest2 = std::max(longest2, l2);
      }
      double nx = e[0][1] * e[2][2] - e[0][2] * e[2][1], ny = e[0][2] * e[2][0] - e[0][0] * e[2][2],
             nz = e[0][0] * e[2][1] - e[0][1] * e[2][0];
      double a = 0.5 * std::sqrt(nx * nx + ny * ny + nz * nz);
      edge[t] = std::sqrt(longest2);
      area[t] = a;
      aspect[t] = a > 0 ? longest2 * std::sqrt(3.0) / (4.0 * a) : INFINITY;
    }
  });
  BBox b = mesh.bounds();
  double diag = std::max(1e-30, static_cast<double>(length(b.extent())));
  std::vector<double> finite_aspect;
  finite_aspect.reserve(n);
  for (size_t t = 0; t < n; ++t) {
    edge[t] /= diag;
    if (area[t] > 0) {
      finite_aspect.push_back(aspect[t]);
    } else {
      ++s.degenerate;
    }
  }
  size_t good = finite_aspect.size();
  s.area = quantiles(area);
  if (s.area.median > 0) {
    double m = s.area.median;
    for (double* q : {&s.area.median, &s.area.p90, &s.area.p99, &s.area.max}) *q /= m;
  }
  if (good > 0) {
    for (double a : finite_aspect) {
      s.aspect_over_10 += a > 10 ? 1 : 0;
      s.aspect_over_100 += a > 100 ? 1 : 0;
    }
    s.aspect_over_10 /= static_cast<double>(good);
    s.aspect_over_100 /= static_cast<double>(good);
  }
  s.edge = quantiles(edge);
  s.aspect = quantiles(finite_aspect);
  return s;
}

std::string format_triangle_stats(const TriangleStats& s) {
  char buf[1024];
  auto row = [](const char* name, const Quantiles& q) {
    char line[256];
    std::snprintf(line, sizeof(line), "  %-38s %10.3g %10.3g %10.3g %10.3g\n", name, q.median, q.p90, q.p99, q.max);
    return std::string(line);
  };
  std::snprintf(buf, sizeof(buf), "triangles: %zu (%zu degenerate); %.1f%% with aspect ratio > 10, %.2f%% > 100\n  %-38s %10s %10s %10s %10s\n",
                s.triangles, s.degenerate, 100.0 * s.aspect_over_10, 100.0 * s.aspect_over_100, "", "median", "p90", "p99", "max");
  return buf + row("longest edge / bounding-box diagonal", s.edge) + row("area / median area", s.area) +
         row("aspect ratio (1 = equilateral)", s.aspect);
}

}  // namespace pt
