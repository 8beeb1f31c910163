// Reading a glTF file. tinygltf parses, but trusts what it reads: it opens any file a URI names,
// and it hands an image the bytes of its buffer view without checking that the view lies inside
// its buffer. So the JSON is read first (nlohmann-json) and everything tinygltf would take on
// trust is checked there, with JSON pointers in the messages: the GLB chunks, the buffers' sizes
// against their files or data URIs, the buffer views against their buffers, the image files, and
// the extensions the file requires. tinygltf then reads files only through FsCallbacks that go
// through core/util/input_file.h, and its image callback keeps the encoded bytes for pt's own
// image code instead of decoding them with stb_image.
#include <nlohmann/json.hpp>

#include <bit>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <set>
#include <utility>
#include <vector>

#include "core/scene/gltf_file.h"
#include "core/util/error.h"
#include "core/util/input_file.h"

namespace pt {
namespace fs = std::filesystem;
using nlohmann::json;

bool gltf_extension_supported(const std::string& name) {
  static const std::set<std::string> kSupported = {
      "KHR_draco_mesh_compression",      // Draco-compressed primitives, decoded by libdraco (gltf_draco.cpp)
      "KHR_lights_punctual",             // point, spot and directional lights (gltf_loader.cpp converts the units)
      "KHR_materials_clearcoat",          // the metallic-roughness model's coat (factors; textures not used)
      "KHR_materials_emissive_strength",  // multiplies emissiveFactor
      "KHR_materials_ior",                // the dielectric's F0 and the transmission's index
      "KHR_materials_transmission",       // the metallic-roughness model's rough transmission (factor; texture not used)
      "KHR_mesh_quantization",            // integer and normalised attributes: every accessor is read by its type
      "KHR_texture_transform",            // a texture's offset, rotation and scale (TextureBinding)
  };
  return kSupported.count(name) > 0;
}

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;
constexpr uint32_t kChunkBin = 0x004E4942;

uint32_t le32(const std::string& s, size_t at) {
  uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap32(v);
  return v;
}

struct Glb {
  std::string_view json, bin;
  bool has_bin = false;
};

// The two chunks of a GLB (glTF 2.0 specification, section 4.4: "Binary glTF Layout").
Glb split_glb(const std::string& path, const std::string& bytes) {
  auto fail = [&](const std::string& m) { return Error(path, "GLB: " + m); };
  if (bytes.size() < 20) throw fail("shorter than a GLB header and one chunk (20 bytes)");
  if (le32(bytes, 0) != kGlbMagic) throw fail("does not start with 'glTF' (not a binary glTF file)");
  if (le32(bytes, 4) != 2) throw fail("container version " + std::to_string(le32(bytes, 4)) + " (pt reads version 2)");
  if (le32(bytes, 8) != bytes.size()) {
    throw fail("the header says " + std::to_string(le32(bytes, 8)) + " bytes, the file has " + std::to_string(bytes.size()) +
               " (truncated?)");
  }
  Glb glb;
  uint64_t json_length = le32(bytes, 12);
  if (le32(bytes, 16) != kChunkJson) throw fail("the first chunk is not JSON");
  if (json_length > bytes.size() - 20) throw fail("the JSON chunk's length " + std::to_string(json_length) + " runs past the end");
  glb.json = std::string_view(bytes).substr(20, json_length);
  size_t at = 20 + json_length;
  if (at < bytes.size()) {
    if (bytes.size() - at < 8) throw fail("a chunk header cut short at byte " + std::to_string(at));
    uint64_t bin_length = le32(bytes, at);
    if (le32(bytes, at + 4) != kChunkBin) throw fail("the second chunk is not BIN");
    if (bin_length > bytes.size() - at - 8) throw fail("the BIN chunk's length " + std::to_string(bin_length) + " runs past the end");
    glb.bin = std::string_view(bytes).substr(at + 8, bin_length);
    glb.has_bin = true;
  }
  return glb;
}

// A URI as a file name: percent-escapes decoded (RFC 3986), as tinygltf decodes them.
std::string decode_uri(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    auto hex = [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; };
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) && hex(uri[i + 2])) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i] == '+' ? ' ' : uri[i];
    }
  }
  return out;
}

}  // namespace

