// `pt gen dense OUT.obj` and `pt gen scan OUT.obj`: write the benchmark meshes of scenes/dense and
// scenes/scan (see gen_dense.h, gen_scan.h), so the repository ships short procedures instead of
// large OBJs; `pt gen instances OUT.json` writes a large instanced scene (gen_instances.h).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/geometry/icosphere.h"
#include "core/util/error.h"
#include "core/util/output_file.h"
#include "renderer/commands/commands.h"
#include "renderer/tools/gen_dense.h"
#include "renderer/tools/gen_instances.h"
#include "renderer/tools/gen_obj.h"
#include "renderer/tools/gen_scan.h"

namespace pt {
namespace {

// Smooth radial relief: three octaves of products of sines of the unit direction.
float relief(const Vec3f& d) {
  float r = 0.5f * std::sin(6.0f * d.x + 0.3f) * std::sin(7.0f * d.y + 1.1f) * std::sin(5.0f * d.z + 0.7f);
  r += 0.3f * std::sin(17.0f * d.x + 2.0f) * std::sin(19.0f * d.y + 0.4f) * std::sin(23.0f * d.z + 1.7f);
  r += 0.2f * std::sin(53.0f * d.x + 0.9f) * std::sin(47.0f * d.y + 2.3f) * std::sin(59.0f * d.z + 0.2f);
  return r;
}

}  // namespace

void add_displaced_icosphere(Mesh& mesh, int level, const Vec3f& center, float radius, float amplitude,
                             uint32_t material) {
  if (level < 0 || level > 10) throw Error("icosphere level must be 0 to 10");
  std::vector<Vec3f> verts;
  std::vector<uint32_t> tris;
  unit_icosphere(level, verts, tris);
  uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  for (const Vec3f& d : verts) mesh.positions.push_back(center + d * (radius * (1.0f + amplitude * relief(d))));
  for (uint32_t i : tris) mesh.indices.push_back(base + i);
  mesh.material.insert(mesh.material.end(), tris.size() / 3, material);
  if (!mesh.corner_normals.empty()) mesh.corner_normals.resize(mesh.indices.size());
  if (!mesh.corner_uvs.empty()) mesh.corner_uvs.resize(mesh.indices.size());
}

void write_mesh_obj(const std::string& path, const Mesh& mesh, const std::string& comment) {
  OutputFile out(path);  // never a half-written OBJ, never a device replaced, no temporary left
  out.write("# ");
  out.write(comment);
  out.write("\n");
  char line[128];
  for (const Vec3f& p : mesh.positions) {
    out.write(std::string_view(line, std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", p.x, p.y, p.z)));
  }
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    out.write(std::string_view(line, std::snprintf(line, sizeof line, "f %u %u %u\n", mesh.indices[3 * t] + 1,
                                                    mesh.indices[3 * t + 1] + 1, mesh.indices[3 * t + 2] + 1)));
  }
  out.commit();
}

void write_dense_obj(const std::string& path, int level) {
  Mesh mesh;
  add_displaced_icosphere(mesh, level, Vec3f(0.0f), 1.0f, 0.15f, 0);
  write_mesh_obj(path, mesh,
                 "pt gen dense --level " + std::to_string(level) + ": displaced icosphere, " +
                     std::to_string(mesh.triangle_count()) + " triangles");
}

void add_gen_command(CLI::App& app, Action& action) {
  CLI::App* gen = app.add_subcommand("gen", "Generate procedural benchmark meshes");
  gen->require_subcommand(1);
  CLI::App* dense = gen->add_subcommand("dense", "The displaced icosphere of scenes/dense (20 * 4^level triangles)");
  auto path = std::make_shared<std::string>();
  auto level = std::make_shared<int>(8);
  dense->add_option("output", *path, "Output .obj (scenes/dense/scene.json expects scenes/dense/dense.obj)")->required();
  dense->add_option("--level", *level, "Subdivision level (8: 1.3M triangles)")->check(CLI::Range(0, 10));
  dense->callback([&action, path, level] {
    action = [path, level] {
      write_dense_obj(*path, *level);
      std::fprintf(stderr, "pt: wrote %s\n", path->c_str());
      return 0;
    };
  });

  CLI::App* scan_cmd = gen->add_subcommand("scan", "The simulated range scan of scenes/scan (long thin triangles, holes, overlaps)");
  auto scan_path = std::make_shared<std::string>();
  auto scan = std::make_shared<ScanOptions>();
  scan_cmd->add_option("output", *scan_path, "Output .obj (scenes/scan/scene.json expects scenes/scan/scan.obj)")->required();
  scan_cmd->add_option("--views", scan->views, "Scanner positions (default 8)")->check(CLI::Range(1, 64));
  scan_cmd->add_option("--resolution", scan->resolution, "Range samples per view and side (default 1400: ~1M triangles)")
      ->check(CLI::Range(2, 4096));
  scan_cmd->add_option("--seed", scan->seed, "Seed of the range noise");
  scan_cmd->callback([&action, scan_path, scan] {
    action = [scan_path, scan] {
      write_scan_obj(*scan_path, *scan);
      std::fprintf(stderr, "pt: wrote %s\n", scan_path->c_str());
      return 0;
    };
  });

  CLI::App* inst_cmd = gen->add_subcommand("instances", "A JSON scene or binary glTF placing one mesh file many times over a field (instancing)");
  auto inst_path = std::make_shared<std::string>();
  auto inst = std::make_shared<InstanceFieldOptions>();
  inst_cmd->add_option("output", *inst_path, "Output: a .json scene, or a .glb holding the mesh once and a node per copy")->required();
  inst_cmd->add_option("--mesh", inst->mesh, "The .obj placed (named relative to the output's folder)")->required();
  inst_cmd->add_option("--count", inst->count, "Copies (default 10000)")->check(CLI::Range(1, 1000000));
  inst_cmd->add_option("--seed", inst->seed, "Seed of the turns, scales and jitter");
  inst_cmd->add_flag("--flatten", inst->flatten, "One object per copy (baked into world space at load) instead of instances");
  inst_cmd->callback([&action, inst_path, inst] {
    action = [inst_path, inst] {
      write_instance_field(*inst_path, *inst);
      std::fprintf(stderr, "pt: wrote %s\n", inst_path->c_str());
      return 0;
    };
  });
}

}  // namespace pt
