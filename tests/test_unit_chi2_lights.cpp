// Chi-square tests of light sampling from a shading point, Scene::sample_light against
// Scene::light_pdf (the pair MIS relies on): triangle lights by area and by solid angle, sphere
// lights, and the choice among lights by power and by the light tree (the harness is chi2_test.h).
#include <doctest/doctest.h>

#include <memory>

#include "chi2_test.h"
#include "core/accel/accel.h"
#include "core/scene/scene.h"
#include "scene_helpers.h"

using namespace pt;
using namespace pt::test;

namespace {

Chi2Family g_family(30);
void expect_accepted(const stats::Chi2Result& r, const std::string& what) { g_family.expect_accepted(r, what); }

// A scene of emitters only, with an accelerator, to test Scene::sample_light against
// Scene::light_pdf (the pair MIS relies on) from a shading point.
struct LightScene {
  SceneBuilder builder;
  std::unique_ptr<const Scene> scene_;
  std::unique_ptr<Accel> accel;
  Vec3f normal{0.0f};  // the shading point's normal the light sampler is given (zero: none)

  void add_triangle(Vec3f a, Vec3f b, Vec3f c, Spectrum emission) {
    Material m;
    m.emission = emission;
    uint32_t id = test::add_material(builder, m);
    Mesh& mesh = builder.mesh;
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {a, b, c});
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    mesh.material.push_back(id);
  }
  void add_sphere(Vec3f c, float r, Spectrum emission) {
    Material m;
    m.emission = emission;
    test::add_sphere(builder, c, r, test::add_material(builder, m));
  }
  void finish() {
    scene_ = std::make_unique<const Scene>(std::move(builder));
    accel = make_accel(scene_->geometry(), AccelOptions{});
  }
  const Scene& scene() const { return *scene_; }
  // The emitting surfaces along the ray from p in direction d, each with light_pdf's density of
  // choosing it there. Every one of them counts, not only the first: a light sampler picks a light
  // and a point of it whatever lies in front of it (occlusion is the shadow ray's business).
  struct Seen {
    float t;
    double pdf;
  };
  std::vector<Seen> seen(const Vec3f& p, const Vec3f& d) const {
    std::vector<Seen> out;
    Ray r{p, d, 0.0f, kInf};
    for (int k = 0; k < 16; ++k) {
      auto hit = accel->intersect(r);
      if (!hit) break;
      SurfaceInteraction si = scene().interaction(r, *hit);
      if (!is_black(scene().emitted(si, -d))) out.push_back({hit->t, scene().light_pdf(p, normal, si)});
      r.tmin = hit->t * (1.0f + 1e-5f) + 1e-6f;  // beyond this surface (a quad's shared edge: one of its halves)
    }
    return out;
  }
  // Solid-angle density of choosing direction d from p: light_pdf summed over what the ray meets.
  double pdf(const Vec3f& p, const Vec3f& d) const {
    double sum = 0;
    for (const Seen& s : seen(p, d)) sum += s.pdf;
    return sum;
  }
  // light_pdf of the emitting surface the ray meets nearest to distance t (0: none).
  double pdf_at(const Vec3f& p, const Vec3f& d, float t) const {
    double best = 0, gap = kInf;
    for (const Seen& s : seen(p, d)) {
      if (std::abs(s.t - t) < gap) gap = std::abs(s.t - t), best = s.pdf;
    }
    return best;
  }
  // Also counts samples whose reported pdf differs from light_pdf at the sampled point. Where
  // `can_fail`, refused samples are expected to hold the density's missing mass: the share of
  // choices that go to lights facing away from p, and (light tree) to lights below its normal or
  // to clusters that cannot reach p.
  stats::Chi2Result chi2(const Vec3f& p, const DirGrid& grid = DirGrid(), int samples = 400000,
                         bool can_fail = false) const {
    int mismatches = 0, accepted = 0;
    auto r = chi2_directions(
        [&](Pcg32& rng, Vec3f& d) {
          LightSample ls;
          float u_select = rng.next_float();
          if (!scene().sample_light(p, normal, u_select, next2(rng), ls)) return false;
          d = ls.wi;
          ++accepted;
          double expected = pdf_at(p, d, ls.distance);
          if (!(std::abs(ls.pdf - expected) <= 1e-3 * expected)) {
            if (mismatches++ < 3) MESSAGE("sampled pdf " << ls.pdf << " but light_pdf " << expected);
          }
          return true;
        },
        [&](const Vec3f& d) { return pdf(p, d); }, samples, grid, can_fail);
    INFO(mismatches << " of " << accepted << " samples disagree with light_pdf");
    CHECK(mismatches <= accepted / 10000);
    return r;
  }
};

