// A glTF 2.0 scene put into pt's: the default scene (or the first), its node hierarchy with
// matrices or TRS, triangle primitives (lists, strips, fans; indexed or not), materials, the
// first camera (or the one --camera names) and KHR_lights_punctual lights.
//
// Units of KHR_lights_punctual: point and spot intensities are in candela (lm/sr), directional
// ones in lux (lm/m^2). pt's are radiometric (W/sr for point and spot lights, W/m^2 of irradiance
// for directional ones, and radiance in W/(m^2 sr), as the environment maps it is lit by), so
// they are divided by 683 lm/W, the luminous efficacy at 555 nm that defines the candela;
// Blender's glTF importer converts with the same constant. A spot's cone angles are the
// extension's (radians from the axis) and its falloff is the one SpotLight implements.
//
// Each glTF mesh becomes one object-space mesh (SceneBuilder::add_mesh) and each node that uses it
// an instance of it (add_instance): a mesh used by several nodes is stored once.
#include <array>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/geometry/instance.h"
#include "core/scene/gltf_accessor.h"
#include "core/scene/gltf_draco.h"
#include "core/scene/gltf_file.h"
#include "core/scene/loader.h"
#include "core/util/error.h"

namespace pt {
namespace {

constexpr double kLumensPerWatt = 683.0;

using Mat4 = std::array<double, 16>;  // column-major, as glTF writes matrices

Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  }
  return r;
}

// The node's local transform: its matrix, or T * R * S (glTF 2.0 section 3.5.3).
Mat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) {
    Mat4 m;
    for (int i = 0; i < 16; ++i) m[i] = n.matrix[i];
    return m;
  }
  Mat4 m = identity();
  if (n.scale.size() == 3) {
    for (int i = 0; i < 3; ++i) m[i * 5] = n.scale[i];
  }
  if (n.rotation.size() == 4) {
    double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    double l = std::sqrt(x * x + y * y + z * z + w * w);
    x /= l, y /= l, z /= l, w /= l;
    Mat4 r = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),     0,
              2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),     0,
              2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y), 0,
              0,                       0,                       0,                       1};
    m = multiply(r, m);
  }
  if (n.translation.size() == 3) {
    for (int i = 0; i < 3; ++i) m[12 + i] = n.translation[i];
  }
  return m;
}

Transform to_transform(const Mat4& m) {
  Transform t;
  for (int row = 0; row < 3; ++row) {
    for (int c = 0; c < 4; ++c) t.m[row][c] = static_cast<float>(m[c * 4 + row]);
  }
  return t;
}

struct Loader {
  Loader(SceneBuilder& s, const GltfFile& f, const Transform& t, int override, const GltfOptions& o)
      : scene(s), file(f), placement(t), override_material(override), options(o), m(f.model) {}
  SceneBuilder& scene;
  const GltfFile& file;
  const Transform& placement;
  int override_material;
  const GltfOptions& options;
  const tinygltf::Model& m;

  std::map<std::pair<int, int>, uint32_t> materials;  // (glTF material, uv set) -> pt material
  std::vector<int64_t> mesh_ids;                      // glTF mesh -> SceneBuilder mesh; -1 not yet, -2 no triangles
  std::vector<size_t> mesh_uses;                      // nodes that place each mesh
  std::vector<size_t> mesh_triangles;                 // triangles of one copy of each mesh
  size_t triangles = 0, skipped_primitives = 0, lights = 0;
  std::set<int> textures_used;
  bool rest_pose = false, other_uv_set = false, clearcoat_texture = false, transmission_texture = false;
  bool occlusion_texture = false;
  std::string missing_uvs;  // the first primitive whose material's textures name a uv set it lacks
  std::vector<std::pair<int, Mat4>> cameras;  // (camera, world matrix) in the order the nodes are met
  bool light_range = false;

  std::string where_primitive(int mesh, size_t k) const {
    return "/meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(k);
  }

