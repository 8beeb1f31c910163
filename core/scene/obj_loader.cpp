// OBJ + MTL through tinyobjloader, after obj_validate.cpp has checked what tinyobjloader would
// misread; tinyobjloader does the real parse and triangulation.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/scene/loader.h"
#include "core/scene/mtl_maps.h"
#include "core/scene/obj_validate.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/text.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

// Ambient colours are reflectances (<= 1); well above that, the exporter probably meant a light.
constexpr float kLightLikeKa = 1.5f;

// "file:line: material 'name'" for a warning about one material.
std::string where(const tinyobj::material_t& m, const MtlFacts* facts, const std::string& obj) {
  std::string place = facts ? facts->file + ":" + std::to_string(facts->line) : obj;
  return place + ": material '" + m.name + "'";
}

std::string number(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The coverage (opacity) a non-glass material's `d` or `Tr` give, and the one warning line that
// says how an unusual value was read. `d` is coverage and wins over `Tr`. `Tr` alone is ambiguous:
// the MTL convention reads it as transparency (1 - d), MeshLab and 3ds Max write it as opacity
// (`Tr 1` on opaque models); the reading that keeps the material more visible is taken.
float read_opacity(const tinyobj::material_t& m, const MtlFacts* facts, const std::string& place,
                   std::vector<std::string>& notes) {
  if (!facts) return std::clamp(static_cast<float>(m.dissolve), 0.0f, 1.0f);
  auto percent = [](float o) { return number(std::round(o * 1000.0f) / 10.0f) + "% opaque"; };
  if (facts->d) {
    float d = std::clamp(*facts->d, 0.0f, 1.0f);
    if (facts->tr && std::abs((1.0f - *facts->tr) - d) > 1e-3f) {
      notes.push_back(place + ": 'd " + number(*facts->d) + "' and 'Tr " + number(*facts->tr) +
                      "' disagree; d wins (coverage): " + percent(d));
    } else if (d < 1.0f) {
      notes.push_back(place + ": 'd " + number(*facts->d) + "' read as coverage: " + percent(d) +
                      ", the rest lets light through unchanged (illum 4, 6 or 7 makes glass)");
    }
    return d;
  }
  if (facts->tr) {
    float t = std::clamp(*facts->tr, 0.0f, 1.0f);
    if (t == 0.0f) return 1.0f;
    if (t > 0.5f) {
      notes.push_back(place + ": 'Tr " + number(*facts->tr) + "' without 'd' read as opacity, as MeshLab and 3ds Max " +
                      "write it: " + percent(t) + " (as transparency, the MTL convention, it would be " +
                      (t == 1.0f ? std::string("invisible") : percent(1.0f - t)) + ")");
      return t;
    }
    notes.push_back(place + ": 'Tr " + number(*facts->tr) + "' without 'd' read as transparency (the MTL convention): " +
                    percent(1.0f - t));
    return 1.0f - t;
  }
  return 1.0f;
}

// A material with the PBR extension's keys, as Blender's OBJ exporter writes the Principled BSDF
// with "PBR Extensions" on, is the metallic-roughness model (core/material/metallic_roughness.h):
// Kd the base colour, Pr roughness, Pm metallic, Pc and Pcr the clear coat's weight and roughness,
// Ks the Principled BSDF's "Specular" s, whose
// dielectric reflectance is F0 = 0.08 s (0.04 at Blender's default 0.5; Ni sets only refraction
// there, so it is not used). Without Pr, roughness is Blender's reading of Ns,
// 1 - sqrt(Ns / 1000), or 1 (glTF's default). illum is not used. map_Kd, map_Pr, map_Pm and map_Ke
// are attached by load_obj. scenes/README.md has the table.
MetallicRoughness pbr_model(const tinyobj::material_t& m, const MtlFacts& facts, const std::string& place,
                            std::vector<std::string>& notes) {
  MetallicRoughness mr;
  Spectrum kd{m.diffuse[0], m.diffuse[1], m.diffuse[2]};
  if (max_component(kd) > 1.0f) {
    notes.push_back(place + ": Kd " + number(max_component(kd)) + " is a base colour above 1; clamped to 1");
    kd = vmin(kd, Spectrum(1.0f));
  }
  mr.base_color = kd;
  mr.metallic = facts.pm.value_or(0.0f);
  if (facts.pr) {
    mr.roughness = *facts.pr;
  } else if (facts.ns) {
    mr.roughness = 1.0f - std::sqrt(std::clamp(*facts.ns, 0.0f, 1000.0f) / 1000.0f);
  } else {
    mr.roughness = 1.0f;
  }
  mr.clearcoat = facts.pc.value_or(0.0f);
  mr.clearcoat_roughness = facts.pcr.value_or(0.0f);
  float specular = facts.has_ks ? (m.specular[0] + m.specular[1] + m.specular[2]) / 3.0f : 0.5f;
  float f0 = std::clamp(0.08f * specular, 0.0f, 0.99f);
  mr.ior = (1.0f + std::sqrt(f0)) / (1.0f - std::sqrt(f0));  // F0 = ((ior - 1) / (ior + 1))^2
  return mr;
}

Material convert_material(const tinyobj::material_t& m, const MtlFacts* facts, const std::string& obj,
                          std::vector<std::string>& notes) {
  std::string place = where(m, facts, obj);
  Material out;
  out.name = m.name;
  Spectrum kd{m.diffuse[0], m.diffuse[1], m.diffuse[2]};
  Spectrum ks{m.specular[0], m.specular[1], m.specular[2]};
  out.emission = {m.emission[0], m.emission[1], m.emission[2]};
  if (facts && facts->pbr) {
    out.model = pbr_model(m, *facts, place, notes);
    out.opacity = read_opacity(m, facts, place, notes);
    if (out.is_emissive() && out.opacity < 1.0f) {
      out.opacity = 1.0f;
      notes.push_back(place + ": emits light (Ke), so it is kept opaque (its d or Tr is ignored)");
    }
    return out;
  }
  // Glass only where the illumination model says so: `d` and `Tr` are coverage, not refraction.
  bool glass = m.illum == 4 || m.illum == 6 || m.illum == 7;
  bool mirror = !glass && (m.illum == 3 || m.illum == 5);
  bool glossy = !glass && !mirror && max_component(ks) > 0 && m.illum != 1;
  if (mirror && max_component(ks) <= 0) ks = Spectrum(1.0f);
  // Glass models its transparency by refraction; coverage applies to everything else.
  if (!glass) {
    std::vector<std::string> reading;
    out.opacity = read_opacity(m, facts, place, reading);
    if (out.is_emissive() && out.opacity < 1.0f) {
      out.opacity = 1.0f;
      reading.assign(1, place + ": emits light (Ke), so it is kept opaque (its d or Tr is ignored)");
    }
    notes.insert(notes.end(), reading.begin(), reading.end());
  }
  // Energy conservation: kd + ks <= 1 per channel, scaling both down where they exceed it.
  float sum = max_component(kd + (glossy ? ks : Spectrum(0.0f)));
  if (sum > 1.0f && !mirror) {
    kd = kd / sum;
    if (glossy) ks = ks / sum;
    notes.push_back(place + ": " + (glossy ? "Kd + Ks" : "Kd") + " reaches " + number(sum) +
                    " in a channel; scaled by " + number(1.0f / sum) +
                    " so it reflects no more light than it receives (it renders darker than its Kd)");
  }
  if (mirror && max_component(ks) > 1.0f) {
    notes.push_back(place + ": mirror Ks " + number(max_component(ks)) + " capped at 1");
    ks = vmin(ks, Spectrum(1.0f));
  }
  if (glass) {
    out.model = Dielectric{m.ior > 1.0f ? m.ior : 1.5f};
  } else if (mirror) {
    out.model = Mirror{ks};
  } else if (glossy) {
    out.model = Glossy{kd, -1, ks, std::max(0.0f, m.shininess)};
  } else {
    out.model = Diffuse{kd, -1};
  }
  return out;
}

// The name an MTL material without one is given.
constexpr const char* kUnnamedMaterial = "(unnamed)";

// `text` with every `newmtl` line that names nothing naming kUnnamedMaterial.
std::string name_unnamed_materials(const std::string& text) {
  std::string out;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    size_t stop = end == std::string::npos ? text.size() : end + 1;
    std::string line = text.substr(pos, stop - pos);
    size_t first = line.find_first_not_of(" \t");
    size_t last = line.find_last_not_of(" \t\r\n");
    if (first != std::string::npos && line.compare(first, last - first + 1, "newmtl") == 0) {
      line = "newmtl " + std::string(kUnnamedMaterial) + (end == std::string::npos ? "" : "\n");
    }
    out += line;
    pos = stop;
  }
  return out;
}

