// JSON scene files (format in scenes/README.md). Syntax errors carry file:line:column; semantic
// errors name the file and the JSON pointer of the offending value. Keys we do not know are
// reported once each, not silently dropped.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "core/scene/input_limits.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "core/util/file_extension.h"
#include "core/util/input_file.h"

namespace pt {
namespace fs = std::filesystem;
using nlohmann::json;
namespace {

struct Reader {
  std::string file;
  fs::path dir;
  SceneBuilder& scene;

  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    throw Error(file, where + ": " + message);
  }
  void check_keys(const json& j, const std::string& where, std::initializer_list<const char*> known) const {
    if (!j.is_object()) fail(where, "expected an object");
    for (const auto& [key, value] : j.items()) {
      bool ok = false;
      for (const char* k : known) ok = ok || key == k;
      if (!ok) scene.notes.push_back(file + ": " + where + ": unknown key " + quote(key) + " ignored");
    }
  }
  float number(const json& j, const std::string& where) const {
    if (!j.is_number()) fail(where, "expected a number");
    double v = j.get<double>();
    if (!std::isfinite(v) || std::abs(v) > 3.0e38) fail(where, "expected a finite number");
    return static_cast<float>(v);
  }
  float positive(const json& j, const std::string& where) const {
    float v = number(j, where);
    if (!(v > 0)) fail(where, "expected a positive number");
    return v;
  }
  int integer(const json& j, const std::string& where, long lo, long hi) const {
    if (!j.is_number_integer()) fail(where, "expected an integer");
    long v = j.get<long>();
    if (v < lo || v > hi) fail(where, "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
    return static_cast<int>(v);
  }
  std::string string(const json& j, const std::string& where) const {
    if (!j.is_string()) fail(where, "expected a string");
    return j.get<std::string>();
  }
  // A name from one of the settings' tables (render_settings.h), as its value.
  template <class E, size_t N>
  E name(const NameTable<E, N>& table, const json& j, const std::string& where) const {
    std::string text = string(j, where);
    if (!table.contains(text)) fail(where, "unknown " + std::string(table.what) + " " + quote(text) + " (" + table.list() + ")");
    return table.parse(text);
  }
  Vec3f vec3(const json& j, const std::string& where) const {
    if (!j.is_array() || j.size() != 3) fail(where, "expected an array of 3 numbers");
    return {number(j[0], where + "/0"), number(j[1], where + "/1"), number(j[2], where + "/2")};
  }
  // A colour is an RGB triple or one number for grey; never negative.
  Spectrum colour(const json& j, const std::string& where) const {
    Spectrum c = j.is_number() ? Spectrum(number(j, where)) : vec3(j, where);
    if (min_component(c) < 0) fail(where, "colour components must not be negative");
    if (max_component(c) > static_cast<float>(kMaxRadiance)) fail(where, std::string("colour components must be at most ") + kMaxRadianceText);
    return c;
  }
  std::string path(const json& j, const std::string& where) const {
    std::string p = string(j, where);
    if (p.empty()) fail(where, "empty file name");
    fs::path full = fs::path(p).is_absolute() ? fs::path(p) : dir / p;
    return full.lexically_normal().string();
  }

  // A texture slot: a file name, or {"file", "wrap" (or "wrap_s", "wrap_t"), "offset", "rotation",
  // "scale"}: KHR_texture_transform's placement, in glTF's uv (origin top-left).
  int texture(const json& j, const std::string& where, TextureEncoding encoding) {
    if (j.is_string()) return texture_index(scene, path(j, where), file, encoding);
    if (!j.is_object()) fail(where, "expected a file name or an object with 'file'");
    check_keys(j, where, {"file", "wrap", "wrap_s", "wrap_t", "offset", "rotation", "scale"});
    if (!j.contains("file")) fail(where, "needs 'file'");
    TextureBinding placement;
    auto wrap = [&](const char* key, TextureWrap& out) {
      if (j.contains(key)) out = name(kTextureWrapNames, j[key], where + "/" + key);
    };
    wrap("wrap", placement.wrap_s);
    wrap("wrap", placement.wrap_t);
    wrap("wrap_s", placement.wrap_s);
    wrap("wrap_t", placement.wrap_t);
    auto vec2 = [&](const char* key) {
      const json& v = j[key];
      std::string w = where + "/" + key;
      if (!v.is_array() || v.size() != 2) fail(w, "expected an array of 2 numbers");
      return Vec2f(number(v[0], w + "/0"), number(v[1], w + "/1"));
    };
    if (j.contains("offset")) placement.transform.offset = vec2("offset");
    if (j.contains("scale")) placement.transform.scale = vec2("scale");
    if (j.contains("rotation")) placement.transform.rotation = number(j["rotation"], where + "/rotation");
    return texture_index(scene, path(j["file"], where + "/file"), file, encoding, placement);
  }

  void read_camera(const json& j) {
    check_keys(j, "/camera", {"position", "look_at", "up", "fov", "ortho_height"});
    Camera c;
    if (j.contains("position")) c.position = vec3(j["position"], "/camera/position");
    if (j.contains("look_at")) c.look_at = vec3(j["look_at"], "/camera/look_at");
    if (j.contains("up")) c.up = vec3(j["up"], "/camera/up");
    if (j.contains("fov")) {
      c.vfov_degrees = number(j["fov"], "/camera/fov");
      if (!(c.vfov_degrees > 0 && c.vfov_degrees < 180)) fail("/camera/fov", "expected degrees in (0, 180)");
    }
    if (j.contains("ortho_height")) {
      c.ortho_height = positive(j["ortho_height"], "/camera/ortho_height");
      if (j.contains("fov")) fail("/camera/ortho_height", "an orthographic camera has no field of view: give 'fov' or 'ortho_height'");
    }
    Vec3f f = c.look_at - c.position;
    if (!(length(f) > 0)) fail("/camera", "position and look_at coincide");
    if (!(length(cross(f, c.up)) > 1e-6f * length(f) * length(c.up))) fail("/camera/up", "up is parallel to the view direction");
    scene.camera = c;
  }

  std::map<std::string, uint32_t> read_materials(const json& j) {
    std::map<std::string, uint32_t> ids;
    if (!j.is_object()) fail("/materials", "expected an object of named materials");
    for (const auto& [name, m] : j.items()) {
      std::string where = "/materials/" + cut(name);
      check_keys(m, where, {"type", "albedo", "texture", "specular", "exponent", "ior", "emission", "opacity", "base_color",
                            "base_color_texture", "metallic", "roughness", "metallic_roughness_texture", "roughness_texture",
                            "metallic_texture", "clearcoat", "clearcoat_roughness", "transmission", "normal_texture", "normal_scale",
                            "bump_texture", "bump_scale", "emission_texture"});
      Material mat;
      mat.name = name;
      std::string type = m.contains("type") ? string(m["type"], where + "/type") : "diffuse";
      if (type == "glass") type = "dielectric";  // aliases
      if (type == "principled") type = "metallic-roughness";
      if (!is_model_name(type)) fail(where + "/type", "unknown material type " + quote(type) + " (" + model_list() + ")");
      // The keys every model shared before models had files of their own are read (and checked)
      // whatever the type, so a scene that names a key its type ignores still loads.
      Spectrum kd{0.8f}, ks{type == "mirror" ? 1.0f : 0.2f};
      int kd_texture = -1;
      float exponent = 50.0f, ior = 1.5f;
      if (m.contains("albedo")) kd = colour(m["albedo"], where + "/albedo");
      if (m.contains("texture")) {
        kd_texture = texture(m["texture"], where + "/texture", TextureEncoding::kColour);
        if (!m.contains("albedo")) kd = Spectrum(1.0f);
      }
      if (m.contains("specular")) ks = colour(m["specular"], where + "/specular");
      if (m.contains("exponent")) exponent = number(m["exponent"], where + "/exponent");
      if (exponent < 0) fail(where + "/exponent", "must not be negative");
      if (m.contains("ior")) ior = positive(m["ior"], where + "/ior");
      if (type == "metallic-roughness") {
        MetallicRoughness mr;
        if (m.contains("base_color")) mr.base_color = colour(m["base_color"], where + "/base_color");
        if (max_component(mr.base_color) > 1.0f) fail(where + "/base_color", "exceeds 1: the material would create energy");
        if (m.contains("base_color_texture")) {
          mr.base_color_texture = texture(m["base_color_texture"], where + "/base_color_texture", TextureEncoding::kColour);
        }
        // Data textures (values, not colours: an 8-bit file is not sRGB-decoded).
        for (auto [key, slot] : {std::pair<const char*, int*>{"metallic_roughness_texture", &mr.metallic_roughness_texture},
                                 {"roughness_texture", &mr.roughness_texture},
                                 {"metallic_texture", &mr.metallic_texture}}) {
          if (m.contains(key)) *slot = texture(m[key], where + "/" + key, TextureEncoding::kData);
        }
        for (auto [key, field] : {std::pair<const char*, float*>{"metallic", &mr.metallic},
                                  {"roughness", &mr.roughness},
                                  {"clearcoat", &mr.clearcoat},
                                  {"clearcoat_roughness", &mr.clearcoat_roughness},
                                  {"transmission", &mr.transmission}}) {
          if (!m.contains(key)) continue;
          *field = number(m[key], where + "/" + key);
          if (!(*field >= 0.0f && *field <= 1.0f)) fail(where + "/" + key, "expected a number from 0 to 1");
        }
        mr.ior = ior;
        mat.model = mr;
      } else if (type == "glossy") {
        if (max_component(kd + ks) > 1.0f) fail(where, "albedo + specular exceeds 1 in some channel: the material would create energy");
        mat.model = Glossy{kd, kd_texture, ks, exponent};
      } else if (type == "mirror") {
        if (max_component(ks) > 1.0f) fail(where + "/specular", "exceeds 1");
        mat.model = Mirror{ks};
      } else {
        if (max_component(kd) > 1.0f) fail(where + "/albedo", "exceeds 1: the material would create energy");
        if (type == "dielectric") {
          mat.model = Dielectric{ior};
        } else {
          mat.model = Diffuse{kd, kd_texture};
        }
      }
      if (m.contains("normal_texture")) {
        mat.normal_texture = texture(m["normal_texture"], where + "/normal_texture", TextureEncoding::kData);
      }
      if (m.contains("normal_scale")) mat.normal_scale = number(m["normal_scale"], where + "/normal_scale");
      if (m.contains("bump_texture")) mat.bump_texture = texture(m["bump_texture"], where + "/bump_texture", TextureEncoding::kData);
      if (m.contains("bump_scale")) mat.bump_scale = number(m["bump_scale"], where + "/bump_scale");
      if (mat.normal_texture >= 0 && mat.bump_texture >= 0) {
        fail(where + "/bump_texture", "a material takes a normal_texture or a bump_texture, not both");
      }
      if (m.contains("emission")) mat.emission = colour(m["emission"], where + "/emission");
      if (m.contains("emission_texture")) {
        mat.emission_texture = texture(m["emission_texture"], where + "/emission_texture", TextureEncoding::kColour);
        if (!m.contains("emission")) mat.emission = Spectrum(1.0f);
      }
      if (m.contains("opacity")) {
        mat.opacity = number(m["opacity"], where + "/opacity");
        if (!(mat.opacity >= 0.0f && mat.opacity <= 1.0f)) fail(where + "/opacity", "expected a number from 0 to 1");
        if (mat.is_emissive() && mat.opacity < 1.0f) fail(where + "/opacity", "a material that emits light must be opaque");
      }
      ids[name] = scene.add_material(mat);
    }
    return ids;
  }

  uint32_t material_ref(const json& j, const std::string& where, const std::map<std::string, uint32_t>& ids) {
    std::string name = string(j, where);
    auto it = ids.find(name);
    if (it == ids.end()) fail(where, "unknown material " + quote(name));
    return it->second;
  }

  // scale, then rotate (degrees about x, then y, then z), then translate; or a row-major "matrix"
  // of 12 numbers (3 rows of 4) or 16 (the last row 0 0 0 1).
  Transform transform(const json& o, const std::string& where) const {
    Transform t;
    if (o.contains("matrix")) {
      if (o.contains("scale") || o.contains("rotate") || o.contains("translate")) {
        fail(where + "/matrix", "a 'matrix' replaces 'scale', 'rotate' and 'translate': give one or the other");
      }
      const json& m = o["matrix"];
      if (!m.is_array() || (m.size() != 12 && m.size() != 16)) fail(where + "/matrix", "expected an array of 12 or 16 numbers (rows of 4)");
      for (size_t i = 0; i < m.size(); ++i) {
        float v = number(m[i], where + "/matrix/" + std::to_string(i));
        if (i < 12) t.m[i / 4][i % 4] = v;
        else if (v != (i == 15 ? 1.0f : 0.0f)) fail(where + "/matrix/" + std::to_string(i), "the last row must be 0 0 0 1");
      }
    } else {
      if (o.contains("scale")) {
        Vec3f s = o["scale"].is_number() ? Vec3f(number(o["scale"], where + "/scale")) : vec3(o["scale"], where + "/scale");
        if (s.x == 0 || s.y == 0 || s.z == 0) fail(where + "/scale", "a zero scale flattens the object");
        t = Transform::scale(s);
      }
      if (o.contains("rotate")) {
        Vec3f r = vec3(o["rotate"], where + "/rotate");
        t = Transform::rotate_axis(2, r.z) * Transform::rotate_axis(1, r.y) * Transform::rotate_axis(0, r.x) * t;
      }
      if (o.contains("translate")) t = Transform::translate(vec3(o["translate"], where + "/translate")) * t;
    }
    std::string problem = instance_transform_problem(t);
    if (!problem.empty()) fail(where, problem);
    return t;
  }

  void read_object(const json& o, const std::string& where, const std::map<std::string, uint32_t>& ids) {
    check_keys(o, where, {"file", "translate", "rotate", "scale", "matrix", "material", "instances"});
    if (!o.contains("file")) fail(where, "an object needs a 'file'");
    std::string obj = path(o["file"], where + "/file");
    Transform t = transform(o, where);
    int override_material = o.contains("material") ? static_cast<int>(material_ref(o["material"], where + "/material", ids)) : -1;
    const std::string ext = lower_extension(obj);
    const bool gltf = ext == ".gltf" || ext == ".glb";
    if (ext != ".obj" && ext != ".ply" && !gltf) {
      fail(where + "/file", "unknown kind of object file " + quote(ext.empty() ? fs::path(obj).filename().string() : ext) +
                                " (pt reads .obj, .gltf, .glb and .ply)");
    }
    if (!o.contains("instances")) {
      if (ext == ".obj") load_obj(scene, obj, t, override_material);
      else if (ext == ".ply") load_ply(scene, obj, t, override_material);
      else load_gltf(scene, obj, t, override_material);
      return;
    }
    if (gltf) fail(where + "/instances", "a glTF file places its meshes by its own nodes; 'instances' takes OBJ and PLY files");
    // One mesh, placed once per entry: the object's own transform applies after each entry's.
    const json& list = o["instances"];
    if (!list.is_array() || list.empty()) fail(where + "/instances", "expected a non-empty array of transforms");
    std::vector<Transform> placements;
    placements.reserve(list.size());
    for (size_t i = 0; i < list.size(); ++i) {
      std::string at = where + "/instances/" + std::to_string(i);
      check_keys(list[i], at, {"translate", "rotate", "scale", "matrix"});
      Transform world = t * transform(list[i], at);
      std::string problem = instance_transform_problem(world);
      if (!problem.empty()) fail(at, problem + " (with the object's own transform)");
      placements.push_back(world);
    }
    Mesh object;
    if (ext == ".obj") load_obj(scene, obj, Transform(), override_material, &object);
    else load_ply(scene, obj, Transform(), override_material, &object);
    uint32_t id = scene.add_mesh(std::move(object));
    for (const Transform& world : placements) scene.add_instance(id, world);
  }

  void add_emitter(const std::vector<Vec3f>& corners, Spectrum radiance, const std::string& where) {
    Material m;
    m.name = "light" + where;
    m.model = Diffuse{Spectrum(0.0f)};
    m.emission = radiance;
    uint32_t id = scene.add_material(m);
    Mesh& mesh = scene.mesh;
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (const Vec3f& c : corners) mesh.positions.push_back(c);
    for (size_t k = 1; k + 1 < corners.size(); ++k) {
      mesh.indices.insert(mesh.indices.end(), {base, base + static_cast<uint32_t>(k), base + static_cast<uint32_t>(k + 1)});
      mesh.material.push_back(id);
      if (!mesh.corner_normals.empty()) mesh.corner_normals.insert(mesh.corner_normals.end(), 3, Vec3f(0.0f));
      if (!mesh.corner_uvs.empty()) {
        mesh.corner_uvs.insert(mesh.corner_uvs.end(), {Vec2f(0, 0), Vec2f(1, 0), Vec2f(1, 1)});
      }
    }
    Vec3f n = cross(corners[1] - corners[0], corners[2] - corners[0]);
    if (!(length(n) > 0)) fail(where + "/corners", "the light has zero area");
  }

  // A unit direction; any non-zero length is accepted.
  Vec3f direction(const json& j, const std::string& where) const {
    Vec3f d = vec3(j, where);
    float longest = max_component(vabs(d));
    if (!(longest > 0)) fail(where, "a direction must not be zero");
    return normalize(d / longest);  // scaled first, so that its squared length cannot overflow
  }
  // An angle in degrees from 0 to 90, returned in radians.
  float cone_angle(const json& j, const std::string& where) const {
    float degrees = number(j, where);
    if (!(degrees >= 0 && degrees <= 90)) fail(where, "expected degrees from 0 to 90");
    return degrees * (kPi / 180.0f);
  }

  void read_light(const json& l, const std::string& where) {
    static const char* kTypes = "point, spot, directional, quad, triangle";
    if (!l.is_object() || !l.contains("type")) fail(where, std::string("a light needs a 'type' (") + kTypes + ")");
    std::string type = string(l["type"], where + "/type");
    if (type == "point") {
      check_keys(l, where, {"type", "position", "intensity"});
      if (!l.contains("position") || !l.contains("intensity")) fail(where, "a point light needs 'position' and 'intensity'");
      PointLight light;
      light.position = vec3(l["position"], where + "/position");
      light.intensity = colour(l["intensity"], where + "/intensity");
      scene.point_lights.push_back(light);
    } else if (type == "spot") {
      check_keys(l, where, {"type", "position", "direction", "intensity", "inner_angle", "outer_angle"});
      if (!l.contains("position") || !l.contains("direction") || !l.contains("intensity")) {
        fail(where, "a spot light needs 'position', 'direction' and 'intensity'");
      }
      // KHR_lights_punctual's defaults: no inner cone, an outer cone of 45 degrees.
      float inner = l.contains("inner_angle") ? cone_angle(l["inner_angle"], where + "/inner_angle") : 0.0f;
      float outer = l.contains("outer_angle") ? cone_angle(l["outer_angle"], where + "/outer_angle") : kPi / 4;
      if (!(inner < outer)) fail(where + "/inner_angle", "the inner angle must be less than the outer angle");
      scene.spot_lights.emplace_back(vec3(l["position"], where + "/position"), direction(l["direction"], where + "/direction"),
                                     colour(l["intensity"], where + "/intensity"), inner, outer);
    } else if (type == "directional") {
      check_keys(l, where, {"type", "direction", "irradiance"});
      if (!l.contains("direction") || !l.contains("irradiance")) fail(where, "a directional light needs 'direction' and 'irradiance'");
      DirectionalLight light;
      light.direction = direction(l["direction"], where + "/direction");
      light.irradiance = colour(l["irradiance"], where + "/irradiance");
      scene.directional_lights.push_back(light);
    } else if (type == "quad" || type == "triangle") {
      check_keys(l, where, {"type", "corners", "radiance"});
      size_t n = type == "quad" ? 4 : 3;
      if (!l.contains("corners") || !l["corners"].is_array() || l["corners"].size() != n) {
        fail(where + "/corners", "a " + type + " light needs " + std::to_string(n) + " corners");
      }
      if (!l.contains("radiance")) fail(where, "an area light needs 'radiance'");
      std::vector<Vec3f> corners;
      for (size_t i = 0; i < n; ++i) corners.push_back(vec3(l["corners"][i], where + "/corners/" + std::to_string(i)));
      add_emitter(corners, colour(l["radiance"], where + "/radiance"), where);
    } else {
      fail(where + "/type", "unknown light type " + quote(type) + " (" + kTypes + ")");
    }
  }

  void read_environment(const json& e) {
    check_keys(e, "/environment", {"radiance", "file", "scale", "rotation"});
    if (e.contains("file")) {
      std::string image = path(e["file"], "/environment/file");
      float scale = e.contains("scale") ? number(e["scale"], "/environment/scale") : 1.0f;
      if (scale < 0) fail("/environment/scale", "must not be negative");
      float rotation = e.contains("rotation") ? number(e["rotation"], "/environment/rotation") : 0.0f;
      scene.environment = Environment(environment_image(scene, image, file), scale, rotation);
    } else if (e.contains("radiance")) {
      scene.environment = Environment(colour(e["radiance"], "/environment/radiance"));
    } else {
      fail("/environment", "needs 'radiance' or 'file'");
    }
  }

  void read_render(const json& r) {
    check_keys(r, "/render", {"resolution", "spp", "integrator", "seed", "shadow_rays", "max_depth", "strategy", "sampler"});
    RenderSettings& s = scene.settings;
    if (r.contains("resolution")) {
      const json& res = r["resolution"];
      if (!res.is_array() || res.size() != 2) fail("/render/resolution", "expected [width, height]");
      s.width = integer(res[0], "/render/resolution/0", 1, RenderSettings::kMaxSide);
      s.height = integer(res[1], "/render/resolution/1", 1, RenderSettings::kMaxSide);
      if (!RenderSettings::valid_resolution(s.width, s.height)) {
        fail("/render/resolution", "the image may hold at most " + std::to_string(RenderSettings::kMaxPixels >> 20) + " Mpixels");
      }
    }
    if (r.contains("spp")) s.spp = integer(r["spp"], "/render/spp", 1, 1 << 24);
    if (r.contains("integrator")) s.integrator = name(kIntegratorNames, r["integrator"], "/render/integrator");
    if (r.contains("seed")) s.seed = static_cast<uint64_t>(integer(r["seed"], "/render/seed", 0, INT32_MAX));
    if (r.contains("shadow_rays")) s.shadow_rays = integer(r["shadow_rays"], "/render/shadow_rays", 1, 1024);
    if (r.contains("max_depth")) s.max_depth = integer(r["max_depth"], "/render/max_depth", 1, 1024);
    if (r.contains("strategy")) s.strategy = name(kStrategyNames, r["strategy"], "/render/strategy");
    if (r.contains("sampler")) s.sampler = name(kSamplerNames, r["sampler"], "/render/sampler");
  }
};

std::string cut_message(const std::string& message) {
  constexpr size_t kMax = 240;
  return message.size() <= kMax ? message : message.substr(0, kMax) + "... (" + std::to_string(message.size()) + " bytes)";
}

std::pair<int, int> line_and_column(const std::string& text, size_t byte) {
  int line = 1, column = 1;
  for (size_t i = 0; i < text.size() && i + 1 < byte; ++i) {
    if (text[i] == '\n') ++line, column = 1;
    else ++column;
  }
  return {line, column};
}

// nlohmann::json keeps the last of two equal keys in an object without a word: a scene with two
// "camera" blocks, or a sphere with two "radius" keys, would silently lose the first. The parser's
// callback sees every key; this records the JSON pointer of the first repeated one.
class DuplicateKeys {
 public:
  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    using E = json::parse_event_t;
    switch (event) {
      case E::object_start: frames_.emplace_back(true); break;
      case E::array_start: frames_.emplace_back(false); break;
      case E::key:
        if (!frames_.empty()) {
          Frame& f = frames_.back();
          f.key = parsed.get<std::string>();
          if (!f.keys.insert(f.key).second && first_.empty()) first_ = pointer();
        }
        break;
      case E::object_end:
      case E::array_end:
        if (!frames_.empty()) frames_.pop_back();
        element_done();
        break;
      case E::value: element_done(); break;
    }
    return true;
  }
  // The pointer of the first repeated key, or empty.
  const std::string& first() const { return first_; }

