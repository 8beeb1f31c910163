// The geometry of light sampling through a mirror sphere (integrators/sphere_mirror.h), against
// answers nobody chose: the law of reflection at the point found, and the density D^2 against the
// solid angle a small light patch's reflection subtends at x, measured by re-solving for the
// patch's corners.
#include <doctest/doctest.h>

#include <cmath>

#include "core/math/rng.h"
#include "integrators/sphere_mirror.h"

using namespace pt;

namespace {

Vec3f unit(const Vec3f& v) { return v / length(v); }

Vec3f random_outside(Pcg32& rng, const Vec3f& c, float r) {
  for (;;) {
    Vec3f p{rng.next_float() * 8 - 4, rng.next_float() * 8 - 4, rng.next_float() * 8 - 4};
    if (length(p - c) > r * 1.05f) return p;
  }
}

}  // namespace

TEST_CASE("sphere mirror: the point found reflects y toward x, and exists exactly when the arc both see holds it") {
  Pcg32 rng(7, 1);
  const Vec3f c{0.3f, -0.2f, 0.5f};
  const float r = 0.9f;
  int found = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3f x = random_outside(rng, c, r), y = random_outside(rng, c, r);
    SphereReflection sr;
    if (!reflect_in_sphere(c, r, x, y, sr)) continue;
    ++found;
    Vec3f n = unit(sr.m - c);
    CHECK(length(sr.m - c) == doctest::Approx(r).epsilon(1e-5));
    Vec3f to_x = unit(x - sr.m), to_y = unit(y - sr.m);
    // Both see m, and the normal bisects the two directions (law of reflection).
    REQUIRE(dot(to_x, n) > 0);
    REQUIRE(dot(to_y, n) > 0);
    Vec3f reflected = n * (2 * dot(n, to_x)) - to_x;
    CHECK(length(reflected - to_y) < 2e-4f);
    CHECK(dot(to_x, n) == doctest::Approx(sr.cos_theta).epsilon(1e-4));
  }
  // Random pairs mostly see a common reflection point; some (y behind the sphere) do not.
  CHECK(found > 10000);
  CHECK(found < 20000);
  // A point inside the sphere has none.
  SphereReflection sr;
  CHECK_FALSE(reflect_in_sphere(c, r, c + Vec3f{0.1f, 0, 0}, Vec3f{3, 3, 3}, sr));
  // Straight back: y on the ray from c through x.
  REQUIRE(reflect_in_sphere(c, r, c + Vec3f{0, 2, 0}, c + Vec3f{0, 3, 0}, sr));
  CHECK(length(sr.m - (c + Vec3f{0, r, 0})) < 1e-5f);
  CHECK_FALSE(reflect_in_sphere(c, r, c + Vec3f{0, 2, 0}, c + Vec3f{0, -3, 0}, sr));
}

TEST_CASE("sphere mirror: D^2 is the solid angle a light patch's reflection subtends at x") {
  Pcg32 rng(11, 1);
  const Vec3f c{0, 0, 0};
  const float r = 0.6f;
  int checked = 0;
  for (int i = 0; i < 400 && checked < 150; ++i) {
    Vec3f x = random_outside(rng, c, r), y = random_outside(rng, c, r);
    SphereReflection sr;
    if (!reflect_in_sphere(c, r, x, y, sr)) continue;
    if (sr.cos_theta < 0.1f) continue;  // grazing: the finite differences lose their precision
    // A small square patch at y facing m, and the directions at x toward its corners' reflections.
    Vec3f ny = unit(sr.m - y);
    Vec3f t1 = unit(std::abs(ny.x) < 0.9f ? cross(ny, Vec3f{1, 0, 0}) : cross(ny, Vec3f{0, 1, 0}));
    Vec3f t2 = cross(ny, t1);
    const float h = 5e-3f * sr.s;
    SphereReflection a, b, cc, dd;
    if (!reflect_in_sphere(c, r, x, y + t1 * h, a) || !reflect_in_sphere(c, r, x, y - t1 * h, b) ||
        !reflect_in_sphere(c, r, x, y + t2 * h, cc) || !reflect_in_sphere(c, r, x, y - t2 * h, dd)) {
      continue;
    }
    Vec3f w1 = unit(a.m - x) - unit(b.m - x), w2 = unit(cc.m - x) - unit(dd.m - x);
    double solid_angle = length(cross(w1, w2));  // (2h)^2 of patch
    double area = 4.0 * h * h;
    double expected = area / sphere_mirror_distance2(sr.s, sr.d, sr.cos_theta, r);  // cos_y = 1
    CHECK(solid_angle == doctest::Approx(expected).epsilon(3e-3));
    ++checked;
  }
  CHECK(checked >= 100);
  // A huge sphere is a flat mirror: (s + d)^2.
  CHECK(sphere_mirror_distance2(2.0f, 3.0f, 0.5f, 1e9f) == doctest::Approx(25.0f).epsilon(1e-5));
}
