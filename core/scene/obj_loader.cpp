// OBJ + MTL through tinyobjloader. Debian's tinyobjloader (2.0.0rc10) reads "nan", "inf" and
// non-numbers as 0 and accepts out-of-range indices, so a first pass validates what it would let
// through and reports file:line; tinyobjloader then does the real parse and triangulation.
#include <tiny_obj_loader.h>

#include <cfloat>
#include <climits>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/util/error.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream in(line);
  std::string t;
  while (in >> t) tokens.push_back(t);
  return tokens;
}

// Finite as a float, too: geometry is stored in float, and 1e39 would become infinity there.
bool parse_finite(const std::string& token, double& value) {
  const char* begin = token.c_str();
  char* end = nullptr;
  value = std::strtod(begin, &end);
  return end != begin && *end == '\0' && std::isfinite(value) && std::abs(value) <= FLT_MAX;
}

// OBJ and MTL keywords are printable ASCII; anything else means the file is not text we can read
// (a binary file without NUL bytes would otherwise pass as a list of unknown statements).
bool is_keyword(const std::string& token) {
  for (unsigned char c : token) {
    if (c < 0x21 || c > 0x7e) return false;
  }
  return true;
}

void require_numbers(const std::vector<std::string>& tokens, size_t min_count, size_t max_count,
                     const std::string& file, int line) {
  size_t n = tokens.size() - 1;
  if (n < min_count || n > max_count) {
    throw Error(file, line, "'" + tokens[0] + "' expects " + std::to_string(min_count) +
                                (max_count > min_count ? " to " + std::to_string(max_count) : "") + " numbers, got " +
                                std::to_string(n));
  }
  for (size_t i = 1; i < tokens.size(); ++i) {
    double v;
    if (!parse_finite(tokens[i], v)) {
      throw Error(file, line, "'" + tokens[i] + "' in '" + tokens[0] + "' is not a finite number");
    }
  }
}

struct IndexCheck {
  long max_positive = 0;
  int line_of_max = 0;
};

// Validates one index of a face corner; negative indices are relative to the count so far.
void check_index(const std::string& token, long count_so_far, IndexCheck& check, const std::string& what,
                 const std::string& file, int line) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  long value = std::strtol(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE || value > INT_MAX || value < -INT_MAX) {
    throw Error(file, line, "face " + what + " index '" + token + "' is not a valid integer");
  }
  if (value == 0) throw Error(file, line, "face " + what + " index 0 (OBJ indices start at 1)");
  if (value < 0 && -value > count_so_far) {
    throw Error(file, line, "face " + what + " index " + token + " points before the first " + what);
  }
  if (value > check.max_positive) {
    check.max_positive = value;
    check.line_of_max = line;
  }
}

struct ObjScan {
  std::vector<std::string> mtllibs;
  std::set<std::string> unsupported;
};

