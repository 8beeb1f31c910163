#include "core/scene/scene.h"

#include <bit>
#include <cstring>

#include "core/util/error.h"

namespace pt {

const char* material_type_name(MaterialType type) {
  switch (type) {
    case MaterialType::kDiffuse: return "diffuse";
    case MaterialType::kMirror: return "mirror";
    case MaterialType::kDielectric: return "dielectric";
    case MaterialType::kGlossy: return "glossy";
  }
  return "?";
}

uint32_t Scene::default_material() {
  for (size_t i = 0; i < materials_.size(); ++i) {
    if (materials_[i].name == "default") return static_cast<uint32_t>(i);
  }
  Material m;
  m.name = "default";
  materials_.push_back(m);
  return static_cast<uint32_t>(materials_.size() - 1);
}

void Scene::finalize() {
  if (mesh_.triangle_count() == 0 && spheres_.empty()) throw Error(source_, "the scene has no geometry");
  mesh_.finalize();
  for (const Vec3f& p : mesh_.positions) {
    if (!is_finite(p)) throw Error(source_, "non-finite vertex position after transforms");
  }
  bounds_ = mesh_.bounds();
  for (const Sphere& s : spheres_) {
    if (!is_finite(s.center) || !std::isfinite(s.radius) || !(s.radius > 0)) {
      throw Error(source_, "sphere with a non-finite centre or a radius that is not positive");
    }
    bounds_.expand(s.bounds());
  }
  // The bounds are the geometry's only: the default camera frames them, and a point light off to
  // one side would otherwise pull the view off the model (and push the model into a corner).
  scene_radius_ = std::max(1e-3f, 0.5f * length(bounds_.extent()));
  if (!has_camera_) {
    camera_ = Camera::framing(bounds_, static_cast<float>(settings_.width) / settings_.height);
  }

  degenerate_triangles_ = 0;
  for (size_t t = 0; t < mesh_.triangle_count(); ++t) {
    if (!(mesh_.area(t) > 0)) ++degenerate_triangles_;
  }

  lights_.clear();
  triangle_light_.clear();
  sphere_light_.clear();
  environment_light_ = -1;
  for (Light l : point_lights_) {
    l.type = LightType::kPoint;
    l.power = 4.0f * kPi * luminance(l.intensity);
    lights_.push_back(l);
  }
  for (size_t t = 0; t < mesh_.triangle_count(); ++t) {
    const Material& m = materials_[mesh_.material[t]];
    float area = mesh_.area(t);
    if (!m.is_emissive() || !(area > 0)) continue;
    if (triangle_light_.empty()) triangle_light_.assign(mesh_.triangle_count(), -1);
    triangle_light_[t] = static_cast<int32_t>(lights_.size());
    Light l;
    l.type = LightType::kTriangle;
    l.index = static_cast<uint32_t>(t);
    l.position = mesh_.vertex(t, 0);
    l.edge1 = mesh_.vertex(t, 1) - l.position;
    l.edge2 = mesh_.vertex(t, 2) - l.position;
    l.normal = normalize(cross(l.edge1, l.edge2));
    l.area = area;
    l.intensity = m.emission;
    l.power = kPi * area * luminance(m.emission);
    lights_.push_back(l);
  }
  for (size_t s = 0; s < spheres_.size(); ++s) {
    const Material& m = materials_[spheres_[s].material];
    if (!m.is_emissive()) continue;
    if (sphere_light_.empty()) sphere_light_.assign(spheres_.size(), -1);
    sphere_light_[s] = static_cast<int32_t>(lights_.size());
    Light l;
    l.type = LightType::kSphere;
    l.index = static_cast<uint32_t>(s);
    l.power = kPi * spheres_[s].area() * luminance(m.emission);
    lights_.push_back(l);
  }
  if (environment_ && luminance(environment_->average()) > 0) {
    environment_light_ = static_cast<int>(lights_.size());
    float power = kPi * kPi * scene_radius_ * scene_radius_ * luminance(environment_->average());
    Light l;
    l.type = LightType::kEnvironment;
    l.power = power;
    lights_.push_back(l);
  }
  std::vector<float> powers;
  for (const Light& l : lights_) powers.push_back(l.power);
  light_distribution_ = lights_.empty() ? Distribution1D() : Distribution1D(powers);
}

SurfaceInteraction Scene::interaction(const Ray& ray, const Hit& hit) const {
  SurfaceInteraction si;
  si.geom = hit.geom;
  si.prim = hit.prim;
  if (hit.geom == kGeomSpheres) {
    const Sphere& s = spheres_[hit.prim];
    Vec3f n = normalize(ray.o + ray.d * hit.t - s.center);
    si.p = s.center + n * s.radius;  // reprojected onto the surface: removes the error of o + t d
    si.ng = si.ns = n;
    si.uv = {0.5f + std::atan2(n.x, n.z) / (2.0f * kPi), 1.0f - std::acos(std::clamp(n.y, -1.0f, 1.0f)) * kInvPi};
    si.material = s.material;
    return si;
  }
  size_t t = hit.prim;
  float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
  Vec3f p0 = mesh_.vertex(t, 0), p1 = mesh_.vertex(t, 1), p2 = mesh_.vertex(t, 2);
  si.p = p0 * b0 + p1 * b1 + p2 * b2;
  Vec3f ng = cross(p1 - p0, p2 - p0);
  float len = length(ng);
  si.ng = len > 0 ? ng / len : -ray.d;
  si.ns = si.ng;
  if (!mesh_.corner_normals.empty()) {
    Vec3f n = mesh_.corner_normals[3 * t] * b0 + mesh_.corner_normals[3 * t + 1] * b1 +
              mesh_.corner_normals[3 * t + 2] * b2;
    float nl = length(n);
    if (nl > 0 && std::isfinite(nl)) {
      n = n / nl;
      si.ns = dot(n, si.ng) < 0 ? -n : n;
    }
  }
  if (!mesh_.corner_uvs.empty()) {
    si.uv = mesh_.corner_uvs[3 * t] * b0 + mesh_.corner_uvs[3 * t + 1] * b1 + mesh_.corner_uvs[3 * t + 2] * b2;
  } else {
    si.uv = {b1, b2};
  }
  si.material = mesh_.material[t];
  return si;
}

Spectrum Scene::albedo(const SurfaceInteraction& si) const {
  const Material& m = materials_[si.material];
  if (m.kd_texture >= 0) return textures_[m.kd_texture]->lookup(si.uv) * m.kd;
  if (m.type == MaterialType::kMirror) return m.ks;
  if (m.type == MaterialType::kDielectric) return Spectrum(1.0f);
  return m.kd;
}

Bsdf Scene::bsdf(const SurfaceInteraction& si) const {
  const Material& m = materials_[si.material];
  Bsdf b;
  b.type = m.type;
  b.kd = m.kd_texture >= 0 ? textures_[m.kd_texture]->lookup(si.uv) * m.kd : m.kd;
  b.ks = m.ks;
  b.exponent = m.exponent;
  b.ior = m.ior;
  return b;
}

Spectrum Scene::emitted(const SurfaceInteraction& si, const Vec3f& w) const {
  const Material& m = materials_[si.material];
  if (!m.is_emissive() || dot(w, si.ng) <= 0) return Spectrum(0.0f);
  return m.emission;
}

bool Scene::sample_light(const Vec3f& p, float u_select, Vec2f u, LightSample& ls) const {
  if (lights_.empty()) return false;
  float pick;
  size_t index = light_distribution_.sample_discrete(u_select, &pick);
  const Light& light = lights_[index];
  switch (light.type) {
    case LightType::kPoint: {
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
    case LightType::kTriangle: {
      Vec2f b = square_to_triangle(u);
      Vec3f q = light.position + light.edge1 * b.x + light.edge2 * b.y;
      const Vec3f& n = light.normal;
      float area = light.area;
      Vec3f d = q - p;
      float d2 = length_squared(d);
      if (!(d2 > 0)) return false;
      ls.distance = std::sqrt(d2);
      ls.wi = d / ls.distance;
      float cos_l = -dot(ls.wi, n);
      if (cos_l <= 0) return false;
      ls.point = q;
      ls.normal = n;
      ls.radiance = light.intensity;
      ls.pdf = pick * d2 / (cos_l * area);
      ls.delta = false;
      return true;
    }
    case LightType::kSphere: {
      const Sphere& s = spheres_[light.index];
      Vec3f to_c = s.center - p;
      float dc2 = length_squared(to_c);
      float r2 = s.radius * s.radius;
      ls.radiance = materials_[s.material].emission;
      ls.delta = false;
      if (dc2 > r2 * 1.0001f) {
        // Outside: sample the cone of directions the sphere subtends (PBRT 3rd ed. 14.2.2).
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
        ls.normal = normalize(ls.point - s.center);
        ls.point = s.center + ls.normal * s.radius;
        ls.pdf = pick * uniform_cone_pdf(one_minus_cos_max);
        return ls.pdf > 0 && std::isfinite(ls.pdf);
      }
      Vec3f n = square_to_uniform_sphere(u);
      Vec3f q = s.center + n * s.radius;
      Vec3f d = q - p;
      float d2 = length_squared(d);
      if (!(d2 > 0)) return false;
      ls.distance = std::sqrt(d2);
      ls.wi = d / ls.distance;
      float cos_l = -dot(ls.wi, n);
      if (cos_l <= 0) return false;
      ls.point = q;
      ls.normal = n;
      ls.pdf = pick * d2 / (cos_l * s.area());
      return true;
    }
    case LightType::kEnvironment: {
      float pdf;
      ls.wi = environment_->sample(u, &pdf);
      if (!(pdf > 0)) return false;
      ls.radiance = environment_->eval(ls.wi);
      ls.distance = kInf;
      ls.pdf = pick * pdf;
      ls.delta = false;
      return true;
    }
  }
  return false;
}

float Scene::light_pdf(const Vec3f& p, const SurfaceInteraction& si) const {
  if (si.geom == kGeomTriangles) {
    if (triangle_light_.empty() || triangle_light_[si.prim] < 0) return 0.0f;
    Vec3f d = si.p - p;
    float d2 = length_squared(d);
    float cos_l = std::abs(dot(d, si.ng)) / std::sqrt(d2);
    float area = lights_[triangle_light_[si.prim]].area;
    return cos_l > 0 ? light_choice_pdf(triangle_light_[si.prim]) * d2 / (cos_l * area) : 0.0f;
  }
  if (sphere_light_.empty() || sphere_light_[si.prim] < 0) return 0.0f;
  const Sphere& s = spheres_[si.prim];
  float pick = light_choice_pdf(sphere_light_[si.prim]);
  float dc2 = length_squared(s.center - p), r2 = s.radius * s.radius;
  if (dc2 > r2 * 1.0001f) {
    return pick * uniform_cone_pdf(one_minus_cos_from_sin2(r2 / dc2));
  }
  Vec3f d = si.p - p;
  float d2 = length_squared(d);
  float cos_l = std::abs(dot(d, si.ng)) / std::sqrt(d2);
  return cos_l > 0 ? pick * d2 / (cos_l * s.area()) : 0.0f;
}

float Scene::environment_pdf(const Vec3f& dir) const {
  if (environment_light_ < 0) return 0.0f;
  return light_choice_pdf(environment_light_) * environment_->pdf(dir);
}

Vec3f offset_ray_origin(const Vec3f& p, const Vec3f& n) {
  constexpr float kOrigin = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  Vec3f out;
  for (int i = 0; i < 3; ++i) {
    int32_t offset = static_cast<int32_t>(kIntScale * n[i]);
    int32_t bits = std::bit_cast<int32_t>(p[i]);
    float moved = std::bit_cast<float>(bits + (p[i] < 0 ? -offset : offset));
    out[i] = std::abs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : moved;
  }
  return out;
}

Ray shadow_ray_to(const Vec3f& p, const Vec3f& n, const Vec3f& q) {
  Ray r;
  r.o = offset_ray_origin(p, n);
  Vec3f d = q - r.o;
  float dist = length(d);
  r.d = d / dist;
  r.tmin = 0.0f;
  r.tmax = dist * (1.0f - 1e-4f);
  return r;
}

}  // namespace pt
