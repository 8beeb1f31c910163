// Writing a generated mesh as an OBJ (vertices and faces only), shared by the `pt gen` meshes.
#pragma once
#include <string>

#include "core/geometry/mesh.h"

namespace pt {

// Writes to a temporary file renamed to `path` when complete; `comment` becomes the first line.
void write_mesh_obj(const std::string& path, const Mesh& mesh, const std::string& comment);

}  // namespace pt