ObjScan scan_obj(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open the file");
  ObjScan scan;
  long nv = 0, nvt = 0, nvn = 0;
  IndexCheck cv, cvt, cvn;
  std::string raw;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    if (raw.find('\0') != std::string::npos) throw Error(path, line, "binary data in a text OBJ file");
    auto tokens = split(raw);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (!is_keyword(tokens[0])) throw Error(path, line, "binary data or an unreadable statement in an OBJ file");
    const std::string& key = tokens[0];
    if (key == "v") {
      require_numbers(tokens, 3, 7, path, line);  // x y z [w] or x y z r g b
      ++nv;
    } else if (key == "vn") {
      require_numbers(tokens, 3, 3, path, line);
      ++nvn;
    } else if (key == "vt") {
      require_numbers(tokens, 1, 3, path, line);
      ++nvt;
    } else if (key == "f") {
      if (tokens.size() < 4) throw Error(path, line, "a face needs at least 3 vertices");
      for (size_t i = 1; i < tokens.size(); ++i) {
        const std::string& corner = tokens[i];
        size_t s1 = corner.find('/');
        size_t s2 = s1 == std::string::npos ? std::string::npos : corner.find('/', s1 + 1);
        check_index(corner.substr(0, s1), nv, cv, "vertex", path, line);
        if (s1 != std::string::npos) {
          std::string t = corner.substr(s1 + 1, s2 == std::string::npos ? std::string::npos : s2 - s1 - 1);
          if (!t.empty()) check_index(t, nvt, cvt, "texture coordinate", path, line);
          if (s2 != std::string::npos) check_index(corner.substr(s2 + 1), nvn, cvn, "normal", path, line);
        }
      }
    } else if (key == "mtllib") {
      if (tokens.size() < 2) throw Error(path, line, "'mtllib' without a file name");
      scan.mtllibs.push_back(raw.substr(raw.find("mtllib") + 6));
      auto& name = scan.mtllibs.back();
      name.erase(0, name.find_first_not_of(" \t"));
      name.erase(name.find_last_not_of(" \t\r") + 1);
    } else if (key == "usemtl" || key == "o" || key == "g" || key == "s") {
    } else {
      scan.unsupported.insert(key);
    }
  }
  if (in.bad()) throw Error(path, "read error");
  if (cv.max_positive > nv) {
    throw Error(path, cv.line_of_max, "face vertex index " + std::to_string(cv.max_positive) + " but the file has " +
                                          std::to_string(nv) + " vertices");
  }
  if (cvt.max_positive > nvt) {
    throw Error(path, cvt.line_of_max, "face texture coordinate index " + std::to_string(cvt.max_positive) +
                                           " but the file has " + std::to_string(nvt));
  }
  if (cvn.max_positive > nvn) {
    throw Error(path, cvn.line_of_max, "face normal index " + std::to_string(cvn.max_positive) +
                                           " but the file has " + std::to_string(nvn));
  }
  return scan;
}

// Validates an MTL file's numbers and collects the keys we do not model.
void scan_mtl(const std::string& path, std::set<std::string>& unsupported) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open the material library");
  static const std::set<std::string> kColour = {"Kd", "Ks", "Ke", "Ka", "Tf"};
  static const std::set<std::string> kScalar = {"Ns", "Ni", "d", "Tr", "illum"};
  static const std::set<std::string> kUsed = {"newmtl", "Kd", "Ks", "Ke", "Ns", "Ni", "d", "Tr", "illum", "map_Kd"};
  std::string raw;
  int line = 0;
  bool in_material = false;
  while (std::getline(in, raw)) {
    ++line;
    if (raw.find('\0') != std::string::npos) throw Error(path, line, "binary data in a text MTL file");
    auto tokens = split(raw);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (!is_keyword(tokens[0])) throw Error(path, line, "binary data or an unreadable statement in an MTL file");
    const std::string& key = tokens[0];
    if (key == "newmtl") {
      if (tokens.size() < 2) throw Error(path, line, "'newmtl' without a name");
      in_material = true;
      continue;
    }
    if (!in_material) throw Error(path, line, "'" + key + "' before any 'newmtl'");
    if (kColour.count(key)) {
      if (tokens.size() > 1 && (tokens[1] == "spectral" || tokens[1] == "xyz")) {
        unsupported.insert(key + " " + tokens[1]);
        continue;
      }
      require_numbers(tokens, 1, 3, path, line);
      for (size_t i = 1; i < tokens.size(); ++i) {
        if (std::strtod(tokens[i].c_str(), nullptr) < 0) throw Error(path, line, "negative value in '" + key + "'");
      }
    } else if (kScalar.count(key)) {
      require_numbers(tokens, 1, 1, path, line);
    } else if (key == "map_Kd") {
      if (tokens.size() < 2) throw Error(path, line, "'map_Kd' without a file name");
    }
    if (!kUsed.count(key)) unsupported.insert(key);
  }
}

