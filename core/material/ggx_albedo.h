// Directional albedo tables of single-scattering GGX (core/material/ggx.h, height-correlated
// Smith), for Kulla & Conty's multiple-scattering compensation (2017, "Revisiting Physically Based
// Shading at Imageworks"). Written by ggx_albedo_gen.cpp into ggx_albedo_table.cpp and
// ggx_albedo_schlick_table.cpp; regenerate with (4.6 CPU-minutes each)
//   build/core/ggx_albedo_gen > core/material/ggx_albedo_table.cpp
//   build/core/ggx_albedo_gen schlick > core/material/ggx_albedo_schlick_table.cpp
//
// e(mu, r)         integral of D G2 / (4 mu_o mu_i) cos_i over the hemisphere (Fresnel 1), for
//                  mu = cos(theta_o) and glTF roughness r (alpha = r^2)
// e_schlick(mu, r) the same with Schlick's weight (1 - wo.h)^5: a Schlick Fresnel F0 gives the
//                  albedo F0 e + (1 - F0) e_schlick
// *_avg(r)         their cosine-weighted hemispherical averages 2 integral(e(mu) mu dmu), taken of
//                  the tables' own interpolant so the compensation lobe integrates to exactly what
//                  it is meant to
//
// Both axes are spaced in the square root of the value (entry k holds (k / (N - 1))^2). Height-
// correlated Smith's e(mu) is not monotonic: it dips to about 0.89 where mu is near alpha and
// rises again to 0.995 at the horizon, a feature as narrow as alpha. Evenly spaced in mu, the
// first interval [0, 1/31] held it for every alpha below 0.03 and the interpolant was off by up to
// 7% at 89 degrees; spaced in sqrt(mu) the first entries are 2.5e-4, 1e-3, 2.3e-3 ... apart, and
// sqrt(r) puts the rows' alphas at most 1.6x apart from alpha = 2.6e-4 up.
#pragma once
#include <algorithm>
#include <cmath>

namespace pt {

inline constexpr int kGgxAlbedoSize = 64;  // entries in each axis, endpoints included

extern const float kGgxAlbedo[kGgxAlbedoSize][kGgxAlbedoSize];         // [roughness][mu]
extern const float kGgxAlbedoSchlick[kGgxAlbedoSize][kGgxAlbedoSize];  // [roughness][mu]
extern const float kGgxAlbedoAvg[kGgxAlbedoSize];                      // [roughness]
extern const float kGgxAlbedoSchlickAvg[kGgxAlbedoSize];               // [roughness]

// The value table entry k stands for (roughness or mu).
inline double ggx_albedo_node(int k) {
  double x = static_cast<double>(k) / (kGgxAlbedoSize - 1);
  return x * x;
}

// Where a value v in [0, 1] falls among the entries (linear in sqrt(v)).
struct TableCoord {
  int i;
  float t;
  explicit TableCoord(float v) {
    float f = std::sqrt(std::clamp(v, 0.0f, 1.0f)) * (kGgxAlbedoSize - 1);
    i = std::min(static_cast<int>(f), kGgxAlbedoSize - 2);
    t = f - static_cast<float>(i);
  }
};

inline float table_lookup(const float (&table)[kGgxAlbedoSize][kGgxAlbedoSize], TableCoord r, float mu) {
  TableCoord m(mu);
  float a = table[r.i][m.i] * (1 - m.t) + table[r.i][m.i + 1] * m.t;
  float b = table[r.i + 1][m.i] * (1 - m.t) + table[r.i + 1][m.i + 1] * m.t;
  return a * (1 - r.t) + b * r.t;
}
inline float table_lookup(const float (&table)[kGgxAlbedoSize], TableCoord r) {
  return table[r.i] * (1 - r.t) + table[r.i + 1] * r.t;
}

}  // namespace pt