std::string gltf_uri_path(const std::string& gltf_path, const std::string& uri) {
  return (fs::path(gltf_path).parent_path() / decode_uri(uri)).lexically_normal().string();
}

namespace {

bool is_data_uri(const std::string& uri) { return uri.rfind("data:", 0) == 0; }

// The number of bytes a base64 data URI decodes to, or -1 if it is not base64 as tinygltf reads it.
int64_t data_uri_bytes(const std::string& uri) {
  size_t comma = uri.find(',');
  // The media types tinygltf decodes a buffer's data URI from.
  static const char* kTypes[] = {"application/octet-stream", "application/gltf-buffer", "text/plain"};
  bool known = false;
  for (const char* t : kTypes) known = known || uri.compare(5, comma - 5, std::string(t) + ";base64") == 0;
  if (comma == std::string::npos || !known) return -1;
  size_t n = uri.size() - comma - 1, pad = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i) {
    char c = uri[i];
    bool b64 = std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/';
    if (c == '=' && i + 2 >= uri.size()) {
      ++pad;
      continue;
    }
    if (!b64 || pad > 0) return -1;
  }
  if (n % 4 != 0) return -1;
  return static_cast<int64_t>(n / 4 * 3 - pad);
}

// glTF's own structure nests a few levels; `extras` may hold any JSON. tinygltf copies it into its
// Value recursively, and a file of 100 KB nesting 50,000 arrays overflowed the stack there. The
// deepest value is found here without recursion and a file nesting more than kMaxJsonDepth refused.
constexpr size_t kMaxJsonDepth = 256;
void check_json_depth(const std::string& path, const json& doc) {
  std::vector<std::pair<const json*, size_t>> stack{{&doc, 1}};
  while (!stack.empty()) {
    auto [v, depth] = stack.back();
    stack.pop_back();
    if (!v->is_structured()) continue;
    if (depth > kMaxJsonDepth) {
      throw Error(path, "JSON nested more than " + std::to_string(kMaxJsonDepth) + " levels deep (glTF needs a handful)");
    }
    for (const json& child : *v) stack.push_back({&child, depth + 1});
  }
}

struct Prepass {
  const std::string& path;
  fs::path dir;
  [[noreturn]] void fail(const std::string& where, const std::string& message) const { throw Error(path, where + ": " + message); }

