// The binary on glTF and PLY files: `pt render model.gltf|.glb|.ply` works as for an OBJ, `--env`
// lights any scene, `pt info` says what a glTF file held, bad files give one line and exit 2; and
// the loose ends of the OBJ and JSON loaders (an unnamed MTL material, object files of unknown kinds).
#include <doctest/doctest.h>

#include <filesystem>

#include "core/image/image.h"
#include "gltf_text.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace pt;

namespace {

const char* kPly = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n1 0 -1\n0 0 -1\n4 0 1 2 3\n";

GltfText square_gltf() {
  GltfText g;
  int mesh = add_square(g);
  g.doc["nodes"] = {{{"mesh", mesh}}, {{"camera", 0}, {"translation", {0.5, 2, 3}}}};
  g.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  return g;
}

bool has_line(const Outcome& o, const std::string& needle) {
  for (const std::string& l : o.err_lines) {
    if (l.find(needle) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("pt render model.gltf, .glb and .ply as for an OBJ; pt info summarises a glTF") {
  TempDir dir("pt-formats");
  GltfText g = square_gltf();
  std::string gltf = dir.write("m.gltf", g.gltf());
  std::string glb = dir.write("m.glb", g.glb());
  std::string ply = dir.write("m.ply", kPly);
  std::vector<std::vector<std::string>> runs;
  for (const std::string& in : {gltf, glb, ply}) {
    runs.push_back({"render", in, "--spp", "2", "--res", "32x24", "-o", (dir.path / (fs::path(in).filename().string() + ".exr")).string()});
  }
  runs.push_back({"info", gltf});
  std::vector<Outcome> o = run_pt_all(runs, dir);
  for (size_t i = 0; i < 3; ++i) {
    CAPTURE(i);
    CHECK(o[i].exited);
    CHECK(o[i].code == 0);
  }
  // Both glTF forms use the file's camera and light nothing, so the studio lights them.
  Image a = read_image((dir.path / "m.gltf.exr").string());
  Image b = read_image((dir.path / "m.glb.exr").string());
  CHECK(a.pixels == b.pixels);
  CHECK(o[3].code == 0);
  CHECK(o[3].out.find("contents     " + gltf + ": glTF: 1 meshes placed by 1 nodes") != std::string::npos);
  CHECK(o[3].out.find("scene file's") != std::string::npos);
}

TEST_CASE("--env lights any scene; --env-rotate and --env-strength need it; --camera needs a glTF file") {
  TempDir dir("pt-formats");
  std::string ply = dir.write("m.ply", kPly);
  Image sky(8, 4, {"R", "G", "B"});
  for (float& p : sky.pixels) p = 0.5f;
  std::string env = (dir.path / "sky.exr").string();
  write_image(env, sky);
  std::vector<Outcome> o = run_pt_all({{"info", ply, "--env", env, "--env-rotate", "90", "--env-strength", "2"},
                                       {"render", ply, "--env-strength", "2", "-o", (dir.path / "x.png").string()},
                                       {"render", ply, "--camera", "1", "-o", (dir.path / "y.png").string()},
                                       {"render", ply, "--env", (dir.path / "none.exr").string(), "-o", (dir.path / "z.png").string()}},
                                      dir);
  CHECK(o[0].code == 0);
  CHECK(o[0].out.find("environment  image " + env + " (8x4), scale 2, rotation 90 degrees") != std::string::npos);
  CHECK(o[0].out.find("studio") == std::string::npos);
  CHECK(o[1].code == 2);
  CHECK(has_line(o[1], "--env-rotate and --env-strength apply to the map given with --env"));
  CHECK(o[2].code == 2);
  CHECK(has_line(o[2], ply + ": --camera picks a camera of a glTF file"));
  CHECK(o[3].code == 2);
  CHECK(has_line(o[3], "none.exr"));
  CHECK(!fs::exists(dir.path / "x.png"));
}

TEST_CASE("bad glTF and PLY files: one line, exit 2, nothing written") {
  TempDir dir("pt-formats");
  Batch batch(dir);
  GltfText g = square_gltf();
  g.doc["accessors"][0]["count"] = 40;
  std::string bad = dir.write("bad.gltf", g.gltf());
  batch.add({bad}, {bad + ": /accessors/0/count:"});
  std::string cut = g.glb();
  std::string glb = dir.write("cut.glb", cut.substr(0, cut.size() / 2));
  batch.add({glb}, {glb + ": GLB:"});
  std::string ply = dir.write("bad.ply", std::string(kPly).replace(std::string(kPly).find("4 0 1 2 3"), 9, "4 0 1 2 9"));
  batch.add({ply}, {ply + ":14: vertex index 9 but the file has 4 vertices"});
  std::string huge = dir.write("huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                                           "property float y\nproperty float z\nend_header\n");
  batch.add({huge}, {huge + ":3: the header promises 4000000000 'vertex' elements"});
  std::string json = dir.write("scene.json", R"({"objects": [{"file": "m.stl"}]})");
  batch.add({json}, {json + ": /objects/0/file: unknown kind of object file '.stl'"});
  batch.run();
}

TEST_CASE("an MTL 'newmtl' without a name loads, with one warning") {
  TempDir dir("pt-formats");
  dir.write("m.mtl", "newmtl \nKd 0.2 0.3 0.4\nnewmtl named\nKd 0.5 0.5 0.5\n");
  std::string obj = dir.write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl named\nf 1 2 3\n");
  Outcome o = run_pt({"info", obj}, dir);
  CHECK(o.code == 0);
  size_t warnings = 0;
  for (const std::string& l : o.err_lines) warnings += l.find("'newmtl' without a name") != std::string::npos;
  CHECK(warnings == 1);
  CHECK(o.out.find("(unnamed)") != std::string::npos);
  CHECK(o.out.find("kd (0.2, 0.3, 0.4)") != std::string::npos);
}
