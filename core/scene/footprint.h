// A ray's footprint on the surface it hit, from its differentials (Igehy 1999; pbrt 3rd ed. 10.1.1,
// SurfaceInteraction::ComputeDifferentials): the neighbouring rays meet the hit's tangent plane at
// p + dpdx and p + dpdy, and the uv change that goes with those offsets is their dot product with the
// gradients of u and v (core/geometry/uv_gradients.h). After a bounce the footprint keeps widening
// (bounce_differential).
#pragma once
#include <emmintrin.h>

#include <cmath>
#include <cstddef>

#include "core/geometry/ray.h"
#include "core/geometry/uv_gradients.h"
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

namespace footprint_detail {
static_assert(sizeof(Vec3f) == 12 && offsetof(Vec3f, z) == 8, "x, y, z packed, as load3 and store3 read them");
// (x, y, z, 0) in three instructions (_mm_setr_ps took six); no byte past z is read.
inline __m128 load3(const Vec3f& v) {
  const __m128 xy = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(&v.x)));
  return _mm_movelh_ps(xy, _mm_load_ss(&v.z));
}
inline void store3(Vec3f& out, __m128 v) {
  _mm_storel_epi64(reinterpret_cast<__m128i*>(&out.x), _mm_castps_si128(v));
  _mm_store_ss(&out.z, _mm_movehl_ps(v, v));
}
inline __m128 splat(float x) { return _mm_set1_ps(x); }
// The x + y + z of four vectors, one in each lane, added as dot() adds them ((x + y) + z), so that
// dot products made of them are dot()'s to the bit.
inline __m128 sum_xyz4(__m128 a, __m128 b, __m128 c, __m128 d) {
  _MM_TRANSPOSE4_PS(a, b, c, d);
  return _mm_add_ps(_mm_add_ps(a, b), c);
}
// Whether every lane is finite: x * 0 is 0 for finite x, NaN for an infinity or NaN.
inline bool all_finite(__m128 v) {
  return _mm_movemask_ps(_mm_cmpeq_ps(_mm_mul_ps(v, _mm_setzero_ps()), _mm_setzero_ps())) == 0xf;
}
}  // namespace footprint_detail