  static TextureWrap wrap_mode(int gl) {
    switch (gl) {
      case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::kClamp;
      case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::kMirror;
      default: return TextureWrap::kRepeat;
    }
  }

  // A texture reference of a material (index, its KHR_texture_transform), as a texture slot: its
  // image registered once as colour or data, placed by its sampler's wrap modes and the transform.
  int texture(int index, const tinygltf::ExtensionMap& extensions, const std::string& where, TextureEncoding encoding) {
    int image = m.textures[index].source;
    if (image < 0) {
      scene.notes.push_back(file.path + ": " + where + ": texture " + std::to_string(index) + " has no image; the factor alone is used");
      return -1;
    }
    textures_used.insert(index);
    TextureBinding placement;
    int texcoord = -1;
    std::string problem = texture_transform(extensions, placement.transform, texcoord);
    if (!problem.empty()) throw Error(file.path, where + "/extensions/KHR_texture_transform" + problem);
    if (texcoord > 0) other_uv_set = true;
    if (int s = m.textures[index].sampler; s >= 0) {
      placement.wrap_s = wrap_mode(m.samplers[s].wrapS);
      placement.wrap_t = wrap_mode(m.samplers[s].wrapT);
    }
    const tinygltf::Image& img = m.images[image];
    if (!img.uri.empty()) {
      std::string name = gltf_uri_path(file.path, img.uri);
      return texture_index(scene, name, file.path + ": /images/" + std::to_string(image), encoding, placement);
    }
    auto bytes = file.embedded_images.find(image);
    if (bytes == file.embedded_images.end()) throw Error(file.path, "/images/" + std::to_string(image) + ": no image data");
    return texture_index_bytes(scene, file.path + "#/images/" + std::to_string(image), bytes->second, img.mimeType, encoding,
                               placement);
  }

  // The uv set a material's textures are read through: the base colour texture's, else the
  // metallicRoughnessTexture's.
  static int uv_set_of(const tinygltf::Material& g) {
    const auto& pbr = g.pbrMetallicRoughness;
    if (pbr.baseColorTexture.index >= 0) return pbr.baseColorTexture.texCoord;
    return pbr.metallicRoughnessTexture.index >= 0 ? pbr.metallicRoughnessTexture.texCoord : 0;
  }

