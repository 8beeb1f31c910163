#include "core/scene/studio.h"

#include <cmath>
#include <memory>

namespace pt {
namespace {

// The look, in linear RGB. A grey 0.8 model facing the sun comes out near 0.8, in the sky's light
// alone near 0.3; the ground (albedo 0.5) shows the model's shadow at about half its lit value.
constexpr float kGroundAlbedo = 0.5f;
const Spectrum kZenith{0.32f, 0.40f, 0.52f};   // sky radiance straight up
const Spectrum kHorizon{0.72f, 0.76f, 0.80f};  // and at the horizon
const Spectrum kSunColour{1.0f, 0.95f, 0.88f};
constexpr float kSunIrradiance = 2.2f;         // on a surface facing the sun (W/m^2 scale of the sky's)
constexpr float kSunRadiusDegrees = 3.0f;      // a little soft: sharp contact shadows, soft far ones
constexpr float kSunElevationDegrees = 50.0f;
constexpr float kSunAzimuthDegrees = 35.0f;    // from the default view (+z for y up) toward its left
constexpr int kSkyWidth = 512, kSkyHeight = 256;

// Ground squares around the model: each ring reaches this many model radii; the last one reaches
// so far that the gap to the horizon is below a pixel. Rings keep each triangle near the size of
// the region it covers, so hits near the model are as precise as the model's own.
constexpr float kRings[] = {4.0f, 100.0f, 10000.0f};

// The direction of the texel centre (x, y) of a lat-long image, as Environment reads it
// (environment.h: +y up, v = 0 at the top, u = 0.5 toward -z, growing toward +x).
Vec3f texel_direction(int x, int y) {
  float phi = ((x + 0.5f) / kSkyWidth - 0.5f) * 2.0f * kPi;
  float theta = (y + 0.5f) / kSkyHeight * kPi;
  float st = std::sin(theta);
  return {st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
}

// Toward the sun: kSunElevationDegrees up, kSunAzimuthDegrees to the left of the view seen from
// above (the view's horizontal part, or the front if the view looks straight down).
Vec3f sun_direction(UpAxis axis, std::optional<Vec3f> view) {
  Vec3f up = up_vector(axis), front = from_y_up(axis, {0, 0, 1});
  if (view) {
    Vec3f h = *view - up * dot(*view, up);
    if (length(h) > 1e-3f * length(*view)) front = normalize(h);
  }
  Vec3f left = cross(front, up);
  float el = kSunElevationDegrees * kPi / 180.0f, az = kSunAzimuthDegrees * kPi / 180.0f;
  return normalize((front * std::cos(az) + left * std::sin(az)) * std::cos(el) + up * std::sin(el));
}

std::shared_ptr<const Texture> make_sky(bool sun, UpAxis axis, const Vec3f& to_sun) {
  auto sky = std::make_shared<Texture>();
  sky->path = std::string("(studio sky") + (sun ? " with a sun)" : ")");
  sky->width = kSkyWidth;
  sky->height = kSkyHeight;
  sky->texels.assign(static_cast<size_t>(kSkyWidth) * kSkyHeight, Spectrum(0.0f));
  Vec3f up = up_vector(axis);
  float cos_sun = std::cos(kSunRadiusDegrees * kPi / 180.0f);
  double sun_solid_angle = 0;
  for (int y = 0; y < kSkyHeight; ++y) {
    for (int x = 0; x < kSkyWidth; ++x) {
      Vec3f d = texel_direction(x, y);
      float height = dot(d, up);
      if (height <= 0) continue;  // below the horizon: the ground hides it
      // The gradient follows sqrt(sin(elevation)): most of the change near the horizon, as skies do.
      float t = std::sqrt(height);
      sky->texels[static_cast<size_t>(y) * kSkyWidth + x] = kHorizon * (1.0f - t) + kZenith * t;
      if (sun && dot(d, to_sun) >= cos_sun) {
        float theta = (y + 0.5f) / kSkyHeight * kPi;
        sun_solid_angle += (2.0 * kPi / kSkyWidth) * (kPi / kSkyHeight) * std::sin(theta);
      }
    }
  }
  if (sun) {
    // The sun's texels carry its irradiance exactly, whatever their count.
    Spectrum radiance = kSunColour * static_cast<float>(kSunIrradiance / sun_solid_angle);
    for (int y = 0; y < kSkyHeight; ++y) {
      for (int x = 0; x < kSkyWidth; ++x) {
        if (dot(texel_direction(x, y), to_sun) >= cos_sun && dot(texel_direction(x, y), up) > 0) {
          sky->texels[static_cast<size_t>(y) * kSkyWidth + x] += radiance;
        }
      }
    }
  }
  return sky;
}

void add_ground(SceneBuilder& scene, const BBox& model, UpAxis axis) {
  Material m;
  m.name = "studio ground";
  m.model = Diffuse{Spectrum(kGroundAlbedo)};
  uint32_t id = scene.add_material(m);
  Vec3f up = up_vector(axis), e1 = from_y_up(axis, {1, 0, 0}), e2 = from_y_up(axis, {0, 0, -1});  // e1 x e2 = up
  float radius = std::max(1e-3f, 0.5f * length(model.extent()));
  // Just under the lowest point, so that a face lying on the bottom of the bounds does not fight
  // with the ground for the same depth.
  Vec3f c = model.center();
  Vec3f origin = c + up * (dot(model.lo - c, up) - 1e-4f * radius);
  Mesh& mesh = scene.mesh;
  auto point = [&](float u, float v) { return origin + e1 * (u * radius) + e2 * (v * radius); };
  auto triangle = [&](Vec3f a, Vec3f b, Vec3f d) {  // counter-clockwise seen from above
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {a, b, d});
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    mesh.material.push_back(id);
    if (!mesh.corner_normals.empty()) mesh.corner_normals.insert(mesh.corner_normals.end(), 3, Vec3f(0.0f));
    if (!mesh.corner_uvs.empty()) mesh.corner_uvs.insert(mesh.corner_uvs.end(), 3, Vec2f(0, 0));
    // Per-corner arrays stay one entry per corner (readers index them by triangle).
    if (!mesh.corner_tangents.empty()) mesh.corner_tangents.insert(mesh.corner_tangents.end(), 3, Vec3f(0.0f));
    if (!mesh.corner_tangent_signs.empty()) mesh.corner_tangent_signs.insert(mesh.corner_tangent_signs.end(), 3, 1.0f);
  };
  auto quad = [&](Vec3f a, Vec3f b, Vec3f c2, Vec3f d) {
    triangle(a, b, c2);
    triangle(a, c2, d);
  };
  float inner = 0;
  for (float s : kRings) {
    if (inner == 0) {
      quad(point(-s, -s), point(s, -s), point(s, s), point(-s, s));
    } else {
      // Four trapezoids between the squares of half-size inner and s.
      const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (int k = 0; k < 4; ++k) {
        const float* p = corners[k];
        const float* q = corners[(k + 1) % 4];
        quad(point(p[0] * s, p[1] * s), point(q[0] * s, q[1] * s), point(q[0] * inner, q[1] * inner),
             point(p[0] * inner, p[1] * inner));
      }
    }
    inner = s;
  }
}

}  // namespace

Environment studio_sky(bool sun, UpAxis axis, std::optional<Vec3f> view) {
  return Environment(make_sky(sun, axis, sun_direction(axis, view)), 1.0f, 0.0f);
}

void add_studio(SceneBuilder& scene, Studio studio, UpAxis axis, std::optional<Vec3f> view) {
  if (studio == Studio::kNone) return;
  StudioInfo info;
  info.model_bounds = scene.geometry_bounds();
  info.first_triangle = scene.mesh.triangle_count();
  add_ground(scene, info.model_bounds, axis);
  bool sun = studio == Studio::kSun;
  scene.environment = studio_sky(sun, axis, view);
  info.sun = sun;
  info.up = axis;
  info.description = std::string("a ground under the model and a sky") + (sun ? " with a sun" : "") + ", up +" +
                     kUpAxisNames.name(axis);
  scene.studio = info;
}

}  // namespace pt
