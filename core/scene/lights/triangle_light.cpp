#include "core/scene/lights/triangle_light.h"

#include <cmath>
#include <string>

#include "core/math/sampling.h"
#include "core/util/error.h"

namespace pt {
namespace {

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

}  // namespace

TriangleLights::TriangleLights(const Geometry& geometry, const MaterialEmission& emission, LightSampling sampling)
    : textures_(emission.textures), sampling_(sampling) {
  const Mesh& mesh = geometry.mesh();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) add(geometry, mesh, t, kNoInstance, emission);
  const std::vector<Instance>& instances = geometry.instances();
  if (instances.empty()) return;
  std::vector<size_t> emitting(geometry.objects().size(), 0);
  for (size_t o = 0; o < emitting.size(); ++o) {
    for (uint32_t m : geometry.objects()[o].mesh().material) emitting[o] += max_component(emission.radiance[m]) > 0;
  }
  size_t instanced_lights = 0;
  for (const Instance& i : instances) instanced_lights += emitting[i.mesh];
  if (instanced_lights > kMaxInstancedLights) {
    throw Error("the instances hold " + std::to_string(instanced_lights) + " emitting triangles, more than the " +
                std::to_string(kMaxInstancedLights) + " lights pt takes from instances");
  }
  for (size_t i = 0; i < instances.size() && instanced_lights > 0; ++i) {
    if (emitting[instances[i].mesh] == 0) continue;
    const Mesh& object = geometry.objects()[instances[i].mesh].mesh();
    for (size_t t = 0; t < object.triangle_count(); ++t) add(geometry, object, t, static_cast<uint32_t>(i), emission);
  }
}

namespace {

// The world-space corner c of triangle light l: as its mesh has it, or placed by its instance. The
// world mesh's corners are read as they are, so that its lights round as they did before instances.
Vec3f corner(const Geometry& geometry, const TriangleLight& l, int c) {
  if (l.instance == kNoInstance) return geometry.mesh().vertex(l.triangle, c);
  return geometry.instances()[l.instance].to_world.point(geometry.instance_mesh(l.instance).vertex(l.triangle, c));
}

}  // namespace

void TriangleLights::add(const Geometry& geometry, const Mesh& mesh, size_t t, uint32_t inst,
                         const MaterialEmission& emission) {
  const Spectrum& e = emission.radiance[mesh.material[t]];
  if (!(max_component(e) > 0)) return;
  TriangleLight l;
  l.triangle = static_cast<uint32_t>(t);
  l.instance = inst;
  Vec3f p0 = corner(geometry, l, 0), p1 = corner(geometry, l, 1), p2 = corner(geometry, l, 2);
  float area = inst == kNoInstance ? mesh.area(t) : 0.5f * length(cross(p1 - p0, p2 - p0));
  if (!(area > 0)) return;
  l.v0 = p0;
  l.edge1 = p1 - l.v0;
  l.edge2 = p2 - l.v0;
  l.normal = normalize(cross(l.edge1, l.edge2));
  l.centroid = l.v0 + (l.edge1 + l.edge2) * (1.0f / 3.0f);
  l.area = area;
  l.radiance = e;
  l.texture = emission.texture_of(mesh.material[t]);
  if (l.texture >= 0) {
    Vec2f uv[3] = {{0, 0}, {1, 0}, {0, 1}};
    if (!mesh.corner_uvs.empty()) uv[0] = mesh.corner_uvs[3 * t], uv[1] = mesh.corner_uvs[3 * t + 1], uv[2] = mesh.corner_uvs[3 * t + 2];
    l.uv0 = uv[0], l.duv1 = uv[1] - uv[0], l.duv2 = uv[2] - uv[0];
    l.emission = e;
    // The texture over the triangle: filtered at its centroid over the edges' extent in uv (a
    // footprint the size of the triangle: coarse levels, pt's own), so that the light is chosen by
    // what it sends on average.
    Vec2f centre = l.uv0 + (l.duv1 + l.duv2) * (1.0f / 3.0f);
    l.radiance = e * emission.textures->lookup(l.texture, centre, l.duv1 * 0.5f, l.duv2 * 0.5f, true);
    if (!(max_component(l.radiance) > 0)) return;  // black where it lies: it sends nothing
  }
  lights_.push_back(l);
  add_to_group(geometry, lights_.size() - 1);
}

