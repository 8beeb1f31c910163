// Embree 3 backend: one triangle geometry sharing the scene's buffers, and spheres as user geometry.
#pragma once
#include "core/accel/accel.h"

namespace pt {

std::unique_ptr<Accel> make_embree_accel(const Geometry& geometry, bool robust);

}  // namespace pt
