// The light hierarchy (core/scene/lights/light_tree.h) against its own pdf: chi-square of the
// lights its descent chooses against LightTree::pdf at points inside, beside and far from a
// cluster of lights, the pdf summing to one over all lights, and the triangle-group and infinite
// light shares. Timings are pt bench lights's, never here.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "core/math/rng.h"
#include "core/scene/lights/light_tree.h"
#include "core/scene/lights/point_light.h"
#include "core/scene/lights/spot_light.h"
#include "core/scene/lights/power_light_sampler.h"
#include "stats.h"

using namespace pt;

namespace {

constexpr double kSignificance = 0.01 / 12;  // Šidák-like share of 1% over this file's chi-square tests

// A cluster of n lights in the box [-1, 1]^3 around `centre`, of powers spread over three decades:
// points, one-sided emitters facing random ways, and spheres; every third light is paired with the
// next into a group of two (as a quad light's halves are).
struct Cluster {
  std::vector<LightBounds> bounds;
  std::vector<float> power;
  std::vector<LightGroupRange> groups;

  Cluster(int n, Vec3f centre, uint64_t seed, int infinite = 0) {
    Pcg32 rng(seed, 3);
    for (int i = 0; i < n; ++i) {
      LightBounds b;
      Vec3f c = centre + Vec3f(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
      float size = 0.05f * rng.next_float();
      b.box.expand(c - Vec3f(size));
      b.box.expand(c + Vec3f(size));
      b.phi = std::pow(10.0f, 3 * rng.next_float());
      int kind = i % 3;
      if (kind == 0) {
        b.cos_o = -1, b.cos_e = 0;  // a point or sphere: every direction
      } else {
        float z = 2 * rng.next_float() - 1, phi = 6.2831853f * rng.next_float(), r = std::sqrt(std::max(0.0f, 1 - z * z));
        b.axis = {r * std::cos(phi), r * std::sin(phi), z};
        b.cos_o = 1, b.cos_e = 0;  // one-sided, a hemisphere about its normal
      }
      bounds.push_back(b);
      power.push_back(b.phi);
    }
    for (int i = 1; i + 1 < n; i += 3) {
      // A group of two: the same orientation, side by side.
      bounds[i + 1].axis = bounds[i].axis;
      bounds[i + 1].cos_o = bounds[i].cos_o;
      groups.push_back({static_cast<uint32_t>(i), 2});
    }
    for (int k = 0; k < infinite; ++k) {
      bounds.emplace_back();  // empty: infinitely far
      power.push_back(50.0f * (k + 1));
    }
  }
};

// Chi-square of `samples` choices at (p, n) against the pdf; also checks that every sample
// reports the pdf of the light it chose, bit for bit.
stats::Chi2Result choice_chi2(const LightSampler& s, size_t lights, const Vec3f& p, const Vec3f& n, int samples) {
  std::vector<double> observed(lights, 0.0), expected(lights, 0.0);
  Pcg32 rng(17, 9);
  int mismatches = 0, failures = 0;
  for (int i = 0; i < samples; ++i) {
    LightChoice c;
    if (!s.sample(p, n, rng.next_float(), c)) {
      ++failures;
      continue;
    }
    observed[c.light] += 1;
    mismatches += c.pick != s.pdf(p, n, static_cast<uint32_t>(c.light));
  }
  for (size_t l = 0; l < lights; ++l) expected[l] = samples * double(s.pdf(p, n, static_cast<uint32_t>(l)));
  CHECK(mismatches == 0);
  // A sample fails only where no light can reach: the expected counts then sum to less than samples.
  double sum = 0;
  for (double e : expected) sum += e;
  CHECK(std::abs(sum + failures - samples) < 1e-3 * samples);
  return stats::chi2_test(observed, expected);
}

}  // namespace

TEST_CASE("light tree: chosen lights follow its pdf inside, beside and far from a cluster") {
  Cluster cluster(300, {0, 0, 0}, 5, 2);
  LightTree tree(cluster.bounds, cluster.power, cluster.groups);
  CHECK(tree.emitter_count() == 300 - cluster.groups.size());
  CHECK(tree.depth() < 64);
  struct Case {
    Vec3f p, n;
    const char* where;
  };
  const Case cases[] = {
      {{0.1f, -0.2f, 0.3f}, {0, 0, 0}, "inside, no normal"},
      {{0.1f, -0.2f, 0.3f}, normalize(Vec3f(1, 2, -1)), "inside, with a normal"},
      {{2.5f, 0.3f, 0}, {-1, 0, 0}, "beside, facing it"},
      {{2.5f, 0.3f, 0}, normalize(Vec3f(0.3f, 1, 0)), "beside, grazing"},
      {{40, 30, -20}, normalize(Vec3f(-4, -3, 2)), "far, facing it"},
  };
  for (const Case& c : cases) {
    stats::Chi2Result r = choice_chi2(tree, cluster.bounds.size(), c.p, c.n, 400000);
    INFO(c.where << ": " << r.message);
    CHECK(r.p_value > kSignificance);
  }
}

TEST_CASE("light tree: the pdf sums to one over all lights, at many points") {
  Cluster cluster(1000, {3, 0, 0}, 8, 1);
  LightTree tree(cluster.bounds, cluster.power, cluster.groups);
  Pcg32 rng(4, 4);
  int zero = 0;
  for (int i = 0; i < 300; ++i) {
    // Points from inside the cluster to far beyond it, half of them with a normal.
    float scale = std::pow(10.0f, 2 * rng.next_float() - 0.5f);
    Vec3f p = Vec3f(3, 0, 0) + Vec3f(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * scale;
    Vec3f n(0.0f);
    if (i % 2) n = normalize(Vec3f(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
    double sum = 0;
    for (size_t l = 0; l < cluster.bounds.size(); ++l) sum += tree.pdf(p, n, static_cast<uint32_t>(l));
    // The infinite light's share alone where no light of the tree can reach the point.
    double infinite = tree.infinite_pdf(static_cast<uint32_t>(cluster.bounds.size() - 1));
    if (std::abs(sum - infinite) < 1e-6) {
      ++zero;
      continue;
    }
    CAPTURE(i);
    CHECK(sum == doctest::Approx(1.0).epsilon(1e-4));
  }
  CHECK(zero < 30);  // most points see some light
}

TEST_CASE("light tree: a group's members share its leaf by power, and group_pdf is their sum") {
  Cluster cluster(60, {0, 0, 0}, 11);
  LightTree tree(cluster.bounds, cluster.power, cluster.groups);
  const Vec3f p{0.3f, 2.0f, -0.4f}, n{0, -1, 0};
  for (uint32_t g = 0; g < cluster.groups.size(); ++g) {
    const LightGroupRange& r = cluster.groups[g];
    double members = tree.pdf(p, n, r.first) + tree.pdf(p, n, r.first + 1);
    CHECK(members == doctest::Approx(tree.group_pdf(p, n, g)).epsilon(1e-5));
    if (members > 0) {
      CHECK(tree.pdf(p, n, r.first) / members == doctest::Approx(cluster.power[r.first] / (cluster.power[r.first] + cluster.power[r.first + 1])).epsilon(1e-4));
    }
  }
}

TEST_CASE("light tree: infinite lights keep their share of the power; lights behind the normal get none") {
  Cluster cluster(50, {0, 0, 0}, 2, 2);
  LightTree tree(cluster.bounds, cluster.power, cluster.groups);
  PowerLightSampler power(cluster.power, cluster.groups);
  for (uint32_t l = 50; l < 52; ++l) CHECK(tree.infinite_pdf(l) == doctest::Approx(power.infinite_pdf(l)).epsilon(1e-5));
  // Far above the cluster, facing up: the whole cluster is below the surface.
  Vec3f p{0, 10, 0}, up{0, 1, 0};
  for (uint32_t l = 0; l < 50; ++l) CHECK(tree.pdf(p, up, l) == 0.0f);
  LightChoice c;
  Pcg32 rng(1, 1);
  for (int i = 0; i < 1000; ++i) {
    if (tree.sample(p, up, rng.next_float(), c)) CHECK(c.light >= 50);
  }
}

TEST_CASE("light tree: a spot light without a falloff ramp is chosen inside its cone, never outside") {
  // Its inner and outer angles a hair apart: cos theta_e rounds to one.
  SpotLight spot({0, 4, 0}, {0, -1, 0}, Spectrum(40.0f), 0.5f, 0.5001f);
  PointLight point;
  point.position = {3, 4, 0};
  point.intensity = Spectrum(1.0f);
  std::vector<LightBounds> bounds = {spot.bounds(), point.bounds()};
  CHECK(bounds[0].cos_e == 1.0f);
  std::vector<float> power = {spot.power(), point.power()};
  LightTree tree(bounds, power, {});
  const Vec3f up{0, 1, 0};
  CHECK(tree.pdf({0.5f, 0, 0}, up, 0) > 0.5f);  // inside the cone (its power 31, the point's 13)
  CHECK(tree.pdf({4, 0, 0}, up, 0) == 0.0f);     // outside it
  CHECK(tree.pdf({4, 0, 0}, up, 1) == 1.0f);
}

TEST_CASE("light tree: the four-lane importance is the scalar one, bit for bit") {
  // Random clusters (omnidirectional, one-sided, spot-like, flat and point-sized, some of no power)
  // at random points inside, beside and far from them, with and without a normal.
  Pcg32 rng(21, 4);
  auto unit = [&] {
    float z = 2 * rng.next_float() - 1, a = 6.2831853f * rng.next_float(), r = std::sqrt(std::max(0.0f, 1 - z * z));
    return Vec3f(r * std::cos(a), r * std::sin(a), z);
  };
  int mismatches = 0, nonzero = 0, inside = 0;
  for (int i = 0; i < 20000; ++i) {
    LightCones4 lanes;
    LightCone cones[4];
    for (int k = 0; k < 4; ++k) {
      LightBounds b;
      Vec3f c(4 * rng.next_float() - 2, 4 * rng.next_float() - 2, 4 * rng.next_float() - 2);
      Vec3f half(rng.next_float(), rng.next_float() * (k == 1 ? 0.0f : 1.0f), rng.next_float());
      if (k == 3) half = Vec3f(0.0f);
      b.box.expand(c - half);
      b.box.expand(c + half);
      b.phi = rng.next_float() < 0.1f ? 0.0f : std::pow(10.0f, 3 * rng.next_float());
      b.axis = unit();
      float kind = rng.next_float();
      b.cos_o = kind < 0.3f ? -1.0f : kind < 0.6f ? 1.0f : 2 * rng.next_float() - 1;
      b.cos_e = kind < 0.8f ? 0.0f : rng.next_float();
      cones[k] = light_cone(b);
      lanes.set(k, cones[k]);
    }
    Vec3f p(12 * rng.next_float() - 6, 12 * rng.next_float() - 6, 12 * rng.next_float() - 6);
    if (i % 7 == 0) p = p * 20.0f;
    if (i % 5 == 1) p = cones[i % 4].center + Vec3f(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
    Vec3f n = i % 3 == 0 ? Vec3f(0.0f) : unit();
    float w[4];
    importance4(lanes, p, n, w);
    for (int k = 0; k < 4; ++k) {
      float scalar = importance(cones[k], p, n);
      mismatches += std::memcmp(&scalar, &w[k], sizeof(float)) != 0;
      nonzero += scalar > 0;
      inside += length_squared(p - cones[k].center) <= cones[k].radius2;
    }
  }
  CHECK(mismatches == 0);
  CHECK(nonzero > 20000);  // the cases cover lit and unlit lanes, and points inside the spheres
  CHECK(inside > 1000);
}

TEST_CASE("light tree: emitters that all face one way give nothing behind them, even inside their bounding sphere") {
  // A ceiling of 4 x 4 panels at y = 3 facing down, the ceiling itself 1 cm above them.
  std::vector<LightBounds> bounds;
  for (int i = 0; i < 16; ++i) {
    LightBounds b;
    Vec3f c(-1.5f + i % 4, 3.0f, -1.5f + i / 4);
    b.box.expand(c - Vec3f(0.4f, 0.0f, 0.4f));
    b.box.expand(c + Vec3f(0.4f, 0.0f, 0.4f));
    b.phi = 1.0f + i;
    b.axis = {0, -1, 0};
    b.cos_o = 1, b.cos_e = 0;
    bounds.push_back(b);
  }
  std::vector<float> power;
  for (const LightBounds& b : bounds) power.push_back(b.phi);
  LightTree tree(bounds, power, {});
  LightBounds all;
  for (const LightBounds& b : bounds) all = merge(all, b);
  LightCone cone = light_cone(all);
  const Vec3f ceiling{0.3f, 3.01f, 0.2f}, down{0, -1, 0}, floor{0.3f, 0.0f, 0.2f}, up{0, 1, 0};
  REQUIRE(length_squared(ceiling - cone.center) < cone.radius2);  // where the cone bound says nothing
  CHECK(importance(cone, ceiling, Vec3f(0.0f)) == 0.0f);
  CHECK(importance(cone, floor, up) > 0.0f);
  LightChoice c;
  Pcg32 rng(3, 3);
  int chosen = 0;
  for (int i = 0; i < 1000; ++i) chosen += tree.sample(ceiling, down, rng.next_float(), c);
  CHECK(chosen == 0);  // no sample wasted on a panel the ceiling is behind
  double sum = 0;
  for (uint32_t l = 0; l < 16; ++l) {
    CHECK(tree.pdf(ceiling, down, l) == 0.0f);
    sum += tree.pdf(floor, up, l);
  }
  CHECK(sum == doctest::Approx(1.0).epsilon(1e-5));
}