  uint64_t count(const json& o, const char* key, const std::string& where, uint64_t fallback, bool required = false) const {
    if (!o.contains(key)) {
      if (required) fail(where, std::string("needs '") + key + "'");
      return fallback;
    }
    const json& v = o[key];
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0)) {
      fail(where + "/" + key, "expected an integer that is not negative");
    }
    return v.get<uint64_t>();
  }
  const json& array(const json& doc, const char* key) const {
    static const json kEmpty = json::array();
    if (!doc.contains(key)) return kEmpty;
    if (!doc[key].is_array()) fail(std::string("/") + key, "expected an array");
    return doc[key];
  }
  std::string uri(const json& o, const std::string& where) const {
    if (!o.contains("uri")) return "";
    if (!o["uri"].is_string()) fail(where + "/uri", "expected a string");
    std::string u = o["uri"].get<std::string>();
    if (u.empty()) fail(where + "/uri", "empty");
    // A scheme (RFC 3986: a letter, then letters, digits, '+', '-' or '.', then ':'; a relative
    // path whose first segment holds ':' is written "./a:b"): pt reads data: URIs and local files.
    size_t colon = u.find(':');
    if (colon != std::string::npos && std::isalpha(static_cast<unsigned char>(u[0])) &&
        u.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789+-.") == colon &&
        !is_data_uri(u)) {
      fail(where + "/uri", quote(u.substr(0, 64)) + ": pt reads data: URIs and file paths, not " + u.substr(0, colon) +
                               ": URIs");
    }
    if (!is_data_uri(u) && decode_uri(u).find('\0') != std::string::npos) {
      fail(where + "/uri", "encodes a NUL byte (%00), which no file name holds");
    }
    return u;
  }
  // The file a URI names, checked to be a regular file of at most kMaxGltfBytes; returns its size.
  uint64_t file(const std::string& u, const std::string& where, const char* what) const {
    std::string name = gltf_uri_path(path, u);
    try {
      require_regular_file(name, what);
    } catch (const Error& e) {
      fail(where + "/uri", e.what());
    }
    uint64_t size = fs::file_size(name);
    if (size > kMaxGltfBytes) {
      fail(where + "/uri", name + " is " + std::to_string(size) + " bytes; pt reads at most " + std::to_string(kMaxGltfBytes));
    }
    return size;
  }

  void check(const json& doc, const Glb* glb, std::vector<std::string>& notes) const {
    if (!doc.is_object()) fail("/", "a glTF file is a JSON object");
    if (!doc.contains("asset") || !doc["asset"].is_object() || !doc["asset"].contains("version") ||
        !doc["asset"]["version"].is_string()) {
      fail("/asset/version", "missing (every glTF file says its version)");
    }
    std::string version = doc["asset"]["version"].get<std::string>();
    if (version.rfind("2.", 0) != 0) fail("/asset/version", quote(version) + ": pt reads glTF 2.x");
    // tinygltf keeps only the matrix of a node that has both, so the conflict is caught here.
    const json& nodes = array(doc, "nodes");
    for (size_t i = 0; i < nodes.size(); ++i) {
      const json& n = nodes[i];
      if (n.is_object() && n.contains("matrix") && (n.contains("translation") || n.contains("rotation") || n.contains("scale"))) {
        fail("/nodes/" + std::to_string(i), "has both a matrix and translation, rotation or scale (glTF allows one or the other)");
      }
    }
    const json& required = array(doc, "extensionsRequired");
    for (size_t i = 0; i < required.size(); ++i) {
      if (!required[i].is_string()) fail("/extensionsRequired/" + std::to_string(i), "expected a string");
      std::string name = required[i].get<std::string>();
      if (!gltf_extension_supported(name)) {
        fail("/extensionsRequired/" + std::to_string(i), "the file requires extension " + quote(name) + ", which pt does not support");
      }
    }
    const json& used = array(doc, "extensionsUsed");
    for (size_t i = 0; i < used.size(); ++i) {
      if (used[i].is_string() && !gltf_extension_supported(used[i].get<std::string>())) {
        notes.push_back(path + ": /extensionsUsed/" + std::to_string(i) + ": extension " + quote(used[i].get<std::string>()) +
                        " is not supported; what it adds is ignored");
      }
    }
    // tinygltf refuses a spot light without its cone object, in words without a pointer.
    if (doc.contains("extensions") && doc["extensions"].is_object() && doc["extensions"].contains("KHR_lights_punctual")) {
      const json& punctual = doc["extensions"]["KHR_lights_punctual"];
      if (punctual.is_object() && punctual.contains("lights") && punctual["lights"].is_array()) {
        const json& lights = punctual["lights"];
        for (size_t i = 0; i < lights.size(); ++i) {
          const json& l = lights[i];
          if (l.is_object() && l.contains("type") && l["type"] == "spot" && !(l.contains("spot") && l["spot"].is_object())) {
            fail("/extensions/KHR_lights_punctual/lights/" + std::to_string(i) + "/spot", "a spot light needs its cone ('spot')");
          }
        }
      }
    }
    const json& buffers = array(doc, "buffers");
    std::vector<uint64_t> lengths;
    for (size_t i = 0; i < buffers.size(); ++i) {
      std::string where = "/buffers/" + std::to_string(i);
      if (!buffers[i].is_object()) fail(where, "expected an object");
      uint64_t length = count(buffers[i], "byteLength", where, 0, true);
      if (length == 0 || length > kMaxGltfBytes) fail(where + "/byteLength", "expected 1 to " + std::to_string(kMaxGltfBytes) + " bytes");
      std::string u = uri(buffers[i], where);
      if (u.empty()) {
        if (!glb || !glb->has_bin || i != 0) fail(where, "has no 'uri' and is not the BIN chunk of a GLB file");
        if (glb->bin.size() < length) {
          fail(where + "/byteLength", std::to_string(length) + " bytes, but the BIN chunk holds " + std::to_string(glb->bin.size()));
        }
      } else if (is_data_uri(u)) {
        int64_t n = data_uri_bytes(u);
        if (n < 0) fail(where + "/uri", "a data URI that is not base64 application/octet-stream or application/gltf-buffer");
        if (static_cast<uint64_t>(n) != length) {
          fail(where + "/byteLength", std::to_string(length) + " bytes, but the data URI holds " + std::to_string(n));
        }
      } else {
        uint64_t size = file(u, where, "a glTF buffer");
        if (size != length) fail(where + "/byteLength", std::to_string(length) + " bytes, but the file has " + std::to_string(size));
      }
      lengths.push_back(length);
    }
    const json& views = array(doc, "bufferViews");
    for (size_t i = 0; i < views.size(); ++i) {
      std::string where = "/bufferViews/" + std::to_string(i);
      if (!views[i].is_object()) fail(where, "expected an object");
      uint64_t buffer = count(views[i], "buffer", where, 0, true);
      if (buffer >= lengths.size()) fail(where + "/buffer", "no buffer " + std::to_string(buffer));
      uint64_t offset = count(views[i], "byteOffset", where, 0);
      uint64_t length = count(views[i], "byteLength", where, 0, true);
      if (length == 0) fail(where + "/byteLength", "must be at least 1");
      if (offset > lengths[buffer] || length > lengths[buffer] - offset) {
        fail(where + "/byteLength", "bytes " + std::to_string(offset) + " + " + std::to_string(length) + " run past the end of buffer " +
                                        std::to_string(buffer) + " (" + std::to_string(lengths[buffer]) + " bytes)");
      }
    }
    const json& images = array(doc, "images");
    for (size_t i = 0; i < images.size(); ++i) {
      std::string where = "/images/" + std::to_string(i);
      if (!images[i].is_object()) fail(where, "expected an object");
      std::string u = uri(images[i], where);
      bool has_view = images[i].contains("bufferView");
      if (u.empty() == !has_view) fail(where, "needs either 'uri' or 'bufferView'");
      if (has_view && count(images[i], "bufferView", where, 0) >= views.size()) fail(where + "/bufferView", "no such buffer view");
      if (!u.empty() && !is_data_uri(u)) file(u, where, "an image");
      if (is_data_uri(u)) {
        // tinygltf decodes these two; any other it would take for a file name (the whole URI).
        const size_t end = std::min(u.find(','), size_t{64});  // past "data:", at the comma or cut
        const std::string type = u.substr(5, end - 5);
        if (type != "image/png;base64" && type != "image/jpeg;base64") {
          fail(where + "/uri", "a data: URI of type " + quote(type) + " (pt reads image/png and image/jpeg, base64)");
        }
      }
    }
  }
};

