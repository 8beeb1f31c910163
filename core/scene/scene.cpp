#include "core/scene/scene.h"

#include <bit>
#include <cstdio>
#include <cstring>

#include <emmintrin.h>

#include "core/geometry/tangents.h"
#include "core/geometry/uv_gradients.h"
#include "core/scene/footprint.h"
#include "core/scene/studio.h"
#include "core/util/error.h"

namespace pt {

namespace {
// Scene::texture_use_: a hit on the material looks textures up (its footprint in uv, from dp/du and
// dp/dv, is needed where the ray has differentials), or bends its normal by a map (the tangent
// frame: the mesh's tangents, else dp/du and dp/dv). A hit needing neither in a textured scene
// gets only the footprint's extent (dp/dx, dp/dy), which the bounce's differentials start from.
constexpr uint8_t kTextureLookups = 1, kTangentFrame = 2;
}  // namespace

void check_geometry(const SceneBuilder& b, const std::string& source, size_t studio_first_triangle) {
  if (!b.has_geometry()) throw Error(source, "the scene has no geometry");
  for (const Vec3f& p : b.mesh.positions) {
    if (!is_finite(p)) throw Error(source, "non-finite vertex position after transforms");
  }
  for (const Mesh& m : b.meshes) {
    for (const Vec3f& p : m.positions) {
      if (!is_finite(p)) throw Error(source, "non-finite vertex position in an instanced mesh");
    }
  }
  for (const Sphere& s : b.spheres) {
    if (!is_finite(s.center) || !std::isfinite(s.radius) || !(s.radius > 0)) {
      throw Error(source, "sphere with a non-finite centre or a radius that is not positive");
    }
  }
  // Extents: what Embree can trace (and float can still resolve), checked before any ray exists.
  auto check_extent = [&](const Vec3f& p, const char* what) {
    if (!within_extent(p, kMaxCoordinate)) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%s at (%g, %g, %g) lies beyond +-%g, the largest coordinate pt takes; scale the scene down",
                    what, p.x, p.y, p.z, static_cast<double>(kMaxCoordinate));
      throw Error(source, buf);
    }
  };
  // The studio's ground (appended last, core/scene/studio.cpp) reaches far beyond the model: a
  // model that fits may still be too large for its ground, which is then the one to name.
  size_t model_vertices = studio_first_triangle < b.mesh.triangle_count() ? b.mesh.indices[3 * studio_first_triangle]
                                                                          : b.mesh.positions.size();
  for (size_t i = 0; i < b.mesh.positions.size(); ++i) {
    check_extent(b.mesh.positions[i], i < model_vertices ? "a vertex (after transforms)"
                                                         : "the studio's ground (--studio none leaves it out)");
  }
  std::vector<BBox> object_bounds;
  for (const Mesh& m : b.meshes) object_bounds.push_back(m.bounds());
  for (const Instance& i : b.instances) {
    BBox box = transform_bounds(object_bounds[i.mesh], i.to_world);
    if (box.empty()) continue;
    check_extent(box.lo, "an instance's bounds");
    check_extent(box.hi, "an instance's bounds");
  }
  for (const Sphere& s : b.spheres) {
    check_extent(s.center - Vec3f(s.radius), "a sphere's bounds");
    check_extent(s.center + Vec3f(s.radius), "a sphere's bounds");
  }
  for (const PointLight& l : b.point_lights) check_extent(l.position, "a point light");
  for (const SpotLight& l : b.spot_lights) check_extent(l.position(), "a spot light");
  if (b.camera) {
    check_extent(b.camera->position, "the camera");
    check_extent(b.camera->look_at, "the camera's look_at");
  }
}

