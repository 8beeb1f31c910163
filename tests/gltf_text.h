// Small glTF 2.0 files for tests, written with nlohmann-json: a buffer built from typed arrays
// (as a data URI, a .bin file or a GLB's BIN chunk) and helpers to add accessors.
#pragma once
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

struct GltfText {
  nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};
  std::string bin;

  static std::string base64(const std::string& in) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
      uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
      for (int s = 18; s >= 0; s -= 6) out += k[(v >> s) & 63];
    }
    if (i + 1 == in.size()) {
      uint32_t v = uint8_t(in[i]) << 16;
      out += k[(v >> 18) & 63];
      out += k[(v >> 12) & 63];
      out += "==";
    } else if (i + 2 == in.size()) {
      uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
      out += k[(v >> 18) & 63];
      out += k[(v >> 12) & 63];
      out += k[(v >> 6) & 63];
      out += '=';
    }
    return out;
  }

  // Appends `values` to the buffer (4-byte aligned) as a buffer view and an accessor; returns the
  // accessor's index.
  template <class T>
  int accessor(const std::vector<T>& values, const char* type, int component_type, size_t components) {
    while (bin.size() % 4) bin += '\0';
    size_t offset = bin.size();
    bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                {"componentType", component_type},
                                {"count", values.size() / components},
                                {"type", type}});
    return static_cast<int>(doc["accessors"].size() - 1);
  }
  int vec3(const std::vector<float>& v) { return accessor(v, "VEC3", 5126, 3); }
  int vec2(const std::vector<float>& v) { return accessor(v, "VEC2", 5126, 2); }
  int indices(const std::vector<uint16_t>& v) { return accessor(v, "SCALAR", 5123, 1); }

  // The buffer as a data URI (a .gltf with everything inside).
  std::string gltf() const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    return d.dump(1);
  }
  // The buffer as a file of its own, named `uri`.
  std::string gltf_external(const std::string& uri) const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}, {"uri", uri}}};
    return d.dump(1);
  }
  // A GLB: header, JSON chunk, BIN chunk.
  std::string glb() const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}}};
    std::string json = d.dump();
    while (json.size() % 4) json += ' ';
    std::string body = bin;
    while (body.size() % 4) body += '\0';
    std::string out;
    auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    u32(0x46546C67);
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + body.size()));
    u32(static_cast<uint32_t>(json.size()));
    u32(0x4E4F534A);
    out += json;
    u32(static_cast<uint32_t>(body.size()));
    u32(0x004E4942);
    out += body;
    return out;
  }
};

// A unit square in the y = 0 plane, front face up, as one mesh with normals and uvs; returns the
// mesh index. `material` < 0: none.
inline int add_square(GltfText& g, int material = -1, int mode = 4) {
  int pos = g.vec3({0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1});
  int nrm = g.vec3({0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0});
  int uv = g.vec2({0, 1, 1, 1, 1, 0, 0, 0});
  int idx = g.indices({0, 1, 2, 0, 2, 3});
  nlohmann::json prim = {{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", uv}}}, {"indices", idx}, {"mode", mode}};
  if (material >= 0) prim["material"] = material;
  g.doc["meshes"].push_back({{"primitives", nlohmann::json::array({prim})}});
  return static_cast<int>(g.doc["meshes"].size() - 1);
}
