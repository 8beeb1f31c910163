// A procedural benchmark mesh: a subdivided icosahedron projected to a sphere and displaced along
// the radius by a smooth sum of sines, so it is dense, closed and irregular enough that a BVH
// cannot exploit a grid. Used by `pt gen dense` (which writes it as an OBJ) and directly by tests.
#pragma once
#include <cstdint>
#include <string>

#include "core/geometry/mesh.h"

namespace pt {

// Appends 20 * 4^level triangles (level 8: 1,310,720) around `center`. Vertices are shared between
// neighbouring triangles (each edge midpoint is created once), so the surface has no cracks.
// amplitude 0 gives the plain icosphere.
void add_displaced_icosphere(Mesh& mesh, int level, const Vec3f& center, float radius, float amplitude,
                             uint32_t material);

// Writes the displaced icosphere of `level` as an OBJ (vertices and faces only) to `path`.
void write_dense_obj(const std::string& path, int level);

}  // namespace pt