Scene::Scene(SceneBuilder&& b)
    : source_(std::move(b.source)),
      inputs_(std::move(b.inputs)),
      materials_(std::move(b.materials)),
      textures_(std::move(b.textures)),
      environment_(std::move(b.environment)),
      camera_(b.camera),
      settings_(b.settings),
      notes_(std::move(b.notes)),
      contents_(std::move(b.contents)),
      studio_(std::move(b.studio)) {
  b.resolve_instances();
  check_geometry(b, source_, studio_ ? studio_->first_triangle : SIZE_MAX);
  if (textures_.cache) textures_.cache->finish_loading();
  if (textured()) {
    for (const Material& m : materials_) {
      texture_use_.push_back(static_cast<uint8_t>((m.reads_textures() ? kTextureLookups : 0) |
                                                  (m.has_normal_map() ? kTangentFrame : 0)));
    }
  }
  for (const Material& m : materials_) {
    if (!(m.opacity >= 0.0f && m.opacity <= 1.0f)) {
      throw Error(source_, "material '" + m.name + "': opacity must be from 0 to 1");
    }
    if (m.is_emissive() && m.is_partly_transparent()) {
      throw Error(source_, "material '" + m.name + "' emits light, so it must be opaque");
    }
  }
  std::vector<bool> seen(materials_.size(), false);
  b.for_each_used_material([&](uint32_t m) {
    if (seen[m]) return;
    seen[m] = true;
    partial_coverage_ = partial_coverage_ || materials_[m].is_partly_transparent();
    specular_surfaces_ = specular_surfaces_ || (materials_[m].flags() & kBsdfDelta) != 0;
  });
  // Normal maps need tangent frames: the file's, else made once here, for the meshes that have them.
  auto needs_tangents = [&](const Mesh& m) {
    if (!m.corner_tangents.empty()) return false;
    for (uint32_t id : m.material) {
      if (materials_[id].normal_texture >= 0) return true;
    }
    return false;
  };
  if (needs_tangents(b.mesh)) compute_tangents(b.mesh);
  for (Mesh& m : b.meshes) {
    if (needs_tangents(m)) compute_tangents(m);
  }
  // Filtered lookups turn the footprint into uv by the triangle's uv gradients: made once here for
  // the meshes with a material that looks textures up (24 bytes a triangle).
  auto needs_uv_gradients = [&](const Mesh& m) {
    if (!textured() || !textures_.filtered()) return false;
    for (uint32_t id : m.material) {
      if (id < texture_use_.size() && (texture_use_[id] & kTextureLookups)) return true;
    }
    return false;
  };
  if (needs_uv_gradients(b.mesh)) compute_uv_gradients(b.mesh);
  for (Mesh& m : b.meshes) {
    if (needs_uv_gradients(m)) compute_uv_gradients(m);
  }
  geometry_ = Geometry(std::move(b.mesh), std::move(b.spheres), std::move(b.meshes), std::move(b.instances));
  // The bounds are the geometry's only: the default camera frames them, and a point light off to
  // one side would otherwise pull the view off the model (and push the model into a corner).
  bounds_ = studio_ ? studio_->model_bounds : geometry_.bounds();
  const Mesh& mesh = geometry_.mesh();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (!(mesh.area(t) > 0)) ++degenerate_triangles_;
  }
  std::vector<size_t> object_degenerate;
  for (const Geometry& object : geometry_.objects()) {
    const Mesh& m = object.mesh();
    size_t n = 0;
    for (size_t t = 0; t < m.triangle_count(); ++t) n += !(m.area(t) > 0);
    object_degenerate.push_back(n);
  }
  for (const Instance& i : geometry_.instances()) degenerate_triangles_ += object_degenerate[i.mesh];
  const SceneChoices& choices = settings_.choices;
  environment_sampled_ = environment_emits() && (choices.sky_sampling == SkySampling::kLight ||
                                                 (choices.sky_sampling == SkySampling::kAuto && environment_->has_image()));
  make_lights(PunctualLights{std::move(b.point_lights), std::move(b.spot_lights), std::move(b.directional_lights)});
  const float scene_radius = std::max(1e-3f, 0.5f * length(bounds_.extent()));

  mirror_planes_ = find_mirror_planes(geometry_, materials_, 2.0f * scene_radius, mirror_plane_of_);
  flat_mirror_planes_found_ = mirror_planes_.size();
  // Each mirror (plane or sphere) costs two rays per light sample at every diffuse vertex: automatic
  // up to a few of each kind. Its visibility test is an opaque query, so scenes with partial coverage
  // leave mirrors to BSDF sampling.
  auto use_mirrors = [&](size_t count) {
    return count > 0 && !lights_.empty() && !partial_coverage_ &&
           (choices.mirror_sampling == MirrorSampling::kOn ||
            (choices.mirror_sampling == MirrorSampling::kAuto && count <= kMaxAutoMirrorPlanes));
  };
  if (!use_mirrors(mirror_planes_.size())) {
    mirror_planes_.clear();
    mirror_plane_of_.clear();
  }
  // Mirror spheres: the same switch and rule, counted apart.
  const std::vector<Sphere>& spheres = geometry_.spheres();
  for (size_t i = 0; i < spheres.size(); ++i) {
    if (materials_[spheres[i].material].flags() == (kBsdfReflection | kBsdfDelta)) {
      mirror_spheres_.push_back(static_cast<uint32_t>(i));
    }
  }
  mirror_spheres_found_ = mirror_spheres_.size();
  if (!use_mirrors(mirror_spheres_.size())) mirror_spheres_.clear();
  if (!mirror_spheres_.empty()) {
    mirror_sphere_of_.assign(spheres.size(), -1);
    for (size_t j = 0; j < mirror_spheres_.size(); ++j) mirror_sphere_of_[mirror_spheres_[j]] = static_cast<int32_t>(j);
  }
}

