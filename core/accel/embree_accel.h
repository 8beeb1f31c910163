// Embree 3 backend: one triangle geometry sharing the scene's buffers, spheres as user geometry, and
// an instance geometry per instance over a scene of its own per instanced mesh.
#pragma once
#include "core/accel/accel.h"

namespace pt {

std::unique_ptr<Accel> make_embree_accel(const Geometry& geometry, bool robust);

}  // namespace pt
