// Reading glTF accessors into plain arrays, checked as they are read: the layout the specification
// allows for each attribute, finite values, and indices within the vertices. Messages name the
// file and the JSON pointer of the accessor. Also small facts about a model shared by the
// validator and the loader.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/material/texture_binding.h"
#include "core/scene/gltf_file.h"

namespace pt {

// Bytes of one component (0 for an unknown component type) and components of one element (0 for
// an unknown type); element_bytes is their product.
size_t component_bytes(int component_type);
size_t component_count(int type);
inline size_t element_bytes(const tinygltf::Accessor& a) { return component_bytes(a.componentType) * component_count(a.type); }

// The light a node carries (KHR_lights_punctual), or -1.
int node_light(const tinygltf::Node& node);
// KHR_materials_emissive_strength's emissiveStrength, or 1.
double emissive_strength(const tinygltf::Material& material);
// KHR_materials_clearcoat's factors (0 where absent; -1 where not a number) and whether it names
// any of its textures (clearcoatTexture, clearcoatRoughnessTexture, clearcoatNormalTexture).
struct GltfClearcoat {
  double factor = 0, roughness = 0;
  bool textured = false;
};
GltfClearcoat clearcoat_of(const tinygltf::Material& material);
// KHR_materials_transmission's transmissionFactor (0 where absent; -1 where not a number) and
// whether it names a transmissionTexture.
struct GltfTransmission {
  double factor = 0;
  bool textured = false;
};
GltfTransmission transmission_of(const tinygltf::Material& material);
// KHR_materials_ior's ior (1.5 where absent; -1 where not a number).
double ior_of(const tinygltf::Material& material);
// A texture reference's KHR_texture_transform (offset, rotation, scale; texCoord where it
// overrides the reference's), or the identity. Returns an error: the key under the extension that
// is malformed (as "offset: expected ..."), or empty.
std::string texture_transform(const tinygltf::ExtensionMap& extensions, UvTransform& transform, int& texcoord);

// Accessor `index` as floats, `components` per element, for an attribute `name` (used in
// messages). Integer components are read as the specification says for the attribute:
// normalised to [0, 1] or [-1, 1] where `normalized` is set, else as their values
// (KHR_mesh_quantization). `allowed` lists the accepted element sizes (e.g. {3, 4} for COLOR_0;
// 3-component colours get alpha 1 when 4 are asked for).
std::vector<float> read_floats(const GltfFile& file, int index, const std::string& name, std::vector<int> allowed, int components);

// Vertex indices of a primitive, each checked to be below `vertices`.
std::vector<uint32_t> read_indices(const GltfFile& file, int index, size_t vertices);

}  // namespace pt