// Sets si.dpdx, dpdy and, given the surface's uv gradients, duvdx, duvdy and duv_centre, from
// ray.diff (si.p and ng must be set). Zero when the ray has no differentials or runs parallel to the
// surface. Without `uv`, only dpdx and dpdy (a hit that looks no texture up: its bounce's
// differentials start from them). In SSE registers, three components and a zero to each: written
// with Vec3f, GCC's code for it took 340 instructions a hit (a sixth of a textured camera sample's
// on the horizon with --splits 1).
inline void compute_footprint(const Ray& ray, SurfaceInteraction& si, const UvGradients* uv = nullptr) {
  using namespace footprint_detail;
  si.dpdx = si.dpdy = Vec3f(0.0f);
  si.duvdx = si.duvdy = si.duv_centre = Vec2f(0.0f, 0.0f);
  si.rough_footprint = ray.diff.rough;
  if (ray.diff.empty()) return;
  // A neighbouring ray o + dodx + (d + dddx) t meets the tangent plane n.(x - p) = 0 at
  // t = n.(p - o - dodx) / n.(d + dddx), dodx + (d + dddx) t - (p - o) away from p. The ray
  // through the footprint's centre, o + c.x dodx + c.y dody + (d + c.x dddx + c.y dddy) t, meets
  // it where the same four dot products, weighted by c, say.
  const RayDifferential& rd = ray.diff;
  Vec3f dddx_v, dddy_v;
  direction_differentials(ray, dddx_v, dddy_v);
  const __m128 n = load3(si.ng), d = load3(ray.d), ox = load3(rd.dodx), oy = load3(rd.dody);
  const __m128 dx = load3(dddx_v), dy = load3(dddy_v), po = _mm_sub_ps(load3(si.p), load3(ray.o));
  // (n.po, n.d, n.dodx, n.dody) and (n.dddx, n.dddy, 0, 0)
  const __m128 n4 = sum_xyz4(_mm_mul_ps(n, po), _mm_mul_ps(n, d), _mm_mul_ps(n, ox), _mm_mul_ps(n, oy));
  const __m128 n2 = sum_xyz4(_mm_mul_ps(n, dx), _mm_mul_ps(n, dy), _mm_setzero_ps(), _mm_setzero_ps());
  // (tx, ty) = (n.po - (n.dodx, n.dody)) / (n.d + (n.dddx, n.dddy)), in lanes 0 and 1.
  const __m128 num = _mm_sub_ps(_mm_shuffle_ps(n4, n4, _MM_SHUFFLE(0, 0, 0, 0)), _mm_movehl_ps(n4, n4));
  const __m128 den = _mm_add_ps(_mm_shuffle_ps(n4, n4, _MM_SHUFFLE(1, 1, 1, 1)), n2);
  const __m128 t = _mm_div_ps(num, den);
  const __m128 tx = _mm_shuffle_ps(t, t, _MM_SHUFFLE(0, 0, 0, 0)), ty = _mm_shuffle_ps(t, t, _MM_SHUFFLE(1, 1, 1, 1));
  const __m128 dpdx = _mm_sub_ps(_mm_add_ps(ox, _mm_mul_ps(_mm_add_ps(d, dx), tx)), po);
  const __m128 dpdy = _mm_sub_ps(_mm_add_ps(oy, _mm_mul_ps(_mm_add_ps(d, dy), ty)), po);
  // An infinity or NaN in any of them (a ray parallel to the plane) leaves the footprint empty.
  if (!all_finite(_mm_add_ps(_mm_movelh_ps(t, t), _mm_add_ps(dpdx, dpdy)))) return;
  store3(si.dpdx, dpdx);
  store3(si.dpdy, dpdy);
  if (!uv) return;
  // The offsets lie in the tangent plane, along which uv moves by the gradients:
  // (duvdx.x, duvdx.y, duvdy.x, duvdy.y).
  const __m128 gu = load3(uv->u), gv = load3(uv->v);
  const __m128 duv = sum_xyz4(_mm_mul_ps(gu, dpdx), _mm_mul_ps(gv, dpdx), _mm_mul_ps(gu, dpdy), _mm_mul_ps(gv, dpdy));
  if (!all_finite(duv)) return;
  alignas(16) float f[4];
  _mm_store_ps(f, duv);
  si.duvdx = {f[0], f[1]};
  si.duvdy = {f[2], f[3]};
  // The footprint's centre: the ray through it met with the same plane, so that its uv is not
  // linearised where the surface runs edge-on.
  const Vec2f c = rd.centre;
  if (c.x != 0.0f || c.y != 0.0f) {
    alignas(16) float a[4], b[4];
    _mm_store_ps(a, n4);
    _mm_store_ps(b, n2);
    const float tc = (a[0] - (c.x * a[2] + c.y * a[3])) / (a[1] + (c.x * b[0] + c.y * b[1]));
    const __m128 cx = splat(c.x), cy = splat(c.y);
    const __m128 pc = _mm_sub_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(ox, cx), _mm_mul_ps(oy, cy)),
                   _mm_mul_ps(_mm_add_ps(d, _mm_add_ps(_mm_mul_ps(dx, cx), _mm_mul_ps(dy, cy))), splat(tc))),
        po);
    const __m128 duvc = sum_xyz4(_mm_mul_ps(gu, pc), _mm_mul_ps(gv, pc), _mm_setzero_ps(), _mm_setzero_ps());
    _mm_store_ps(f, duvc);
    if (std::isfinite(f[0] + f[1])) si.duv_centre = {f[0], f[1]};
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