// A cap around `axis` that holds every direction within `half_angle` (radians) of it.
DirGrid cap(const Vec3f& axis, double half_angle) {
  DirGrid g;
  g.frame = Frame(normalize(axis));
  g.cos_cap = std::cos(std::min(kPiD, half_angle));
  return g;
}
// The cap around a triangle as seen from p, with a margin.
DirGrid triangle_cap(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  Vec3f da = normalize(a - p), db = normalize(b - p), dc = normalize(c - p);
  Vec3f axis = normalize(da + db + dc);
  double angle = 0;
  for (Vec3f d : {da, db, dc}) angle = std::max(angle, std::acos(std::clamp<double>(dot(d, axis), -1, 1)));
  return cap(axis, 1.15 * angle);
}

}  // namespace

TEST_CASE("triangle lights: area sampling seen from a point matches light_pdf") {
  const Vec3f a{-1, 2, -1}, b{2, 2, -0.5f}, c{0, 1.5f, 2};
  LightScene one;
  one.add_triangle(a, b, c, Spectrum(1.0f));
  one.finish();
  // Points on the emitting side, none near the triangle's plane: seen edge-on the triangle is a
  // sliver thinner than the quadrature's sample spacing and its integral would be missed.
  for (Vec3f p : {Vec3f(0.1f, 0, 0.2f), Vec3f(-2, 0.5f, 3), Vec3f(3, 0.5f, -2)}) {
    expect_accepted(one.chi2(p, triangle_cap(p, a, b, c)),
                    "one triangle from " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z));
  }
  // The same on the whole sphere of directions.
  expect_accepted(one.chi2({0.1f, 0, 0.2f}), "one triangle, whole sphere");

  // Three lights of different power and shape, none in front of another: the choice by power is
  // part of the density.
  LightScene three;
  three.add_triangle({-1, 2, -1}, {2, 2, -0.5f}, {0, 1.5f, 2}, Spectrum(1.0f));
  three.add_triangle({2, -1, 0}, {2, 0, 1}, {2, 1, 0}, Spectrum(5.0f, 2.0f, 1.0f));  // faces -x, the origin
  three.add_triangle({-2, -1, -1}, {-2, 0.5f, -1.2f}, {-1.5f, -1, 1}, Spectrum(0.3f));
  three.finish();
  expect_accepted(three.chi2({0, 0, 0}), "three triangles");
}

