#include "renderer/measure/stability.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include "core/math/frame.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "core/geometry/icosphere.h"
#include "core/scene/loader.h"
#include "core/scene/scene.h"
#include "core/util/error.h"
#include "renderer/measure/stability_scenes.h"
#include "renderer/measure/vec3d.h"

namespace pt {
namespace fs = std::filesystem;
using namespace stability;

std::vector<StabilityMethod> stability_methods() {
  std::vector<StabilityMethod> m(4);
  m[0].name = "bvh-mt";
  m[0].options.backend = Backend::kBvh;
  m[0].options.triangle_test = TriangleTest::kMollerTrumbore;
  m[1].name = "bvh-watertight";
  m[1].options.backend = Backend::kBvh;
  m[1].options.triangle_test = TriangleTest::kWatertight;
  m[2].name = "embree";
  m[2].options.backend = Backend::kEmbree;
  m[3].name = "embree-robust";
  m[3].options.backend = Backend::kEmbree;
  m[3].options.embree_robust = true;
  return m;
}

std::vector<StabilityRow> measure_leaks(const StabilityOptions& o) {
  std::vector<StabilityRow> rows;
  for (double distance : o.distances) {
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices;
    struct Target {
      Vec3f o, p;
      bool vertex;
    };
    std::vector<Target> targets;
    Pcg32 rng(o.seed, 11);
    int mesh_id = 0;
    for (auto make : {+[](std::vector<D3>& v, std::vector<uint32_t>& f) { unit_icosphere(2, v, f); },
                      +[](std::vector<D3>& v, std::vector<uint32_t>& f) { cone(64, v, f); }}) {
      std::vector<D3> v;
      std::vector<uint32_t> f;
      make(v, f);
      // Two meshes side by side, 4 units apart; each ray starts inside the one it aims at.
      D3 centre = kAway * distance + D3(4.0 * mesh_id++, 0, 0);
      uint32_t base = static_cast<uint32_t>(positions.size());
      for (const D3& p : v) positions.push_back((centre + p).f());
      for (uint32_t i : f) indices.push_back(base + i);
      auto origin = [&] { return (centre + random_in_ball(rng) * 0.25).f(); };
      const int per_target = 4 * o.effort;
      for (size_t i = 0; i < v.size(); ++i) {
        for (int k = 0; k < per_target; ++k) targets.push_back({origin(), positions[base + i], true});
      }
      std::map<std::pair<uint32_t, uint32_t>, bool> edges;
      for (size_t i = 0; i < f.size(); i += 3) {
        for (int e = 0; e < 3; ++e) edges[std::minmax(f[i + e], f[i + (e + 1) % 3])] = true;
      }
      for (const auto& [edge, unused] : edges) {
        Vec3f a = positions[base + edge.first], b = positions[base + edge.second];
        for (int k = 0; k < per_target; ++k) {
          float s = k == 0 ? 0.5f : rng.next_float();
          targets.push_back({origin(), a + (b - a) * s, false});
        }
      }
    }
    Geometry scene = triangles(positions, indices);
    for (const StabilityMethod& m : stability_methods()) {
      Built b = build(scene, m);
      for (bool vertex : {true, false}) {
        std::string variant = vertex ? "vertices" : "edges";
        if (!b.accel) {
          rows.push_back(unavailable("leaks", variant, m, distance, b.error));
          continue;
        }
        StabilityRow row{"leaks", variant, m.name, distance, 0, 0, ""};
        uint64_t missed_closest = 0, missed_any = 0;
        for (const Target& t : targets) {
          if (t.vertex != vertex) continue;
          Ray ray;
          ray.o = t.o;
          ray.d = normalize(t.p - t.o);
          ++row.trials;
          bool hit = b.accel->intersect(ray).has_value();
          bool occluded = b.accel->occluded(ray);
          missed_closest += !hit;
          missed_any += !occluded;
          row.failures += !hit || !occluded;
        }
        row.note = "closest-hit misses " + std::to_string(missed_closest) + ", any-hit misses " + std::to_string(missed_any);
        rows.push_back(row);
      }
    }
  }
  return rows;
}

std::vector<StabilityRow> measure_self_intersection(const StabilityOptions& o) {
  std::vector<StabilityRow> rows;
  const char* kVariants[] = {"none", "fixed-1e-4", "scaled"};
  for (double distance : o.distances) {
    Pcg32 rng(o.seed, 23);
    const D3 centre = kAway * distance;
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices;
    const int kTriangles = 64, kSpheres = 16;
    for (int i = 0; i < kTriangles; ++i) {
      D3 c = centre + random_in_ball(rng) * 20.0;
      for (int k = 0; k < 3; ++k) {
        positions.push_back((c + random_unit(rng) * (0.5 + rng.next_double())).f());
        indices.push_back(static_cast<uint32_t>(positions.size() - 1));
      }
    }
    SceneBuilder builder;
    builder.source = "(stability)";
    builder.mesh.positions = positions;
    builder.mesh.indices = indices;
    uint32_t mat = builder.default_material();
    builder.mesh.material.assign(kTriangles, mat);
    for (int i = 0; i < kSpheres; ++i) {
      Sphere s;
      s.center = (centre + random_in_ball(rng) * 20.0).f();
      s.radius = 1.0f;
      s.material = mat;
      builder.spheres.push_back(s);
    }
    const Scene scene(std::move(builder));

    // Trials: a surface point and a primary ray from the side it is seen from; then one shadow
    // direction per trial, shared by all offset variants.
    struct Trial {
      Ray primary;
      uint32_t geom, prim;
      Vec3f shadow_dir_local;  // in the frame of the normal the primary ray saw
    };
    std::vector<Trial> trials;
    const int per_prim = 16 * o.effort;
    for (uint32_t t = 0; t < kTriangles; ++t) {
      for (int k = 0; k < per_prim; ++k) {
        Vec2f b = square_to_triangle({rng.next_float(), rng.next_float()});
        const Mesh& mesh = scene.mesh();
        Vec3f q = mesh.vertex(t, 0) * (1 - b.x - b.y) + mesh.vertex(t, 1) * b.x + mesh.vertex(t, 2) * b.y;
        Vec3f from = (D3(q) + random_unit(rng) * 2.0).f();
        Ray r;
        r.o = from;
        r.d = normalize(q - from);
        trials.push_back({r, kGeomTriangles, t, square_to_uniform_hemisphere({rng.next_float(), rng.next_float()})});
      }
    }
    for (uint32_t s = 0; s < kSpheres; ++s) {
      for (int k = 0; k < per_prim; ++k) {
        const Sphere& sp = scene.spheres()[s];
        D3 n = random_unit(rng);
        Vec3f q = (D3(sp.center) + n * sp.radius).f();
        D3 w = normalize(n + random_unit(rng) * 0.9);
        if (dot(w, n) <= 0.1) w = n;
        Vec3f from = (D3(q) + w * 2.0).f();
        Ray r;
        r.o = from;
        r.d = normalize(q - from);
        trials.push_back({r, kGeomSpheres, s, square_to_uniform_hemisphere({rng.next_float(), rng.next_float()})});
      }
    }

    for (const StabilityMethod& m : stability_methods()) {
      Built b = build(scene.geometry(), m);
      for (const char* surface : {"triangles", "spheres"}) {
        uint32_t geom = std::string(surface) == "triangles" ? kGeomTriangles : kGeomSpheres;
        for (const char* variant : kVariants) {
          std::string name = std::string(surface) + "/" + variant;
          if (!b.accel) {
            rows.push_back(unavailable("self-intersection", name, m, distance, b.error));
            continue;
          }
          StabilityRow row{"self-intersection", name, m.name, distance, 0, 0, ""};
          double offset_sum = 0;
          for (const Trial& t : trials) {
            if (t.geom != geom) continue;
            std::optional<Hit> hit = b.accel->intersect(t.primary);
            if (!hit || hit->geom != t.geom || hit->prim != t.prim) continue;  // something else was in the way
            SurfaceInteraction si = scene.interaction(t.primary, *hit);
            Vec3f n = dot(si.ng, t.primary.d) < 0 ? si.ng : -si.ng;
            Ray shadow;
            std::string v = variant;
            shadow.o = v == "none" ? si.p : v == "fixed-1e-4" ? si.p + n * 1e-4f : offset_ray_origin(si.p, n);
            shadow.d = Frame(n).to_world(t.shadow_dir_local);
            shadow.tmin = 0;
            shadow.tmax = kInf;
            offset_sum += length(D3(shadow.o) - D3(si.p));
            ++row.trials;
            std::optional<Hit> again = b.accel->intersect(shadow);
            if (again && again->geom == t.geom && again->prim == t.prim) ++row.failures;
          }
          row.note = "mean offset " + fmt(row.trials ? offset_sum / row.trials : 0);
          rows.push_back(row);
        }
      }
    }
  }
  return rows;
}

std::vector<StabilityRow> measure_grazing(const StabilityOptions& o) {
  std::vector<StabilityRow> rows;
  const double kAngles[] = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5};
  for (double distance : o.distances) {
    Pcg32 rng(o.seed, 53);
    // A tilted 2 x 2 square (two triangles) centred kAway * distance.
    Frame frame(normalize(D3(0.3, 1.0, -0.4)).f());
    D3 c = kAway * distance, s(frame.s), t(frame.t), n(frame.n);
    std::vector<Vec3f> p = {(c - s - t).f(), (c + s - t).f(), (c + s + t).f(), (c - s + t).f()};
    Geometry scene = triangles(p, {0, 1, 2, 0, 2, 3});
    const D3 p0(p[0]), p1(p[1]), p2(p[2]);
    const double ulp = std::nextafter(static_cast<float>(distance), kInf) - static_cast<float>(distance);
    struct Aim {
      Ray ray;
      double t_exact;
    };
    std::map<double, std::vector<Aim>> aims;
    for (double angle : kAngles) {
      for (int k = 0; k < 1000 * o.effort; ++k) {
        // An interior point of triangle 0, at least 0.1 from its edges in barycentric terms.
        double b1 = 0.1 + 0.8 * rng.next_double(), b2 = 0.1 + (0.8 - (b1 - 0.1)) * rng.next_double();
        D3 target = p0 + (p1 - p0) * b1 + (p2 - p0) * b2;
        double phi = 2 * M_PI * rng.next_double();
        D3 tangent = s * std::cos(phi) + t * std::sin(phi);
        D3 dir = tangent * std::cos(angle) - n * std::sin(angle);
        // Far enough back that the origin sits well above the plane despite rounding.
        double back = std::max(1.0, 16 * ulp / std::sin(angle));
        Ray r;
        r.o = (target - dir * back).f();
        r.d = dir.f();
        std::optional<Bary> exact = line_triangle(D3(r.o), D3(r.d), p0, p1, p2);
        if (!exact || exact->t <= 0 || exact->b1 < 0.01 || exact->b2 < 0.01 || exact->b1 + exact->b2 > 0.99) continue;
        aims[angle].push_back({r, exact->t});
      }
    }
    for (const StabilityMethod& m : stability_methods()) {
      Built b = build(scene, m);
      for (double angle : kAngles) {
        std::string variant = "angle=" + fmt(angle);
        if (!b.accel) {
          rows.push_back(unavailable("grazing", variant, m, distance, b.error));
          continue;
        }
        StabilityRow row{"grazing", variant, m.name, distance, 0, 0, ""};
        double worst = 0;
        for (const Aim& a : aims[angle]) {
          ++row.trials;
          std::optional<Hit> hit = b.accel->intersect(a.ray);
          if (!hit) {
            ++row.failures;
            continue;
          }
          worst = std::max(worst, std::abs(hit->t - a.t_exact) / a.t_exact);
        }
        row.note = "max relative t error " + fmt(worst);
        rows.push_back(row);
      }
    }
  }
  return rows;
}