void Scene::make_lights(PunctualLights punctual) {
  const float scene_radius = std::max(1e-3f, 0.5f * length(bounds_.extent()));
  MaterialEmission emission;
  emission.textures = &textures_;
  for (const Material& m : materials_) {
    emission.radiance.push_back(m.is_emissive() ? m.emission : Spectrum(0.0f));
    emission.texture.push_back(m.is_emissive() ? m.emission_texture : -1);
  }
  const SceneChoices& choices = settings_.choices;
  try {
    lights_ = LightSet(geometry_, emission, punctual, environment_sampled_ ? &*environment_ : nullptr, scene_radius,
                       choices.light_sampling, choices.light_selection);
  } catch (const Error& e) {
    throw Error(source_, e.what());
  }
  surface_lights_ = lights_.count(LightType::kTriangle) + lights_.count(LightType::kSphere) > 0;
}

void Scene::arrange_studio(const Camera& camera) {
  if (!studio_) throw Error(source_, "arrange_studio: the scene has no studio");
  // A studio lights a scene where nothing else does: the sky is the one light.
  studio_->camera = camera;
  environment_ = studio_sky(studio_->sun, studio_->up, camera.position - camera.look_at);
  make_lights(PunctualLights{});
}

std::vector<std::string> Scene::sampling_choices() const {
  std::vector<std::string> out;
  if (environment_) {
    if (environment_sampled()) {
      out.push_back(std::string("sky: light-sampled") +
                    (environment_->has_image() ? " (the environment varies with direction)" : " (forced by --sky-sampling light)"));
    } else if (environment_emits()) {
      out.push_back(std::string("sky: found by BSDF sampling only") +
                    (environment_->has_image() ? " (forced by --sky-sampling bsdf)"
                                               : " (constant: light samples could not beat cosine-weighted ones; --sky-sampling light overrides)"));
    }
  }
  if (lights_.emitters() > 0) {  // directional lights and the environment alone are chosen by power
    std::string n = std::to_string(lights_.emitters()) + " emitter" + (lights_.emitters() == 1 ? "" : "s");
    if (lights_.selection() == LightSelection::kTree) {
      out.push_back("light selection: a light tree over " + n +
                    (lights_.requested_selection() == LightSelection::kTree
                         ? " (--light-selection tree)"
                         : " (" + std::to_string(LightSet::kAutoTreeEmitters) + " or more; --light-selection power overrides)"));
    } else {
      out.push_back("light selection: by power among " + n +
                    (lights_.requested_selection() == LightSelection::kPower
                         ? " (--light-selection power)"
                         : " (fewer than " + std::to_string(LightSet::kAutoTreeEmitters) + "; --light-selection tree overrides)"));
    }
  }
  if (!lights_.triangles().empty()) {
    switch (lights_.triangle_sampling()) {
      case LightSampling::kAuto:
        out.push_back("triangle lights: by solid angle where near, else by area (--light-sampling area or solid-angle overrides)");
        break;
      case LightSampling::kArea: out.push_back("triangle lights: by area (--light-sampling area)"); break;
      case LightSampling::kSolidAngle: out.push_back("triangle lights: by solid angle (--light-sampling solid-angle)"); break;
    }
  }
  // One line per kind of mirror the scene has: sampled through, or why not.
  auto mirrors = [&](size_t used, size_t found, const char* kind) {
    const std::string plural = (used > 0 ? used : found) > 1 ? "s" : "";
    if (used > 0) {
      out.push_back("mirrors: lights sampled through " + std::to_string(used) + " " + kind + plural +
                    " (--mirror-sampling off turns it off)");
    } else if (found > 0) {
      out.push_back("mirrors: " + std::to_string(found) + " " + kind + plural + ", not light-sampled" +
                    (lights_.empty() ? std::string(" (no lights)")
                     : settings_.choices.mirror_sampling == MirrorSampling::kOff ? " (--mirror-sampling off)"
                     : partial_coverage_ ? " (the scene has partly transparent surfaces)"
                                         : " (more than " + std::to_string(kMaxAutoMirrorPlanes) + "; --mirror-sampling on)"));
    }
  };
  mirrors(mirror_planes_.size(), flat_mirror_planes_found_, "flat mirror plane");
  mirrors(mirror_spheres_.size(), mirror_spheres_found_, "mirror sphere");
  return out;
}