TEST_CASE("triangle lights: area, solid-angle and auto sampling each match light_pdf") {
  const Vec3f a{-1, 2, -1}, b{2, 2, -0.5f}, c{0, 1.5f, 2};
  // Near (a large solid angle, where auto takes it), at a grazing angle, and far (auto: the area).
  const Vec3f points[] = {Vec3f(0.1f, 1.2f, 0.2f), Vec3f(-2, 0.5f, 3), Vec3f(6, -9, 5)};
  for (const char* mode : {"area", "solid-angle", "auto"}) {
    LightScene one;
    one.builder.settings.choices.light_sampling = kLightSamplingNames.parse(mode);
    one.add_triangle(a, b, c, Spectrum(1.0f));
    one.finish();
    for (Vec3f p : points) {
      expect_accepted(one.chi2(p, triangle_cap(p, a, b, c), 200000),
                      std::string(mode) + ", one triangle from " + std::to_string(p.x) + " " + std::to_string(p.y) +
                          " " + std::to_string(p.z));
    }
  }
  // A quad light (two coplanar triangles that share an edge) is one group: near it a member is
  // chosen by its solid angle, far from it by power; seen from beside it, from above its middle
  // and from afar.
  for (const char* mode : {"solid-angle", "auto"}) {
    LightScene quad;
    quad.builder.settings.choices.light_sampling = kLightSamplingNames.parse(mode);
    const Vec3f q0{-1, 1, -1}, q1{1, 1, -1}, q2{1, 1, 1}, q3{-1, 1, 1};  // faces -y
    quad.add_triangle(q0, q1, q2, Spectrum(1.0f));
    quad.add_triangle(q0, q2, q3, Spectrum(1.0f));
    quad.finish();
    REQUIRE(quad.scene().light_set().triangle_groups().size() == 1);
    CHECK(quad.scene().light_set().triangle_groups()[0].count == 2);
    for (Vec3f p : {Vec3f(1.6f, 0.5f, 0.3f), Vec3f(0.1f, 0.4f, -0.2f), Vec3f(3, -6, 2)}) {
      expect_accepted(quad.chi2(p, DirGrid(), 200000), std::string(mode) + ", a quad from " + std::to_string(p.x) + " " +
                                                           std::to_string(p.y) + " " + std::to_string(p.z));
    }
  }
  // Light chosen by power with a near and a far triangle: each decides from the same point.
  LightScene two;
  two.builder.settings.choices.light_sampling = LightSampling::kAuto;
  two.add_triangle({-0.5f, 0.3f, -0.5f}, {0.6f, 0.3f, -0.4f}, {0, 0.3f, 0.7f}, Spectrum(1.0f));  // faces -y, near
  two.add_triangle({4, -1, 0}, {4, 0, 1}, {4, 1, 0}, Spectrum(5.0f, 2.0f, 1.0f));                 // faces -x, far
  two.finish();
  CHECK(two.scene().light_set().triangle_groups().size() == 2);  // not coplanar, not touching
  expect_accepted(two.chi2({0, 0, 0}), "auto, a near and a far triangle");
}

TEST_CASE("sphere lights: cone sampling matches light_pdf") {
  for (float distance : {1.3f, 3.0f, 12.0f}) {
    LightScene s;
    s.add_sphere({distance * 0.6f, distance * 0.8f, 0}, 1.0f, Spectrum(2.0f));
    s.finish();
    // The cap is the sphere's silhouette with a margin.
    Vec3f centre{distance * 0.6f, distance * 0.8f, 0};
    expect_accepted(s.chi2({0, 0, 0}, cap(centre, 1.3 * std::asin(1.0 / distance))),
                    "sphere light at distance " + std::to_string(distance));
  }
  // A sphere and a triangle together.
  LightScene mixed;
  mixed.add_sphere({0, 0, 3}, 0.8f, Spectrum(4.0f));
  mixed.add_triangle({-1, 2, -1}, {2, 2, -0.5f}, {0, 1.5f, 2}, Spectrum(1.0f));
  mixed.finish();
  expect_accepted(mixed.chi2({0, 0, 0}), "sphere and triangle");
}

