// A ray's footprint on the surface it hit, from its differentials (Igehy 1999; pbrt 3rd ed. 10.1.1,
// SurfaceInteraction::ComputeDifferentials): the neighbouring rays meet the hit's tangent plane at
// p + dpdx and p + dpdy, and the uv change that goes with those offsets is solved for through
// dpdu, dpdv. After a bounce the footprint keeps widening (bounce_differential).
#pragma once
#include <cmath>

#include "core/geometry/ray.h"
#include "core/math/frame.h"
#include "core/scene/interaction.h"

namespace pt {

// A ray's direction differentials, dddx and dddy, also where bounce_differential left them to be made
// (RayDifferential::spread).
inline void direction_differentials(const Ray& ray, Vec3f& dddx, Vec3f& dddy) {
  if (ray.diff.spread > 0.0f) {
    const Frame f(ray.d);
    dddx = f.s * ray.diff.spread;
    dddy = f.t * ray.diff.spread;
  } else {
    dddx = ray.diff.dddx;
    dddy = ray.diff.dddy;
  }
}
// Makes them in place: a ray whose differentials are read directly (visibility.cpp moves them on).
inline void make_direction_differentials(Ray& ray) {
  if (ray.diff.spread > 0.0f) {
    direction_differentials(ray, ray.diff.dddx, ray.diff.dddy);
    ray.diff.spread = 0.0f;
  }
}

// Sets si.dpdx, dpdy, duvdx, duvdy from ray.diff (si.p, ng, dpdu, dpdv must be set). Zero when the
// ray has no differentials, runs parallel to the surface, or the uv map is degenerate. Without `uv`,
// only dpdx and dpdy (a hit that looks no texture up: its bounce's differentials start from them).
inline void compute_footprint(const Ray& ray, SurfaceInteraction& si, bool uv = true) {
  si.dpdx = si.dpdy = Vec3f(0.0f);
  si.duvdx = si.duvdy = si.duv_centre = Vec2f(0.0f, 0.0f);
  si.rough_footprint = ray.diff.rough;
  if (ray.diff.empty()) return;
  // A neighbouring ray o + dodx + (d + dddx) t meets the tangent plane n.(x - p) = 0 at
  // t = n.(p - o - dodx) / n.(d + dddx), dodx + (d + dddx) t - (p - o) away from p. The ray
  // through the footprint's centre, o + c.x dodx + c.y dody + (d + c.x dddx + c.y dddy) t, meets
  // it where the same four dot products, weighted by c, say.
  const Vec3f& n = si.ng;
  const RayDifferential& rd = ray.diff;
  Vec3f dddx, dddy;
  direction_differentials(ray, dddx, dddy);
  const Vec3f po = si.p - ray.o;
  const float n_po = dot(n, po), n_d = dot(n, ray.d);
  const float n_ox = dot(n, rd.dodx), n_oy = dot(n, rd.dody), n_dx = dot(n, dddx), n_dy = dot(n, dddy);
  const float tx = (n_po - n_ox) / (n_d + n_dx), ty = (n_po - n_oy) / (n_d + n_dy);
  const Vec3f dpdx = rd.dodx + (ray.d + dddx) * tx - po, dpdy = rd.dody + (ray.d + dddy) * ty - po;
  // An infinity or NaN in any of them (a ray parallel to the plane) leaves the footprint empty.
  if (!std::isfinite(tx + ty + (dpdx.x + dpdx.y + dpdx.z) + (dpdy.x + dpdy.y + dpdy.z))) return;
  si.dpdx = dpdx;
  si.dpdy = dpdy;
  if (!uv) return;
  // Least squares over the two axes the surface is least parallel to; one division.
  int d0 = 1, d1 = 2;
  if (std::abs(n.y) > std::abs(n.x) && std::abs(n.y) > std::abs(n.z)) {
    d0 = 0, d1 = 2;
  } else if (std::abs(n.z) > std::abs(n.x) && std::abs(n.z) >= std::abs(n.y)) {
    d0 = 0, d1 = 1;
  }
  const float a00 = si.dpdu[d0], a01 = si.dpdv[d0], a10 = si.dpdu[d1], a11 = si.dpdv[d1];
  const float det = a00 * a11 - a01 * a10;
  if (!(std::abs(det) > 1e-20f)) return;
  const float inv = 1.0f / det;
  auto solve = [&](float p0, float p1) {
    const Vec2f r{(a11 * p0 - a01 * p1) * inv, (a00 * p1 - a10 * p0) * inv};
    return std::isfinite(r.x + r.y) ? r : Vec2f(0.0f, 0.0f);
  };
  si.duvdx = solve(dpdx[d0], dpdx[d1]);
  si.duvdy = solve(dpdy[d0], dpdy[d1]);
  // The footprint's centre: the ray through it met with the same plane, so that its uv is not
  // linearised where the surface runs edge-on. Only its two components on d0 and d1 are needed.
  const Vec2f c = rd.centre;
  if (c.x != 0.0f || c.y != 0.0f) {
    const float tc = (n_po - (c.x * n_ox + c.y * n_oy)) / (n_d + (c.x * n_dx + c.y * n_dy));
    auto at = [&](int a) {
      return rd.dodx[a] * c.x + rd.dody[a] * c.y + (ray.d[a] + (dddx[a] * c.x + dddy[a] * c.y)) * tc - po[a];
    };
    const float p0 = at(d0), p1 = at(d1);
    if (std::isfinite(tc + p0 + p1)) si.duv_centre = solve(p0, p1);
  }
}

// The differentials of a ray leaving si after a bounce whose sampling density was
// `pdf` (0 for a specular event). The origin offsets are the footprint at si; the directions spread
// by the incoming spread plus, for a non-specular bounce, the lobe's width: the half-angle of a cone
// holding the solid angle 1/pdf, sqrt(1 / (pi pdf)) (the footprint of a stochastic bounce follows
// its pdf: Suykens & Willems 2001, "Path Differentials and Applications"; the per-bounce widening
// of ray cones, Akenine-Moeller et al. 2019), scaled as the camera's are. The spread is isotropic:
// curvature, and the anisotropy of a lobe, are not followed. The direction differentials are left
// to be made where the ray meets a surface that needs them (RayDifferential::spread): making them
// for every bounce was 4% of a sky-lit scene's instructions, whose bounce rays mostly miss.
inline RayDifferential bounce_differential(const RayDifferential& in, const SurfaceInteraction& si, float pdf) {
  RayDifferential out;
  if (in.empty()) return out;
  float spread = in.spread > 0.0f ? in.spread : 0.5f * (length(in.dddx) + length(in.dddy));
  if (pdf > 0) spread += in.scale * std::min(1.0f, std::sqrt(1.0f / (kPi * pdf)));
  out.rough = in.rough || pdf > 0;
  out.dodx = si.dpdx;
  out.dody = si.dpdy;
  out.spread = spread;
  out.scale = in.scale;
  return out;
}

}  // namespace pt