struct Callbacks {
  std::vector<std::string>* inputs;
  std::string error;  // the first failure, with its own file name
  std::map<int, std::vector<unsigned char>>* embedded;
};

bool file_exists(const std::string& name, void*) {
  try {
    return file_kind(name) == FileKind::kRegular;
  } catch (const Error&) {
    return false;
  }
}
std::string expand_path(const std::string& name, void*) { return name; }
bool read_file(std::vector<unsigned char>* out, std::string* err, const std::string& name, void* user) {
  auto* cb = static_cast<Callbacks*>(user);
  try {
    std::string bytes = read_whole_file(name, kMaxGltfBytes, "a file a glTF file names");
    out->assign(bytes.begin(), bytes.end());
    cb->inputs->push_back(name);
    return true;
  } catch (const Error& e) {
    if (cb->error.empty()) cb->error = e.what();
    if (err) *err += e.what();
    return false;
  }
}
bool write_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "pt does not write through tinygltf";
  return false;
}

// tinygltf's image callback: keep the encoded bytes of embedded images; images in files of their
// own (image->uri set) are read later by path, like every other texture.
bool keep_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int, const unsigned char* bytes,
                int size, void* user) {
  auto* cb = static_cast<Callbacks*>(user);
  if (image->uri.empty() && size > 0) (*cb->embedded)[index].assign(bytes, bytes + size);
  return true;
}

