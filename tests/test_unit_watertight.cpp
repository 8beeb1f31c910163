// The watertight triangle test's double-precision fallback (intersect.h): rays that pass within
// float rounding of a silhouette edge, checked against the edge functions in long double.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <vector>

#include "bvh_test_scenes.h"
#include "core/accel/bvh_accel.h"
#include "core/geometry/intersect.h"
#include "core/scene/loader.h"
#include "core/scene/studio.h"

using namespace pt;

namespace {

// The edge functions d . ((q - o) x (r - o)) in long double (64-bit significands: the differences
// of floats and their pairwise products are exact, so the error is far below float's), as
// weights of the corners; `inside` when none is below zero or none above, and not all zero.
struct Reference {
  long double e[3];
  long double t;
  bool inside;
};

Reference reference(const Ray& ray, const Vec3f& p0, const Vec3f& p1, const Vec3f& p2) {
  long double P[3][3];
  const Vec3f* p[3] = {&p0, &p1, &p2};
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) P[k][a] = static_cast<long double>((*p[k])[a]) - static_cast<long double>(ray.o[a]);
  long double d[3] = {ray.d.x, ray.d.y, ray.d.z};
  auto triple = [&](const long double* a, const long double* b) {
    return d[0] * (a[1] * b[2] - a[2] * b[1]) + d[1] * (a[2] * b[0] - a[0] * b[2]) + d[2] * (a[0] * b[1] - a[1] * b[0]);
  };
  Reference r;
  r.e[0] = triple(P[1], P[2]);
  r.e[1] = triple(P[2], P[0]);
  r.e[2] = triple(P[0], P[1]);
  long double lo = std::min({r.e[0], r.e[1], r.e[2]}), hi = std::max({r.e[0], r.e[1], r.e[2]});
  long double det = r.e[0] + r.e[1] + r.e[2];
  r.inside = (lo >= 0 || hi <= 0) && det != 0;
  // t from the plane: n . (p0 - o) / n . d.
  long double e1[3], e2[3], n[3];
  for (int a = 0; a < 3; ++a) e1[a] = P[1][a] - P[0][a], e2[a] = P[2][a] - P[0][a];
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  r.t = (n[0] * P[0][0] + n[1] * P[0][1] + n[2] * P[0][2]) / (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
  return r;
}

}  // namespace