  // glTF's material is pt's metallic-roughness model (core/material/metallic_roughness.h): the
  // factors, the base colour texture (colour) and metallicRoughnessTexture (data: B metallic,
  // G roughness), both read through one uv set (uv_set_of).
  uint32_t material(int index, int uv_set) {
    if (override_material >= 0) return static_cast<uint32_t>(override_material);
    if (index < 0) return scene.default_material();
    auto found = materials.find({index, uv_set});
    if (found != materials.end()) return found->second;
    const tinygltf::Material& g = m.materials[index];
    const auto& pbr = g.pbrMetallicRoughness;
    std::string where = "/materials/" + std::to_string(index);
    MetallicRoughness p;
    p.base_color = Spectrum(static_cast<float>(pbr.baseColorFactor[0]), static_cast<float>(pbr.baseColorFactor[1]),
                            static_cast<float>(pbr.baseColorFactor[2]));
    p.metallic = static_cast<float>(pbr.metallicFactor);
    p.roughness = static_cast<float>(pbr.roughnessFactor);
    float alpha = static_cast<float>(pbr.baseColorFactor[3]);
    int tex = pbr.baseColorTexture.index >= 0 ? texture(pbr.baseColorTexture.index, pbr.baseColorTexture.extensions,
                                                        where + "/pbrMetallicRoughness/baseColorTexture", TextureEncoding::kColour)
                                              : -1;
    p.base_color_texture = tex;
    if (const auto& mr = pbr.metallicRoughnessTexture; mr.index >= 0) {
      if (mr.texCoord != uv_set) {
        scene.notes.push_back(file.path + ": " + where + "/pbrMetallicRoughness/metallicRoughnessTexture: on TEXCOORD_" +
                              std::to_string(mr.texCoord) + " while the base colour uses TEXCOORD_" + std::to_string(uv_set) +
                              "; pt reads one uv set per material, so the factors alone are used");
      } else {
        // Linear data (B metallic, G roughness), read through the same filtered lookup as the colour.
        p.metallic_roughness_texture = texture(mr.index, mr.extensions, where + "/pbrMetallicRoughness/metallicRoughnessTexture",
                                               TextureEncoding::kData);
      }
    }
    p.ior = static_cast<float>(ior_of(g));
    GltfClearcoat coat = clearcoat_of(g);
    p.clearcoat = static_cast<float>(coat.factor);
    p.clearcoat_roughness = static_cast<float>(coat.roughness);
    if (coat.textured) clearcoat_texture = true;
    GltfTransmission transmission = transmission_of(g);
    p.transmission = static_cast<float>(transmission.factor);
    if (transmission.textured) transmission_texture = true;
    if (g.occlusionTexture.index >= 0) occlusion_texture = true;
    Material out;
    out.model = p;
    out.name = g.name.empty() ? "glTF material " + std::to_string(index) : g.name;
    // Alpha is coverage: the rest of the surface lets light through unchanged. MASK cuts the
    // factor's alpha times the texture's at alphaCutoff; BLEND takes it as a fraction.
    bool textured_alpha = false;
    if (tex >= 0) {
      const int channels = scene.textures.cache->info(scene.textures.bindings[tex].texture).channels;
      textured_alpha = channels == 2 || channels == 4;
    }
    if (g.alphaMode == "MASK") {
      out.opacity = textured_alpha ? alpha : (alpha >= g.alphaCutoff ? 1.0f : 0.0f);
      if (textured_alpha) out.alpha_texture = tex, out.alpha_cutoff = std::max(1e-6f, static_cast<float>(g.alphaCutoff));
    } else if (g.alphaMode == "BLEND") {
      out.opacity = alpha;
      if (textured_alpha) out.alpha_texture = tex;
    }
    double strength = emissive_strength(g);
    out.emission = Spectrum(static_cast<float>(g.emissiveFactor[0] * strength), static_cast<float>(g.emissiveFactor[1] * strength),
                            static_cast<float>(g.emissiveFactor[2] * strength));
    if (g.emissiveTexture.index >= 0 && max_component(out.emission) > 0) {
      out.emission_texture = texture(g.emissiveTexture.index, g.emissiveTexture.extensions, where + "/emissiveTexture",
                                     TextureEncoding::kColour);
    }
    if (g.normalTexture.index >= 0) {
      out.normal_texture = texture(g.normalTexture.index, g.normalTexture.extensions, where + "/normalTexture", TextureEncoding::kData);
      out.normal_scale = static_cast<float>(g.normalTexture.scale);
    }
    if (out.is_emissive() && out.is_partly_transparent()) {
      out.opacity = 1.0f;
      out.alpha_texture = -1;
      scene.notes.push_back(file.path + ": " + where + ": emits light, so it is kept opaque (its alpha is ignored)");
    }
    uint32_t id = scene.add_material(out);
    materials[{index, uv_set}] = id;
    return id;
  }