std::vector<StabilityRow> measure_spheres(const StabilityOptions& o) {
  std::vector<StabilityRow> rows;
  const double kRadii[] = {1e-4, 1e-2, 1, 1e2, 1e4};
  for (double distance : o.distances) {
    for (double radius : kRadii) {
      Pcg32 rng(o.seed, 71);
      Sphere sphere;
      sphere.center = (kAway * distance).f();
      sphere.radius = static_cast<float>(radius);
      Geometry scene(Mesh(), {sphere});
      const D3 c(sphere.center);
      const double r = sphere.radius;
      struct Aim {
        Ray ray;
        bool should_hit;
      };
      std::vector<Aim> aims;
      for (int k = 0; k < 1000 * o.effort; ++k) {
        Ray ray;
        ray.o = (c + random_unit(rng) * (4 * r)).f();
        Vec3f target = (c + random_in_ball(rng) * (1.3 * r)).f();
        if (target.x == ray.o.x && target.y == ray.o.y && target.z == ray.o.z) continue;
        ray.d = normalize(target - ray.o);
        D3 oc = c - D3(ray.o), d(ray.d);
        double tc = dot(oc, d) / dot(d, d);
        double miss_distance = length(oc - d * tc);
        bool inside = length(oc) < r;
        if (inside || (tc > 0 && miss_distance < 0.98 * r)) {
          aims.push_back({ray, true});
        } else if (miss_distance > 1.02 * r || (tc < 0 && length(oc) > 1.02 * r)) {
          aims.push_back({ray, false});
        }
      }
      for (const StabilityMethod& m : stability_methods()) {
        std::string wrong = "r=" + fmt(radius) + "/wrong-answer", off = "r=" + fmt(radius) + "/point-off-surface";
        Built b = build(scene, m);
        if (!b.accel) {
          rows.push_back(unavailable("sphere", wrong, m, distance, b.error));
          rows.push_back(unavailable("sphere", off, m, distance, b.error));
          continue;
        }
        StabilityRow w{"sphere", wrong, m.name, distance, 0, 0, ""}, p{"sphere", off, m.name, distance, 0, 0, ""};
        for (const Aim& a : aims) {
          ++w.trials;
          std::optional<Hit> hit = b.accel->intersect(a.ray);
          if (hit.has_value() != a.should_hit) {
            ++w.failures;
            continue;
          }
          if (!hit) continue;
          ++p.trials;
          D3 point = D3(a.ray.o) + D3(a.ray.d) * static_cast<double>(hit->t);
          if (std::abs(length(point - c) - r) > 1e-3 * r) ++p.failures;
        }
        w.note = "should hit " + std::to_string(std::count_if(aims.begin(), aims.end(), [](const Aim& a) { return a.should_hit; })) +
                 " of " + std::to_string(aims.size());
        p.note = "o + t d more than 1e-3 r off the sphere";
        rows.push_back(w);
        rows.push_back(p);
      }
    }
  }
  return rows;
}

}  // namespace pt
