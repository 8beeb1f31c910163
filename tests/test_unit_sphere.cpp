// Spheres as Embree user geometry are hit where the analytic sphere is, and the shared ray/sphere
// and ray/triangle routines are right on cases with known answers.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "core/accel/accel.h"
#include "core/geometry/intersect.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "core/scene/scene.h"

using namespace pt;

namespace {

struct Vec3d {
  double x, y, z;
};
Vec3d to_d(const Vec3f& v) { return {v.x, v.y, v.z}; }
double dotd(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3d sub(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

// Closed-form ray/sphere in double precision: the nearer root in (tmin, tmax), or NaN.
// `margin` receives how far the ray is from the tangent case, relative to the radius, so that
// callers can skip rays whose hit or miss float precision cannot decide.
double exact_sphere_t(const Ray& ray, const Sphere& s, double& margin) {
  Vec3d o = to_d(ray.o), d = to_d(ray.d), c = to_d(s.center);
  Vec3d f = sub(o, c);
  double a = dotd(d, d), b = dotd(f, d), cc = dotd(f, f) - double(s.radius) * s.radius;
  double disc = b * b - a * cc;
  // Squared distance from the centre to the line is (|f|^2 a - b^2) / a.
  double dist2 = (dotd(f, f) * a - b * b) / a;
  margin = std::abs(std::sqrt(std::max(0.0, dist2)) - s.radius) / s.radius;
  if (disc < 0) return std::nan("");
  double sq = std::sqrt(disc);
  for (double t : {(-b - sq) / a, (-b + sq) / a}) {
    if (t > ray.tmin && t < ray.tmax) return t;
  }
  return std::nan("");
}

Vec3f random_unit(Pcg32& rng) { return square_to_uniform_sphere({rng.next_float(), rng.next_float()}); }

SceneBuilder sphere_scene(const std::vector<Sphere>& spheres) {
  SceneBuilder scene;
  Material m;
  m.name = "grey";
  scene.add_material(m);
  for (Sphere s : spheres) {
    s.material = 0;
    scene.spheres.push_back(s);
  }
  scene.environment = Environment(Spectrum(1.0f));
  return scene;
}

// Float rounding in o + t d and in the quadratic, relative to the size of the numbers involved;
// ~80 ulps, far below any geometric error a wrong routine would make.
constexpr double kRelEps = 1e-5;

}  // namespace

TEST_CASE("Embree sphere user geometry hits where the analytic sphere is") {
  Sphere s;
  s.center = {1.5f, -2.0f, 0.75f};
  s.radius = 1.25f;
  const Scene scene(sphere_scene({s}));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  Pcg32 rng(12345, 1);
  int hits = 0, misses = 0, inside = 0, grazing = 0, undecided = 0;
  for (int i = 0; i < 20000; ++i) {
    Ray ray;
    int kind = i % 4;
    if (kind == 0) {  // from outside toward random points near the sphere
      ray.o = s.center + random_unit(rng) * (s.radius * (1.5f + 8.0f * rng.next_float()));
      Vec3f target = s.center + random_unit(rng) * (s.radius * 1.5f * rng.next_float());
      ray.d = normalize(target - ray.o);
    } else if (kind == 1) {  // starting inside: must hit the far side
      ray.o = s.center + random_unit(rng) * (s.radius * 0.95f * rng.next_float());
      ray.d = random_unit(rng);
    } else if (kind == 2) {  // grazing: the line passes within 0.1% of the tangent distance
      Vec3f dir = random_unit(rng);
      Frame frame(dir);
      float offset = s.radius * (1.0f + 2e-3f * (rng.next_float() - 0.5f));
      Vec3f side = frame.s * std::cos(6.2831853f * rng.next_float()) + frame.t * std::sin(6.2831853f * rng.next_float());
      side = normalize(side - dir * dot(side, dir));
      ray.o = s.center + side * offset - dir * (s.radius * 4.0f);
      ray.d = dir;
    } else {  // non-unit directions and a bounded interval
      ray.o = s.center + random_unit(rng) * (s.radius * 3.0f);
      ray.d = normalize(s.center + random_unit(rng) * s.radius - ray.o) * (0.25f + 4.0f * rng.next_float());
      ray.tmin = 0.1f * rng.next_float();
      ray.tmax = 1.0f + 2.0f * rng.next_float();
    }
    double margin;
    double t_exact = exact_sphere_t(ray, s, margin);
    std::optional<Hit> hit = accel->intersect(ray);
    bool occluded = accel->occluded(ray);
    // Where the ray is within rounding of tangent, or a root sits within rounding of tmin/tmax,
    // float may decide either way.
    double scale = length(ray.o - s.center) + s.radius;
    double dlen = length(ray.d);
    bool near_bound = std::isfinite(t_exact) &&
                      (std::abs(t_exact - ray.tmin) * dlen < kRelEps * scale || std::abs(t_exact - ray.tmax) * dlen < kRelEps * scale);
    if (margin < kRelEps * scale / s.radius || near_bound) {
      ++undecided;
      continue;
    }
    CAPTURE(i);
    CAPTURE(kind);
    if (std::isnan(t_exact)) {
      // Also covers rays whose roots both lie outside (tmin, tmax).
      CHECK_FALSE(hit.has_value());
      CHECK_FALSE(occluded);
      ++misses;
      continue;
    }
    REQUIRE(hit.has_value());
    CHECK(occluded);
    ++hits;
    inside += kind == 1;
    grazing += kind == 2;
    CHECK(hit->geom == kGeomSpheres);
    CHECK(hit->prim == 0);
    // t compared to the closed form: the error of a root grows like 1/sqrt(discriminant) near
    // tangency, so the bound widens there by r / half-chord.
    double half_chord = s.radius * std::sqrt(std::max(1e-12, margin * (2 - margin)));
    double t_tol = kRelEps * scale / dlen * (1.0 + s.radius / half_chord);
    CHECK(std::abs(hit->t - t_exact) <= t_tol);
    // The reported point and normal: on the sphere, normal radial and outward.
    SurfaceInteraction si = scene.interaction(ray, *hit);
    CHECK(std::abs(length(si.p - s.center) - s.radius) <= kRelEps * scale);
    Vec3d p = {ray.o.x + t_exact * ray.d.x, ray.o.y + t_exact * ray.d.y, ray.o.z + t_exact * ray.d.z};
    Vec3d n_exact = sub(p, to_d(s.center));
    double nl = std::sqrt(dotd(n_exact, n_exact));
    Vec3d ng = to_d(si.ng);
    double cos_err = dotd(ng, n_exact) / nl;
    CHECK(cos_err > 1.0 - 1e-6 * (1.0 + s.radius / half_chord));
    CHECK(length(si.ng) == doctest::Approx(1.0f).epsilon(1e-5));
  }
  // Every kind of ray must have been exercised, or the test proves little.
  CHECK(hits > 8000);
  CHECK(misses > 1000);
  CHECK(inside > 4000);
  CHECK(grazing > 1000);
  CHECK(undecided < 500);
}

TEST_CASE("Embree returns the closest of overlapping spheres and respects tmax in occlusion") {
  std::vector<Sphere> spheres(3);
  spheres[0].center = {0, 0, 0};
  spheres[0].radius = 1.0f;
  spheres[1].center = {0.8f, 0, 0};
  spheres[1].radius = 0.5f;
  spheres[2].center = {-3, 1, 2};
  spheres[2].radius = 2.0f;
  const Scene scene(sphere_scene(spheres));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  Pcg32 rng(99, 3);
  int checked = 0;
  for (int i = 0; i < 5000; ++i) {
    Ray ray;
    ray.o = random_unit(rng) * 8.0f;
    ray.d = normalize(random_unit(rng) * 2.5f - ray.o);
    double best = std::numeric_limits<double>::infinity();
    int best_index = -1;
    bool ambiguous = false;
    for (int k = 0; k < 3; ++k) {
      double margin;
      double t = exact_sphere_t(ray, spheres[k], margin);
      if (margin < 1e-4) ambiguous = true;
      if (std::isfinite(t) && t < best) best = t, best_index = k;
    }
    if (ambiguous) continue;
    // Two spheres' surfaces crossing at nearly the same t make the closest one a coin toss.
    bool tie = false;
    for (int k = 0; k < 3; ++k) {
      double margin;
      double t = exact_sphere_t(ray, spheres[k], margin);
      if (k != best_index && std::isfinite(t) && std::abs(t - best) < 1e-4 * (1 + best)) tie = true;
    }
    if (tie) continue;
    ++checked;
    std::optional<Hit> hit = accel->intersect(ray);
    CAPTURE(i);
    if (best_index < 0) {
      CHECK_FALSE(hit.has_value());
      continue;
    }
    REQUIRE(hit.has_value());
    CHECK(hit->prim == static_cast<uint32_t>(best_index));
    CHECK(hit->t == doctest::Approx(best).epsilon(1e-4));
    // Occlusion bounded just short of and just past the hit.
    Ray shorter = ray, longer = ray;
    shorter.tmax = static_cast<float>(best * (1 - 1e-3));
    longer.tmax = static_cast<float>(best * (1 + 1e-3));
    CHECK_FALSE(accel->occluded(shorter));
    CHECK(accel->occluded(longer));
  }
  CHECK(checked > 4000);
}

TEST_CASE("intersect_sphere on known cases") {
  const Vec3f c{1, 2, 3};
  const float r = 2.0f;
  float t = -1;
  SUBCASE("from outside, head on") {
    Ray ray{{1, 2, -7}, {0, 0, 1}};
    REQUIRE(intersect_sphere(ray, c, r, t));
    CHECK(t == doctest::Approx(8.0f));
  }
  SUBCASE("from inside: the far root") {
    Ray ray{{1, 2, 3.5f}, {0, 0, 1}};
    REQUIRE(intersect_sphere(ray, c, r, t));
    CHECK(t == doctest::Approx(1.5f));
  }
  SUBCASE("pointing away misses") {
    Ray ray{{1, 2, -7}, {0, 0, -1}};
    CHECK_FALSE(intersect_sphere(ray, c, r, t));
  }
  SUBCASE("passing by misses") {
    Ray ray{{1, 4.01f, -7}, {0, 0, 1}};
    CHECK_FALSE(intersect_sphere(ray, c, r, t));
  }
  SUBCASE("just inside the silhouette hits near the tangent point") {
    Ray ray{{1, 3.999f, -7}, {0, 0, 1}};
    REQUIRE(intersect_sphere(ray, c, r, t));
    // z = 3 - sqrt(r^2 - 1.999^2)
    CHECK(t == doctest::Approx(10.0 - std::sqrt(4.0 - 1.999 * 1.999)).epsilon(1e-4));
  }
  SUBCASE("tmax before the sphere misses; tmin past the near root gives the far root") {
    Ray ray{{1, 2, -7}, {0, 0, 1}, 0.0f, 7.9f};
    CHECK_FALSE(intersect_sphere(ray, c, r, t));
    ray.tmin = 8.1f;
    ray.tmax = kInf;
    REQUIRE(intersect_sphere(ray, c, r, t));
    CHECK(t == doctest::Approx(12.0f));
  }
  SUBCASE("a non-unit direction scales t") {
    Ray ray{{1, 2, -7}, {0, 0, 4}};
    REQUIRE(intersect_sphere(ray, c, r, t));
    CHECK(t == doctest::Approx(2.0f));
  }
  SUBCASE("far from the origin: the stable form keeps the near root accurate") {
    // A tiny sphere a long way down the ray: the textbook formula loses most digits here.
    Vec3f far_c{0, 0, 1e4f};
    Ray ray{{0.001f, 0, 0}, {0, 0, 1}};
    REQUIRE(intersect_sphere(ray, far_c, 0.01f, t));
    double expected = 1e4 - std::sqrt(0.01 * 0.01 - 0.001 * 0.001);
    CHECK(std::abs(t - expected) < 2e-3);  // a few ulps of 1e4 (ulp = 1e-3)
  }
}

TEST_CASE("intersect_triangle_mt on known cases") {
  const Vec3f p0{0, 0, 0}, p1{2, 0, 0}, p2{0, 2, 0};
  float t = -1, u = -1, v = -1;
  SUBCASE("hit with barycentrics of p1 and p2") {
    Ray ray{{0.5f, 0.25f, 3}, {0, 0, -1}};
    REQUIRE(intersect_triangle_mt(ray, p0, p1, p2, t, u, v));
    CHECK(t == doctest::Approx(3.0f));
    CHECK(u == doctest::Approx(0.25f));
    CHECK(v == doctest::Approx(0.125f));
  }
  SUBCASE("both faces are hit (no culling)") {
    Ray ray{{0.5f, 0.5f, -2}, {0, 0, 1}};
    REQUIRE(intersect_triangle_mt(ray, p0, p1, p2, t, u, v));
    CHECK(t == doctest::Approx(2.0f));
  }
  SUBCASE("outside each edge misses") {
    for (Vec3f o : {Vec3f(-0.1f, 0.5f, 1), Vec3f(0.5f, -0.1f, 1), Vec3f(1.1f, 1.0f, 1)}) {
      Ray ray{o, {0, 0, -1}};
      CHECK_FALSE(intersect_triangle_mt(ray, p0, p1, p2, t, u, v));
    }
  }
  SUBCASE("parallel to the plane misses") {
    Ray ray{{0.5f, 0.5f, 0}, {1, 0, 0}};
    CHECK_FALSE(intersect_triangle_mt(ray, p0, p1, p2, t, u, v));
  }
  SUBCASE("behind the origin and beyond tmax miss") {
    Ray behind{{0.5f, 0.5f, 1}, {0, 0, 1}};
    CHECK_FALSE(intersect_triangle_mt(behind, p0, p1, p2, t, u, v));
    Ray short_ray{{0.5f, 0.5f, 1}, {0, 0, -1}, 0.0f, 0.99f};
    CHECK_FALSE(intersect_triangle_mt(short_ray, p0, p1, p2, t, u, v));
  }
  SUBCASE("degenerate triangle never hits") {
    Ray ray{{0.5f, 0, 1}, {0, 0, -1}};
    CHECK_FALSE(intersect_triangle_mt(ray, p0, p1, Vec3f(4, 0, 0), t, u, v));
  }
  SUBCASE("random rays: the hit point is the barycentric combination") {
    Pcg32 rng(5, 5);
    for (int i = 0; i < 1000; ++i) {
      float b1 = rng.next_float(), b2 = rng.next_float();
      if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
      Vec3f q = p0 * (1 - b1 - b2) + p1 * b1 + p2 * b2;
      Vec3f o = q + random_unit(rng) * 3.0f;
      Ray ray{o, normalize(q - o)};
      if (std::abs(ray.d.z) < 0.05f) continue;  // nearly edge-on: barycentrics ill-conditioned
      REQUIRE(intersect_triangle_mt(ray, p0, p1, p2, t, u, v));
      CHECK(u == doctest::Approx(b1).epsilon(1e-4).scale(1));
      CHECK(v == doctest::Approx(b2).epsilon(1e-4).scale(1));
      CHECK(t == doctest::Approx(3.0f).epsilon(1e-4));
    }
  }
}