  // Appends primitive k of mesh `mesh_index` to `mesh`, in the mesh's own space.
  void primitive(int mesh_index, size_t k, Mesh& mesh) {
    const tinygltf::Primitive& p = m.meshes[mesh_index].primitives[k];
    std::string where = where_primitive(mesh_index, k);
    if (p.mode < TINYGLTF_MODE_TRIANGLES) {
      ++skipped_primitives;
      return;
    }
    if (!p.targets.empty()) rest_pose = true;
    auto attribute = [&](const char* name) {
      auto it = p.attributes.find(name);
      return it == p.attributes.end() ? -1 : it->second;
    };
    int position = attribute("POSITION");
    if (position < 0) {
      throw Error(file.path, where + "/attributes: no POSITION");
    }
    std::vector<float> positions = read_floats(file, position, "POSITION", {3}, 3);
    size_t vertices = positions.size() / 3;
    auto same_count = [&](int accessor, const char* name) {
      if (m.accessors[accessor].count != vertices) {
        throw Error(file.path, where + "/attributes/" + name + ": " + std::to_string(m.accessors[accessor].count) +
                                   " elements, but POSITION has " + std::to_string(vertices));
      }
    };
    std::vector<uint32_t> index;
    if (p.indices >= 0) {
      index = read_indices(file, p.indices, vertices);
    } else {
      index.resize(vertices);
      for (size_t i = 0; i < vertices; ++i) index[i] = static_cast<uint32_t>(i);
    }
    // Triangles from lists, strips and fans (glTF 2.0 section 3.7.2.1).
    std::vector<uint32_t> tri;
    size_t n = index.size();
    if (p.mode == TINYGLTF_MODE_TRIANGLES) {
      if (n % 3 != 0) throw Error(file.path, where + ": " + std::to_string(n) + " vertices is not a whole number of triangles");
      tri = index;
    } else if (n >= 3) {
      for (size_t i = 0; i + 2 < n; ++i) {
        if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
          tri.insert(tri.end(), {index[i], index[i + 1 + i % 2], index[i + 2 - i % 2]});
        } else {
          tri.insert(tri.end(), {index[i + 1], index[i + 2], index[0]});
        }
      }
    }
    int mat_index = p.material;
    int uv_set = mat_index >= 0 ? uv_set_of(m.materials[mat_index]) : 0;
    std::vector<float> normals, uvs, colors;
    if (int a = attribute("NORMAL"); a >= 0) {
      same_count(a, "NORMAL");
      normals = read_floats(file, a, "NORMAL", {3}, 3);
    }
    const char* uv_name = uv_set == 1 ? "TEXCOORD_1" : "TEXCOORD_0";
    if (int a = attribute(uv_name); a >= 0) {
      same_count(a, uv_name);
      uvs = read_floats(file, a, uv_name, {2}, 2);
    } else if (mat_index >= 0 && missing_uvs.empty() && override_material < 0) {
      const tinygltf::Material& g = m.materials[mat_index];
      if (g.pbrMetallicRoughness.baseColorTexture.index >= 0 || g.pbrMetallicRoughness.metallicRoughnessTexture.index >= 0 ||
          g.normalTexture.index >= 0 || g.emissiveTexture.index >= 0) {
        missing_uvs = where + ": material " + std::to_string(mat_index) + "'s textures use " + uv_name +
                      ", which the primitive does not have";
      }
    }
    if (int a = attribute("COLOR_0"); a >= 0 && override_material < 0) {
      same_count(a, "COLOR_0");
      colors = read_floats(file, a, "COLOR_0", {3, 4}, 3);
    }
    std::vector<float> tangents;
    if (int a = attribute("TANGENT"); a >= 0) {
      same_count(a, "TANGENT");
      tangents = read_floats(file, a, "TANGENT", {4}, 4);
    }
    const char* other_uv = uv_set == 1 ? "TEXCOORD_0" : "TEXCOORD_1";
    if (int a = attribute(other_uv); a >= 0) {
      same_count(a, other_uv);
      read_floats(file, a, other_uv, {2}, 1);
    }
    uint32_t material_id = material(mat_index, uv_set);

