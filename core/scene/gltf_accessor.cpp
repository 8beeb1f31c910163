#include "core/scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/util/error.h"

namespace pt {

size_t component_bytes(int t) {
  switch (t) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;  // INT and DOUBLE are not glTF 2.0 component types
  }
}

size_t component_count(int t) {
  switch (t) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

int node_light(const tinygltf::Node& node) {
  auto it = node.extensions.find("KHR_lights_punctual");
  if (it == node.extensions.end() || !it->second.IsObject() || !it->second.Has("light")) return -1;
  const tinygltf::Value& v = it->second.Get("light");
  return v.IsInt() ? v.Get<int>() : -2;  // -2: present but not an index, refused by the validator
}

double emissive_strength(const tinygltf::Material& material) {
  auto it = material.extensions.find("KHR_materials_emissive_strength");
  if (it == material.extensions.end() || !it->second.IsObject() || !it->second.Has("emissiveStrength")) return 1.0;
  const tinygltf::Value& v = it->second.Get("emissiveStrength");
  return v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
}

double ior_of(const tinygltf::Material& material) {
  auto it = material.extensions.find("KHR_materials_ior");
  if (it == material.extensions.end() || !it->second.IsObject() || !it->second.Has("ior")) return 1.5;
  const tinygltf::Value& v = it->second.Get("ior");
  return v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
}

GltfClearcoat clearcoat_of(const tinygltf::Material& material) {
  GltfClearcoat c;
  auto it = material.extensions.find("KHR_materials_clearcoat");
  if (it == material.extensions.end() || !it->second.IsObject()) return c;
  const tinygltf::Value& v = it->second;
  auto number = [&](const char* key) {
    if (!v.Has(key)) return 0.0;
    return v.Get(key).IsNumber() ? v.Get(key).GetNumberAsDouble() : -1.0;
  };
  c.factor = number("clearcoatFactor");
  c.roughness = number("clearcoatRoughnessFactor");
  c.textured = v.Has("clearcoatTexture") || v.Has("clearcoatRoughnessTexture") || v.Has("clearcoatNormalTexture");
  return c;
}

GltfTransmission transmission_of(const tinygltf::Material& material) {
  GltfTransmission t;
  auto it = material.extensions.find("KHR_materials_transmission");
  if (it == material.extensions.end() || !it->second.IsObject()) return t;
  const tinygltf::Value& v = it->second;
  if (v.Has("transmissionFactor")) {
    t.factor = v.Get("transmissionFactor").IsNumber() ? v.Get("transmissionFactor").GetNumberAsDouble() : -1.0;
  }
  t.textured = v.Has("transmissionTexture");
  return t;
}

std::string texture_transform(const tinygltf::ExtensionMap& extensions, UvTransform& transform, int& texcoord) {
  auto it = extensions.find("KHR_texture_transform");
  if (it == extensions.end()) return {};
  const tinygltf::Value& e = it->second;
  if (!e.IsObject()) return ": expected an object";
  auto number = [](const tinygltf::Value& v, float& out) {
    if (!v.IsNumber()) return false;
    double d = v.GetNumberAsDouble();
    out = static_cast<float>(d);
    return std::isfinite(d) && std::isfinite(out);
  };
  auto pair = [&](const char* key, Vec2f& out) -> std::string {
    if (!e.Has(key)) return {};
    const tinygltf::Value& v = e.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 2 || !number(v.Get(0), out.x) || !number(v.Get(1), out.y)) {
      std::string error = "/";
      error += key;
      error += ": expected an array of 2 finite numbers";
      return error;
    }
    return {};
  };
  if (std::string error = pair("offset", transform.offset); !error.empty()) return error;
  if (std::string error = pair("scale", transform.scale); !error.empty()) return error;
  if (e.Has("rotation") && !number(e.Get("rotation"), transform.rotation)) return "/rotation: expected a finite number";
  if (e.Has("texCoord")) {
    const tinygltf::Value& v = e.Get("texCoord");
    if (!v.IsInt() || v.Get<int>() < 0) return "/texCoord: expected a non-negative integer";
    texcoord = v.Get<int>();
  }
  return {};
}

namespace {

// One component at `p` as a float: the value, or normalised (glTF 2.0 section 3.11, "Animation":
// the same conversions as for attributes: c / 127 clamped to -1 for bytes, c / 32767 for shorts).
float component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      float c = static_cast<float>(static_cast<int8_t>(*p));
      return normalized ? std::max(c / 127.0f, -1.0f) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? *p / 255.0f : *p;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? static_cast<float>(v / 4294967295.0) : static_cast<float>(v);
    }
    default: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
  }
}

// The accessor's bytes: the first element and the step between elements (the validator has
// checked that every element lies inside the buffer view). nullptr: no buffer view (all zeros).
const unsigned char* first_element(const GltfFile& file, const tinygltf::Accessor& a, const std::string& where, size_t& stride) {
  if (a.sparse.isSparse) throw Error(file.path, where + "/sparse: sparse accessors are not supported");
  stride = element_bytes(a);
  if (a.bufferView < 0) return nullptr;
  const tinygltf::BufferView& view = file.model.bufferViews[a.bufferView];
  if (view.byteStride) stride = view.byteStride;
  return file.model.buffers[view.buffer].data.data() + view.byteOffset + a.byteOffset;
}

}  // namespace

std::vector<float> read_floats(const GltfFile& file, int index, const std::string& name, std::vector<int> allowed, int components) {
  const tinygltf::Accessor& a = file.model.accessors[index];
  std::string where = "/accessors/" + std::to_string(index);
  int n = static_cast<int>(component_count(a.type));
  if (std::find(allowed.begin(), allowed.end(), n) == allowed.end() || a.type == TINYGLTF_TYPE_MAT2) {
    throw Error(file.path, where + "/type: " + name + " with " + std::to_string(n) + " components per element");
  }
  size_t stride;
  const unsigned char* p = first_element(file, a, where, stride);
  std::vector<float> out(a.count * components, 0.0f);
  size_t cb = component_bytes(a.componentType);
  for (size_t i = 0; i < a.count; ++i) {
    for (int c = 0; c < components; ++c) {
      float v = c < n ? (p ? component(p + i * stride + c * cb, a.componentType, a.normalized) : 0.0f) : 1.0f;
      if (!std::isfinite(v)) {
        throw Error(file.path, where + ": " + name + " element " + std::to_string(i) + " is not a finite number");
      }
      out[i * components + c] = v;
    }
  }
  return out;
}

std::vector<uint32_t> read_indices(const GltfFile& file, int index, size_t vertices) {
  const tinygltf::Accessor& a = file.model.accessors[index];
  std::string where = "/accessors/" + std::to_string(index);
  if (a.type != TINYGLTF_TYPE_SCALAR) throw Error(file.path, where + "/type: indices must be SCALAR");
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    throw Error(file.path, where + "/componentType: indices must be unsigned integers");
  }
  size_t stride;
  const unsigned char* p = first_element(file, a, where, stride);
  std::vector<uint32_t> out(a.count, 0);
  for (size_t i = 0; i < a.count; ++i) {
    uint32_t v = p ? static_cast<uint32_t>(component(p + i * stride, a.componentType, false)) : 0;
    if (p && a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) std::memcpy(&v, p + i * stride, 4);  // exact past 2^24
    if (v >= vertices) {
      throw Error(file.path, where + ": index " + std::to_string(v) + " (element " + std::to_string(i) + ") but the primitive has " +
                                 std::to_string(vertices) + " vertices");
    }
    out[i] = v;
  }
  return out;
}

}  // namespace pt