// A texture statement's options with their optional values written out. MTL lets -o, -s and -t
// take one to three numbers and -mm one or two; tinyobjloader always reads three (two), taking
// whatever follows as a number: `map_Kd -o 0.5 0.5 -s 2 2 base.png` lost its texture to the file
// name '2 2 -clamp on base.png', and `map_Kd -s base.png` to an empty one. Missing values get the
// defaults (-o and -t 0, -s 1; -mm base 0, gain 1); an option with none is noted. Lines that are
// not texture statements, and the file name with what follows it, are left as they are.
std::string complete_texture_options(const std::string& line, const std::string& path, int number,
                                     std::vector<std::string>& notes) {
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  auto is_number = [](const std::string& t) {
    if (t.empty()) return false;
    char* end = nullptr;
    std::strtod(t.c_str(), &end);
    return end == t.c_str() + t.size();
  };
  size_t pos = 0;
  auto next = [&](std::string& token, size_t& start) {
    while (pos < line.size() && space(line[pos])) ++pos;
    start = pos;
    while (pos < line.size() && !space(line[pos])) ++pos;
    token = line.substr(start, pos - start);
    return !token.empty();
  };
  std::string key, token;
  size_t start = 0;
  if (!next(key, start)) return line;
  static const std::set<std::string> kTextureKeys = {"bump", "norm", "disp", "decal", "refl"};
  if (key.rfind("map_", 0) != 0 && !kTextureKeys.count(key)) return line;
  std::string out = key;
  bool changed = false;
  for (;;) {
    size_t before = pos;
    if (!next(token, start)) break;
    int most = token == "-o" || token == "-s" || token == "-t" ? 3 : token == "-mm" ? 2 : 0;
    int fixed = token == "-bm" || token == "-boost" || token == "-texres" || token == "-imfchan" || token == "-type" ||
                        token == "-blendu" || token == "-blendv" || token == "-clamp" || token == "-cc"
                    ? 1
                    : 0;
    if (most == 0 && fixed == 0) {
      out += line.substr(before);  // the file name and whatever follows it, as written
      pos = line.size();
      break;
    }
    out += " " + token;
    if (fixed) {
      if (next(token, start)) out += " " + token;
      continue;
    }
    int given = 0;
    for (; given < most; ++given) {
      size_t back = pos;
      std::string value;
      if (!next(value, start) || !is_number(value)) {
        pos = back;
        break;
      }
      out += " " + value;
    }
    if (given < most) changed = true;
    if (given == 0) notes.push_back(path + ":" + std::to_string(number) + ": " + quote(key) + " option " + quote(token) +
                                    " without a number; read as its default");
    for (int k = given; k < most; ++k) {
      const bool scale = token == "-s" || (token == "-mm" && k == 1);
      out += scale ? " 1" : " 0";
    }
  }
  return changed ? out : line;
}

