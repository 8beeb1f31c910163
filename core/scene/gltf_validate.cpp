// Structural checks of a parsed glTF model, before any of it is used: every reference in range,
// every accessor inside its buffer view, node trees that are trees, finite transforms, cameras and
// lights. What can only be checked while reading values (non-finite attributes, indices beyond the
// vertices, attribute counts that disagree) is checked in gltf_accessor.cpp as they are read.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/scene/gltf_accessor.h"
#include "core/scene/gltf_file.h"
#include "core/scene/input_limits.h"
#include "core/util/error.h"

namespace pt {
namespace {

struct Checker {
  const GltfFile& file;
  const tinygltf::Model& m;

  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    throw Error(file.path, where + ": " + message);
  }
  template <class T>
  void index(int i, const std::vector<T>& list, const std::string& where, bool optional = true) const {
    if ((optional && i == -1) || (i >= 0 && static_cast<size_t>(i) < list.size())) return;
    fail(where, "refers to " + std::to_string(i) + ", but there are " + std::to_string(list.size()));
  }
  void finite(const std::vector<double>& v, const std::string& where, size_t n0, size_t n1 = SIZE_MAX) const {
    if (v.size() != n0 && v.size() != n1) {
      fail(where, "expected " + std::to_string(n0) + (n1 != SIZE_MAX ? " or " + std::to_string(n1) : "") + " numbers");
    }
    for (size_t k = 0; k < v.size(); ++k) {
      if (!std::isfinite(v[k]) || std::abs(v[k]) > 3.0e38) fail(where + "/" + std::to_string(k), "not a finite number");
    }
  }

  void accessors() const {
    // An accessor without a buffer view is zeros (sparse accessors are refused): its count is all
    // there is of it in the file, so it is bounded by what the file's buffers hold (at least 1 MiB).
    size_t buffers = 0;
    for (const tinygltf::Buffer& b : m.buffers) buffers += b.data.size();
    const size_t zeros_limit = std::max<size_t>(size_t{1} << 20, buffers);
    for (size_t i = 0; i < m.accessors.size(); ++i) {
      const tinygltf::Accessor& a = m.accessors[i];
      std::string where = "/accessors/" + std::to_string(i);
      if (component_bytes(a.componentType) == 0) fail(where + "/componentType", "unknown component type " + std::to_string(a.componentType));
      if (component_count(a.type) == 0) fail(where + "/type", "unknown accessor type");
      if (a.count == 0) fail(where + "/count", "must be at least 1");
      index(a.bufferView, m.bufferViews, where + "/bufferView");
      if (a.bufferView < 0) {
        if (static_cast<unsigned __int128>(a.count) * element_bytes(a) > zeros_limit) {
          fail(where + "/count", std::to_string(a.count) + " elements without a bufferView (zeros) would take more than the " +
                                     std::to_string(zeros_limit) + " bytes the file's buffers allow");
        }
        continue;
      }
      const tinygltf::BufferView& view = m.bufferViews[a.bufferView];
      size_t element = element_bytes(a);
      size_t stride = view.byteStride ? view.byteStride : element;
      if (view.byteStride && (view.byteStride < element || view.byteStride > 252 || view.byteStride % 4 != 0)) {
        fail("/bufferViews/" + std::to_string(a.bufferView) + "/byteStride",
             std::to_string(view.byteStride) + " (a multiple of 4 from 4 to 252, at least the element's " +
                 std::to_string(element) + " bytes)");
      }
      // a.count >= 1; the last element ends at offset + stride * (count - 1) + element.
      unsigned __int128 end = static_cast<unsigned __int128>(a.byteOffset) + static_cast<unsigned __int128>(stride) * (a.count - 1) + element;
      if (end > view.byteLength) {
        fail(where + "/count", std::to_string(a.count) + " elements of " + std::to_string(element) + " bytes from byte " +
                                   std::to_string(a.byteOffset) + " run past the end of buffer view " +
                                   std::to_string(a.bufferView) + " (" + std::to_string(view.byteLength) + " bytes)");
      }
    }
    for (size_t i = 0; i < m.bufferViews.size(); ++i) {
      const tinygltf::BufferView& v = m.bufferViews[i];
      index(v.buffer, m.buffers, "/bufferViews/" + std::to_string(i) + "/buffer", false);
      const tinygltf::Buffer& b = m.buffers[v.buffer];
      if (v.byteOffset > b.data.size() || v.byteLength > b.data.size() - v.byteOffset) {
        fail("/bufferViews/" + std::to_string(i) + "/byteLength", "runs past the end of buffer " + std::to_string(v.buffer));
      }
    }
  }