Material convert_material(const tinyobj::material_t& m) {
  Material out;
  out.name = m.name;
  out.kd = {m.diffuse[0], m.diffuse[1], m.diffuse[2]};
  out.ks = {m.specular[0], m.specular[1], m.specular[2]};
  out.emission = {m.emission[0], m.emission[1], m.emission[2]};
  out.exponent = std::max(0.0f, m.shininess);
  out.ior = m.ior > 1.0f ? m.ior : 1.5f;
  bool glass = m.illum == 4 || m.illum == 6 || m.illum == 7 || m.dissolve < 1.0f;
  if (glass) {
    out.type = MaterialType::kDielectric;
  } else if (m.illum == 3 || m.illum == 5) {
    out.type = MaterialType::kMirror;
    if (max_component(out.ks) <= 0) out.ks = Spectrum(1.0f);
  } else if (max_component(out.ks) > 0 && m.illum != 1) {
    out.type = MaterialType::kGlossy;
  } else {
    out.type = MaterialType::kDiffuse;
  }
  // Energy conservation: kd + ks <= 1 per channel, scaling both down where they exceed it.
  float sum = max_component(out.kd + (out.type == MaterialType::kGlossy ? out.ks : Spectrum(0.0f)));
  if (sum > 1.0f) {
    out.kd = out.kd / sum;
    if (out.type == MaterialType::kGlossy) out.ks = out.ks / sum;
  }
  if (out.type == MaterialType::kMirror) out.ks = vmin(out.ks, Spectrum(1.0f));
  return out;
}

