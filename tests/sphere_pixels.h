// Pixels whose footprint lies wholly on one sphere: all four corner rays of the pixel hit it (the
// image of a sphere is convex), so a closed-form answer for the sphere holds over the whole pixel.
#pragma once
#include <utility>
#include <vector>

#include "core/geometry/intersect.h"
#include "core/scene/camera.h"
#include "core/scene/scene.h"

inline std::vector<std::pair<int, int>> pixels_on_sphere(const pt::Scene& scene, size_t index, int w, int h) {
  const pt::Sphere& s = scene.spheres()[index];
  pt::Camera::Basis basis = scene.camera()->basis(float(w) / h);
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool all = true;
      for (int c = 0; c < 4; ++c) {
        pt::Ray ray = pt::Camera::ray(basis, {float(x + (c & 1)) / w, float(y + (c >> 1)) / h});
        float t;
        all = all && pt::intersect_sphere(ray, s.center, s.radius, t);
      }
      if (all) out.emplace_back(x, y);
    }
  }
  return out;
}