namespace {

// An instance's triangle is interpolated in its mesh's space and taken into the world: the point by
// the transform, normals by its inverse transpose (Transform::normal, which also keeps the front
// face where the transform mirrors, as baking the mesh reverses its winding).
// dp/du and dp/dv of a triangle's affine uv map (pbrt 3rd ed. 3.6.2), for tangent frames; left zero
// if it is degenerate.
void uv_derivatives(const Vec3f& p0, const Vec3f& p1, const Vec3f& p2, Vec2f uv0, Vec2f uv1, Vec2f uv2,
                    SurfaceInteraction& si) {
  Vec2f duv02 = uv0 - uv2, duv12 = uv1 - uv2;
  Vec3f dp02 = p0 - p2, dp12 = p1 - p2;
  float det = duv02.x * duv12.y - duv02.y * duv12.x;
  if (!(std::abs(det) > 1e-20f)) return;
  const float inv = 1.0f / det;  // one division, not six
  Vec3f dpdu = (dp02 * duv12.y - dp12 * duv02.y) * inv, dpdv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
  if (is_finite(dpdu) && is_finite(dpdv)) si.dpdu = dpdu, si.dpdv = dpdv;
}

// The parts of an interaction only textures need, as far as the material's `use` (kTextureLookups,
// kTangentFrame) asks: the footprint in uv (through the mesh's uv gradients), and the uv
// derivatives and tangents of the tangent frame, in the mesh's space (to_world and to_object take
// them out of an instance).
void texture_interaction(const Mesh& m, size_t t, float b0, float b1, float b2, const Ray& ray, const Instance* instance,
                         uint8_t use, SurfaceInteraction& si) {
  const bool lookups = (use & kTextureLookups) && !ray.diff.empty() && t < m.uv_gradients.size();
  if (use & kTangentFrame) {
    uv_derivatives(m.vertex(t, 0), m.vertex(t, 1), m.vertex(t, 2), m.corner_uv(t, 0), m.corner_uv(t, 1),
                   m.corner_uv(t, 2), si);
    if (3 * t + 2 < m.corner_tangents.size() && 3 * t < m.corner_tangent_signs.size()) {
      si.tangent = m.corner_tangents[3 * t] * b0 + m.corner_tangents[3 * t + 1] * b1 + m.corner_tangents[3 * t + 2] * b2;
      si.tangent_sign = m.corner_tangent_signs[3 * t];
    }
    if (instance) {
      si.dpdu = instance->to_world.vector(si.dpdu);
      si.dpdv = instance->to_world.vector(si.dpdv);
      si.tangent = instance->to_world.vector(si.tangent);
      if (instance->to_world.flips_handedness()) si.tangent_sign = -si.tangent_sign;
    }
  }
  if (!lookups) {
    compute_footprint(ray, si);
    return;
  }
  if (!instance) {
    compute_footprint(ray, si, &m.uv_gradients[t]);
    return;
  }
  // u(world p) = u(to_object p): its gradient is to_object's linear part, transposed, times u's.
  const UvGradients& g = m.uv_gradients[t];
  const UvGradients world{instance->to_object.transposed_vector(g.u), instance->to_object.transposed_vector(g.v)};
  compute_footprint(ray, si, &world);
}

void instance_interaction(const Geometry& geometry, const Ray& ray, const Hit& hit,
                          const std::vector<uint8_t>& texture_use, SurfaceInteraction& si) {
  si.geom = hit.geom;
  si.prim = hit.prim;
  si.inst = hit.inst;
  const Instance& instance = geometry.instances()[hit.inst];
  const Mesh& m = geometry.objects()[instance.mesh].mesh();
  size_t t = hit.prim;
  float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
  Vec3f p0 = m.vertex(t, 0), p1 = m.vertex(t, 1), p2 = m.vertex(t, 2);
  si.p = instance.to_world.point(p0 * b0 + p1 * b1 + p2 * b2);
  Vec3f ng = instance.to_world.normal(cross(p1 - p0, p2 - p0));
  float len = length(ng);
  si.ng = len > 0 && std::isfinite(len) ? ng / len : -ray.d;
  si.ns = si.ng;
  if (!m.corner_normals.empty()) {
    Vec3f n = instance.to_world.normal(m.corner_normals[3 * t] * b0 + m.corner_normals[3 * t + 1] * b1 +
                                       m.corner_normals[3 * t + 2] * b2);
    float nl = length(n);
    if (nl > 0 && std::isfinite(nl)) {
      n = n / nl;
      si.ns = dot(n, si.ng) < 0 ? -n : n;
    }
  }
  if (!m.corner_uvs.empty()) {
    si.uv = m.corner_uvs[3 * t] * b0 + m.corner_uvs[3 * t + 1] * b1 + m.corner_uvs[3 * t + 2] * b2;
  } else {
    si.uv = {b1, b2};
  }
  if (3 * t + 2 < m.corner_colors.size()) {
    si.color = m.corner_colors[3 * t] * b0 + m.corner_colors[3 * t + 1] * b1 + m.corner_colors[3 * t + 2] * b2;
  }
  si.material = m.material[t];
  if (!texture_use.empty()) texture_interaction(m, t, b0, b1, b2, ray, &instance, texture_use[si.material], si);
}

}  // namespace

