// Per-corner tangents for normal mapping where the file gives none, consistent with MikkTSpace
// (Mikkelsen 2008, "Simulation of Wrinkled Surfaces Revisited"), the convention glTF and Blender
// bake normal maps in: each triangle's tangent is the direction of increasing u (from its uv
// derivatives), projected into the plane of the corner's normal and normalised; corners that share
// position, normal, uv and the triangle's uv orientation share one tangent, the sum of their
// triangles' tangents weighted by the angle at the corner, orthonormalised against the normal; the
// sign is the triangle's uv orientation. Like MikkTSpace's, but not its code: results agree on
// the tangent spaces bakers produce up to float rounding and the treatment of degenerate
// triangles, which here keep the tangent of the corner's group or, alone, any tangent.
#pragma once
#include "core/geometry/mesh.h"

namespace pt {

// Fills mesh.corner_tangents and corner_tangent_signs (3 per triangle). Needs corner_uvs; a mesh
// without them gets tangents from the barycentric parameterisation (consistent, but arbitrary).
void compute_tangents(Mesh& mesh);

}  // namespace pt
