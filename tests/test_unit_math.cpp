#include <doctest/doctest.h>

#include "core/math/frame.h"
#include "core/math/transform.h"

using namespace pt;

TEST_CASE("frame is orthonormal") {
  for (Vec3f n : {Vec3f(0, 0, 1), Vec3f(0, 0, -1), normalize(Vec3f(1, 2, 3)), normalize(Vec3f(-0.3f, 0.1f, -0.9f))}) {
    Frame f(n);
    CHECK(dot(f.s, f.t) == doctest::Approx(0).epsilon(1e-6));
    CHECK(dot(f.s, f.n) == doctest::Approx(0).epsilon(1e-6));
    CHECK(length(f.s) == doctest::Approx(1));
    CHECK(length(f.t) == doctest::Approx(1));
    Vec3f v = normalize(Vec3f(0.2f, -0.5f, 0.7f));
    Vec3f back = f.to_world(f.to_local(v));
    CHECK(length(back - v) < 1e-6f);
  }
}

TEST_CASE("transform normals stay perpendicular to transformed surfaces") {
  Transform t = Transform::translate({1, 2, 3}) * Transform::rotate_axis(1, 30) * Transform::scale({2, 1, 0.5f});
  Vec3f a{1, 0, 0}, b{0, 1, 0};
  Vec3f n = cross(a, b);
  Vec3f ta = t.vector(a), tb = t.vector(b), tn = t.normal(n);
  CHECK(dot(ta, tn) == doctest::Approx(0).epsilon(1e-5));
  CHECK(dot(tb, tn) == doctest::Approx(0).epsilon(1e-5));
  CHECK(dot(cross(ta, tb), tn) > 0);
}
