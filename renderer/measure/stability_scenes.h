// The small scenes and helpers the stability experiments (stability.cpp, stability_inputs.cpp)
// share: random directions, an exact line/triangle test in double, building a backend over a
// handful of triangles.
#pragma once
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/geometry/geometry.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "renderer/measure/stability.h"
#include "renderer/measure/vec3d.h"

namespace pt::stability {



// The direction the test geometry is moved along: no axis-aligned shortcut for any coordinate.
inline const D3 kAway = normalize(D3(1.0, 0.6, 0.3));

inline D3 random_unit(Pcg32& rng) {
  Vec3f v = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
  return D3(v);
}
inline D3 random_in_ball(Pcg32& rng) {
  for (;;) {
    D3 p(2 * rng.next_double() - 1, 2 * rng.next_double() - 1, 2 * rng.next_double() - 1);
    if (dot(p, p) <= 1) return p;
  }
}

// Barycentrics (b1, b2) and t of a ray's line through a triangle, in double. No range checks.
struct Bary {
  double t, b1, b2;
};
inline std::optional<Bary> line_triangle(const D3& o, const D3& d, const D3& p0, const D3& p1, const D3& p2) {
  D3 e1 = p1 - p0, e2 = p2 - p0, pv = cross(d, e2);
  double det = dot(e1, pv);
  if (det == 0) return std::nullopt;
  D3 tv = o - p0, qv = cross(tv, e1);
  return Bary{dot(e2, qv) / det, dot(tv, pv) / det, dot(d, qv) / det};
}

struct Built {
  std::unique_ptr<Accel> accel;
  std::string error;
};
inline Built build(const Geometry& geometry, const StabilityMethod& m) {
  Built b;
  try {
    b.accel = make_accel(geometry, m.options);
  } catch (const std::exception& e) {
    b.error = e.what();
  }
  return b;
}

inline StabilityRow unavailable(const std::string& test, const std::string& variant, const StabilityMethod& m, double distance,
                         const std::string& error) {
  return {test, variant, m.name, distance, 0, 0, "unavailable: " + error};
}

// Triangles alone, as the backends see them (materials do not matter here).
inline Geometry triangles(const std::vector<Vec3f>& positions, const std::vector<uint32_t>& indices) {
  Mesh mesh;
  mesh.positions = positions;
  mesh.indices = indices;
  mesh.material.assign(indices.size() / 3, 0);
  return Geometry(std::move(mesh), {});
}

// A cone with a fanned base: high-valence vertices (apex, base centre) and long thin triangles.
inline void cone(int segments, std::vector<D3>& v, std::vector<uint32_t>& f) {
  v = {{0, 1, 0}, {0, -1, 0}};
  for (int i = 0; i < segments; ++i) {
    double a = 2 * M_PI * i / segments;
    v.push_back({std::cos(a), -1, std::sin(a)});
  }
  for (int i = 0; i < segments; ++i) {
    uint32_t r0 = 2 + i, r1 = 2 + (i + 1) % segments;
    f.insert(f.end(), {r0, r1, 0, 1, r1, r0});
  }
}

inline std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}


}  // namespace pt::stability