TEST_CASE("watertight fallback: the Chinese dragon's silhouette ray hits") {
  // Four corners of the Chinese dragon scan (libcgal-demo's data, 20k triangles) and a primary ray
  // of `pt bench rays --studio none` that Embree hit and the float test missed: it passes
  // 2.4e-6 (in barycentrics) inside triangle (a, b, c) at the edge (a, b), whose other triangle
  // (d, b, a) faces the other way, so the ray is also inside it, by 2.3e-6.
  Vec3f a(0x1.118a12p+3f, -0x1.98d04p+3f, -0x1.029476p+10f), b(0x1.e16b6cp+2f, -0x1.884794p+3f, -0x1.026578p+10f),
      c(0x1.2fb592p+3f, -0x1.8428bcp+3f, -0x1.025cb0p+10f), d(0x1.7edaeap+2f, -0x1.a16b0ep+3f, -0x1.027c7ep+10f);
  Ray ray;
  ray.o = {0x1.d77e12p+7f, 0x1.fcbcb0p+5f, -0x1.eafc5cp+9f};
  ray.d = {-0x1.da8f40p-1f, -0x1.3d6208p-2f, -0x1.b1abp-3f};
  Reference abc = reference(ray, a, b, c), dba = reference(ray, d, b, a);
  REQUIRE(abc.inside);
  REQUIRE(dba.inside);

  // In float the edge (a, b) gets the wrong sign (the three edge functions have both signs), within
  // its error bound; in double all three have one sign, and the weight of c is the exact one's.
  WatertightRay w(ray.d);
  WatertightCorner ca = watertight_corner(ray, w, a), cb = watertight_corner(ray, w, b), cc = watertight_corner(ray, w, c);
  auto in_float = [](const WatertightCorner& p, const WatertightCorner& q) {
    return rounded_product(q.x, p.y) - rounded_product(q.y, p.x);
  };
  float f[3] = {in_float(cb, cc), in_float(cc, ca), in_float(ca, cb)};
  CHECK(std::min({f[0], f[1], f[2]}) < 0.0f);
  CHECK(std::max({f[0], f[1], f[2]}) > 0.0f);
  CHECK(std::abs(f[2]) <= watertight_edge_bound(ca, cb));
  double g[3] = {watertight_edge(cb, cc), watertight_edge(cc, ca), watertight_edge(ca, cb)};
  CHECK(((g[0] > 0 && g[1] > 0 && g[2] > 0) || (g[0] < 0 && g[1] < 0 && g[2] < 0)));
  long double exact_weight = abc.e[2] / (abc.e[0] + abc.e[1] + abc.e[2]);
  CHECK(exact_weight == doctest::Approx(2.41e-6).epsilon(0.01));
  CHECK(g[2] / (g[0] + g[1] + g[2]) == doctest::Approx(static_cast<double>(exact_weight)).epsilon(1e-6));

  float t = 0, u = 0, v = 0;
  REQUIRE(intersect_triangle_watertight(ray, a, b, c, t, u, v));
  CHECK(t == doctest::Approx(static_cast<double>(abc.t)).epsilon(1e-6));
  CHECK(v == doctest::Approx(static_cast<double>(abc.e[2] / (abc.e[0] + abc.e[1] + abc.e[2]))).epsilon(1e-3));
  CHECK(intersect_triangle_watertight(ray, d, b, a, t, u, v));

  // And through the BVH, whose SIMD kernels filter the lanes for the fallback.
  Mesh mesh;
  mesh.positions = {a, b, c, d};
  mesh.indices = {0, 1, 2, 3, 1, 0};
  mesh.material = {0, 0};
  Geometry scene(std::move(mesh), {});
  auto bvh = make_bvh_accel(scene, TriangleTest::kWatertight);
  auto hit = bvh->intersect(ray);
  REQUIRE(hit);
  CHECK(hit->t == doctest::Approx(static_cast<double>(abc.t)).epsilon(1e-6));
  CHECK(bvh->occluded(ray));
}