TEST_CASE("light tree selection: sampled lights match light_pdf inside, beside and far from the lights") {
  // Seven triangles (two of them a quad: one group) and two spheres around the origin, of
  // different powers and facing different ways, chosen by the light tree. Some face away from the
  // points below and some hide others, so samples are refused (a cell of the test of its own) and
  // a direction can meet several lights.
  LightScene s;
  s.builder.settings.choices.light_selection = LightSelection::kTree;
  s.add_triangle({-1, 2, -1}, {2, 2, -0.5f}, {0, 1.5f, 2}, Spectrum(1.0f));
  s.add_triangle({2, -1, 0}, {2, 0, 1}, {2, 1, 0}, Spectrum(5.0f, 2.0f, 1.0f));
  s.add_triangle({-2, -1, -1}, {-2, 0.5f, -1.2f}, {-1.5f, -1, 1}, Spectrum(0.3f));
  s.add_triangle({-1, -2, 3}, {1, -2, 3}, {1, 0, 3}, Spectrum(2.0f));  // a quad facing +z
  s.add_triangle({-1, -2, 3}, {1, 0, 3}, {-1, 0, 3}, Spectrum(2.0f));
  s.add_triangle({0.5f, -3, -2}, {1.5f, -3, -2}, {1, -3, -1}, Spectrum(8.0f));
  s.add_triangle({-3, 3, 3}, {-3, 4, 3}, {-3, 3, 4}, Spectrum(20.0f));
  s.add_sphere({0, 0, -4}, 0.7f, Spectrum(3.0f));
  s.add_sphere({4, 3, 1}, 0.4f, Spectrum(10.0f));
  s.finish();
  REQUIRE(s.scene().light_set().selection() == LightSelection::kTree);
  const int n = 300000;
  DirGrid whole;
  whole.quadrature = 12;  // fine enough for the corners of lights that fill a sliver of a cell
  expect_accepted(s.chi2({0, 0, 0}, whole, n, true), "light tree, inside, no normal");
  s.normal = normalize(Vec3f(0.3f, 1, -0.2f));
  expect_accepted(s.chi2({0, 0, 0}, whole, n, true), "light tree, inside, with a normal");
  s.normal = Vec3f(0.0f);
  expect_accepted(s.chi2({0.5f, -1.5f, 2.5f}, whole, n, true), "light tree, under the quad");
  s.normal = normalize(Vec3f(-1, 0.2f, 0.1f));
  expect_accepted(s.chi2({7, 0.5f, 0}, whole, n, true), "light tree, beside the lights, facing them");
  // Far: the lights (within 6 of the origin) fill a small cone, which the grid covers alone, in
  // coarser cells with a finer quadrature (the lights are small, near the grid's pole).
  const Vec3f far{40, 30, -20};
  s.normal = normalize(-far);
  DirGrid around = cap(-far, 1.2 * std::asin(6.0 / length(far)));
  around.nx = around.ny = 20;
  around.quadrature = 24;
  expect_accepted(s.chi2(far, around, n, true), "light tree, far");
}

TEST_CASE("sphere light pdf is the subtended solid angle, even for small distant spheres") {
  // Every cone sample must hit the sphere and the pdf must be 1 / (2 pi (1 - cos theta_max)),
  // evaluated here in double. Catastrophic cancellation in 1 - cos theta_max in float would sample a
  // cone of the wrong size (or none at all).
  for (double distance : {5.0, 50.0, 300.0, 2000.0}) {
    LightScene s;
    const double radius = 0.5;
    Vec3f centre{0, static_cast<float>(distance), 0};
    s.add_sphere(centre, static_cast<float>(radius), Spectrum(1.0f));
    s.finish();
    double sin2 = radius * radius / (distance * distance);
    double one_minus_cos = sin2 / (1.0 + std::sqrt(1.0 - sin2));
    double expected_pdf = 1.0 / (kTwoPi * one_minus_cos);
    Pcg32 rng(11, 5);
    int hits = 0, n = 2000;
    double max_rel = 0;
    for (int i = 0; i < n; ++i) {
      LightSample ls;
      if (!s.scene().sample_light({0, 0, 0}, Vec3f(0.0f), rng.next_float(), next2(rng), ls)) continue;
      max_rel = std::max(max_rel, std::abs(ls.pdf / expected_pdf - 1.0));
      // Distance from the centre to the sampled ray, in double.
      double dx = ls.wi.x, dy = ls.wi.y, dz = ls.wi.z, len = std::sqrt(dx * dx + dy * dy + dz * dz);
      double t = distance * dy / len;
      double miss2 = distance * distance - t * t;
      if (miss2 <= radius * radius * (1 + 1e-3)) ++hits;
    }
    INFO("distance " << distance << ": " << hits << " of " << n << " hit, max pdf error " << max_rel);
    CHECK(hits == n);
    CHECK(max_rel < 1e-3);
  }
}