// Takes the "indices" out of every Draco-compressed primitive (GltfFile::draco_indices says why);
// returns whether any was.
bool detach_draco_indices(json& doc, std::map<std::pair<size_t, size_t>, uint64_t>& out) {
  if (!doc.contains("meshes") || !doc["meshes"].is_array()) return false;
  json& meshes = doc["meshes"];
  for (size_t i = 0; i < meshes.size(); ++i) {
    if (!meshes[i].is_object() || !meshes[i].contains("primitives") || !meshes[i]["primitives"].is_array()) continue;
    json& primitives = meshes[i]["primitives"];
    for (size_t k = 0; k < primitives.size(); ++k) {
      json& p = primitives[k];
      if (!p.is_object() || !p.contains("indices") || !p["indices"].is_number_unsigned()) continue;
      if (!p.contains("extensions") || !p["extensions"].is_object() || !p["extensions"].contains("KHR_draco_mesh_compression")) continue;
      out[{i, k}] = p["indices"].get<uint64_t>();
      p.erase("indices");
    }
  }
  return !out.empty();
}

}  // namespace

std::string glb_container(std::string json, std::string_view bin, bool has_bin) {
  while (json.size() % 4) json.push_back(' ');
  const size_t bin_padded = (bin.size() + 3) / 4 * 4;
  std::string out;
  auto u32 = [&out](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(kGlbMagic);
  u32(2);
  u32(static_cast<uint32_t>(12 + 8 + json.size() + (has_bin ? 8 + bin_padded : 0)));
  u32(static_cast<uint32_t>(json.size()));
  u32(0x4E4F534A);  // "JSON"
  out += json;
  if (has_bin) {
    u32(static_cast<uint32_t>(bin_padded));
    u32(0x004E4942);  // "BIN"
    out += bin;
    out.resize(out.size() + bin_padded - bin.size(), '\0');
  }
  return out;
}

GltfFile read_gltf(const std::string& path) {
  GltfFile out;
  out.path = path;
  std::string bytes = read_whole_file(path, kMaxGltfBytes, "a glTF file");
  out.inputs.push_back(path);
  if (bytes.empty()) throw Error(path, "the file is empty (0 bytes)");
  bool binary = bytes.size() >= 4 && le32(bytes, 0) == kGlbMagic;
  Glb glb;
  std::string_view text = bytes;
  if (binary) {
    glb = split_glb(path, bytes);
    text = glb.json;
  }
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    std::string what = e.what();
    size_t at = what.find("] ");
    std::string message = at != std::string::npos ? what.substr(at + 2) : what;
    if (message.size() > 240) message = message.substr(0, 240) + "...";
    throw Error(path, "not valid JSON: " + message);
  }
  check_json_depth(path, doc);
  Prepass{path, fs::path(path).parent_path()}.check(doc, binary ? &glb : nullptr, out.notes);
  if (detach_draco_indices(doc, out.draco_indices)) {
    std::string rewritten = binary ? glb_container(doc.dump(), glb.bin, glb.has_bin) : doc.dump();
    bytes = std::move(rewritten);  // glb's views into the old bytes are not used after this
  }

  Callbacks cb{&out.inputs, "", &out.embedded_images};
  tinygltf::TinyGLTF reader;
  reader.SetFsCallbacks({&file_exists, &expand_path, &read_file, &write_file, &cb});
  reader.SetImageLoader(&keep_image, &cb);
  std::string err, warn;
  std::string base = fs::path(path).parent_path().string();
  bool ok = binary ? reader.LoadBinaryFromMemory(&out.model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                 static_cast<unsigned int>(bytes.size()), base)
                   : reader.LoadASCIIFromString(&out.model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()), base);
  if (!cb.error.empty()) throw Error(cb.error);
  if (!ok) {
    std::string first = err.substr(0, err.find('\n'));
    throw Error(path, "tinygltf: " + (first.empty() ? std::string("cannot parse the file") : cut(first)));
  }
  return out;
}

}  // namespace pt
