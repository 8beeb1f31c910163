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
// Auto's "near": the group's area exceeds this times the squared distance to its centroid (closer
// than the light's size). A solid-angle sample costs more than an area sample, and pays many times
// over only close to a light (`pt bench converge --light-sampling area,auto`, 256x256, 32 spp, one
// thread, docs/cycles.md): under scenes/panel-floor's panel 1/(MSE x time) rose 5.6-5.9x at 0.5-1
// and 1.8x at 2; in the hexagonal room, whose error lies elsewhere, 0.2 cost 28% more time for 5%
// less MSE and 0.5 cost 20% for 3%, while at 1 none of the comparison rooms' points qualifies.
constexpr float kNearSolidAngle = 1.0f;

// The group's plane faces p, and the group is near enough (or solid angles are forced).
inline bool group_near(const TriangleGroup& g, LightSampling mode, const Vec3f& p) {
  if (mode == LightSampling::kArea || !(dot(p - g.point, g.normal) > 0)) return false;
  return mode == LightSampling::kSolidAngle || g.area > kNearSolidAngle * length_squared(g.centroid - p);
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
    add_triangle_to_group(mesh, lights_.size() - 1);
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
  for (TriangleGroup& g : groups_) {
    g.pick = 0;
    for (uint32_t m = g.first; m < g.first + g.count; ++m) {
      lights_[m].group_offset = g.pick;
      g.pick += choice_pdf(static_cast<int>(m));
    }
  }
}

// Joins the triangle light `index` (the last one added) to the group before it when it continues
// that group, else starts a group of its own.
void LightSet::add_triangle_to_group(const Mesh& mesh, size_t index) {
  Light& l = lights_[index];
  const Vec3f v[3] = {mesh.vertex(l.index, 0), mesh.vertex(l.index, 1), mesh.vertex(l.index, 2)};
  if (!groups_.empty()) {
    TriangleGroup& g = groups_.back();
    const Light& first = lights_[g.first];
    bool joins = g.first + g.count == index && g.count < TriangleGroup::kMaxTriangles &&
                 l.intensity.x == first.intensity.x && l.intensity.y == first.intensity.y &&
                 l.intensity.z == first.intensity.z && dot(l.normal, g.normal) > 1.0f - 1e-5f;
    const float tolerance = 1e-5f * std::sqrt(g.area + l.area);
    for (const Vec3f& q : v) joins = joins && std::abs(dot(q - g.point, g.normal)) <= tolerance;
    bool touches = false;
    for (uint32_t m = g.first; m < g.first + g.count && joins && !touches; ++m) {
      for (int c = 0; c < 3; ++c) {
        for (const Vec3f& q : v) touches = touches || (mesh.vertex(lights_[m].index, c) == q);
      }
    }
    if (joins && touches) {
      g.centroid = (g.centroid * g.area + l.centroid * l.area) / (g.area + l.area);
      g.area += l.area;
      ++g.count;
      l.group = static_cast<uint32_t>(groups_.size() - 1);
      return;
    }
  }
  TriangleGroup g;
  g.first = static_cast<uint32_t>(index);
  g.count = 1;
  g.area = l.area;
  g.centroid = l.centroid;
  g.normal = l.normal;
  g.point = l.position;
  l.group = static_cast<uint32_t>(groups_.size());
  groups_.push_back(g);
}

bool LightSet::group_solid_angles(const TriangleGroup& g, const Vec3f& p, SphericalTriangle* st, float& total) const {
  total = 0;
  for (uint32_t m = 0; m < g.count; ++m) {
    const Light& l = lights_[g.first + m];
    // A member too small (or too large) for the map's precision sends the whole group to area
    // sampling, so that no part of it goes unsampled.
    if (!make_spherical_triangle(p, l.position, l.position + l.edge1, l.position + l.edge2, st[m]) ||
        !(st[m].area >= kMinSolidAngle && st[m].area <= kMaxSolidAngle)) {
      return false;
    }
    total += st[m].area;
  }
  return total <= kMaxSolidAngle;
}

// Near a group: a member in proportion to its solid angle, then a direction uniform in it, so the
// density is the group's choice probability over its summed solid angle. The member is chosen with
// a number uniform over the group: where u_select fell among the members' choice probabilities.
bool LightSet::sample_triangle(size_t index, float pick, float u_rest, const Vec3f& p, Vec2f u, LightSample& ls) const {
  const Light& light = lights_[index];
  const TriangleGroup& g = groups_[light.group];
  ls.delta = false;
  // The spherical triangles are made (and their array set up) only near a light, not for the far
  // samples that are most of them.
  if (group_near(g, triangle_sampling_, p)) {
    SphericalTriangle st[TriangleGroup::kMaxTriangles];
    float total;
    if (group_solid_angles(g, p, st, total)) {
      float target = std::min((light.group_offset + u_rest * pick) / g.pick, 0x1.fffffep-1f) * total;
      uint32_t m = 0;
      while (m + 1 < g.count && target >= st[m].area) target -= st[m].area, ++m;
      Vec3f w = sample_spherical_triangle(st[m], u);
      float cos_l = -dot(w, g.normal);
      if (!(cos_l > 0)) return false;
      ls.radiance = lights_[g.first + m].intensity;
      ls.wi = w;
      ls.distance = dot(p - g.point, g.normal) / cos_l;  // along w to the group's plane
      ls.point = p + w * ls.distance;
      ls.normal = g.normal;
      ls.pdf = g.pick / total;
      return std::isfinite(ls.distance);
    }
  }
  ls.radiance = light.intensity;
  Vec2f b = square_to_triangle(u);
  Vec3f q = light.position + light.edge1 * b.x + light.edge2 * b.y;
  return area_sample(p, q, light.normal, pick, light.area, ls);
}

float LightSet::triangle_pdf(size_t index, const Vec3f& p, const Vec3f& q, const Vec3f& n) const {
  const TriangleGroup& g = groups_[lights_[index].group];
  if (group_near(g, triangle_sampling_, p)) {
    SphericalTriangle st[TriangleGroup::kMaxTriangles];
    float total;
    if (group_solid_angles(g, p, st, total)) return g.pick / total;
  }
  return area_pdf(p, q, n, choice_pdf(static_cast<int>(index)), lights_[index].area);
}

bool LightSet::sample(const Environment* environment, const Vec3f& p, float u_select, Vec2f u, LightSample& ls) const {
  if (lights_.empty()) return false;
  float pick, u_rest;
  size_t index = distribution_.sample_discrete(u_select, &pick, &u_rest);
  const Light& light = lights_[index];
  switch (light.type) {
    case LightType::kPoint: return sample_point(light, pick, p, ls);
    case LightType::kTriangle: return sample_triangle(index, pick, u_rest, p, u, ls);
    case LightType::kSphere: return sample_sphere(light, pick, p, u, ls);
    case LightType::kEnvironment: return sample_environment(*environment, pick, u, ls);
  }
  return false;
}

float LightSet::pdf(const Vec3f& p, const SurfaceInteraction& si) const {
  if (si.geom == kGeomTriangles) {
    if (triangle_light_.empty() || triangle_light_[si.prim] < 0) return 0.0f;
    int index = triangle_light_[si.prim];
    return triangle_pdf(index, p, si.p, si.ng);
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
