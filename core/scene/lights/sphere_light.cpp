#include "core/scene/lights/sphere_light.h"

#include "core/math/frame.h"
#include "core/math/sampling.h"

namespace pt {

bool SphereLight::sample(const Vec3f& p, float pick, Vec2f u, LightSample& ls) const {
  float dc2, r2;
  ls.radiance = radiance;
  ls.delta = false;
  if (outside(p, &dc2, &r2)) {
    Vec3f to_c = center - p;
    float dc = std::sqrt(dc2);
    float one_minus_cos_max = one_minus_cos_from_sin2(r2 / dc2);
    Frame frame(to_c / dc);
    Vec3f local = square_to_uniform_cone(u, one_minus_cos_max);
    ls.wi = frame.to_world(local);
    float cos_t = local.z;
    float sin2_t = local.x * local.x + local.y * local.y;
    float ds = dc * cos_t - std::sqrt(std::max(0.0f, r2 - dc2 * sin2_t));
    ls.distance = ds;
    ls.point = p + ls.wi * ds;
    ls.normal = normalize(ls.point - center);
    ls.point = center + ls.normal * radius;
    ls.pdf = pick * uniform_cone_pdf(one_minus_cos_max);
    return ls.pdf > 0 && std::isfinite(ls.pdf);
  }
  Vec3f n = square_to_uniform_sphere(u);
  return area_sample(p, center + n * radius, n, pick, area, ls);
}

float SphereLight::pdf(const Vec3f& p, float pick, const Vec3f& q, const Vec3f& n) const {
  float dc2, r2;
  if (outside(p, &dc2, &r2)) return pick * uniform_cone_pdf(one_minus_cos_from_sin2(r2 / dc2));
  return area_pdf(p, q, n, pick, area);
}

}  // namespace pt
