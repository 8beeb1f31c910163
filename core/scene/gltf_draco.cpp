#include "core/scene/gltf_draco.h"

#include <draco/compression/decode.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "core/scene/gltf_accessor.h"
#include "core/util/error.h"

namespace pt {
namespace {

constexpr const char* kDraco = "KHR_draco_mesh_compression";

// The largest integer an accessor's normalized integer type holds (its 1.0).
double normalized_scale(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return 127.0;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 255.0;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return 32767.0;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 65535.0;
    default: return 1.0;
  }
}

bool integer_type(draco::DataType t) {
  return t != draco::DT_FLOAT32 && t != draco::DT_FLOAT64 && t != draco::DT_BOOL && t != draco::DT_INVALID;
}

struct Decoder {
  GltfFile& file;
  tinygltf::Model& m;
  // Accessors already pointed at decoded data, and by which (buffer view, Draco attribute id or -1
  // for the indices): one accessor may serve two primitives only if it is the same data.
  std::map<int, std::pair<int, int>> decoded;

  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    throw Error(file.path, where + ": " + message);
  }

  // A new buffer and buffer view holding `bytes`; returns the view's index.
  int add_view(std::vector<unsigned char> bytes) {
    tinygltf::Buffer buffer;
    buffer.data = std::move(bytes);
    tinygltf::BufferView view;
    view.buffer = static_cast<int>(m.buffers.size());
    view.byteOffset = 0;
    view.byteLength = buffer.data.size();
    m.buffers.push_back(std::move(buffer));
    m.bufferViews.push_back(view);
    return static_cast<int>(m.bufferViews.size()) - 1;
  }

  // Accessor `index` becomes `count` elements of `type` in a new view holding `bytes`.
  void repoint(int index, int component_type, size_t count, std::vector<unsigned char> bytes) {
    tinygltf::Accessor& a = m.accessors[index];
    a.bufferView = add_view(std::move(bytes));
    a.byteOffset = 0;
    a.componentType = component_type;
    a.normalized = false;
    a.count = count;
  }