    const size_t first = mesh.triangle_count();
    const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (size_t i = 0; i < vertices; ++i) mesh.positions.push_back({positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]});
    if (!normals.empty() && mesh.corner_normals.empty()) mesh.corner_normals.assign(3 * first, Vec3f(0.0f));
    if (!uvs.empty() && mesh.corner_uvs.empty()) mesh.corner_uvs.assign(3 * first, Vec2f(0, 0));
    if (!colors.empty()) mesh.corner_colors.resize(3 * first, Spectrum(1.0f));
    if (!tangents.empty() && mesh.corner_tangents.empty()) {
      mesh.corner_tangents.assign(3 * first, Vec3f(0.0f));
      mesh.corner_tangent_signs.assign(3 * first, 1.0f);
    }
    for (size_t f = 0; f + 2 < tri.size(); f += 3) {
      for (int c = 0; c < 3; ++c) {
        uint32_t v = tri[f + c];
        mesh.indices.push_back(base + v);
        if (!normals.empty()) {
          Vec3f n{normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]};
          float l = length(n);
          mesh.corner_normals.push_back(l > 0 && std::isfinite(l) ? n / l : Vec3f(0.0f));
        }
        // glTF puts v = 0 at the image's top, pt (as OBJ) at its bottom.
        if (!uvs.empty()) mesh.corner_uvs.push_back({uvs[2 * v], 1.0f - uvs[2 * v + 1]});
        if (!colors.empty()) mesh.corner_colors.push_back({colors[3 * v], colors[3 * v + 1], colors[3 * v + 2]});
        if (!tangents.empty()) {
          // The bitangent is w * cross(normal, tangent) (glTF 2.0, "Meshes"): w is the handedness.
          mesh.corner_tangents.push_back({tangents[4 * v], tangents[4 * v + 1], tangents[4 * v + 2]});
          mesh.corner_tangent_signs.push_back(tangents[4 * v + 3] < 0 ? -1.0f : 1.0f);
        }
      }
      mesh.material.push_back(material_id);
    }
    if (!mesh.corner_normals.empty()) mesh.corner_normals.resize(3 * mesh.triangle_count(), Vec3f(0.0f));
    if (!mesh.corner_uvs.empty()) mesh.corner_uvs.resize(3 * mesh.triangle_count(), Vec2f(0, 0));
    if (!mesh.corner_tangents.empty()) {
      mesh.corner_tangents.resize(3 * mesh.triangle_count(), Vec3f(0.0f));
      mesh.corner_tangent_signs.resize(3 * mesh.triangle_count(), 1.0f);
    }
  }

  // A KHR_lights_punctual light at the node's origin; spot and directional lights shine down the
  // node's -z axis. Intensities are photometric (cd, or lux for directional lights), pt's
  // radiometric: divided by kLumensPerWatt. `range` is not used: pt's punctual lights fall off
  // with the inverse square everywhere (the extension allows that reading: range is a hint).
  void light(int index, int node, const Mat4& world) {
    const tinygltf::Light& l = m.lights[index];
    Spectrum color = l.color.size() == 3 ? Spectrum(static_cast<float>(l.color[0]), static_cast<float>(l.color[1]),
                                                    static_cast<float>(l.color[2]))
                                         : Spectrum(1.0f);
    Spectrum radiometric = color * static_cast<float>(l.intensity / kLumensPerWatt);
    if (l.range > 0) light_range = true;
    Transform t = placement * to_transform(world);
    Vec3f position = t.point({0, 0, 0});
    Vec3f axis = t.vector({0, 0, -1});
    if (l.type != "point" && !(length(axis) > 1e-20f && std::isfinite(length(axis)))) {
      throw Error(file.path, "/nodes/" + std::to_string(node) + ": the transform of a " + l.type + " light leaves it no direction");
    }
    if (l.type == "point") {
      PointLight out;
      out.position = position;
      out.intensity = radiometric;
      scene.point_lights.push_back(out);
    } else if (l.type == "spot") {
      scene.spot_lights.emplace_back(position, normalize(axis), radiometric, static_cast<float>(l.spot.innerConeAngle),
                                     static_cast<float>(l.spot.outerConeAngle));
    } else {
      DirectionalLight out;
      out.direction = normalize(axis);
      out.irradiance = radiometric;
      scene.directional_lights.push_back(out);
    }
    ++lights;
  }

  void node(int root) {
    // Depth-first without recursion: a chain of a million nodes must not overflow the stack.
    std::vector<std::pair<int, Mat4>> stack{{root, local_matrix(m.nodes[root])}};
    while (!stack.empty()) {
      auto [index, world] = stack.back();
      stack.pop_back();
      const tinygltf::Node& n = m.nodes[index];
      if (n.skin >= 0) rest_pose = true;
      if (n.mesh >= 0) {
        if (mesh_ids[n.mesh] < 0) {
          Mesh object;
          for (size_t k = 0; k < m.meshes[n.mesh].primitives.size(); ++k) primitive(n.mesh, k, object);
          mesh_triangles[n.mesh] = object.triangle_count();
          mesh_ids[n.mesh] = object.triangle_count() > 0 ? static_cast<int64_t>(scene.add_mesh(std::move(object))) : -2;
        }
        Transform t = placement * to_transform(world);
        if (std::string problem = instance_transform_problem(t); !problem.empty()) {
          throw Error(file.path, "/nodes/" + std::to_string(index) + ": " + problem);
        }
        if (mesh_ids[n.mesh] >= 0) scene.add_instance(static_cast<uint32_t>(mesh_ids[n.mesh]), t);
        ++mesh_uses[n.mesh];
        triangles += mesh_triangles[n.mesh];
      }
      if (n.camera >= 0) cameras.push_back({n.camera, world});
      if (int l = node_light(n); l >= 0) light(l, index, world);
      for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) {
        stack.push_back({*c, multiply(world, local_matrix(m.nodes[*c]))});
      }
    }
  }

  void camera() {
    if (!options.take_camera) return;
    const std::pair<int, Mat4>* chosen = nullptr;
    for (const auto& c : cameras) {
      if (!chosen && (options.camera < 0 || c.first == options.camera)) chosen = &c;
    }
    if (options.camera >= 0 && !chosen) {
      throw Error(file.path, "--camera " + std::to_string(options.camera) + ": " +
                                 (options.camera < static_cast<int>(m.cameras.size()) ? "no node of the scene places that camera"
                                                                                      : "the file has " + std::to_string(m.cameras.size()) + " cameras"));
    }
    if (!chosen) return;
    const tinygltf::Camera& c = m.cameras[chosen->first];
    std::string where = "/cameras/" + std::to_string(chosen->first);
    Transform t = placement * to_transform(chosen->second);
    Camera cam;
    cam.position = t.point({0, 0, 0});
    cam.look_at = cam.position + normalize(t.vector({0, 0, -1}));
    cam.up = normalize(t.vector({0, 1, 0}));
    double aspect = c.perspective.aspectRatio;
    if (c.type == "orthographic") {
      // ymag is half the film's height in the camera node's space: scaled as the node is.
      cam.ortho_height = static_cast<float>(2.0 * std::abs(c.orthographic.ymag)) * length(t.vector({0, 1, 0}));
      aspect = std::abs(c.orthographic.xmag / c.orthographic.ymag);
      if (!(cam.ortho_height > 0 && std::isfinite(cam.ortho_height))) {
        throw Error(file.path, where + "/orthographic/ymag: the film's height is not a positive finite size after the node's transform");
      }
    } else {
      cam.vfov_degrees = static_cast<float>(c.perspective.yfov * 180.0 / M_PI);
    }
    if (!(length(cross(cam.look_at - cam.position, cam.up)) > 1e-6f)) throw Error(file.path, where + ": the node's transform is degenerate");
    scene.camera = cam;
    if (std::isfinite(aspect) && aspect > 0) {
      RenderSettings& s = scene.settings;
      int width = static_cast<int>(std::lround(s.height * aspect));
      if (RenderSettings::valid_resolution(width, s.height) && width >= 1) s.width = width;
    }
  }

  void run() {
    mesh_ids.assign(m.meshes.size(), -1);
    mesh_uses.assign(m.meshes.size(), 0);
    mesh_triangles.assign(m.meshes.size(), 0);
    int s = m.defaultScene >= 0 ? m.defaultScene : (m.scenes.empty() ? -1 : 0);
    std::vector<int> roots;
    if (s >= 0) {
      roots = m.scenes[s].nodes;
    } else {
      // No scene: every node without a parent (the validator has made sure there is a tree).
      std::vector<bool> child(m.nodes.size(), false);
      for (const tinygltf::Node& n : m.nodes) {
        for (int c : n.children) child[c] = true;
      }
      for (size_t i = 0; i < m.nodes.size(); ++i) {
        if (!child[i]) roots.push_back(static_cast<int>(i));
      }
    }
    for (int r : roots) node(r);
    camera();
    if (skipped_primitives > 0) {
      scene.notes.push_back(file.path + ": " + std::to_string(skipped_primitives) +
                            " points or lines primitives skipped (pt renders surfaces)");
    }
    if (triangles == 0) throw Error(file.path, "the glTF scene has no triangles (" +
                                                   std::string(skipped_primitives ? "only points or lines" : "no mesh in its nodes") + ")");
    if (rest_pose) scene.notes.push_back(file.path + ": morph targets and skins are rendered in their rest pose");
    if (clearcoat_texture) {
      scene.notes.push_back(file.path + ": KHR_materials_clearcoat textures are not used (clearcoatFactor and clearcoatRoughnessFactor are)");
    }
    if (transmission_texture) {
      scene.notes.push_back(file.path + ": KHR_materials_transmission's transmissionTexture is not used (transmissionFactor is)");
    }
    if (occlusion_texture) {
      scene.notes.push_back(file.path + ": occlusionTexture is not used (a path tracer finds the occlusion itself)");
    }
    if (!missing_uvs.empty()) {
      scene.notes.push_back(file.path + ": " + missing_uvs + " (its textures have no uvs to follow: export the mesh with them)");
    }
    if (other_uv_set) {
      scene.notes.push_back(file.path + ": KHR_texture_transform's texCoord is not used (each mesh carries the uv set its base colour texture names)");
    }
    if (light_range) {
      scene.notes.push_back(file.path + ": KHR_lights_punctual 'range' is not used (pt's lights fall off with the inverse square)");
    }
    summarize();
  }

  void summarize() {
    size_t meshes = 0, instances = 0, before = 0;
    for (size_t i = 0; i < mesh_uses.size(); ++i) {
      if (mesh_uses[i] == 0) continue;
      ++meshes;
      instances += mesh_uses[i];
      before += mesh_triangles[i];
    }
    std::string used, ignored;
    for (const std::string& e : m.extensionsUsed) {
      std::string& list = gltf_extension_supported(e) ? used : ignored;
      list += ' ';
      list += cut(e);
    }
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on long chains of + here.
    std::string line = file.path;
    line += ": glTF: " + std::to_string(meshes);
    line += " meshes placed by " + std::to_string(instances);
    line += " nodes (instances); " + std::to_string(before);
    line += " triangles in the meshes, " + std::to_string(triangles);
    line += " after instancing; " + std::to_string(materials.size());
    line += " materials, " + std::to_string(textures_used.size());
    line += " textures, " + std::to_string(lights);
    line += " lights (" + std::to_string(m.lights.size());
    line += " in the file), " + std::to_string(m.cameras.size());
    line += " cameras; extensions used:";
    line += used.empty() ? std::string(" none") : used;
    line += "; ignored:";
    line += ignored.empty() ? std::string(" none") : ignored;
    scene.contents.push_back(line);
  }
};

}  // namespace

void load_gltf(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material,
               const GltfOptions& options) {
  GltfFile file = read_gltf(path);
  validate_gltf(file);
  decode_draco(file);
  scene.inputs.insert(scene.inputs.end(), file.inputs.begin(), file.inputs.end());
  scene.notes.insert(scene.notes.end(), file.notes.begin(), file.notes.end());
  Loader{scene, file, transform, override_material, options}.run();
}

}  // namespace pt