// Joins the triangle light `index` (the last one added) to the group before it when it continues
// that group, else starts a group of its own.
void TriangleLights::add_to_group(const Geometry& geometry, size_t index) {
  TriangleLight& l = lights_[index];
  const Vec3f v[3] = {corner(geometry, l, 0), corner(geometry, l, 1), corner(geometry, l, 2)};
  if (!groups_.empty()) {
    TriangleGroup& g = groups_.back();
    const TriangleLight& first = lights_[g.first];
    const Spectrum& a = l.texture >= 0 ? l.emission : l.radiance;
    const Spectrum& b = first.texture >= 0 ? first.emission : first.radiance;
    bool joins = g.first + g.count == index && g.count < TriangleGroup::kMaxTriangles && l.instance == first.instance &&
                 l.texture == first.texture && a.x == b.x && a.y == b.y && a.z == b.z && dot(l.normal, g.normal) > 1.0f - 1e-5f;
    const float tolerance = 1e-5f * std::sqrt(g.area + l.area);
    for (const Vec3f& q : v) joins = joins && std::abs(dot(q - g.point, g.normal)) <= tolerance;
    bool touches = false;
    for (uint32_t m = g.first; m < g.first + g.count && joins && !touches; ++m) {
      for (int c = 0; c < 3; ++c) {
        for (const Vec3f& q : v) touches = touches || (corner(geometry, lights_[m], c) == q);
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
  g.point = l.v0;
  l.group = static_cast<uint32_t>(groups_.size());
  groups_.push_back(g);
}

bool TriangleLights::near_solid_angles(const TriangleGroup& g, const Vec3f& p, SphericalTriangle* st,
                                       float& total) const {
  if (!group_near(g, sampling_, p)) return false;
  total = 0;
  for (uint32_t m = 0; m < g.count; ++m) {
    const TriangleLight& l = lights_[g.first + m];
    // A member too small (or too large) for the map's precision sends the whole group to area
    // sampling, so that no part of it goes unsampled.
    if (!make_spherical_triangle(p, l.v0, l.v0 + l.edge1, l.v0 + l.edge2, st[m]) ||
        !(st[m].area >= kMinSolidAngle && st[m].area <= kMaxSolidAngle)) {
      return false;
    }
    total += st[m].area;
  }
  return total <= kMaxSolidAngle;
}

// Near a group: a member in proportion to its solid angle, then a direction uniform in it, so the
// density is the group's choice probability over its summed solid angle. The member is chosen with
// a number uniform over the group: where the selection number fell among the members' choices.
// The spherical triangles are made (and their array set up) only near a light, not for the far
// samples that are most of them.
bool TriangleLights::sample(uint32_t i, const LightChoice& c, const Vec3f& p, Vec2f u, LightSample& ls) const {
  const TriangleLight& light = lights_[i];
  const TriangleGroup& g = groups_[light.group];
  ls.delta = false;
  SphericalTriangle st[TriangleGroup::kMaxTriangles];
  float total;
  if (near_solid_angles(g, p, st, total)) {
    float target = std::min((c.group_offset + c.u_rest * c.pick) / c.group_pick, 0x1.fffffep-1f) * total;
    uint32_t m = 0;
    while (m + 1 < g.count && target >= st[m].area) target -= st[m].area, ++m;
    Vec3f w = sample_spherical_triangle(st[m], u);
    float cos_l = -dot(w, g.normal);
    if (!(cos_l > 0)) return false;
    ls.wi = w;
    ls.distance = dot(p - g.point, g.normal) / cos_l;  // along w to the group's plane
    ls.point = p + w * ls.distance;
    ls.radiance = radiance_at(lights_[g.first + m], ls.point);
    ls.normal = g.normal;
    ls.pdf = c.group_pick / total;
    return std::isfinite(ls.distance);
  }
  Vec2f b = square_to_triangle(u);
  Vec3f q = light.v0 + light.edge1 * b.x + light.edge2 * b.y;
  ls.radiance = light.texture < 0 ? light.radiance
                                  : light.emission * textures_->lookup(light.texture, light.uv0 + light.duv1 * b.x + light.duv2 * b.y,
                                                                       {0, 0}, {0, 0});
  return area_sample(p, q, light.normal, c.pick, light.area, ls);
}

Spectrum TriangleLights::radiance_at(const TriangleLight& l, const Vec3f& q) const {
  if (l.texture < 0) return l.radiance;
  // q's barycentrics along the edges, by the normal equations of q - v0 = b1 e1 + b2 e2.
  const Vec3f d = q - l.v0;
  const float e11 = dot(l.edge1, l.edge1), e12 = dot(l.edge1, l.edge2), e22 = dot(l.edge2, l.edge2);
  const float d1 = dot(d, l.edge1), d2 = dot(d, l.edge2), det = e11 * e22 - e12 * e12;
  const float b1 = (e22 * d1 - e12 * d2) / det, b2 = (e11 * d2 - e12 * d1) / det;
  return l.emission * textures_->lookup(l.texture, l.uv0 + l.duv1 * b1 + l.duv2 * b2, {0, 0}, {0, 0});
}

float TriangleLights::pdf(uint32_t i, uint32_t light, const LightSampler& sampler, const Vec3f& p, const Vec3f& n_p,
                          const Vec3f& q, const Vec3f& n) const {
  uint32_t group = lights_[i].group;
  SphericalTriangle st[TriangleGroup::kMaxTriangles];
  float total;
  if (near_solid_angles(groups_[group], p, st, total)) return sampler.group_pdf(p, n_p, group) / total;
  return area_pdf(p, q, n, sampler.pdf(p, n_p, light), lights_[i].area);
}

}  // namespace pt
