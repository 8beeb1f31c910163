#include "renderer/measure/analytic.h"

#include <cmath>
#include <optional>
#include <vector>

#include "core/util/error.h"
#include "renderer/measure/vec3d.h"

namespace pt {
namespace {


struct Tri {
  D3 p0, p1, p2;
  uint32_t material = 0;
};

// Möller-Trumbore in double, hits with t > 0 only. `slack` widens the edges a little, so a ray
// exactly along a shared diagonal of the plane is not lost to rounding (double MT leaks too).
std::optional<double> hit_triangle(const D3& o, const D3& d, const Tri& tri, double slack = 0) {
  D3 e1 = tri.p1 - tri.p0, e2 = tri.p2 - tri.p0;
  D3 pv = cross(d, e2);
  double det = dot(e1, pv);
  if (det == 0) return std::nullopt;
  D3 tv = o - tri.p0;
  double u = dot(tv, pv) / det;
  if (u < -slack || u > 1 + slack) return std::nullopt;
  D3 qv = cross(tv, e1);
  double v = dot(d, qv) / det;
  if (v < -slack || u + v > 1 + slack) return std::nullopt;
  double t = dot(e2, qv) / det;
  return t > 0 ? std::optional<double>(t) : std::nullopt;
}

std::optional<double> hit_sphere(const D3& o, const D3& d, const D3& c, double r) {
  D3 f = o - c;
  double b = dot(f, d), cc = dot(f, f) - r * r;  // d is unit
  double disc = b * b - cc;
  if (disc < 0) return std::nullopt;
  double s = std::sqrt(disc);
  double t0 = -b - s, t1 = -b + s;
  if (t0 > 0) return t0;
  if (t1 > 0) return t1;
  return std::nullopt;
}

bool is_plain_diffuse(const Material& m) { return m.is<Diffuse>() && std::get<Diffuse>(m.model).kd_texture < 0; }
// The albedo of a diffuse material; any other model counts as reflecting (never 0).
Spectrum diffuse_kd(const Material& m) { return m.is<Diffuse>() ? std::get<Diffuse>(m.model).kd : Spectrum(1.0f); }

// What the scene is made of, gathered once and checked against each case's assumptions.
struct Parts {
  std::vector<Tri> receivers, emitters;  // non-emissive and emissive triangles
  std::vector<const Sphere*> sphere_emitters, sphere_receivers;
};

Parts gather(const Scene& scene) {
  Parts parts;
  const Mesh& mesh = scene.mesh();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (!(mesh.area(t) > 0)) continue;
    Tri tri{D3(mesh.vertex(t, 0)), D3(mesh.vertex(t, 1)), D3(mesh.vertex(t, 2)), mesh.material[t]};
    (scene.materials()[tri.material].is_emissive() ? parts.emitters : parts.receivers).push_back(tri);
  }
  for (const Sphere& s : scene.spheres()) {
    (scene.materials()[s.material].is_emissive() ? parts.sphere_emitters : parts.sphere_receivers).push_back(&s);
  }
  return parts;
}

bool constant_environment(const Scene& scene) {
  return scene.environment() && !scene.environment()->has_image() && luminance(scene.environment()->constant()) > 0;
}

[[noreturn]] void not_closed_form(const Scene& scene, const std::string& why) {
  throw Error(scene.source(), "not a closed-form scene for --reference analytic: " + why);
}

// The receiving plane of the plane cases: all non-emissive triangles, coplanar, one plain diffuse
// material. Returns its unit normal and a point on it.
struct Plane {
  D3 n, p;
  Spectrum kd;
};
Plane receiving_plane(const Scene& scene, const Parts& parts) {
  if (parts.receivers.empty()) not_closed_form(scene, "no receiving plane");
  const Tri& first = parts.receivers[0];
  Plane plane{normalize(cross(first.p1 - first.p0, first.p2 - first.p0)), first.p0, {}};
  const Material& m = scene.materials()[first.material];
  if (!is_plain_diffuse(m)) not_closed_form(scene, "the plane must be untextured diffuse");
  plane.kd = diffuse_kd(m);
  double extent = 0;
  for (const Tri& t : parts.receivers) extent = std::max({extent, length(t.p1 - t.p0), length(t.p2 - t.p0)});
  for (const Tri& t : parts.receivers) {
    if (t.material != first.material) not_closed_form(scene, "the plane has more than one material");
    for (const D3& q : {t.p0, t.p1, t.p2}) {
      if (std::abs(dot(q - plane.p, plane.n)) > 1e-5 * extent) not_closed_form(scene, "non-emissive triangles are not coplanar");
    }
  }
  return plane;
}

}  // namespace

