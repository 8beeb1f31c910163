// Instances: an object-space mesh placed in the world by an affine transform. A mesh placed more
// than once is stored once and traced through its instances (both backends take the ray into the
// mesh's space); a mesh placed once is baked into the world-space mesh (SceneBuilder::resolve_instances).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/ray.h"
#include "core/math/bbox.h"
#include "core/math/transform.h"

namespace pt {

struct Instance {
  uint32_t mesh = 0;     // index into Geometry::meshes()
  Transform to_world;
  Transform to_object;   // to_world's inverse
};

// Why `t` cannot place an object (a non-finite entry, or a linear part that flattens it), or an
// empty string when it can. Loaders check with it first, to name the offending value themselves.
std::string instance_transform_problem(const Transform& t);

// The box holding `box` after `t`: its eight corners transformed, rounded outward by one ulp so that
// rounding in the corners' transform never lets a box cull a ray that hits the mesh.
BBox transform_bounds(const BBox& box, const Transform& t);

// The bounds of `mesh`'s vertices after `t`, each transformed as append_transformed does: the same
// box the mesh baked into the world would have (the default camera and the studio frame it).
BBox transformed_mesh_bounds(const Mesh& mesh, const Transform& t);

// The bounds of every instance of `meshes` (indexed by Instance::mesh) in the world. Exact (each
// vertex transformed: the box of the baked meshes) up to kExactBoundsPoints transformed vertices in
// all; beyond, each instance's box is its mesh's box transformed (transform_bounds), which may be
// loose: the exact box would cost a pass over every vertex of every instance.
constexpr size_t kExactBoundsPoints = size_t(1) << 25;
BBox instances_bounds(const std::vector<const Mesh*>& meshes, const std::vector<Instance>& instances);

// Appends `object` after `t` to `world`: positions and normals transformed (normals by the inverse
// transpose, renormalised), the winding reversed where `t` mirrors so front faces stay front.
void append_transformed(Mesh& world, const Mesh& object, const Transform& t);

}  // namespace pt
