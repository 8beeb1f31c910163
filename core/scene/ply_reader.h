// PLY (the Stanford polygon file format, G. Turk 1994) read into triangles: ASCII and binary of
// either byte order. pt reads PLY with its own small reader rather than a library: Debian's only
// PLY reader is assimp's, a large dependency for one format, and its importer neither checks what
// pt must check (counts against the file's size, indices, non-finite values) nor reports errors
// with the file and line or element. ply_reader.cpp holds the parser; load_ply() (ply_loader.cpp)
// puts the result into a scene.
#pragma once
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/math/vec.h"

namespace pt {

// The largest PLY file read (documented in scenes/README.md): the file is read whole.
constexpr uint64_t kMaxPlyBytes = uint64_t(2) << 30;

struct PlyMesh {
  std::string format;             // "ascii", "binary_little_endian" or "binary_big_endian"
  std::vector<Vec3f> positions;   // one per vertex
  std::vector<Vec3f> normals;     // one per vertex, or empty
  std::vector<Vec2f> uvs;         // one per vertex, or empty
  std::vector<Spectrum> colors;   // one per vertex (linear RGB), or empty
  std::vector<uint32_t> triangles;  // 3 vertex indices per triangle, in the file's winding
  uint64_t faces = 0;             // polygons read from face lists
  uint64_t strips = 0;            // triangle strips read
  std::set<std::string> ignored;  // "element.property" (or "element") read and not used
};

// Parses the bytes of a PLY file; errors name `path` and the line (ASCII) or the element and its
// index (binary).
PlyMesh parse_ply(const std::string& path, std::string_view bytes);
// Reads and parses `path` (a regular file of at most kMaxPlyBytes).
PlyMesh read_ply(const std::string& path);

}  // namespace pt
