// What `pt render` writes: the AOV channels of the beauty EXR (--aov, renderer/render/aov.h), tone mapped
// 8-bit outputs (--tonemap, --exposure), the extensions it accepts and refuses
// (renderer/render/output_format.h), and the name of an unknown command.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/image/image.h"
#include "run_pt.h"

namespace fs = std::filesystem;

namespace {

const char* kScene = R"({"spheres": [{"center": [0, 1, 0], "radius": 1}, {"center": [2, 0.5, -1], "radius": 0.5}],
  "lights": [{"type": "point", "position": [2, 5, 4], "intensity": 100}],
  "camera": {"position": [0, 1.5, 6], "look_at": [0.5, 0.75, 0], "fov": 40},
  "render": {"resolution": [32, 24], "spp": 4, "integrator": "path"}})";

size_t channel(const pt::Image& image, const std::string& name) {
  for (size_t c = 0; c < image.channels.size(); ++c) {
    if (image.channels[c] == name) return c;
  }
  FAIL("no channel " << name);
  return 0;
}

}  // namespace

TEST_CASE("--aov writes the named AOV channels into the beauty EXR") {
  TempDir dir("pt-cli-aov");
  std::string scene = dir.write("scene.json", kScene);
  std::string all = (dir.path / "all.exr").string(), plain = (dir.path / "plain.exr").string();
  PtRun r = run_pt({"render", scene, "-q", "-o", all, "--aov", "all"}, dir);
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  REQUIRE(run_pt({"render", scene, "-q", "-o", plain}, dir).code == 0);
  pt::Image image = pt::read_image(all), beauty = pt::read_image(plain);
  std::vector<std::string> names = image.channels;
  std::sort(names.begin(), names.end());
  CHECK(names == std::vector<std::string>{"B", "G", "N.X", "N.Y", "N.Z", "R", "albedo.B", "albedo.G", "albedo.R",
                                          "depth.Z", "nonfinite", "samples", "variance.B", "variance.G", "variance.R"});
  // The default is R, G, B and the variance, as before --aov.
  std::vector<std::string> plain_names = beauty.channels;
  std::sort(plain_names.begin(), plain_names.end());
  CHECK(plain_names == std::vector<std::string>{"B", "G", "R", "variance.B", "variance.G", "variance.R"});
  size_t samples = channel(image, "samples"), nonfinite = channel(image, "nonfinite"), z = channel(image, "depth.Z");
  int hits = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      CHECK(image.at(x, y, samples) == 4.0f);
      CHECK(image.at(x, y, nonfinite) == 0.0f);
      hits += image.at(x, y, z) > 0;
      for (const char* c : {"R", "G", "B"}) CHECK(image.at(x, y, channel(image, c)) == beauty.at(x, y, channel(beauty, c)));
    }
  }
  CHECK(hits > 50);                                    // the spheres
  CHECK(hits < image.width * image.height - 50);       // and the sky around them
}