 private:
  struct Frame {
    explicit Frame(bool is_object) : object(is_object) {}
    bool object;
    std::string key;  // an object's current key
    size_t index = 0;  // an array's current element
    std::set<std::string> keys;
  };
  void element_done() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  std::string pointer() const {
    std::string p;
    for (const Frame& f : frames_) {
      p += '/';
      if (!f.object) {
        p += std::to_string(f.index);
        continue;
      }
      for (char c : f.key) p += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
    }
    return p;
  }
  std::vector<Frame> frames_;
  std::string first_;
};

}  // namespace

void load_scene_file(SceneBuilder& scene, const std::string& file) {
  // Scene files place geometry; the geometry itself lives in OBJs. The cap keeps a wrong file
  // (or a sparse one) from being read whole into memory.
  std::string text = read_whole_file(file, kMaxSceneFileBytes, "a scene file");
  scene.inputs.push_back(file);
  json doc;
  DuplicateKeys duplicates;
  try {
    doc = json::parse(text, std::ref(duplicates));
  } catch (const json::parse_error& e) {
    auto [line, column] = line_and_column(text, e.byte);
    std::string what = e.what();
    size_t at = what.find("syntax error");
    // The parser quotes what it last read, which may be a megabyte-long token.
    throw Error(file, line, "column " + std::to_string(column) + ": " + cut_message(at != std::string::npos ? what.substr(at) : what));
  } catch (const json::exception& e) {
    // The parser throws out_of_range (not parse_error) for a number like 1e999, without a position.
    std::string what = e.what();
    size_t at = what.find("] ");
    throw Error(file, cut_message(at != std::string::npos ? what.substr(at + 2) : what));
  }
  if (!duplicates.first().empty()) {
    throw Error(file, duplicates.first() + ": the key appears twice in its object (JSON keeps only the last)");
  }
  if (!doc.is_object()) throw Error(file, "a scene file is a JSON object");
  Reader r{file, fs::path(file).parent_path(), scene};
  r.check_keys(doc, "/", {"camera", "materials", "objects", "spheres", "lights", "environment", "render"});
  try {
    if (doc.contains("render")) r.read_render(doc["render"]);
    if (doc.contains("camera")) r.read_camera(doc["camera"]);
    std::map<std::string, uint32_t> ids;
    if (doc.contains("materials")) ids = r.read_materials(doc["materials"]);
    if (doc.contains("objects")) {
      if (!doc["objects"].is_array()) r.fail("/objects", "expected an array");
      for (size_t i = 0; i < doc["objects"].size(); ++i) r.read_object(doc["objects"][i], "/objects/" + std::to_string(i), ids);
    }
    if (doc.contains("spheres")) {
      if (!doc["spheres"].is_array()) r.fail("/spheres", "expected an array");
      for (size_t i = 0; i < doc["spheres"].size(); ++i) {
        std::string where = "/spheres/" + std::to_string(i);
        const json& s = doc["spheres"][i];
        r.check_keys(s, where, {"center", "radius", "material"});
        if (!s.contains("center") || !s.contains("radius")) r.fail(where, "a sphere needs 'center' and 'radius'");
        Sphere sphere;
        sphere.center = r.vec3(s["center"], where + "/center");
        sphere.radius = r.positive(s["radius"], where + "/radius");
        sphere.material = s.contains("material") ? r.material_ref(s["material"], where + "/material", ids) : scene.default_material();
        scene.spheres.push_back(sphere);
      }
    }
    if (doc.contains("lights")) {
      if (!doc["lights"].is_array()) r.fail("/lights", "expected an array");
      for (size_t i = 0; i < doc["lights"].size(); ++i) r.read_light(doc["lights"][i], "/lights/" + std::to_string(i));
    }
    if (doc.contains("environment")) r.read_environment(doc["environment"]);
  } catch (const json::exception& e) {
    throw Error(file, e.what());
  }
}

}  // namespace pt