std::string join(const std::set<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

int texture_index(Scene& scene, const std::string& path, const std::string& referenced_from) {
  auto& textures = scene.textures_mut();
  for (size_t i = 0; i < textures.size(); ++i) {
    if (textures[i]->path == path) return static_cast<int>(i);
  }
  try {
    textures.push_back(read_texture(path));
  } catch (const Error& e) {
    throw Error(referenced_from, std::string("texture will not load: ") + e.what());
  }
  return static_cast<int>(textures.size() - 1);
}

void load_obj(Scene& scene, const std::string& path, const Transform& transform, int override_material) {
  if (!fs::exists(path)) throw Error(path, "no such file");
  if (fs::is_directory(path)) throw Error(path, "is a folder, not an OBJ file");
  ObjScan scan = scan_obj(path);
  fs::path dir = fs::path(path).parent_path();
  std::set<std::string> unsupported_mtl;
  for (const std::string& lib : scan.mtllibs) {
    fs::path p = dir / lib;
    if (!fs::exists(p)) {
      scene.notes_mut().push_back(path + ": material library '" + lib + "' not found; its faces use the default material");
      continue;
    }
    scan_mtl(p.string(), unsupported_mtl);
  }
  if (!scan.unsupported.empty()) {
    scene.notes_mut().push_back(path + ": ignoring OBJ statements not supported: " + join(scan.unsupported));
  }
  if (!unsupported_mtl.empty()) {
    scene.notes_mut().push_back(path + ": ignoring MTL keys not supported: " + join(unsupported_mtl));
  }

  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = dir.string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    std::string message = reader.Error();
    while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
    throw Error(path, message.empty() ? "cannot parse" : message);
  }
  const auto& attrib = reader.GetAttrib();
  const auto& shapes = reader.GetShapes();
  const auto& mtls = reader.GetMaterials();

  Mesh& mesh = scene.mesh_mut();
  uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  size_t nverts = attrib.vertices.size() / 3;
  for (size_t i = 0; i < nverts; ++i) {
    Vec3f p{attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
    mesh.positions.push_back(transform.point(p));
  }

  // Materials: the MTL's, then the default for faces without one.
  std::vector<uint32_t> material_map(mtls.size());
  for (size_t i = 0; i < mtls.size(); ++i) {
    Material m = convert_material(mtls[i]);
    if (!mtls[i].diffuse_texname.empty()) {
      fs::path tex = dir / mtls[i].diffuse_texname;
      m.kd_texture = texture_index(scene, tex.string(), path);
      m.kd = Spectrum(1.0f);  // the map replaces Kd, as Blender's and pbrt's importers do
    }
    scene.materials_mut().push_back(m);
    material_map[i] = static_cast<uint32_t>(scene.materials_mut().size() - 1);
  }

  int64_t fallback = -1;  // the default material, created only if a face needs it
  auto default_id = [&] {
    if (fallback < 0) fallback = scene.default_material();
    return static_cast<uint32_t>(fallback);
  };
  bool any_normals = !attrib.normals.empty(), any_uvs = !attrib.texcoords.empty();
  bool flip = transform.flips_handedness();
  for (const auto& shape : shapes) {
    const auto& idx = shape.mesh.indices;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      if (shape.mesh.num_face_vertices[f] != 3) throw Error(path, "a face could not be triangulated");
      size_t tri = mesh.triangle_count();
      int order[3] = {0, flip ? 2 : 1, flip ? 1 : 2};  // keep the front face under mirroring
      for (int c : order) {
        int vi = idx[3 * f + c].vertex_index;
        if (vi < 0 || static_cast<size_t>(vi) >= nverts) throw Error(path, "face vertex index out of range");
        mesh.indices.push_back(base + static_cast<uint32_t>(vi));
      }
      int mid = shape.mesh.material_ids.empty() ? -1 : shape.mesh.material_ids[f];
      uint32_t material = override_material >= 0 ? static_cast<uint32_t>(override_material)
                          : (mid >= 0 && static_cast<size_t>(mid) < material_map.size()) ? material_map[mid]
                                                                                         : default_id();
      mesh.material.push_back(material);
      if (any_normals) {
        if (mesh.corner_normals.empty()) mesh.corner_normals.assign(3 * tri, Vec3f(0.0f));
        for (int c : order) {
          int ni = idx[3 * f + c].normal_index;
          Vec3f n(0.0f);
          if (ni >= 0 && static_cast<size_t>(3 * ni + 2) < attrib.normals.size()) {
            n = transform.normal({attrib.normals[3 * ni], attrib.normals[3 * ni + 1], attrib.normals[3 * ni + 2]});
            float l = length(n);
            n = l > 0 ? n / l : Vec3f(0.0f);
          }
          mesh.corner_normals.push_back(n);
        }
      }
      if (any_uvs) {
        if (mesh.corner_uvs.empty()) mesh.corner_uvs.assign(3 * tri, Vec2f(0, 0));
        for (int c : order) {
          int ti = idx[3 * f + c].texcoord_index;
          Vec2f uv(0, 0);
          if (ti >= 0 && static_cast<size_t>(2 * ti + 1) < attrib.texcoords.size()) {
            uv = {attrib.texcoords[2 * ti], attrib.texcoords[2 * ti + 1]};
          }
          mesh.corner_uvs.push_back(uv);
        }
      }
    }
  }
  // Keep the per-corner arrays the same length as the triangles when an earlier object had them.
  if (!mesh.corner_normals.empty()) mesh.corner_normals.resize(3 * mesh.triangle_count(), Vec3f(0.0f));
  if (!mesh.corner_uvs.empty()) mesh.corner_uvs.resize(3 * mesh.triangle_count(), Vec2f(0, 0));
}

void add_default_lighting(Scene& scene) {
  bool emits = !scene.point_lights_mut().empty() || scene.environment().has_value();
  for (uint32_t m : scene.mesh().material) emits = emits || scene.materials()[m].is_emissive();
  for (const Sphere& s : scene.spheres()) emits = emits || scene.materials()[s.material].is_emissive();
  if (emits) return;
  scene.set_environment(Environment(Spectrum(1.0f)));
  scene.notes_mut().push_back(scene.source() +
                              ": nothing in the scene emits light; using the default white environment (radiance 1)");
}

}  // namespace pt