std::string analytic_case(const Scene& scene, IntegratorKind integrator, int max_depth) {
  if (integrator != IntegratorKind::kDirect && integrator != IntegratorKind::kPath) not_closed_form(scene, "integrator must be direct or path");
  const LightSet& lights = scene.light_set();
  if (lights.count(LightType::kPoint) + lights.count(LightType::kSpot) + lights.count(LightType::kDirectional) > 0) {
    not_closed_form(scene, "point, spot and directional lights are not covered");
  }
  Parts parts = gather(scene);
  bool env = constant_environment(scene);
  bool has_emitters = !parts.emitters.empty() || !parts.sphere_emitters.empty();
  if (scene.environment() && !env && !has_emitters) not_closed_form(scene, "an image environment is not covered");

  if (env && !has_emitters) {
    bool all_white = true;
    for (const Tri& t : parts.receivers) {
      const Material& m = scene.materials()[t.material];
      all_white = all_white && is_plain_diffuse(m) && min_component(diffuse_kd(m)) == 1.0f;
    }
    for (const Sphere* s : parts.sphere_receivers) {
      const Material& m = scene.materials()[s->material];
      all_white = all_white && is_plain_diffuse(m) && min_component(diffuse_kd(m)) == 1.0f;
    }
    if (parts.receivers.empty() && parts.sphere_receivers.size() == 1) {
      if (!is_plain_diffuse(scene.materials()[parts.sphere_receivers[0]->material])) {
        not_closed_form(scene, "the sphere must be untextured diffuse");
      }
      return "sphere-env";  // convex: exact for direct lighting and path tracing alike
    }
    if (!all_white) not_closed_form(scene, "a furnace needs every surface white diffuse (albedo 1)");
    if (integrator != IntegratorKind::kPath) not_closed_form(scene, "a furnace with concave geometry needs --integrator path");
    // Energy is lost only by paths still inside after max_depth bounces; keep that negligible.
    if (max_depth < 32) not_closed_form(scene, "a furnace needs --max-depth 32 or more");
    return "furnace";
  }
  if (scene.environment()) not_closed_form(scene, "an environment together with emitters is not covered");
  if (!parts.sphere_receivers.empty()) not_closed_form(scene, "non-emissive spheres over a plane are not covered");
  receiving_plane(scene, parts);
  if (integrator == IntegratorKind::kPath) {
    // Light reflected by the emitter back onto the plane would add a second bounce.
    for (const Tri& t : parts.emitters) {
      if (max_component(diffuse_kd(scene.materials()[t.material])) > 0) not_closed_form(scene, "emitters must have albedo 0 for path tracing");
    }
    for (const Sphere* s : parts.sphere_emitters) {
      if (max_component(diffuse_kd(scene.materials()[s->material])) > 0) not_closed_form(scene, "emitters must have albedo 0 for path tracing");
    }
  }
  if (!parts.emitters.empty() && parts.sphere_emitters.empty()) {
    // All emitting triangles in one plane, so none shadows another.
    const Tri& e = parts.emitters[0];
    D3 n = normalize(cross(e.p1 - e.p0, e.p2 - e.p0));
    for (const Tri& t : parts.emitters) {
      for (const D3& q : {t.p0, t.p1, t.p2}) {
        if (std::abs(dot(q - e.p0, n)) > 1e-5 * (length(e.p1 - e.p0) + 1e-30)) not_closed_form(scene, "emitting triangles are not coplanar");
      }
    }
    return "rect-light";
  }
  if (parts.emitters.empty() && parts.sphere_emitters.size() == 1) return "sphere-light";
  not_closed_form(scene, "expected emitting triangles in one plane, or one emitting sphere");
}

