// Writing a generated mesh as an OBJ (vertices and faces only), shared by the `pt gen` meshes.
#pragma once
#include <string>

#include "core/geometry/mesh.h"

namespace pt {

// Writes through OutputFile (core/util/output_file.h): complete or not at all, only a regular file
// replaced, no temporary left. `comment` becomes the first line. Throws pt::Error naming `path`.
void write_mesh_obj(const std::string& path, const Mesh& mesh, const std::string& comment);

}  // namespace pt