// `text` with every texture statement's options completed (complete_texture_options).
std::string complete_all_texture_options(const std::string& text, const std::string& path, std::vector<std::string>& notes) {
  std::string out;
  size_t pos = 0;
  int number = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    size_t stop = end == std::string::npos ? text.size() : end + 1;
    ++number;
    std::string line = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    out += complete_texture_options(line, path, number, notes);
    if (end != std::string::npos) out += '\n';
    pos = stop;
  }
  return out;
}

// tinyobjloader asks its MaterialReader for each name of an `mtllib` line in turn until one loads.
// This one validates exactly the file tinyobjloader then parses, from the same bytes, and refuses
// what is not a regular file; tinyobjloader's own reader would split its search path at ':' and
// open a FIFO.
class CheckedMaterialReader : public tinyobj::MaterialReader {
 public:
  CheckedMaterialReader(SceneBuilder& scene, fs::path dir, std::set<std::string>& unsupported, MtlScan& facts)
      : scene_(scene), dir_(std::move(dir)), unsupported_(unsupported), facts_(facts) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* names, std::string* warn, std::string* err) override {
    fs::path path = dir_ / name;
    if (name.empty() || file_kind(path.string()) == FileKind::kMissing) {
      missing.push_back(name);
      return false;
    }
    std::string text = read_whole_file(path.string(), kMaxMtlBytes, "a material library");
    validate_mtl(path.string(), text, unsupported_, &facts_);
    auto unnamed = facts_.find("");
    if (unnamed != facts_.end() && unnamed->second.file == path.string()) {
      // tinyobjloader ignores a 'newmtl' without a name (and would merge its keys into the
      // material before); it is read under a name of its own instead.
      text = name_unnamed_materials(text);
      scene_.notes.push_back(path.string() + ":" + std::to_string(unnamed->second.line) +
                             ": 'newmtl' without a name (as Blender 2.6x writes); loaded as material " + quote(kUnnamedMaterial));
      facts_.erase(unnamed);
    }
    text = complete_all_texture_options(text, path.string(), scene_.notes);
    std::istringstream in(text);
    tinyobj::LoadMtl(names, materials, &in, warn, err);
    scene_.inputs.push_back(path.string());
    loaded.insert(name);
    return true;
  }

  std::vector<std::string> missing;
  std::set<std::string> loaded;

 private:
  SceneBuilder& scene_;
  fs::path dir_;
  std::set<std::string>& unsupported_;
  MtlScan& facts_;
};

