// Geometry and ray sets shared by the BVH tests: built in memory so the tests need no generated files.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <vector>

#include "core/accel/accel.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "core/geometry/geometry.h"
#include "renderer/tools/gen_dense.h"
#include "renderer/tools/gen_scan.h"

namespace pt::test {

// A closed icosphere (amplitude 0) or the displaced benchmark mesh, alone.
inline Geometry icosphere_geometry(int level, float amplitude) {
  Mesh mesh;
  add_displaced_icosphere(mesh, level, Vec3f(0.0f), 1.0f, amplitude, 0);
  return Geometry(std::move(mesh), {});
}

// The closed room of scenes/dense and scenes/scan (6 x 4.3 x 6, faces inward), appended to `mesh`.
inline void add_room(Mesh& mesh, uint32_t material) {
  const Vec3f lo(-3.0f, -1.3f, -3.0f), hi(3.0f, 3.0f, 3.0f);
  uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  for (int i = 0; i < 8; ++i) mesh.positions.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  // Two triangles per face, corners by bit pattern (x = 1, y = 2, z = 4).
  const uint32_t faces[6][4] = {{0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh.indices.insert(mesh.indices.end(), {base + f[0], base + f[1], base + f[2], base + f[0], base + f[2], base + f[3]});
    mesh.material.insert(mesh.material.end(), 2, material);
  }
}

// The scan-like mesh (gen_scan.h) at a lower resolution, inside the closed room.
inline Geometry scan_geometry(int views, int resolution) {
  Mesh mesh;
  add_room(mesh, 0);
  ScanOptions options;
  options.views = views;
  options.resolution = resolution;
  add_scan_mesh(mesh, options, 0);
  return Geometry(std::move(mesh), {});
}

// Random triangles of random sizes in the unit cube: heavy overlap, slivers and long triangles.
inline Geometry triangle_soup(size_t count, uint64_t seed, size_t spheres = 0) {
  const uint32_t m = 0;
  Mesh mesh;
  std::vector<Sphere> balls;
  Pcg32 rng(seed, 7);
  auto uniform = [&] { return Vec3f(rng.next_float(), rng.next_float(), rng.next_float()); };
  for (size_t i = 0; i < count; ++i) {
    Vec3f c = uniform();
    float size = 0.002f + 0.1f * rng.next_float() * rng.next_float() * rng.next_float();
    for (int k = 0; k < 3; ++k) {
      mesh.indices.push_back(static_cast<uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(c + (uniform() - Vec3f(0.5f)) * size);
    }
    mesh.material.push_back(m);
  }
  for (size_t i = 0; i < spheres; ++i) {
    Sphere s;
    s.center = uniform();
    s.radius = 0.005f + 0.05f * rng.next_float();
    s.material = m;
    balls.push_back(s);
  }
  return Geometry(std::move(mesh), std::move(balls));
}

// Rays with origins in the scene's bounds enlarged by half their size and uniform directions;
// every fourth has a finite tmax so that occlusion queries end inside the geometry.
inline std::vector<Ray> random_rays(const Geometry& geometry, size_t n, uint64_t seed) {
  BBox b = geometry.bounds();
  Vec3f lo = b.lo - b.extent() * 0.5f, size = b.extent() * 2.0f;
  float diag = length(b.extent());
  std::vector<Ray> rays(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      Pcg32 rng(hash_combine(seed, i), 3);
      Ray ray;
      ray.o = lo + Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * size;
      ray.d = square_to_uniform_sphere(Vec2f(rng.next_float(), rng.next_float()));
      if (i % 4 == 3) ray.tmax = diag * rng.next_float();
      rays[i] = ray;
    }
  });
  return rays;
}

}  // namespace pt::test