TEST_CASE("--aov mistakes are one-line errors before rendering") {
  TempDir dir("pt-cli-aov-bad");
  std::string scene = dir.write("scene.json", kScene);
  fs::path out = dir.path / "out";
  fs::create_directories(out);
  struct Case {
    std::vector<std::string> args;
    const char* says;
  } cases[] = {
      {{"--aov", "albedo,normals", "-o", "a.exr"}, "unknown AOV 'normals'"},
      {{"--aov", "albedo", "-o", "a.png"}, "--aov"},
      {{"--aov", "depth", "--part", "0/2", "-o", "p.exr"}, "--part"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"render", scene, "-q"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    args.back() = (out / args.back()).string();
    PtRun r = run_pt(args, dir);
    CAPTURE(r.err);
    CHECK(r.code == 2);
    CHECK(r.err_lines.size() == 1);
    CHECK(r.err.find(c.says) != std::string::npos);
  }
  CHECK(listing(out).empty());
}

TEST_CASE("--tonemap and --exposure shape 8-bit outputs; EXR and HDR stay linear and say so") {
  TempDir dir("pt-cli-tonemap");
  std::string scene = dir.write("scene.json", kScene);
  std::string exr = (dir.path / "lin.exr").string();
  REQUIRE(run_pt({"render", scene, "-q", "-o", exr}, dir).code == 0);
  pt::Image linear = pt::read_image(exr);
  for (const char* curve : {"clip", "aces", "filmic"}) {
    std::string png = (dir.path / (std::string(curve) + ".png")).string();
    PtRun r = run_pt({"render", scene, "-q", "-o", png, "--tonemap", curve, "--exposure", "1"}, dir);
    CAPTURE(curve);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(r.err.empty());
    pt::Image img = pt::read_image(png);  // sRGB decoded: display-linear
    REQUIRE(img.width == linear.width);
    // Every pixel is the curve of twice the linear value, within 8-bit rounding; the curves differ.
    int bright = 0, burnt = 0;
    for (int y = 0; y < img.height; ++y) {
      for (int x = 0; x < img.width; ++x) {
        float v = 2.0f * linear.at(x, y, 1), shown = img.at(x, y, 1);
        bright += v > 1.0f;
        burnt += shown > 0.999f;
        if (std::string(curve) == "clip") CHECK(shown == doctest::Approx(std::min(v, 1.0f)).epsilon(0.02));
        if (v > 1.0f && std::string(curve) != "clip") CHECK(shown < 1.0f);  // a shoulder, not a burn
      }
    }
    if (std::string(curve) == "clip") CHECK(burnt == bright);
    CHECK(bright > 0);
  }
  // On linear outputs the options change nothing and a warning says so.
  for (const char* name : {"w.exr", "w.hdr"}) {
    std::string out = (dir.path / name).string();
    PtRun r = run_pt({"render", scene, "-q", "-o", out, "--exposure", "2", "--tonemap", "aces"}, dir);
    CAPTURE(r.err);
    CHECK(r.code == 0);
    CHECK(r.err.find("--exposure") != std::string::npos);
    CHECK(r.err.find("no effect") != std::string::npos);
  }
  pt::Image w = pt::read_image((dir.path / "w.exr").string());
  CHECK(w.pixels == linear.pixels);
  CHECK(pt::read_image((dir.path / "w.hdr").string()).channels.size() == 3);
}

TEST_CASE("output extensions: the documented ones are written, any other is refused up front") {
  TempDir dir("pt-cli-ext");
  std::string scene = dir.write("scene.json", kScene);
  for (const char* name : {"a.jpg", "b.JPEG", "c.hdr", "d.png", "e.EXR"}) {
    PtRun r = run_pt({"render", scene, "-q", "-o", (dir.path / name).string()}, dir);
    CAPTURE(name);
    CAPTURE(r.err);
    CHECK(r.code == 0);
    CHECK(fs::exists(dir.path / name));
  }
  for (const char* name : {"f.tif", "g.bmp", "h", "i.webp"}) {
    PtRun r = run_pt({"render", scene, "-q", "-o", (dir.path / name).string()}, dir);
    CAPTURE(name);
    CHECK(r.code == 2);
    CHECK(r.err_lines.size() == 1);
    CHECK(r.err.find(".exr, .hdr, .png, .jpg or .jpeg") != std::string::npos);
    CHECK_FALSE(fs::exists(dir.path / name));
  }
}

TEST_CASE("an unknown command is named") {
  TempDir dir("pt-cli-command");
  PtRun r = run_pt({"rendr", "x"}, dir);
  CHECK(r.code == 2);
  CHECK(r.err_lines.size() == 1);
  CHECK(r.err.find("unknown command 'rendr'") != std::string::npos);
  CHECK(r.err.find("render") != std::string::npos);
  PtRun b = run_pt({"bench", "convrge", "x"}, dir);
  CHECK(b.code == 2);
  CHECK(b.err.find("unknown command 'bench convrge'") != std::string::npos);
}

TEST_CASE("bench converge makes its reference's folder and says first that the reference takes long") {
  TempDir dir("pt-cli-refs");
  fs::path ref = dir.path / "build" / "refs" / "ref.exr";
  PtRun r = run_pt({"bench", "converge", std::string(PT_SOURCE_DIR) + "/scenes/cornell-box", "--reference", ref.string(),
                    "--reference-spp", "4", "--res", "16x16", "--min-spp", "1", "--max-spp", "2", "--csv",
                    (dir.path / "c.csv").string()},
                   dir);
  CAPTURE(r.err);
  CHECK(r.code == 0);
  CHECK(fs::exists(ref));
  REQUIRE_FALSE(r.err_lines.empty());
  CHECK(r.err_lines[0].find("a long render") != std::string::npos);
}

TEST_CASE("pt merge takes the same output formats and tone curves as pt render") {
  TempDir dir("pt-cli-merge-out");
  std::string scene = dir.write("scene.json", kScene);
  std::string p0 = (dir.path / "p0.exr").string(), p1 = (dir.path / "p1.exr").string();
  for (const std::string& part : {std::string("0/2"), std::string("1/2")}) {
    PtRun r = run_pt({"render", scene, "-q", "--part", part, "-o", part == "0/2" ? p0 : p1}, dir);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
  }
  std::string clip = (dir.path / "clip.png").string(), filmic = (dir.path / "filmic.png").string();
  REQUIRE(run_pt({"merge", p0, p1, "-q", "-o", clip, "--exposure", "1"}, dir).code == 0);
  REQUIRE(run_pt({"merge", p0, p1, "-q", "-o", filmic, "--exposure", "1", "--tonemap", "filmic"}, dir).code == 0);
  CHECK(pt::read_image(clip).pixels != pt::read_image(filmic).pixels);
  PtRun exr = run_pt({"merge", p0, p1, "-q", "-o", (dir.path / "m.exr").string(), "--exposure", "1"}, dir);
  CHECK(exr.code == 0);
  CHECK(exr.err.find("no effect") != std::string::npos);
  PtRun tif = run_pt({"merge", p0, p1, "-q", "-o", (dir.path / "m.tif").string()}, dir);
  CHECK(tif.code == 2);
  CHECK(tif.err.find(".exr, .hdr, .png, .jpg or .jpeg") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "m.tif"));
}

