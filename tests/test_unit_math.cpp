#include <doctest/doctest.h>

#include <vector>

#include "core/math/frame.h"
#include "core/math/rng.h"
#include "core/math/sampler.h"
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

TEST_CASE("sobol: the table form of the second dimension equals the bit-serial definition") {
  using namespace pt::sobol_detail;
  pt::Pcg32 rng(3, 7);
  for (uint32_t i = 0; i < 4096; ++i) CHECK(sobol_dim1(i) == sobol_dim1_serial(i));
  for (int k = 0; k < 100000; ++k) {
    uint32_t i = rng.next_u32();
    REQUIRE(sobol_dim1(i) == sobol_dim1_serial(i));
  }
  // The first 2^k points of the (0,2)-sequence put one point in each of 2^k elementary intervals.
  for (int k = 1; k <= 8; ++k) {
    std::vector<int> seen(1u << k, 0);
    int half = k / 2;
    for (uint32_t i = 0; i < (1u << k); ++i) {
      // x keeps the top `half` bits of dimension 0 (none when half is 0: a shift by 32 is undefined)
      uint32_t x = half ? sobol_dim0(i) >> (32 - half) : 0u, y = sobol_dim1(i) >> (32 - (k - half));
      ++seen[(x << (k - half)) | y];
    }
    for (int c : seen) CHECK(c == 1);
  }
}

TEST_CASE("sobol: the shortcut forms equal owen_scramble of the Sobol dimensions") {
  using namespace pt::sobol_detail;
  pt::Pcg32 rng(5, 9);
  for (int k = 0; k < 100000; ++k) {
    uint32_t i = rng.next_u32(), seed = rng.next_u32(), x = rng.next_u32();
    uint32_t r = 0;
    for (int b = 0; b < 32; ++b) r |= ((x >> b) & 1u) << (31 - b);
    REQUIRE(reverse_bits(x) == r);
    REQUIRE(reverse_bits(laine_karras(i, seed)) == owen_scramble(sobol_dim0(i), seed));
    REQUIRE(reverse_bits(laine_karras(sobol_dim1_reversed(i), seed)) == owen_scramble(sobol_dim1(i), seed));
  }
}