TEST_CASE("watertight fallback: rays at a dense mesh's silhouette edges, on the studio ground") {
  // The displaced benchmark mesh (20k triangles, folds everywhere) on the default studio's ground,
  // seen from 3 to 40 radii away. Rays aimed at points on silhouette edges (the two triangles
  // facing opposite ways from the ray's origin), rounded to float, pass within an ulp or two of
  // the edge: the long double edge functions decide whether the ray enters either triangle, and
  // wherever it does, the BVH must hit that triangle, the other one, or something no farther (t is
  // compared to 1e-4: at the grazing angles of a silhouette the float t of a hit is only so good).
  SceneBuilder sb;
  add_displaced_icosphere(sb.mesh, 5, Vec3f(0.3f, 1.2f, -0.4f), 0.8f, 0.25f, sb.default_material());
  size_t model = sb.mesh.triangle_count();
  add_studio(sb, Studio::kSun, UpAxis::kY);
  Geometry scene(std::move(sb.mesh), {});
  const Mesh& mesh = scene.mesh();
  auto bvh = make_bvh_accel(scene, TriangleTest::kWatertight);

  // Each model edge once, with its two triangles.
  struct Edge {
    uint32_t p, q, t0, t1;
  };
  std::vector<Edge> edges;
  {
    std::vector<std::tuple<uint32_t, uint32_t, uint32_t>> half;
    for (uint32_t t = 0; t < model; ++t)
      for (int k = 0; k < 3; ++k) {
        uint32_t p = mesh.indices[3 * t + k], q = mesh.indices[3 * t + (k + 1) % 3];
        half.emplace_back(std::min(p, q), std::max(p, q), t);
      }
    std::sort(half.begin(), half.end());
    for (size_t i = 0; i + 1 < half.size(); ++i)
      if (std::get<0>(half[i]) == std::get<0>(half[i + 1]) && std::get<1>(half[i]) == std::get<1>(half[i + 1]))
        edges.push_back({std::get<0>(half[i]), std::get<1>(half[i]), std::get<2>(half[i]), std::get<2>(half[i + 1])});
  }
  REQUIRE(edges.size() > model);

  Pcg32 rng(41, 41);
  size_t rays = 0, inside = 0, misses = 0, farther = 0;
  for (int view = 0; view < 64; ++view) {
    // A camera position above the ground, 3-40 radii from the model's centre.
    float phi = 2 * kPi * rng.next_float(), h = 0.05f + 0.9f * rng.next_float(), dist = 2.4f + 30.0f * rng.next_float();
    Vec3f eye = Vec3f(0.3f, 1.2f, -0.4f) +
                Vec3f(std::cos(phi) * std::sqrt(1 - h * h), h, std::sin(phi) * std::sqrt(1 - h * h)) * dist;
    for (const Edge& e : edges) {
      Vec3f p = mesh.positions[e.p], q = mesh.positions[e.q];
      Vec3f n0 = mesh.geometric_normal(e.t0), n1 = mesh.geometric_normal(e.t1);
      if ((dot(n0, p - eye) > 0) == (dot(n1, p - eye) > 0)) continue;  // not a silhouette from here
      for (int k = 0; k < 4; ++k) {
        Ray ray;
        ray.o = eye;
        ray.d = normalize(p + (q - p) * rng.next_float() - eye);
        ++rays;
        Reference r0 = reference(ray, mesh.vertex(e.t0, 0), mesh.vertex(e.t0, 1), mesh.vertex(e.t0, 2));
        Reference r1 = reference(ray, mesh.vertex(e.t1, 0), mesh.vertex(e.t1, 1), mesh.vertex(e.t1, 2));
        long double t_ref = kInf;
        if (r0.inside && r0.t > 0) t_ref = std::min(t_ref, r0.t);
        if (r1.inside && r1.t > 0) t_ref = std::min(t_ref, r1.t);
        if (t_ref == kInf) continue;
        ++inside;
        auto hit = bvh->intersect(ray);
        if (!hit || !bvh->occluded(ray)) {
          ++misses;
        } else if (hit->prim != e.t0 && hit->prim != e.t1 && hit->t > t_ref * (1 + 1e-4L)) {
          ++farther;
        }
      }
    }
  }
  std::printf("silhouette edges: %zu rays, %zu inside a silhouette triangle; the bvh missed %zu, hit something farther %zu\n", rays,
              inside, misses, farther);
  CHECK(inside > 10000);
  CHECK(misses == 0);
  CHECK(farther == 0);
}

// WatertightRay picks its axes without branches (a table on three comparisons); the result must be
// the one of the plain form it replaced: z the largest |d| component (ties to the later axis as
// max_axis breaks them), x and y the next ones, swapped where d_z < 0.
TEST_CASE("watertight ray: the axes and shear of the branch-free set-up, on every sign and tie") {
  const float values[] = {0.0f, -0.0f, 0.5f, -0.5f, 1.0f, -1.0f, 0.75f, -2.0f, 1e-30f};
  int checked = 0;
  for (float x : values)
    for (float y : values)
      for (float z : values) {
        Vec3f d{x, y, z};
        Vec3f a = vabs(d);
        if (max_component(a) == 0.0f) continue;
        int kz = max_axis(a);
        int kx = kz == 2 ? 0 : kz + 1;
        int ky = kx == 2 ? 0 : kx + 1;
        if (d[kz] < 0.0f) std::swap(kx, ky);
        WatertightRay w(d);
        CAPTURE(x);
        CAPTURE(y);
        CAPTURE(z);
        CHECK(w.kz == kz);
        CHECK(w.kx == kx);
        CHECK(w.ky == ky);
        CHECK(w.sx == d[kx] / d[kz]);
        CHECK(w.sy == d[ky] / d[kz]);
        CHECK(w.sz == 1.0f / d[kz]);
        ++checked;
      }
  CHECK(checked == 9 * 9 * 9 - 8);  // all but the eight zero vectors
}
