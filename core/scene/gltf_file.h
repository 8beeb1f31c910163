// A glTF 2.0 file (.gltf with external or data-URI buffers, or .glb) as read and checked, before it
// becomes part of a scene: the parse by tinygltf (Debian's libtinygltf-dev) and the JSON it came
// from. Shared by gltf_read.cpp (reading), gltf_validate.cpp (checks) and gltf_loader.cpp (the
// scene); the rest of pt sees only load_gltf() in loader.h.
#pragma once
#include <tiny_gltf.h>

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace pt {

// The largest .gltf/.glb file and the largest buffer or image file one may name (scenes/README.md).
constexpr uint64_t kMaxGltfBytes = uint64_t(2) << 30;

struct GltfFile {
  std::string path;
  tinygltf::Model model;
  std::vector<std::string> inputs;  // every file read: the glTF, its buffers and images
  // Encoded images held inside the file (a data URI or a buffer view), by image index; images
  // in files of their own are read by path (texture_index in loader.h).
  std::map<int, std::vector<unsigned char>> embedded_images;
  std::vector<std::string> notes;
  // The indices accessors of Draco-compressed primitives, by (mesh, primitive): taken out of the
  // JSON before tinygltf parses it (tinygltf refuses indices without a buffer view, which is what
  // a Draco primitive's are) and put back by decode_draco (gltf_draco.h).
  std::map<std::pair<size_t, size_t>, uint64_t> draco_indices;
};

// Reads `path`, checks what tinygltf would read unchecked (buffer and image files, buffer views
// that images use, required extensions) and parses it. Every file goes through
// core/util/input_file.h. Throws pt::Error naming the file and a JSON pointer.
GltfFile read_gltf(const std::string& path);

// Checks the parsed model before anything is taken from it: accessors within their buffer views,
// indices within the vertices, node trees without cycles or shared nodes, finite numbers, valid
// references. Throws pt::Error naming the file and a JSON pointer (`/accessors/3/count`).
void validate_gltf(const GltfFile& file);

// The file a URI names, relative to the glTF file's folder, percent-escapes decoded as tinygltf
// decodes them (RFC 3986).
std::string gltf_uri_path(const std::string& gltf_path, const std::string& uri);

// A binary glTF (GLB, glTF 2.0 section 4.4): the header, the JSON chunk (padded with spaces) and,
// where has_bin, the BIN chunk (padded with zeros).
std::string glb_container(std::string json, std::string_view bin, bool has_bin = true);

// Extensions pt understands, and what it does with each.
bool gltf_extension_supported(const std::string& name);

}  // namespace pt