TEST_CASE("an .exr output is written by OpenEXR without loading OpenImageIO; a .png one loads it") {
  TempDir dir("pt-cli-exr-direct");
  std::string scene = dir.write("scene.json", kScene);
  // The dynamic loader names every library it opens (dlopen included) when LD_DEBUG=files.
  ::setenv("LD_DEBUG", "files", 1);
  PtRun exr = run_pt({"render", scene, "-q", "-o", (dir.path / "out.exr").string()}, dir);
  PtRun png = run_pt({"render", scene, "-q", "-o", (dir.path / "out.png").string()}, dir);
  ::unsetenv("LD_DEBUG");
  REQUIRE(exr.code == 0);
  REQUIRE(png.code == 0);
  CHECK(exr.err.find("libOpenImageIO") == std::string::npos);
  CHECK(png.err.find("libOpenImageIO") != std::string::npos);  // the check above can see it
  // OpenImageIO reads back what OpenEXR wrote: the channels, the metadata, ZIP compression.
  pt::Image image = pt::read_image((dir.path / "out.exr").string());
  CHECK(image.width == 32);
  CHECK(image.height == 24);
  CHECK(image.channels.size() == 6);
  CHECK(image.metadata.count("pt:spp") == 1);
  CHECK(image.metadata["compression"] == "zip");
  double sum = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) sum += image.at(x, y, static_cast<int>(channel(image, "G")));
  CHECK(sum > 0);
}

TEST_CASE("--light-selection: pt info and the render's header say which light sampler the scene gets") {
  TempDir dir("pt-cli-light-selection");
  // Point lights in a row over a plane: three of them, and nine (auto takes the tree from eight).
  auto scene = [&](int lights) {
    std::string s = R"({"spheres": [{"center": [0, -100, 0], "radius": 100}], "lights": [)";
    for (int i = 0; i < lights; ++i) {
      s += std::string(i ? "," : "") + R"({"type": "point", "position": [)" + std::to_string(i - lights / 2) +
           R"(, 3, 0], "intensity": 10})";
    }
    s += R"(], "camera": {"position": [0, 2, 8], "look_at": [0, 0, 0], "fov": 40},
      "render": {"resolution": [16, 12], "spp": 2, "integrator": "path"}})";
    return dir.write("lights" + std::to_string(lights) + ".json", s);
  };
  std::string three = scene(3), nine = scene(9);
  struct Case {
    std::string scene;
    std::vector<std::string> flags;
    const char* says;
  } cases[] = {
      {three, {}, "light selection: by power among 3 emitters (fewer than 8; --light-selection tree overrides)"},
      {nine, {}, "light selection: a light tree over 9 emitters (8 or more; --light-selection power overrides)"},
      {nine, {"--light-selection", "power"}, "light selection: by power among 9 emitters (--light-selection power)"},
      {three, {"--light-selection", "tree"}, "light selection: a light tree over 3 emitters (--light-selection tree)"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> info = {"info", c.scene}, render = {"render", c.scene, "-o", (dir.path / "out.exr").string()};
    info.insert(info.end(), c.flags.begin(), c.flags.end());
    render.insert(render.end(), c.flags.begin(), c.flags.end());
    PtRun i = run_pt(info, dir), r = run_pt(render, dir);
    CAPTURE(i.out);
    CAPTURE(r.err);
    REQUIRE(i.code == 0);
    REQUIRE(r.code == 0);
    CHECK(i.out.find(c.says) != std::string::npos);
    CHECK(r.err.find(std::string("pt: ") + c.says) != std::string::npos);
    // Only a forced choice is in the image's settings, so renders that leave it to the scene keep theirs.
    std::string settings = pt::read_image((dir.path / "out.exr").string()).metadata["pt:settings"];
    CHECK((settings.find("light_selection=") != std::string::npos) == !c.flags.empty());
  }
  PtRun bad = run_pt({"render", nine, "--light-selection", "bvh", "-o", (dir.path / "bad.exr").string()}, dir);
  CAPTURE(bad.err);
  CHECK(bad.code == 2);
  CHECK(bad.err_lines.size() == 1);
  CHECK(bad.err.find("--light-selection") != std::string::npos);
  CHECK(!fs::exists(dir.path / "bad.exr"));
}

