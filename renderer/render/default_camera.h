// The camera for a scene that names none: frame the bounds from the side that sees the most of
// the model (an open box from its open side, a closed model from the front, +z).
#pragma once
#include "core/accel/accel.h"
#include "core/scene/camera.h"
#include "core/scene/scene.h"
#include "core/scene/up_axis.h"

namespace pt {

// Tries a few directions around the model and keeps the one whose view rays travel farthest
// before they hit something: that side looks into the model rather than at its back. Ties (a
// closed, convex-ish model) keep the front: +z, or -y when +z is up. `aspect` is the image's
// width / height, `vfov` the vertical field of view in degrees.
// The studio's ground (Scene::studio) is looked past.
Camera choose_default_camera(const Scene& scene, const Accel& accel, float aspect, UpAxis up = UpAxis::kY,
                             float vfov = 40.0f);
// The same for geometry that is not a scene yet (the render job chooses the camera before it
// arranges the default lighting for it); triangles from `ignore_from_triangle` on are looked past.
// Throws pt::Error naming `source` when the camera would stand beyond kMaxCameraCoordinate.
Camera choose_default_camera(const std::string& source, const BBox& bounds, const Accel& accel, float aspect, UpAxis up, float vfov,
                             size_t ignore_from_triangle = SIZE_MAX);

}  // namespace pt
