#include "core/scene/light.h"

#include "core/math/frame.h"
#include "core/math/sampling.h"
#include "core/math/spherical_triangle.h"

namespace pt {
namespace {

// --- point lights: a delta distribution, never hit by BSDF sampling (no pdf) ----------------

bool sample_point(const Light& light, float pick, const Vec3f& p, LightSample& ls) {
  Vec3f d = light.position - p;
  float d2 = length_squared(d);
  if (!(d2 > 0)) return false;
  ls.distance = std::sqrt(d2);
  ls.wi = d / ls.distance;
  ls.point = light.position;
  ls.normal = -ls.wi;
  ls.radiance = light.intensity / d2;
  ls.pdf = pick;
  ls.delta = true;
  return true;
}

// --- area lights: a point q with normal n, chosen with density pick / area on the surface -----

bool area_sample(const Vec3f& p, const Vec3f& q, const Vec3f& n, float pick, float area, LightSample& ls) {
  Vec3f d = q - p;
  float d2 = length_squared(d);
  if (!(d2 > 0)) return false;
  ls.distance = std::sqrt(d2);
  ls.wi = d / ls.distance;
  float cos_l = -dot(ls.wi, n);
  if (cos_l <= 0) return false;
  ls.point = q;
  ls.normal = n;
  ls.pdf = area_to_solid_angle(pick, d2, cos_l, area);
  return true;
}

float area_pdf(const Vec3f& p, const Vec3f& q, const Vec3f& n, float pick, float area) {
  Vec3f d = q - p;
  float d2 = length_squared(d);
  float cos_l = std::abs(dot(d, n)) / std::sqrt(d2);
  return cos_l > 0 ? area_to_solid_angle(pick, d2, cos_l, area) : 0.0f;
}

// --- triangles: uniform over the area, or over the solid angle (LightSampling) ----------------

// Below this the spherical triangle's float arithmetic loses precision (and the area density is
// as good); above it the triangle nearly covers a hemisphere and Arvo's map degenerates.
constexpr float kMinSolidAngle = 3e-4f;
constexpr float kMaxSolidAngle = 6.2f;
// Auto's "near": the area exceeds this times the squared distance to the centroid (closer than 2.2
// times the light's size). A solid-angle sample costs more (on the Cornell box, where every light
// sample took it, the render took 28% longer for 4% less MSE); near a light it pays many times over
// (a floor 0.6 below a 2 x 2 panel: MSE / 3.3, MSE x time / 2.6; `pt bench converge
// --light-sampling`, docs/cycles.md). At 0.05 the Cornell box took 12% longer for 4% less MSE; at
// 0.2 no point of it qualifies and the panel keeps its whole gain.
constexpr float kNearSolidAngle = 0.2f;

// Whether triangle `light` is sampled by solid angle from p, and if so its spherical triangle. The
// sample and the pdf of the same p decide alike, so MIS sees one density.
// Behind the light's plane it emits nothing toward p, whichever way it is sampled.
bool by_solid_angle(const Light& light, LightSampling mode, const Vec3f& p, SphericalTriangle& st) {
  if (mode == LightSampling::kArea || !(dot(p - light.position, light.normal) > 0)) return false;
  if (mode == LightSampling::kAuto && !(light.area > kNearSolidAngle * length_squared(light.centroid - p))) return false;
  return make_spherical_triangle(p, light.position, light.position + light.edge1, light.position + light.edge2, st) &&
         st.area >= kMinSolidAngle && st.area <= kMaxSolidAngle;
}

bool sample_triangle(const Light& light, LightSampling mode, float pick, const Vec3f& p, Vec2f u, LightSample& ls) {
  ls.radiance = light.intensity;
  ls.delta = false;
  SphericalTriangle st;
  if (by_solid_angle(light, mode, p, st)) {
    Vec3f w = sample_spherical_triangle(st, u);
    float cos_l = -dot(w, light.normal);
    float height = dot(p - light.position, light.normal);  // p's distance in front of the light's plane
    if (!(cos_l > 0)) return false;
    ls.wi = w;
    ls.distance = height / cos_l;
    ls.point = p + w * ls.distance;
    ls.normal = light.normal;
    ls.pdf = pick / st.area;
    return std::isfinite(ls.distance);
  }
  Vec2f b = square_to_triangle(u);
  Vec3f q = light.position + light.edge1 * b.x + light.edge2 * b.y;
  return area_sample(p, q, light.normal, pick, light.area, ls);
}

float triangle_pdf(const Light& light, LightSampling mode, float pick, const Vec3f& p, const Vec3f& q, const Vec3f& n) {
  SphericalTriangle st;
  if (by_solid_angle(light, mode, p, st)) return pick / st.area;
  return area_pdf(p, q, n, pick, light.area);
}

// --- spheres: the cone they subtend from outside (PBRT 3rd ed. 14.2.2), uniform over the area
// from inside (or so close that the cone degenerates) ----------------------------------------

bool outside_sphere(const Light& light, const Vec3f& p, float* dc2, float* r2) {
  *dc2 = length_squared(light.position - p);
  *r2 = light.radius * light.radius;
  return *dc2 > *r2 * 1.0001f;
}

bool sample_sphere(const Light& light, float pick, const Vec3f& p, Vec2f u, LightSample& ls) {
  float dc2, r2;
  ls.radiance = light.intensity;
  ls.delta = false;
  if (outside_sphere(light, p, &dc2, &r2)) {
    Vec3f to_c = light.position - p;
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
    ls.normal = normalize(ls.point - light.position);
    ls.point = light.position + ls.normal * light.radius;
    ls.pdf = pick * uniform_cone_pdf(one_minus_cos_max);
    return ls.pdf > 0 && std::isfinite(ls.pdf);
  }
  Vec3f n = square_to_uniform_sphere(u);
  return area_sample(p, light.position + n * light.radius, n, pick, light.area, ls);
}

float sphere_pdf(const Light& light, float pick, const Vec3f& p, const Vec3f& q, const Vec3f& n) {
  float dc2, r2;
  if (outside_sphere(light, p, &dc2, &r2)) return pick * uniform_cone_pdf(one_minus_cos_from_sin2(r2 / dc2));
  return area_pdf(p, q, n, pick, light.area);
}

// --- the environment: its own importance sampling (environment.h) ----------------------------

bool sample_environment(const Environment& env, float pick, Vec2f u, LightSample& ls) {
  float pdf;
  ls.wi = env.sample(u, &pdf);
  if (!(pdf > 0)) return false;
  ls.radiance = env.eval(ls.wi);
  ls.distance = kInf;
  ls.pdf = pick * pdf;
  ls.delta = false;
  return true;
}

}  // namespace

LightSet::LightSet(const Geometry& geometry, const std::vector<Material>& materials,
                   const std::vector<Light>& point_lights, const Environment* environment, float scene_radius,
                   LightSampling triangle_sampling)
    : triangle_sampling_(triangle_sampling) {
  const Mesh& mesh = geometry.mesh();
  for (Light l : point_lights) {
    l.type = LightType::kPoint;
    l.power = 4.0f * kPi * luminance(l.intensity);
    lights_.push_back(l);
  }
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Material& m = materials[mesh.material[t]];
    float area = mesh.area(t);
    if (!m.is_emissive() || !(area > 0)) continue;
    if (triangle_light_.empty()) triangle_light_.assign(mesh.triangle_count(), -1);
    triangle_light_[t] = static_cast<int32_t>(lights_.size());
    Light l;
    l.type = LightType::kTriangle;
    l.index = static_cast<uint32_t>(t);
    l.position = mesh.vertex(t, 0);
    l.edge1 = mesh.vertex(t, 1) - l.position;
    l.edge2 = mesh.vertex(t, 2) - l.position;
    l.normal = normalize(cross(l.edge1, l.edge2));
    l.centroid = l.position + (l.edge1 + l.edge2) * (1.0f / 3.0f);
    l.area = area;
    l.intensity = m.emission;
    l.power = kPi * area * luminance(m.emission);
    lights_.push_back(l);
  }
  const std::vector<Sphere>& spheres = geometry.spheres();
  for (size_t s = 0; s < spheres.size(); ++s) {
    const Material& m = materials[spheres[s].material];
    if (!m.is_emissive()) continue;
    if (sphere_light_.empty()) sphere_light_.assign(spheres.size(), -1);
    sphere_light_[s] = static_cast<int32_t>(lights_.size());
    Light l;
    l.type = LightType::kSphere;
    l.index = static_cast<uint32_t>(s);
    l.position = spheres[s].center;
    l.radius = spheres[s].radius;
    l.area = spheres[s].area();
    l.intensity = m.emission;
    l.power = kPi * l.area * luminance(m.emission);
    lights_.push_back(l);
  }
  if (environment && luminance(environment->average()) > 0) {
    environment_light_ = static_cast<int>(lights_.size());
    Light l;
    l.type = LightType::kEnvironment;
    l.power = kPi * kPi * scene_radius * scene_radius * luminance(environment->average());
    lights_.push_back(l);
  }
  std::vector<float> powers;
  for (const Light& l : lights_) powers.push_back(l.power);
  distribution_ = lights_.empty() ? Distribution1D() : Distribution1D(powers);
}