TEST_CASE("bench rays --disagreements lists every ray the backends answer differently, exactly, and needs both") {
  TempDir dir("pt-cli-differ");
  fs::path csv = dir.path / "differ.csv";
  // A 9k-triangle scan-like mesh under the studio's ground, where Embree 3.13's default mode misses
  // a primary ray of these 60,000 that the BVH hits (docs/bvh.md, Agreement).
  PtRun gen = run_pt({"gen", "scan", (dir.path / "scan.obj").string(), "--resolution", "140"}, dir);
  REQUIRE(gen.code == 0);
  PtRun r = run_pt({"bench", "rays", (dir.path / "scan.obj").string(), "--rays", "60000", "--passes", "1", "--threads", "1",
                    "--disagreements", csv.string()},
                   dir);
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  // The counts the agreement table prints: "N hit/miss" for primary and diffuse rays, "N of M
  // occlusion answers" for shadow rays.
  size_t printed = 0;
  std::istringstream out(r.out);
  for (std::string line; std::getline(out, line);) {
    std::istringstream words(line);
    std::string kind, second, third;
    size_t n = 0;
    if (!(words >> kind >> n >> second)) continue;
    if ((kind == "primary" || kind == "diffuse") && second.rfind("hit/miss", 0) == 0) printed += n;
    if (kind == "shadow" && second == "of") printed += n;
  }
  std::ifstream f(csv);
  std::string header;
  REQUIRE(std::getline(f, header));
  CHECK(header == "kind,ray,ox,oy,oz,dx,dy,dz,tmin,tmax,embree_t,embree_geom,embree_prim,embree_inst,bvh_t,bvh_geom,"
                  "bvh_prim,bvh_inst");
  size_t rows = 0;
  for (std::string line; std::getline(f, line);) {
    ++rows;
    CAPTURE(line);
    CHECK(std::count(line.begin(), line.end(), ',') == 17);
    CHECK(line.find("0x") != std::string::npos);  // hexadecimal floats: the ray exactly
  }
  CHECK(printed >= 1);
  CHECK(rows == printed);

  PtRun one = run_pt({"bench", "rays", (dir.path / "scan.obj").string(), "--backend", "bvh", "--disagreements", csv.string()}, dir);
  CHECK(one.code == 2);
  CHECK(one.err.find("--disagreements") != std::string::npos);
}

TEST_CASE("bench rays --from times secondary rays from the studio's ground or from the model alone") {
  TempDir dir("pt-cli-from");
  std::string mesh = (dir.path / "scan.obj").string();
  REQUIRE(run_pt({"gen", "scan", mesh, "--resolution", "60"}, dir).code == 0);
  for (const char* from : {"ground", "model"}) {
    fs::path csv = dir.path / (std::string(from) + ".csv");
    PtRun r = run_pt({"bench", "rays", mesh, "--from", from, "--rays", "4000", "--passes", "1", "--threads", "1", "--csv",
                      csv.string()},
                     dir);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(r.out.find(std::string("shadow and diffuse rays from the ") +
                     (std::string(from) == "ground" ? "studio's ground only" : "model (not the ground) only")) !=
          std::string::npos);
    for (const char* line : {"shadow   0 of 4000 occlusion answers", "diffuse  0 hit/miss"}) CHECK(r.out.find(line) != std::string::npos);
    CHECK(fs::exists(csv));
  }
  // Without the studio there is no ground to start from: a one-line error, no CSV.
  fs::path bad = dir.path / "bad.csv";
  PtRun e = run_pt({"bench", "rays", mesh, "--from", "ground", "--studio", "none", "--rays", "1000", "--csv", bad.string()}, dir);
  CHECK(e.code != 0);
  CHECK(e.err.find("--from ground: no primary ray hits") != std::string::npos);
  CHECK(e.err.find(mesh) != std::string::npos);
  CHECK(!fs::exists(bad));
  PtRun f = run_pt({"bench", "rays", mesh, "--from", "sky"}, dir);
  CHECK(f.code == 2);
  CHECK(f.err_lines.size() == 1);
}