SurfaceInteraction Scene::interaction(const Ray& ray, const Hit& hit) const {
  SurfaceInteraction si;
  interaction(ray, hit, si);
  return si;
}

void Scene::interaction(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const {
  si = SurfaceInteraction{};
  si.geom = hit.geom;
  si.prim = hit.prim;
  if (hit.geom == kGeomSpheres) {
    const Sphere& s = spheres()[hit.prim];
    Vec3f n = normalize(ray.o + ray.d * hit.t - s.center);
    si.p = s.center + n * s.radius;  // reprojected onto the surface: removes the error of o + t d
    si.ng = si.ns = n;
    si.uv = {0.5f + std::atan2(n.x, n.z) / (2.0f * kPi), 1.0f - std::acos(std::clamp(n.y, -1.0f, 1.0f)) * kInvPi};
    si.material = s.material;
    if (textured()) {
      const uint8_t use = texture_use_[si.material];
      const bool lookups = (use & kTextureLookups) && !ray.diff.empty();
      if (!lookups && !(use & kTangentFrame)) {
        compute_footprint(ray, si);
        return;
      }
      // u = 0.5 + phi / 2 pi with phi = atan2(x, z), v = 1 - theta / pi: dp/du = 2 pi r (z, 0, -x) and
      // dp/dv = -pi r dn/dtheta. Both vanish at the poles, where the map is degenerate. They are
      // orthogonal, so u's gradient is dp/du / |dp/du|^2 and v's likewise.
      const float sin_theta = std::sqrt(n.x * n.x + n.z * n.z);
      si.dpdu = Vec3f(n.z, 0.0f, -n.x) * (2.0f * kPi * s.radius);
      UvGradients g{Vec3f(0.0f), Vec3f(0.0f)};
      if (sin_theta > 1e-6f) {
        const Vec3f dn_dtheta{n.y * n.x / sin_theta, -sin_theta, n.y * n.z / sin_theta};
        si.dpdv = dn_dtheta * (-kPi * s.radius);
        g.u = Vec3f(n.z, 0.0f, -n.x) * (1.0f / (2.0f * kPi * s.radius * sin_theta * sin_theta));
        g.v = dn_dtheta * (-1.0f / (kPi * s.radius));
      }
      compute_footprint(ray, si, lookups ? &g : nullptr);
    }
    return;
  }
  if (hit.inst != kNoInstance) {
    instance_interaction(geometry_, ray, hit, texture_use_, si);
    return;
  }
  size_t t = hit.prim;
  float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
  Vec3f p0 = mesh().vertex(t, 0), p1 = mesh().vertex(t, 1), p2 = mesh().vertex(t, 2);
  si.p = p0 * b0 + p1 * b1 + p2 * b2;
  Vec3f ng = cross(p1 - p0, p2 - p0);
  float len = length(ng);
  si.ng = len > 0 ? ng / len : -ray.d;
  si.ns = si.ng;
  if (!mesh().corner_normals.empty()) {
    Vec3f n = mesh().corner_normals[3 * t] * b0 + mesh().corner_normals[3 * t + 1] * b1 +
              mesh().corner_normals[3 * t + 2] * b2;
    float nl = length(n);
    if (nl > 0 && std::isfinite(nl)) {
      n = n / nl;
      si.ns = dot(n, si.ng) < 0 ? -n : n;
    }
  }
  if (!mesh().corner_uvs.empty()) {
    si.uv = mesh().corner_uvs[3 * t] * b0 + mesh().corner_uvs[3 * t + 1] * b1 + mesh().corner_uvs[3 * t + 2] * b2;
  } else {
    si.uv = {b1, b2};
  }
  if (3 * t + 2 < mesh().corner_colors.size()) {
    si.color = mesh().corner_colors[3 * t] * b0 + mesh().corner_colors[3 * t + 1] * b1 + mesh().corner_colors[3 * t + 2] * b2;
  }
  si.material = mesh().material[t];
  if (textured()) texture_interaction(mesh(), t, b0, b1, b2, ray, nullptr, texture_use_[si.material], si);
}

Spectrum Scene::albedo(const SurfaceInteraction& si) const { return bsdf(si).albedo(); }

Bsdf Scene::bsdf(const SurfaceInteraction& si) const {
  return materials_[si.material].bsdf(TextureLookup{&textures_, si.uv, si.duvdx, si.duvdy, si.color, si.rough_footprint,
                                                                   si.duv_centre});
}

Spectrum Scene::emitted(const SurfaceInteraction& si, const Vec3f& w) const {
  const Material& m = materials_[si.material];
  if (!m.is_emissive() || dot(w, si.ng) <= 0) return Spectrum(0.0f);
  if (m.emission_texture >= 0) return m.emission * textures_.lookup(m.emission_texture, si.uv, si.duvdx, si.duvdy,
                                                                         si.rough_footprint, si.duv_centre);
  return m.emission;
}

// The three components in one SSE register: per component, scalar code took some 55 instructions a
// call, on every bounce and shadow ray (tested against the scalar form in test_stability_robustness).
Vec3f offset_ray_origin(const Vec3f& p, const Vec3f& n) {
  constexpr float kOrigin = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  const __m128 vp = _mm_setr_ps(p.x, p.y, p.z, 0.0f), vn = _mm_setr_ps(n.x, n.y, n.z, 0.0f);
  const __m128i offset = _mm_cvttps_epi32(_mm_mul_ps(vn, _mm_set1_ps(kIntScale)));  // truncated, as a cast
  const __m128i bits = _mm_castps_si128(vp);
  // -offset where p's sign bit is set: (offset ^ s) - s with s = 0 or -1. For p = -0 the sign bit
  // and p < 0 differ, but |p| < kOrigin picks the other branch there.
  const __m128i sign = _mm_srai_epi32(bits, 31);
  const __m128 moved = _mm_castsi128_ps(_mm_add_epi32(bits, _mm_sub_epi32(_mm_xor_si128(offset, sign), sign)));
  const __m128 nudged = _mm_add_ps(vp, _mm_mul_ps(_mm_set1_ps(kFloatScale), vn));
  const __m128 abs_p = _mm_andnot_ps(_mm_set1_ps(-0.0f), vp);
  const __m128 near = _mm_cmplt_ps(abs_p, _mm_set1_ps(kOrigin));
  alignas(16) float out[4];
  _mm_store_ps(out, _mm_or_ps(_mm_and_ps(near, nudged), _mm_andnot_ps(near, moved)));
  return {out[0], out[1], out[2]};
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
