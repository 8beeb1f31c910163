#include "renderer/render/default_camera.h"

#include <cstdio>

#include "core/util/error.h"

namespace pt {

Camera choose_default_camera(const Scene& scene, const Accel& accel, float aspect, UpAxis up, float vfov) {
  size_t ignore_from = scene.studio() ? scene.studio()->first_triangle : SIZE_MAX;
  return choose_default_camera(scene.source(), scene.bounds(), accel, aspect, up, vfov, ignore_from);
}

Camera choose_default_camera(const std::string& source, const BBox& bounds, const Accel& accel, float aspect, UpAxis up, float vfov,
                             size_t ignore_from_triangle) {
  // The front first so that it wins ties; then the other sides and the diagonals, all a little
  // above (written for +y up and turned to the scene's up axis).
  const Vec3f directions[] = {{0, 0.25f, 1}, {0, 0.25f, -1}, {1, 0.25f, 0}, {-1, 0.25f, 0},
                              {1, 0.35f, 1}, {-1, 0.35f, 1}, {1, 0.35f, -1}, {-1, 0.35f, -1}};
  Camera best;
  float best_score = -1.0f;
  for (const Vec3f& d : directions) {
    Camera c = Camera::framing(bounds, aspect, normalize(from_y_up(up, d)), up_vector(up), vfov);
    if (!within_extent(c.position, kMaxCameraCoordinate)) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "framing the scene at aspect ratio %g and a %g degree field of view puts the camera beyond +-%g, "
                    "where rays cannot be traced; give a camera, a wider --fov or a less extreme --res", aspect,
                    static_cast<double>(vfov), static_cast<double>(kMaxCameraCoordinate));
      throw Error(source, buf);
    }
    Camera::Basis basis = c.basis(aspect);
    float distance = length(c.position - c.look_at);
    constexpr int kGrid = 16;
    float score = 0.0f;
    for (int y = 0; y < kGrid; ++y) {
      for (int x = 0; x < kGrid; ++x) {
        Ray ray = Camera::ray(basis, {(x + 0.5f) / kGrid, (y + 0.5f) / kGrid});
        std::optional<Hit> hit = accel.intersect(ray);
        bool ignored = hit && hit->geom == kGeomTriangles && hit->inst == kNoInstance && hit->prim >= ignore_from_triangle;
        if (hit && !ignored) score += hit->t / distance;
      }
    }
    score /= kGrid * kGrid;
    if (score > best_score * 1.05f) {
      best_score = score;
      best = c;
    }
  }
  return best;
}

}  // namespace pt