TEST_CASE("bench rays --bvh-variant times more BVHs in one process, with their settings, and refuses bad ones") {
  TempDir dir("pt-cli-variant");
  fs::path csv = dir.path / "variant.csv";
  std::string mesh = (dir.path / "scan.obj").string();
  PtRun gen = run_pt({"gen", "scan", mesh, "--resolution", "60"}, dir);
  REQUIRE(gen.code == 0);
  // Given before the scene: each --bvh-variant takes one value, not the scene's path too.
  PtRun r = run_pt({"bench", "rays", "--bvh-variant", "max_leaf=4", "--bvh-variant", "spatial_split_budget=0, max_leaf=16",
                    mesh, "--studio", "none", "--rays", "4000", "--passes", "1", "--threads", "1", "--csv", csv.string()},
                   dir);
  CAPTURE(r.out);
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("bvh#1: the BVH built with max_leaf=4") != std::string::npos);
  CHECK(r.out.find("bvh#2: the BVH built with spatial_split_budget=0 max_leaf=16") != std::string::npos);
  // Every variant's answers are compared with Embree's, kind by kind.
  for (const char* line : {"primary  bvh#1:", "shadow   bvh#2:", "diffuse  bvh#2:"}) {
    CHECK(r.out.find(line) != std::string::npos);
  }
  std::ifstream f(csv);
  std::string header;
  REQUIRE(std::getline(f, header));
  CHECK(header == "metric,kind,threads,embree,bvh,bvh#1,bvh#2,bvh_over_embree_time,bvh_1_over_embree_time,"
                  "bvh_2_over_embree_time");
  std::map<std::string, std::vector<double>> rows;  // metric (and kind) -> the seven values
  for (std::string line; std::getline(f, line);) {
    std::vector<std::string> cells;
    std::istringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
    if (cells.size() != 10) continue;
    std::vector<double> values;
    for (size_t i = 3; i < cells.size(); ++i) values.push_back(std::stod(cells[i]));
    rows[cells[0] + cells[1]] = values;
  }
  REQUIRE(rows.count("memory_mb") == 1);
  REQUIRE(rows.count("mrays_per_sshadow") == 1);
  const std::vector<double>& memory = rows["memory_mb"];
  // The settings took effect: without spatial splits a scan's tree holds fewer references (smaller),
  // and leaves of at most four triangles make more nodes than the default's sixteen.
  CHECK(memory[3] < memory[1]);
  CHECK(memory[2] != memory[1]);
  for (int a = 1; a <= 3; ++a) {
    CHECK(rows["mrays_per_sshadow"][3 + a] == doctest::Approx(rows["mrays_per_sshadow"][0] / rows["mrays_per_sshadow"][a]));
  }

  // Another copy of the kernels on the same tree: the SSE4.2 one (every x86-64 CPU pt runs on has
  // it) finds what the default finds.
  PtRun k = run_pt({"bench", "rays", mesh, "--bvh-variant", "kernels=sse4.2", "--studio", "none", "--rays", "4000",
                    "--passes", "1", "--threads", "1"},
                   dir);
  CAPTURE(k.err);
  REQUIRE(k.code == 0);
  CHECK(k.out.find("bvh#1: the BVH built with kernels=sse4.2") != std::string::npos);
  for (const char* kind : {"primary", "shadow", "diffuse"}) {
    CHECK(k.out.find(std::string(kind) + std::string(8 - std::strlen(kind), ' ') + " bvh#1: 0 hit/miss") != std::string::npos);
  }

  for (std::vector<std::string> bad : {std::vector<std::string>{"--bvh-variant", "leaves=8"},
                                       std::vector<std::string>{"--bvh-variant", "max_leaf=0"},
                                       std::vector<std::string>{"--bvh-variant", "traversal_cost=x"},
                                       std::vector<std::string>{"--bvh-variant", "kernels=neon"},
                                       std::vector<std::string>{"--bvh-variant", "split_planes=2"},
                                       std::vector<std::string>{"--bvh-variant", "max_leaf=8", "--backend", "embree"}}) {
    std::vector<std::string> args = {"bench", "rays", mesh, "--rays", "100", "--csv", (dir.path / "bad.csv").string()};
    args.insert(args.end(), bad.begin(), bad.end());
    PtRun b = run_pt(args, dir);
    CAPTURE(bad[1]);
    CAPTURE(b.err);
    CHECK(b.code == 2);
    CHECK(b.err_lines.size() == 1);
    CHECK(b.err.find("--bvh-variant") != std::string::npos);
    CHECK(!fs::exists(dir.path / "bad.csv"));
  }
}