Image analytic_reference(const Job& job) {
  const Scene& scene = *job.scene;
  const int width = job.render.width, height = job.render.height;
  const std::string kind = analytic_case(scene, job.settings.integrator, job.settings.max_depth);
  Parts parts = gather(scene);
  Image image(width, height, {"R", "G", "B"});
  Camera::Basis fb = job.render.camera.basis(static_cast<float>(width) / height);
  const D3 origin(fb.origin), forward(fb.forward), right(fb.right), down(fb.down);

  if (kind == "furnace") {
    Spectrum L = scene.environment()->constant();
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = L[c];
    return image;
  }

  if (kind == "sphere-env") {
    // Pixel = L (1 - cov) + kd L cov, cov = the fraction of the pixel's film square whose rays hit
    // the sphere. Along one scanline fy the hit set is where (d.c)^2 - k |d|^2 >= 0 with d = A + fx B,
    // k = |c|^2 - r^2: a quadratic in fx, so each row's covered length is exact; rows are averaged
    // with a fine midpoint rule (the covered length is continuous in fy).
    const Sphere& s = *parts.sphere_receivers[0];
    const Spectrum L = scene.environment()->constant(), kd = diffuse_kd(scene.materials()[s.material]);
    const D3 c = D3(s.center) - origin;
    const double r = s.radius, k = dot(c, c) - r * r;
    if (!(k > 0)) not_closed_form(scene, "the camera is inside the sphere");
    const double qa = dot(right, c) * dot(right, c) - k * dot(right, right);
    if (!(qa < 0)) not_closed_form(scene, "the sphere subtends too wide a cone for the camera");
    constexpr int kRows = 256;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const double x0 = static_cast<double>(x) / width, x1 = static_cast<double>(x + 1) / width;
        double covered = 0;
        for (int row = 0; row < kRows; ++row) {
          double fy = (y + (row + 0.5) / kRows) / height;
          D3 a = forward + down * fy;
          double ac = dot(a, c), bc = dot(right, c);
          double qb = 2 * ac * bc - 2 * k * dot(a, right), qc = ac * ac - k * dot(a, a);
          double disc = qb * qb - 4 * qa * qc;
          if (disc <= 0) continue;
          double sq = std::sqrt(disc);
          double r1 = (-qb + sq) / (2 * qa), r2 = (-qb - sq) / (2 * qa);
          if (r1 > r2) std::swap(r1, r2);
          double mid = 0.5 * (r1 + r2);
          if (dot(a + right * mid, c) <= 0) continue;  // the cone's other nappe, behind the camera
          covered += std::max(0.0, std::min(r2, x1) - std::max(r1, x0));
        }
        double cov = covered / kRows / (x1 - x0);
        for (int ch = 0; ch < 3; ++ch) image.at(x, y, ch) = static_cast<float>(L[ch] * (1 - cov) + kd[ch] * L[ch] * cov);
      }
    }
    return image;
  }

  // The plane cases: radiance kd/pi E(x) at the point x each camera ray meets; each pixel is the
  // mean over a 16x16 grid of film positions (E is smooth over a pixel, so the rule's error is far
  // below any render's noise).
  const Plane plane = receiving_plane(scene, parts);
  D3 up = plane.n;
  if (dot(origin - plane.p, up) < 0) up = up * -1.0;  // the side the camera looks at
  // Irradiance at x, per channel through each emitter's radiance.
  auto irradiance = [&](const D3& xp, double e[3]) {
    e[0] = e[1] = e[2] = 0;
    for (const Tri& t : parts.emitters) {
      D3 ne = cross(t.p1 - t.p0, t.p2 - t.p0);
      if (dot(xp - t.p0, ne) <= 0) continue;  // x is behind the emitting face
      const D3 v[3] = {t.p0, t.p1, t.p2};
      double sum = 0;
      for (int i = 0; i < 3; ++i) {
        D3 a = normalize(v[i] - xp), b = normalize(v[(i + 1) % 3] - xp);
        D3 g = cross(a, b);
        double gl = length(g);
        if (gl == 0) continue;
        sum += std::atan2(gl, dot(a, b)) * dot(up, g) / gl;  // theta_i n.(v_i x v_i+1)/|v_i x v_i+1|
      }
      const Spectrum& le = scene.materials()[t.material].emission;
      for (int ch = 0; ch < 3; ++ch) e[ch] += 0.5 * std::abs(sum) * le[ch];
    }
    for (const Sphere* s : parts.sphere_emitters) {
      D3 to_c = D3(s->center) - xp;
      double dist = length(to_c), h = dot(to_c, up), r = s->radius;
      const Spectrum& le = scene.materials()[s->material].emission;
      for (int ch = 0; ch < 3; ++ch) e[ch] += kPi * (r / dist) * (r / dist) * (h / dist) * le[ch];
    }
  };
  // Every emitter must lie wholly on the camera's side of the plane (one-sided formulas above).
  for (const Tri& t : parts.emitters) {
    for (const D3& q : {t.p0, t.p1, t.p2}) {
      if (!(dot(q - plane.p, up) > 0)) not_closed_form(scene, "an emitter reaches below the plane");
    }
  }
  for (const Sphere* s : parts.sphere_emitters) {
    if (!(dot(D3(s->center) - plane.p, up) >= s->radius)) not_closed_form(scene, "the emitting sphere is not wholly above the plane");
  }

  constexpr int kGrid = 16;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double sum[3] = {0, 0, 0};
      for (int j = 0; j < kGrid; ++j) {
        for (int i = 0; i < kGrid; ++i) {
          double fx = (x + (i + 0.5) / kGrid) / width, fy = (y + (j + 0.5) / kGrid) / height;
          D3 d = normalize(forward + right * fx + down * fy);
          std::optional<double> t_plane;
          for (const Tri& t : parts.receivers) {
            std::optional<double> th = hit_triangle(origin, d, t, 1e-9);
            if (th && (!t_plane || *th < *t_plane)) t_plane = th;
          }
          if (!t_plane) not_closed_form(scene, "the camera sees past the edge of the plane");
          for (const Tri& t : parts.emitters) {
            std::optional<double> th = hit_triangle(origin, d, t);
            if (th && *th < *t_plane) not_closed_form(scene, "the camera sees an emitter");
          }
          for (const Sphere* s : parts.sphere_emitters) {
            std::optional<double> th = hit_sphere(origin, d, D3(s->center), s->radius);
            if (th && *th < *t_plane) not_closed_form(scene, "the camera sees an emitter");
          }
          double e[3];
          irradiance(origin + d * *t_plane, e);
          for (int ch = 0; ch < 3; ++ch) sum[ch] += plane.kd[ch] / kPi * e[ch];
        }
      }
      for (int ch = 0; ch < 3; ++ch) image.at(x, y, ch) = static_cast<float>(sum[ch] / (kGrid * kGrid));
    }
  }
  return image;
}

}  // namespace pt