  // Every node has at most one parent and no node is its own ancestor; a scene's nodes are roots.
  void nodes() const {
    std::vector<int> parent(m.nodes.size(), -1);
    for (size_t i = 0; i < m.nodes.size(); ++i) {
      const tinygltf::Node& n = m.nodes[i];
      std::string where = "/nodes/" + std::to_string(i);
      for (size_t k = 0; k < n.children.size(); ++k) {
        std::string at = where + "/children/" + std::to_string(k);
        int c = n.children[k];
        index(c, m.nodes, at, false);
        if (c == static_cast<int>(i)) fail(at, "node " + std::to_string(i) + " is its own child (a cycle)");
        if (parent[c] >= 0) {
          fail(at, "node " + std::to_string(c) + " already has parent " + std::to_string(parent[c]) +
                       " (node trees must not share nodes; reuse a mesh instead)");
        }
        parent[c] = static_cast<int>(i);
      }
      index(n.mesh, m.meshes, where + "/mesh");
      index(n.camera, m.cameras, where + "/camera");
      if (!n.matrix.empty()) {
        finite(n.matrix, where + "/matrix", 16);
        // Column-major: the bottom row is elements 3, 7, 11 and 15 (glTF 2.0, 3.5.2); a writer's
        // rounding there (1e-6) is let through, and the affine part used.
        if (std::abs(n.matrix[3]) > 1e-6 || std::abs(n.matrix[7]) > 1e-6 || std::abs(n.matrix[11]) > 1e-6 ||
            std::abs(n.matrix[15] - 1) > 1e-6) {
          fail(where + "/matrix", "not an affine transform (its bottom row must be 0 0 0 1)");
        }
      }
      if (!n.translation.empty()) finite(n.translation, where + "/translation", 3);
      if (!n.scale.empty()) finite(n.scale, where + "/scale", 3);
      if (!n.rotation.empty()) {
        finite(n.rotation, where + "/rotation", 4);
        double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] + n.rotation[2] * n.rotation[2] +
                               n.rotation[3] * n.rotation[3]);
        if (!(len > 1e-6)) fail(where + "/rotation", "a zero quaternion is no rotation");
      }
      int light = node_light(n);
      if (light != -1) index(light, m.lights, where + "/extensions/KHR_lights_punctual/light", false);
    }
    // With one parent each, a cycle is a chain of parents that never reaches a root. Each node's
    // chain is walked until it meets a node already known to reach one, so every node is walked
    // once (a chain of 100,000 nodes took 10 s walked from each of them).
    enum : uint8_t { kUnknown, kOnWalk, kRooted };
    std::vector<uint8_t> state(m.nodes.size(), kUnknown);
    std::vector<int> walk;
    for (size_t i = 0; i < m.nodes.size(); ++i) {
      walk.clear();
      int p = static_cast<int>(i);
      while (p >= 0 && state[p] == kUnknown) {
        state[p] = kOnWalk;
        walk.push_back(p);
        p = parent[p];
      }
      if (p >= 0 && state[p] == kOnWalk) fail("/nodes/" + std::to_string(p), "is its own ancestor (the node tree has a cycle)");
      for (int w : walk) state[w] = kRooted;
    }
    if (m.defaultScene >= static_cast<int>(m.scenes.size())) {
      fail("/scene", "refers to scene " + std::to_string(m.defaultScene) + ", but there are " + std::to_string(m.scenes.size()));
    }
    for (size_t s = 0; s < m.scenes.size(); ++s) {
      std::vector<bool> seen(m.nodes.size(), false);
      for (size_t k = 0; k < m.scenes[s].nodes.size(); ++k) {
        std::string at = "/scenes/" + std::to_string(s) + "/nodes/" + std::to_string(k);
        int n = m.scenes[s].nodes[k];
        index(n, m.nodes, at, false);
        if (parent[n] >= 0) fail(at, "node " + std::to_string(n) + " is a child of node " + std::to_string(parent[n]) + ", not a root");
        if (seen[n]) fail(at, "node " + std::to_string(n) + " is listed twice");
        seen[n] = true;
      }
    }
  }

  void meshes() const {
    const bool quantized = std::find(m.extensionsUsed.begin(), m.extensionsUsed.end(), "KHR_mesh_quantization") != m.extensionsUsed.end();
    for (size_t i = 0; i < m.meshes.size(); ++i) {
      std::string where = "/meshes/" + std::to_string(i);
      if (m.meshes[i].primitives.empty()) fail(where + "/primitives", "a mesh needs at least one primitive");
      for (size_t k = 0; k < m.meshes[i].primitives.size(); ++k) {
        const tinygltf::Primitive& p = m.meshes[i].primitives[k];
        std::string at = where + "/primitives/" + std::to_string(k);
        if (p.mode < 0 || p.mode > 6) fail(at + "/mode", "unknown primitive mode " + std::to_string(p.mode));
        for (const auto& [name, accessor] : p.attributes) index(accessor, m.accessors, at + "/attributes/" + name, false);
        index(p.indices, m.accessors, at + "/indices");
        index(p.material, m.materials, at + "/material");
        if (!p.attributes.count("POSITION") && !p.extensions.count("KHR_draco_mesh_compression")) {
          fail(at + "/attributes", "no POSITION");
        }
        // Integer positions are KHR_mesh_quantization's; without it they are floats.
        auto position = p.attributes.find("POSITION");
        if (position != p.attributes.end() && !quantized && m.accessors[position->second].componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) {
          fail(at + "/attributes/POSITION", "integer positions need KHR_mesh_quantization in extensionsUsed");
        }
      }
    }
  }

  void materials() const {
    for (size_t i = 0; i < m.samplers.size(); ++i) {
      for (auto [key, mode] : {std::pair<const char*, int>{"wrapS", m.samplers[i].wrapS}, {"wrapT", m.samplers[i].wrapT}}) {
        if (mode != TINYGLTF_TEXTURE_WRAP_REPEAT && mode != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE &&
            mode != TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) {
          fail("/samplers/" + std::to_string(i) + "/" + key,
               "unknown wrap mode " + std::to_string(mode) + " (10497 repeat, 33071 clamp, 33648 mirrored repeat)");
        }
      }
    }
    for (size_t i = 0; i < m.materials.size(); ++i) {
      const tinygltf::Material& mat = m.materials[i];
      std::string where = "/materials/" + std::to_string(i);
      const auto& pbr = mat.pbrMetallicRoughness;
      finite(pbr.baseColorFactor, where + "/pbrMetallicRoughness/baseColorFactor", 4);
      for (double c : pbr.baseColorFactor) {
        if (c < 0 || c > 1) fail(where + "/pbrMetallicRoughness/baseColorFactor", "components must be from 0 to 1");
      }
      finite({pbr.metallicFactor}, where + "/pbrMetallicRoughness/metallicFactor", 1);
      finite({pbr.roughnessFactor}, where + "/pbrMetallicRoughness/roughnessFactor", 1);
      if (pbr.metallicFactor < 0 || pbr.metallicFactor > 1) fail(where + "/pbrMetallicRoughness/metallicFactor", "must be from 0 to 1");
      if (pbr.roughnessFactor < 0 || pbr.roughnessFactor > 1) fail(where + "/pbrMetallicRoughness/roughnessFactor", "must be from 0 to 1");
      index(pbr.metallicRoughnessTexture.index, m.textures, where + "/pbrMetallicRoughness/metallicRoughnessTexture/index");
      finite(mat.emissiveFactor, where + "/emissiveFactor", 3);
      for (double c : mat.emissiveFactor) {
        if (c < 0) fail(where + "/emissiveFactor", "components must not be negative");
      }
      if (!std::isfinite(mat.alphaCutoff) || mat.alphaCutoff < 0) fail(where + "/alphaCutoff", "expected a number from 0 up");
      if (mat.alphaMode != "OPAQUE" && mat.alphaMode != "MASK" && mat.alphaMode != "BLEND") {
        fail(where + "/alphaMode", "unknown alpha mode " + quote(mat.alphaMode) + " (OPAQUE, MASK, BLEND)");
      }
      index(pbr.baseColorTexture.index, m.textures, where + "/pbrMetallicRoughness/baseColorTexture/index");
      index(mat.emissiveTexture.index, m.textures, where + "/emissiveTexture/index");
      index(mat.normalTexture.index, m.textures, where + "/normalTexture/index");
      index(mat.occlusionTexture.index, m.textures, where + "/occlusionTexture/index");
      if (pbr.baseColorTexture.texCoord < 0 || pbr.baseColorTexture.texCoord > 1) {
        fail(where + "/pbrMetallicRoughness/baseColorTexture/texCoord", "pt reads TEXCOORD_0 and TEXCOORD_1");
      }
      if (pbr.metallicRoughnessTexture.texCoord < 0 || pbr.metallicRoughnessTexture.texCoord > 1) {
        fail(where + "/pbrMetallicRoughness/metallicRoughnessTexture/texCoord", "pt reads TEXCOORD_0 and TEXCOORD_1");
      }
      GltfClearcoat coat = clearcoat_of(mat);
      for (auto [key, value] : {std::pair<const char*, double>{"clearcoatFactor", coat.factor}, {"clearcoatRoughnessFactor", coat.roughness}}) {
        if (!(std::isfinite(value) && value >= 0 && value <= 1)) {
          fail(where + "/extensions/KHR_materials_clearcoat/" + key, "expected a number from 0 to 1");
        }
      }
      if (double t = transmission_of(mat).factor; !(std::isfinite(t) && t >= 0 && t <= 1)) {
        fail(where + "/extensions/KHR_materials_transmission/transmissionFactor", "expected a number from 0 to 1");
      }
      // The schema's minimum is 1; 0 is taken too (F0 = ((0 - 1) / (0 + 1))^2 = 1).
      if (double ior = ior_of(mat); !(std::isfinite(ior) && (ior == 0 || ior >= 1) && ior < 1e6)) {
        fail(where + "/extensions/KHR_materials_ior/ior", "expected a number from 1 up (or 0)");
      }
      double strength = emissive_strength(mat);
      if (!std::isfinite(strength) || strength < 0) {
        fail(where + "/extensions/KHR_materials_emissive_strength/emissiveStrength", "expected a finite number from 0 up");
      }
      // Radiance is a float: emissiveFactor times the strength must stay well inside its range.
      for (double c : mat.emissiveFactor) {
        if (c * strength > kMaxRadiance) {
          fail(where + "/extensions/KHR_materials_emissive_strength/emissiveStrength",
               std::string("emissiveFactor times emissiveStrength is above ") + kMaxRadianceText);
        }
      }
    }
    for (size_t i = 0; i < m.textures.size(); ++i) {
      index(m.textures[i].source, m.images, "/textures/" + std::to_string(i) + "/source");
      index(m.textures[i].sampler, m.samplers, "/textures/" + std::to_string(i) + "/sampler");
    }
  }

  void cameras_and_lights() const {
    for (size_t i = 0; i < m.cameras.size(); ++i) {
      const tinygltf::Camera& c = m.cameras[i];
      std::string where = "/cameras/" + std::to_string(i);
      if (c.type == "perspective") {
        const auto& p = c.perspective;
        if (!(std::isfinite(p.yfov) && p.yfov > 0 && p.yfov < M_PI)) fail(where + "/perspective/yfov", "expected radians in (0, pi)");
      } else if (c.type == "orthographic") {
        const auto& o = c.orthographic;
        if (!(std::isfinite(o.ymag) && o.ymag != 0)) fail(where + "/orthographic/ymag", "expected a finite number other than 0");
        if (!(std::isfinite(o.xmag) && o.xmag != 0)) fail(where + "/orthographic/xmag", "expected a finite number other than 0");
      } else {
        fail(where + "/type", "unknown camera type " + quote(c.type) + " (perspective, orthographic)");
      }
    }
    for (size_t i = 0; i < m.lights.size(); ++i) {
      const tinygltf::Light& l = m.lights[i];
      std::string where = "/extensions/KHR_lights_punctual/lights/" + std::to_string(i);
      if (l.type != "point" && l.type != "spot" && l.type != "directional") {
        fail(where + "/type", "unknown light type " + quote(l.type) + " (point, spot, directional)");
      }
      if (!l.color.empty()) finite(l.color, where + "/color", 3);
      for (double c : l.color) {
        if (c < 0) fail(where + "/color", "components must not be negative");
      }
      if (!std::isfinite(l.intensity) || l.intensity < 0 || l.intensity > kMaxRadiance) {
        fail(where + "/intensity", std::string("expected a number from 0 to ") + kMaxRadianceText);
      }
      for (double c : l.color) {
        if (c * l.intensity > kMaxRadiance) fail(where + "/color", std::string("color times intensity is above ") + kMaxRadianceText);
      }
      if (!std::isfinite(l.range) || l.range < 0) fail(where + "/range", "expected a finite number above 0");
      if (l.type == "spot") {
        // The extension's bounds: 0 <= inner < outer <= pi/2.
        double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
        if (!(std::isfinite(outer) && outer > 0 && outer <= M_PI / 2)) {
          fail(where + "/spot/outerConeAngle", "expected radians in (0, pi/2]");
        }
        if (!(std::isfinite(inner) && inner >= 0 && inner < outer)) {
          fail(where + "/spot/innerConeAngle", "expected radians from 0 up to, not including, outerConeAngle");
        }
      }
    }
  }
};

}  // namespace

void validate_gltf(const GltfFile& file) {
  Checker c{file, file.model};
  c.accessors();
  c.nodes();
  c.meshes();
  c.materials();
  c.cameras_and_lights();
}

}  // namespace pt