bool LightSet::sample(const Environment* environment, const Vec3f& p, float u_select, Vec2f u, LightSample& ls) const {
  if (lights_.empty()) return false;
  float pick;
  size_t index = distribution_.sample_discrete(u_select, &pick);
  const Light& light = lights_[index];
  switch (light.type) {
    case LightType::kPoint: return sample_point(light, pick, p, ls);
    case LightType::kTriangle: return sample_triangle(light, triangle_sampling_, pick, p, u, ls);
    case LightType::kSphere: return sample_sphere(light, pick, p, u, ls);
    case LightType::kEnvironment: return sample_environment(*environment, pick, u, ls);
  }
  return false;
}

float LightSet::pdf(const Vec3f& p, const SurfaceInteraction& si) const {
  if (si.geom == kGeomTriangles) {
    if (triangle_light_.empty() || triangle_light_[si.prim] < 0) return 0.0f;
    int index = triangle_light_[si.prim];
    return triangle_pdf(lights_[index], triangle_sampling_, choice_pdf(index), p, si.p, si.ng);
  }
  if (sphere_light_.empty() || sphere_light_[si.prim] < 0) return 0.0f;
  int index = sphere_light_[si.prim];
  return sphere_pdf(lights_[index], choice_pdf(index), p, si.p, si.ng);
}

float LightSet::environment_pdf(const Environment& environment, const Vec3f& dir) const {
  if (environment_light_ < 0) return 0.0f;
  return choice_pdf(environment_light_) * environment.pdf(dir);
}

}  // namespace pt