  void primitive(tinygltf::Primitive& p, const std::string& where, std::pair<size_t, size_t> key) {
    const std::string at = where + "/extensions/" + kDraco;
    if (auto it = file.draco_indices.find(key); it != file.draco_indices.end()) {
      if (it->second >= m.accessors.size()) {
        fail(where + "/indices", "refers to " + std::to_string(it->second) + ", but there are " + std::to_string(m.accessors.size()));
      }
      p.indices = static_cast<int>(it->second);
    }
    const tinygltf::Value& e = p.extensions.at(kDraco);
    if (!e.IsObject()) fail(at, "expected an object");
    const tinygltf::Value& view_value = e.Get("bufferView");
    if (!view_value.IsInt()) fail(at + "/bufferView", "expected an integer");
    const int view_index = view_value.Get<int>();
    if (view_index < 0 || static_cast<size_t>(view_index) >= m.bufferViews.size()) {
      fail(at + "/bufferView", "refers to " + std::to_string(view_index) + ", but there are " + std::to_string(m.bufferViews.size()));
    }
    const tinygltf::Value& attributes = e.Get("attributes");
    if (!attributes.IsObject()) fail(at + "/attributes", "expected an object");
    if (!attributes.Has("POSITION")) fail(at + "/attributes", "no POSITION");
    if (p.mode != TINYGLTF_MODE_TRIANGLES) fail(where + "/mode", "a Draco-compressed primitive must be triangles (4)");

    // Bounds were checked by validate_gltf.
    const tinygltf::BufferView& view = m.bufferViews[view_index];
    const tinygltf::Buffer& buffer = m.buffers[view.buffer];
    draco::DecoderBuffer in;
    in.Init(reinterpret_cast<const char*>(buffer.data.data() + view.byteOffset), view.byteLength);
    auto geometry = draco::Decoder::GetEncodedGeometryType(&in);
    if (!geometry.ok() || geometry.value() != draco::TRIANGULAR_MESH) {
      fail(at + "/bufferView", "buffer view " + std::to_string(view_index) + " does not hold a Draco triangle mesh");
    }
    draco::Decoder decoder;
    auto decoded_mesh = decoder.DecodeMeshFromBuffer(&in);
    if (!decoded_mesh.ok()) {
      fail(at + "/bufferView", "Draco could not decode buffer view " + std::to_string(view_index) + ": " +
                                   decoded_mesh.status().error_msg_string());
    }
    const std::unique_ptr<draco::Mesh> mesh = std::move(decoded_mesh).value();
    const size_t points = mesh->num_points(), faces = mesh->num_faces();
    if (points == 0 || faces == 0) fail(at + "/bufferView", "the Draco mesh has no triangles");

    for (const std::string& name : attributes.Keys()) {
      const std::string key = at + "/attributes/" + name;
      const tinygltf::Value& id = attributes.Get(name);
      if (!id.IsInt() || id.Get<int>() < 0) fail(key, "expected a non-negative integer");
      auto it = p.attributes.find(name);
      if (it == p.attributes.end()) fail(key, "the primitive's attributes have no " + name);
      const int accessor = it->second;
      const draco::PointAttribute* attribute = mesh->GetAttributeByUniqueId(static_cast<uint32_t>(id.Get<int>()));
      if (!attribute) fail(key, "the Draco mesh has no attribute " + std::to_string(id.Get<int>()));
      if (!claim(accessor, view_index, id.Get<int>(), key)) continue;
      const tinygltf::Accessor& a = m.accessors[accessor];
      const size_t components = component_count(a.type);
      if (components > 4) fail("/accessors/" + std::to_string(accessor) + "/type", "a vertex attribute has at most 4 components");
      if (a.count != points) {
        fail("/accessors/" + std::to_string(accessor) + "/count",
             std::to_string(a.count) + " elements, but the Draco mesh has " + std::to_string(points) + " points");
      }
      if (attribute->num_components() < 1 || static_cast<size_t>(attribute->num_components()) < components) {
        fail(key, "the Draco attribute has " + std::to_string(attribute->num_components()) + " components, the accessor " +
                      std::to_string(components));
      }
      // Integer attributes the accessor calls normalized, and Draco does not, are scaled here.
      const double scale = a.normalized && integer_type(attribute->data_type()) && !attribute->normalized()
                               ? 1.0 / normalized_scale(a.componentType)
                               : 1.0;
      std::vector<unsigned char> bytes(points * components * sizeof(float));
      float* out = reinterpret_cast<float*>(bytes.data());
      float value[4];
      for (size_t i = 0; i < points; ++i) {
        const draco::AttributeValueIndex v = attribute->mapped_index(draco::PointIndex(static_cast<uint32_t>(i)));
        if (v.value() >= attribute->size() || !attribute->ConvertValue<float>(v, static_cast<int8_t>(components), value)) {
          fail(key, "the Draco attribute's value for point " + std::to_string(i) + " cannot be read");
        }
        for (size_t c = 0; c < components; ++c) out[i * components + c] = static_cast<float>(value[c] * scale);
      }
      repoint(accessor, TINYGLTF_COMPONENT_TYPE_FLOAT, points, std::move(bytes));
    }
    if (!p.attributes.count("POSITION")) fail(where + "/attributes", "no POSITION");

    // The indices: the primitive's accessor if it has one (its count must agree), else a new one.
    if (p.indices < 0) {
      tinygltf::Accessor a;
      a.type = TINYGLTF_TYPE_SCALAR;
      a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
      a.count = 3 * faces;
      m.accessors.push_back(a);
      p.indices = static_cast<int>(m.accessors.size()) - 1;
    } else if (m.accessors[p.indices].count != 3 * faces) {
      fail("/accessors/" + std::to_string(p.indices) + "/count",
           std::to_string(m.accessors[p.indices].count) + " indices, but the Draco mesh has " + std::to_string(faces) + " triangles");
    }
    if (!claim(p.indices, view_index, -1, where + "/indices")) return;
    std::vector<unsigned char> bytes(3 * faces * sizeof(uint32_t));
    uint32_t* out = reinterpret_cast<uint32_t*>(bytes.data());
    for (size_t f = 0; f < faces; ++f) {
      const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(static_cast<uint32_t>(f)));
      for (int k = 0; k < 3; ++k) out[3 * f + k] = face[k].value();  // checked against the points when read
    }
    repoint(p.indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, 3 * faces, std::move(bytes));
  }

  // False where the accessor was already decoded from the same data; fails where from other data.
  bool claim(int accessor, int view, int id, const std::string& where) {
    auto [it, fresh] = decoded.try_emplace(accessor, view, id);
    if (fresh) return true;
    if (it->second == std::pair{view, id}) return false;
    fail(where, "accessor " + std::to_string(accessor) + " is also decoded from other Draco data");
  }
};

}  // namespace

void decode_draco(GltfFile& file) {
  Decoder d{file, file.model, {}};
  for (size_t i = 0; i < file.model.meshes.size(); ++i) {
    for (size_t k = 0; k < file.model.meshes[i].primitives.size(); ++k) {
      tinygltf::Primitive& p = file.model.meshes[i].primitives[k];
      if (p.extensions.count(kDraco)) d.primitive(p, "/meshes/" + std::to_string(i) + "/primitives/" + std::to_string(k), {i, k});
    }
  }
}

}  // namespace pt
