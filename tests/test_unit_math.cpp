#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "core/math/frame.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "core/math/sampler.h"
#include "core/math/spherical_triangle.h"
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
    const uint64_t pair = reverse_bits_pair(x, i);
    REQUIRE(static_cast<uint32_t>(pair) == r);
    REQUIRE(static_cast<uint32_t>(pair >> 32) == reverse_bits(i));
    REQUIRE(owen_scramble_reversed(reverse_bits(i), seed) == owen_scramble(i, seed));
    REQUIRE(reverse_bits(laine_karras(i, seed)) == owen_scramble(sobol_dim0(i), seed));
    REQUIRE(reverse_bits(laine_karras(sobol_dim1_reversed(i), seed)) == owen_scramble(sobol_dim1(i), seed));
  }
}

namespace {
struct D3 {
  double x, y, z;
};
D3 d3(const Vec3f& v) { return {v.x, v.y, v.z}; }
D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dotd(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 crossd(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
D3 unitd(D3 a) {
  double l = std::sqrt(dotd(a, a));
  return {a.x / l, a.y / l, a.z / l};
}
double angled(D3 a, D3 b) { return std::atan2(std::sqrt(dotd(crossd(a, b), crossd(a, b))), dotd(a, b)); }
}  // namespace

TEST_CASE("sampling: the quarter-range sincos and the concentric disk it serves match libm's within float rounding") {
  double worst = 0.0;
  for (int i = 0; i <= 100000; ++i) {
    const float a = static_cast<float>(-kPi / 4 + (kPi / 2) * i / 100000.0);
    float s, c;
    sincos_quarter(a, s, c);
    worst = std::max({worst, std::abs(s - std::sin(static_cast<double>(a))), std::abs(c - std::cos(static_cast<double>(a)))});
  }
  CHECK(worst < 2.5e-7);  // about two float ulps of 1
  // The disk map against the polar form it stands for, theta from the sector's formula in double.
  double disk_worst = 0.0;
  int outside = 0;
  Pcg32 rng(3, 5);
  for (int i = 0; i < 100000; ++i) {
    const Vec2f u{rng.next_float(), rng.next_float()};
    const double ox = 2.0 * u.x - 1.0, oy = 2.0 * u.y - 1.0;
    const bool x_major = std::abs(ox) > std::abs(oy);
    const double r = x_major ? ox : oy, theta = x_major ? (kPi / 4) * (oy / ox) : kPi / 2 - (kPi / 4) * (ox / oy);
    const Vec2f d = square_to_disk_concentric(u);
    disk_worst = std::max({disk_worst, std::abs(d.x - r * std::cos(theta)), std::abs(d.y - r * std::sin(theta))});
    if (d.x * d.x + d.y * d.y > 1.0f + 1e-6f) ++outside;
  }
  CHECK(disk_worst < 5e-7);
  CHECK(outside == 0);
}

TEST_CASE("spherical triangle: Girard's area, samples inside and uniform, Lambert's irradiance") {
  SphericalTriangle octant;
  REQUIRE(make_spherical_triangle(Vec3f(0), Vec3f(1, 0, 0), Vec3f(0, 2, 0), Vec3f(0, 0, 3), octant));
  CHECK(octant.area == doctest::Approx(M_PI / 2).epsilon(1e-6));

  const Vec3f p{0.1f, 0.2f, 0.0f};
  const Vec3f v[3] = {{-1, 0.3f, 1}, {1, -0.5f, 1.2f}, {0.2f, 1, 0.8f}};
  SphericalTriangle t;
  REQUIRE(make_spherical_triangle(p, v[0], v[1], v[2], t));
  // Girard: the area is the sum of the angles less pi; each angle lies between the planes through
  // the viewpoint and two sides.
  D3 r[3];
  for (int i = 0; i < 3; ++i) r[i] = unitd(sub(d3(v[i]), d3(p)));
  double angles = 0;
  for (int i = 0; i < 3; ++i) angles += angled(crossd(r[i], r[(i + 1) % 3]), crossd(r[i], r[(i + 2) % 3]));
  CHECK(t.area == doctest::Approx(angles - M_PI).epsilon(1e-5));
  // The corners of the unit square go to the vertices Arvo's construction starts from.
  CHECK(length(sample_spherical_triangle(t, {1, 1}) - t.c) < 1e-5f);
  CHECK(length(sample_spherical_triangle(t, {0.3f, 0}) - t.b) < 1e-5f);

  // Every sample's ray meets the triangle; the four triangles between the edges' midpoints get
  // samples in proportion to their solid angles; and the mean of area * cos against a receiver
  // normal is the irradiance from a unit-radiance polygon, (1/2) sum_i Theta_i n . unit(r_i x r_i+1)
  // (Lambert; e.g. Arvo, "Applications of Irradiance Tensors", SIGGRAPH 1995).
  const D3 n = unitd({0.2, 0.1, 1.0});
  double lambert = 0;
  for (int i = 0; i < 3; ++i) lambert += 0.5 * angled(r[i], r[(i + 1) % 3]) * dotd(n, unitd(crossd(r[i], r[(i + 1) % 3])));
  lambert = std::abs(lambert);
  const Vec3f m01 = (v[0] + v[1]) * 0.5f, m12 = (v[1] + v[2]) * 0.5f, m20 = (v[2] + v[0]) * 0.5f;
  const Vec3f quarters[4][3] = {{v[0], m01, m20}, {v[1], m12, m01}, {v[2], m20, m12}, {m01, m12, m20}};
  auto hits = [&](const Vec3f (&tri)[3], D3 w, double slack) {  // Moeller-Trumbore in double
    D3 e1 = sub(d3(tri[1]), d3(tri[0])), e2 = sub(d3(tri[2]), d3(tri[0])), h = crossd(w, e2);
    double det = dotd(e1, h);
    D3 s = sub(d3(p), d3(tri[0])), q = crossd(s, e1);
    double b1 = dotd(s, h) / det, b2 = dotd(w, q) / det;
    return b1 >= -slack && b2 >= -slack && b1 + b2 <= 1 + slack && dotd(e2, q) / det > 0;
  };
  const int kSamples = 200000;
  Pcg32 rng(7, 3);
  int outside = 0;
  double counts[4] = {0, 0, 0, 0}, sum = 0, sum2 = 0;
  for (int i = 0; i < kSamples; ++i) {
    float u0 = rng.next_float();
    D3 w = d3(sample_spherical_triangle(t, {u0, rng.next_float()}));
    if (!hits(v, w, 1e-4)) ++outside;
    for (int k = 0; k < 4; ++k) {
      if (hits(quarters[k], w, 0)) {
        counts[k] += 1;
        break;
      }
    }
    double e = t.area * std::max(0.0, dotd(n, w));
    sum += e;
    sum2 += e * e;
  }
  CHECK(outside == 0);
  double chi2 = 0;
  for (int k = 0; k < 4; ++k) {
    SphericalTriangle q;
    REQUIRE(make_spherical_triangle(p, quarters[k][0], quarters[k][1], quarters[k][2], q));
    double expected = kSamples * q.area / t.area;
    chi2 += (counts[k] - expected) * (counts[k] - expected) / expected;
  }
  INFO("counts " << counts[0] << " " << counts[1] << " " << counts[2] << " " << counts[3]);
  CHECK(chi2 < 16.27);  // chi-square, 3 degrees of freedom, p = 0.001
  double mean = sum / kSamples, sigma = std::sqrt((sum2 / kSamples - mean * mean) / kSamples);
  INFO("irradiance " << mean << " +- " << sigma << ", Lambert " << lambert);
  CHECK(std::abs(mean - lambert) < 4 * sigma);
}