// The material names tinyobjloader reported as undefined when a `usemtl` named them.
std::set<std::string> undefined_materials(const std::string& warnings) {
  std::set<std::string> names;
  const std::string open = "material [ '", close = "' ] not found in .mtl";
  for (size_t at = warnings.find(open); at != std::string::npos; at = warnings.find(open, at + 1)) {
    size_t end = warnings.find(close, at + open.size());
    if (end == std::string::npos) break;
    names.insert(warnings.substr(at + open.size(), end - at - open.size()));
  }
  return names;
}

std::string join(const std::set<std::string>& items) { return join_names(items); }

}  // namespace

void load_obj(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material, Mesh* into) {
  require_regular_file(path, "an OBJ file");
  ObjScan scan = validate_obj(path);
  scene.inputs.push_back(path);
  fs::path dir = fs::path(path).parent_path();
  std::set<std::string> unsupported_mtl;
  MtlScan mtl_facts;
  CheckedMaterialReader material_reader(scene, dir, unsupported_mtl, mtl_facts);

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> mtls;
  std::string warnings, errors;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open the file");
  if (!tinyobj::LoadObj(&attrib, &shapes, &mtls, &warnings, &errors, &in, &material_reader, /*triangulate=*/true,
                        /*default_vcols_fallback=*/false)) {
    std::string message = errors;
    while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
    throw Error(path, message.empty() ? "cannot parse" : message);
  }

  for (const std::string& lib : material_reader.missing) {
    scene.notes.push_back(path + ": material library " + quote(lib) + " not found; its faces use the default material");
  }
  std::set<std::string> unread;
  for (const std::string& lib : scan.mtllib_names) {
    bool missing = std::find(material_reader.missing.begin(), material_reader.missing.end(), lib) != material_reader.missing.end();
    if (!missing && !material_reader.loaded.count(lib)) unread.insert(lib);
  }
  if (!unread.empty()) {
    std::set<std::string> quoted;
    for (const std::string& lib : unread) quoted.insert(quote(lib));
    scene.notes.push_back(path + ": not read: " + join(quoted) +
                          " (of several libraries on one 'mtllib' line only the first that exists is read)");
  }
  // tinyobjloader looks a `usemtl` name up among the libraries read so far.
  std::set<std::string> undefined, early;
  for (const std::string& name : undefined_materials(warnings)) {
    auto at = scan.usemtl_lines.find(name);
    std::string described = quote(name) + (at != scan.usemtl_lines.end() ? " (line " + std::to_string(at->second) + ")" : "");
    bool defined_later = std::any_of(mtls.begin(), mtls.end(), [&](const tinyobj::material_t& m) { return m.name == name; });
    (defined_later ? early : undefined).insert(described);
  }
  if (!undefined.empty()) {
    scene.notes.push_back(path + ": usemtl names a material that no material library defines: " + join(undefined) +
                          "; its faces use the default material");
  }
  if (!early.empty()) {
    scene.notes.push_back(path + ": usemtl names a material before the 'mtllib' that defines it: " + join(early) +
                          "; those faces use the default material");
  }
  if (scan.normals_missing_line > 0) {
    scene.notes.push_back(path + ":" + std::to_string(scan.normals_missing_line) +
                          ": faces name normals but the file has none; loaded without them (flat shading)");
  }
  if (scan.uvs_missing_line > 0) {
    scene.notes.push_back(path + ":" + std::to_string(scan.uvs_missing_line) +
                          ": faces name texture coordinates but the file has none; loaded without them");
  }
  if (!scan.unsupported.empty()) {
    scene.notes.push_back(path + ": ignoring OBJ statements not supported: " + join(scan.unsupported));
  }
  if (!unsupported_mtl.empty()) {
    scene.notes.push_back(path + ": ignoring MTL keys not supported: " + join(unsupported_mtl));
  }

  Mesh& mesh = into ? *into : scene.mesh;
  uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  size_t nverts = attrib.vertices.size() / 3;
  for (size_t i = 0; i < nverts; ++i) {
    Vec3f p{attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
    mesh.positions.push_back(transform.point(p));
  }

  // Materials: the MTL's, then the default for faces without one.
  std::vector<uint32_t> material_map(mtls.size());
  for (size_t i = 0; i < mtls.size(); ++i) {
    auto found = mtl_facts.find(mtls[i].name);
    const MtlFacts* facts = found == mtl_facts.end() ? nullptr : &found->second;
    Material m = convert_material(mtls[i], facts, path, scene.notes);
    // The colour map_Kd scales: the diffuse albedo of the models that have one.
    Spectrum* kd = nullptr;
    int* kd_texture = nullptr;
    if (auto* d = std::get_if<Diffuse>(&m.model)) kd = &d->kd, kd_texture = &d->kd_texture;
    if (auto* g = std::get_if<Glossy>(&m.model)) kd = &g->kd, kd_texture = &g->kd_texture;
    if (auto* mr = std::get_if<MetallicRoughness>(&m.model)) {
      kd = &mr->base_color, kd_texture = &mr->base_color_texture;
      // map_Pr and map_Pm replace Pr and Pm (Blender writes one or the other), read as data.
      auto data_map = [&](const std::string& name, const tinyobj::texture_option_t& option, int line, const char* key,
                          float& factor, int& slot) {
        if (name.empty()) return;
        fs::path tex = dir / name;
        if (!fs::exists(tex)) {
          std::string place = facts ? facts->file + ":" + std::to_string(line) : path;
          scene.notes.push_back(place + ": texture " + quote(name) + " not found; material " + quote(m.name) + " keeps its " + key +
                                " " + number(factor));
          return;
        }
        slot = texture_index(scene, tex.string(), path, TextureEncoding::kData, mtl_placement(option));
        factor = 1.0f;
      };
      data_map(mtls[i].roughness_texname, mtls[i].roughness_texopt, facts ? facts->map_pr_line : 0, "Pr", mr->roughness, mr->roughness_texture);
      data_map(mtls[i].metallic_texname, mtls[i].metallic_texopt, facts ? facts->map_pm_line : 0, "Pm", mr->metallic, mr->metallic_texture);
    }
    if (!mtls[i].diffuse_texname.empty() && !kd) {
      scene.notes.push_back(where(mtls[i], facts, path) + ": map_Kd ignored: a " + m.type_name() +
                            " material has no diffuse colour");
    } else if (!mtls[i].diffuse_texname.empty()) {
      fs::path tex = dir / mtls[i].diffuse_texname;
      if (!fs::exists(tex)) {
        // Like a missing MTL: the model still renders, in its Kd colour.
        std::string place = facts ? facts->file + ":" + std::to_string(facts->map_kd_line) : path;
        scene.notes.push_back(place + ": texture '" + mtls[i].diffuse_texname + "' not found; material '" + m.name +
                              "' keeps its Kd colour (" + number(kd->x) + ", " + number(kd->y) + ", " +
                              number(kd->z) + ")");
      } else {
        // `-colorspace linear` (tinyobjloader's extension) marks a map stored linear.
        bool linear = mtls[i].diffuse_texopt.colorspace == "linear";
        *kd_texture = texture_index(scene, tex.string(), path, linear ? TextureEncoding::kData : TextureEncoding::kColour,
                                    mtl_placement(mtls[i].diffuse_texopt));
        *kd = Spectrum(1.0f);  // the map replaces Kd, as Blender's and pbrt's importers do
      }
    }
    add_mtl_normal_maps(scene, mtls[i], facts, dir.string(), path, m);
    // map_Ke: a colour texture multiplying Ke, as the MTL format's maps multiply their key. Blender's
    // exporter writes map_Ke and no Ke (the strength is lost) and its importer reads that as the
    // texture at strength 1, so without Ke the emission is the texture itself.
    if (!mtls[i].emissive_texname.empty()) {
      fs::path tex = dir / mtls[i].emissive_texname;
      std::string place = facts ? facts->file + ":" + std::to_string(facts->map_ke_line) : path;
      if (!fs::exists(tex)) {
        scene.notes.push_back(place + ": texture " + quote(mtls[i].emissive_texname) + " not found; material " +
                              quote(m.name) + (m.is_emissive() ? " emits its Ke" : " does not emit"));
      } else {
        m.emission_texture = texture_index(scene, tex.string(), path, TextureEncoding::kColour,
                                           mtl_placement(mtls[i].emissive_texopt));
        if (!m.is_emissive()) m.emission = Spectrum(1.0f);
        if (m.opacity < 1.0f) {
          m.opacity = 1.0f;
          scene.notes.push_back(place + ": emits light (map_Ke), so material " + quote(m.name) +
                                " is kept opaque (its d or Tr is ignored)");
        }
      }
    }
    if (facts && facts->ka_max > kLightLikeKa && !facts->has_ke && !m.is_emissive()) {
      scene.unlit_hints.push_back(where(mtls[i], facts, path) + " has Ka up to " + number(facts->ka_max) +
                                  " and no Ke: if it was meant as a light, give it Ke (pt does not use Ka)");
    }
    material_map[i] = scene.add_material(m);
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

}  // namespace pt
