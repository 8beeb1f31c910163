// The real `pt` binary on bad input: each mistake gets exactly one line on stderr naming the file
// (and line where there is one), exit status 2, no crash, and no output file nor leftover temporary
// file. Also Ctrl-C (SIGINT) and --time, which must stop cleanly with a valid partial image.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <sstream>
#include <thread>
#include <vector>

#include "core/image/image.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

// A good scene to pair with bad options: one sphere lit by a point light (so no warnings).
std::string good_scene(const TempDir& dir) {
  return dir.write("good/scene.json", R"({"spheres": [{"center": [0, 0, 0], "radius": 1}],
    "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 40},
    "lights": [{"type": "point", "position": [0, 3, 3], "intensity": 10}],
    "render": {"resolution": [16, 12], "spp": 2}})");
}

const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

}  // namespace

TEST_CASE("missing files, folders and unknown formats") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  std::string missing = (dir.path / "nope.obj").string();
  batch.add({missing}, {missing, "no such file"});
  batch.add({(dir.path / "nope.json").string()}, {"nope.json"});
  fs::create_directories(dir.path / "empty-folder");
  batch.add({(dir.path / "empty-folder").string()}, {"empty-folder", "scene.json"});
  std::string stl = dir.write("model.stl", "solid x\n");
  batch.add({stl}, {stl, ".stl"});
  batch.run();
}

TEST_CASE("malformed OBJ: every bad line is reported with its line number") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  struct Case {
    const char* name;
    std::string text;
    int line;
  } cases[] = {
      {"bad_number", std::string("v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n"), 2},
      {"too_few_numbers", std::string("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"), 2},
      {"nan_vertex", std::string("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), 2},
      {"inf_vertex", std::string("v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"), 3},
      {"float_overflow", std::string("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"), 2},
      {"nan_normal", std::string(kTriangle) + "vn 0 nan 1\nf 1//1 2//1 3//1\n", 4},
      {"nan_uv", std::string(kTriangle) + "vt 0.5 NaN\nf 1/1 2/1 3/1\n", 4},
      {"bad_index", std::string(kTriangle) + "f 1 2 x\n", 4},
      {"index_out_of_range", std::string(kTriangle) + "# comment\nf 1 2 4\n", 5},
      {"index_zero", std::string(kTriangle) + "f 0 1 2\n", 4},
      {"negative_too_far", std::string(kTriangle) + "f -1 -2 -4\n", 4},
      {"index_overflow", std::string(kTriangle) + "f 1 2 99999999999999999999\n", 4},
      {"index_wraps_int", std::string(kTriangle) + "f 1 2 4294967298\n", 4},
      {"normal_out_of_range", std::string(kTriangle) + "vn 0 0 1\nf 1//1 2//1 3//2\n", 5},
      {"uv_out_of_range", std::string(kTriangle) + "vt 0 0\nf 1/1 2/2 3/1\n", 5},
      {"face_too_small", std::string(kTriangle) + "f 1 2\n", 4},
      {"binary_junk", std::string("v 0 0 0\n\x7f" "ELF\x02\x01\x01\0\0\0\0\x03\x00\x3e\n", 20), 2},
  };
  for (const Case& c : cases) {
    std::string obj = dir.write(std::string(c.name) + ".obj", c.text);
    batch.add({obj}, {obj + ":" + std::to_string(c.line) + ":"});
  }
  batch.run();
}

TEST_CASE("binary junk without NUL bytes is still refused in one line") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  std::string junk;
  uint32_t x = 12345;
  for (int i = 0; i < 4000; ++i) {
    x = x * 1664525u + 1013904223u;
    char ch = static_cast<char>((x >> 24) | 1);  // never 0
    junk += ch;
  }
  std::string obj = dir.write("junk.obj", junk);
  batch.add({obj}, {obj});
  batch.run();
}

TEST_CASE("malformed MTL and textures that will not load") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  struct Case {
    const char* name;
    std::string mtl;
    std::vector<std::string> expected;  // relative to the folder
  } cases[] = {
      {"bad_colour", "newmtl a\nKd 0.5 abc 0.5\n", {"bad_colour.mtl:2:"}},
      {"nan_colour", "newmtl a\n\nKe nan 1 1\n", {"nan_colour.mtl:3:"}},
      {"negative_colour", "newmtl a\nKd -1 0 0\n", {"negative_colour.mtl:2:"}},
      {"huge_colour", "newmtl a\nKe 1e38 1 1\n", {"huge_colour.mtl:2: 'Ke' value above 1e30"}},
      {"bad_scalar", "newmtl a\nNs shiny\n", {"bad_scalar.mtl:2:"}},
      {"before_newmtl", "Kd 1 1 1\nnewmtl a\n", {"before_newmtl.mtl:1:"}},
      {"binary_mtl", std::string("newmtl a\nKd \0\x01\x02\n", 16), {"binary_mtl.mtl:2:"}},
      {"texture_garbage", "newmtl a\nmap_Kd garbage.png\n", {"texture_garbage.obj", "garbage.png"}},
      // A float colour texture below zero: a reflectance never is (found by attack; it rendered).
      {"texture_negative", "newmtl a\nmap_Kd negative.pfm\n", {"texture_negative.obj", "negative.pfm: holds a negative colour value"}},
      // A deep EXR has no flat pixels: OpenImageIO's own message was "without an open file".
      {"texture_deep", "newmtl a\nmap_Kd deep.exr\n", {"texture_deep.obj", "deep.exr: is a deep image"}},
  };
  dir.write("garbage.png", "\x89PNG\r\n\x1a\n but then nothing an image reader wants");
  {
    // A 1x1 PFM (little-endian: negative scale) of (-2, 0.5, 0.5).
    std::string pfm = "PF\n1 1\n-1.0\n";
    for (float v : {-2.0f, 0.5f, 0.5f}) pfm.append(reinterpret_cast<const char*>(&v), sizeof v);
    dir.write("negative.pfm", pfm);
  }
  {
    // A 1x1 deep EXR (R, G, B, A, Z; one sample), made by `oiiotool --nosoftwareattrib --pattern
    // constant:color=0.5,0.5,0.5,1 1x1 4 --chnames R,G,B,A --ch R,G,B,A,Z=0.5 --deepen --compression none`.
    const char* hex =
      "762f3101020800006361704461746500737472696e670013000000323032363a31323a30342031393a33323a34376368616e"
      "6e656c730063686c697374005b00000041000200000000000000010000000100000042000200000000000000010000000100"
      "00004700020000000000000001000000010000005200020000000000000001000000010000005a0002000000000000000100"
      "000001000000006368756e6b436f756e7400696e74000400000001000000636f6d7072657373696f6e00636f6d7072657373"
      "696f6e0001000000006461746157696e646f7700626f78326900100000000000000000000000000000000000000064697370"
      "6c617957696e646f7700626f7832690010000000000000000000000000000000000000006c696e654f72646572006c696e65"
      "4f72646572000100000000706978656c417370656374526174696f00666c6f617400040000000000803f73637265656e5769"
      "6e646f7743656e746572007632660008000000000000000000000073637265656e57696e646f77576964746800666c6f6174"
      "00040000000000803f7479706500737472696e67000c000000646565707363616e6c696e6576657273696f6e00696e740004"
      "0000000100000000d20100000000000000000000040000000000000014000000000000001400000000000000010000000000"
      "803f0000003f0000003f0000003f0000003f";
    std::string bytes;
    for (const char* h = hex; h[0] && h[1]; h += 2) bytes.push_back(static_cast<char>(std::stoi(std::string(h, 2), nullptr, 16)));
    dir.write("deep.exr", bytes);
  }
  for (const Case& c : cases) {
    std::string base = std::string(c.name);
    dir.write(base + ".mtl", c.mtl);
    std::string obj = dir.write(base + ".obj", "mtllib " + base + ".mtl\n" + kTriangle + "usemtl a\nf 1 2 3\n");
    std::vector<std::string> expected;
    for (const std::string& e : c.expected) expected.push_back((dir.path / e).string());
    batch.add({obj}, expected);
  }
  // An environment map below zero: radiance never is.
  std::string plain = dir.write("plain.obj", std::string(kTriangle) + "f 1 2 3\n");
  std::string pfm = (dir.path / "negative.pfm").string();
  batch.add({plain, "--env", pfm}, {"--env: texture will not load: " + pfm + ": holds a negative value (-2"});
  std::string deep = (dir.path / "deep.exr").string();
  batch.add({plain, "--env", deep}, {"--env: texture will not load: " + deep + ": is a deep image"});
  batch.run();
}

TEST_CASE("malformed JSON scene files") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  dir.write("tri.obj", std::string(kTriangle) + "f 1 2 3\n");
  struct Case {
    const char* name;
    const char* text;
    std::string expected;  // besides the file name
  } cases[] = {
      {"syntax", "{\n  \"objects\": [\n    {\"file\": \"tri.obj\"},\n  ]\n}\n", ":4:"},
      {"truncated", "{\"objects\": [{\"file\": \"tri.obj\"}", ":1:"},
      {"not_an_object", "[1, 2]", "JSON object"},
      {"wrong_type_number", R"({"spheres": [{"center": [0, 0, 0], "radius": "one"}]})", "/spheres/0/radius"},
      {"wrong_type_vector", R"({"spheres": [{"center": [0, 0], "radius": 1}]})", "/spheres/0/center"},
      {"wrong_type_section", R"({"objects": {"file": "tri.obj"}})", "/objects"},
      {"wrong_type_camera", R"({"objects": [{"file": "tri.obj"}], "camera": {"fov": "wide"}})", "/camera/fov"},
      {"number_overflow", R"({"objects": [{"file": "tri.obj"}], "camera": {"fov": 1e999}})", ""},
      {"unknown_material", R"({"spheres": [{"center": [0, 0, 0], "radius": 1, "material": "gold"}]})", "gold"},
      {"unknown_material_type", R"({"materials": {"m": {"type": "velvet"}}, "objects": [{"file": "tri.obj"}]})", "velvet"},
      {"missing_center", R"({"spheres": [{"radius": 1}]})", "center"},
      // JSON keeps the last of two equal keys: the first would be lost without a word.
      {"duplicate_key", R"({"objects": [{"file": "tri.obj"}, {"file": "tri.obj", "file": "tri.obj"}]})",
       "/objects/1/file: the key appears twice in its object"},
      {"duplicate_section", R"({"camera": {"fov": 30}, "objects": [{"file": "tri.obj"}], "camera": {"fov": 40}})",
       "/camera: the key appears twice"},
      {"missing_file", R"({"objects": [{"scale": 2}]})", "file"},
      {"missing_intensity", R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "point", "position": [0, 1, 0]}]})",
       "intensity"},
      {"missing_light_type", R"({"objects": [{"file": "tri.obj"}], "lights": [{"position": [0, 1, 0]}]})", "type"},
      {"quad_with_3_corners",
       R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "quad", "corners": [[0,0,0],[1,0,0],[1,1,0]], "radiance": 1}]})",
       "corners"},
      {"environment_needs_something", R"({"objects": [{"file": "tri.obj"}], "environment": {"scale": 2}})", "environment"},
      {"environment_image_missing", R"({"objects": [{"file": "tri.obj"}], "environment": {"file": "sky.exr"}})", "sky.exr"},
      {"bad_integrator_in_file", R"({"objects": [{"file": "tri.obj"}], "render": {"integrator": "magic"}})", "magic"},
      {"bad_sampler_in_file", R"({"objects": [{"file": "tri.obj"}], "render": {"sampler": "lucky"}})", "lucky"},
      {"zero_resolution_in_file", R"({"objects": [{"file": "tri.obj"}], "render": {"resolution": [0, 100]}})", "resolution"},
      {"absurd_resolution_in_file", R"({"objects": [{"file": "tri.obj"}], "render": {"resolution": [30000, 30000]}})",
       "resolution"},
      {"energy_creating_albedo", R"({"materials": {"m": {"albedo": 1.5}}, "objects": [{"file": "tri.obj", "material": "m"}]})",
       "/materials/m/albedo"},
      {"zero_scale", R"({"objects": [{"file": "tri.obj", "scale": [1, 0, 1]}]})", "scale"},
  };
  for (const Case& c : cases) {
    std::string file = dir.write(std::string(c.name) + ".json", c.text);
    std::vector<std::string> expected = {file};
    if (!c.expected.empty()) expected.push_back(c.expected);
    batch.add({file}, expected);
  }
  batch.run();
}

TEST_CASE("empty scenes") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  std::string empty_obj = dir.write("empty.obj", "");
  batch.add({empty_obj}, {empty_obj, "no geometry"});
  std::string points_only = dir.write("points.obj", kTriangle);
  batch.add({points_only}, {points_only, "no geometry"});
  std::string empty_json = dir.write("empty.json", "{}");
  batch.add({empty_json}, {empty_json, "no geometry"});
  std::string lights_only = dir.write("lights.json", R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": 1}]})");
  batch.add({lights_only}, {lights_only, "no geometry"});
  batch.run();
}

TEST_CASE("bad options") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  std::string scene = good_scene(dir);
  batch.add({scene, "--res", "0x0"}, {"--res"});
  batch.add({scene, "--res", "640x0"}, {"--res"});
  batch.add({scene, "--res", "100000x100000"}, {"--res"});
  batch.add({scene, "--res", "16384x16384"}, {"--res"});  // 256 Mpixels
  batch.add({scene, "--res", "wide"}, {"--res"});
  batch.add({scene, "--res", "-5x10"}, {"--res"});
  batch.add({scene, "--frobnicate"}, {"--frobnicate"});
  batch.add({scene, "--integrator", "magic"}, {"magic"});
  batch.add({scene, "--sampler", "lucky"}, {"lucky"});
  batch.add({scene, "--spp", "0"}, {"--spp"});
  batch.add({scene, "--spp", "many"}, {"--spp"});
  batch.add({scene, "--threads", "0"}, {"--threads"});
  batch.add({scene, "--time", "-1"}, {"--time"});
  batch.add({scene, "--backend", "optix"}, {"optix"});
  // No scene at all.
  batch.add({}, {"scene"});
  batch.run();
}

TEST_CASE("bad output paths: nothing is rendered for nothing, nothing is left behind") {
  TempDir dir("pt-cli");
  Batch batch(dir);
  std::string scene = good_scene(dir);
  std::string no_folder = (dir.path / "no" / "such" / "folder" / "out.png").string();
  batch.add({scene, "-o", no_folder}, {no_folder, "folder"});
  std::string file_as_folder = dir.write("plain.txt", "x");
  batch.add({scene, "-o", file_as_folder + "/out.exr"}, {"plain.txt"});
  fs::create_directories(dir.path / "taken.png");
  batch.add({scene, "-o", (dir.path / "taken.png").string()}, {"taken.png"});
  batch.add({scene, "-o", (dir.path / "out.txt").string()}, {"out.txt"});
  // A folder that exists but cannot be written to, even by root: /proc refuses new files.
  batch.add({scene, "-o", "/proc/pt-test-out.png"}, {"/proc/pt-test-out.png"});
  batch.add({scene, "-o", ""}, {"--output: an empty file name"});
  batch.run();
  CHECK_FALSE(fs::exists(dir.path / "out.txt"));
  CHECK_FALSE(fs::exists("/proc/pt-test-out.png"));
}

TEST_CASE("SIGINT, SIGTERM and SIGHUP write the partial image, say how many samples it holds, exit 128 + signal") {
  // SIGTERM is what Slurm, `timeout`, systemd and container runtimes send; SIGHUP a closed terminal.
  struct Signal {
    int number;
    const char* name;
  };
  for (Signal sig : {Signal{SIGINT, "SIGINT"}, Signal{SIGTERM, "SIGTERM"}, Signal{SIGHUP, "SIGHUP"}}) {
    CAPTURE(sig.name);
    TempDir dir("pt-cli");
    std::string scene = good_scene(dir);
    fs::path out = dir.path / "partial.exr";
    fs::path err = dir.path / "sigint-stderr.txt";
    pid_t pid = start_pt({"render", scene, "--spp", "1000000", "--res", "64x48", "--threads", "2", "-o", out.string()}, err);
    // Wait until at least one pass is done (the first pass is always reported), then interrupt.
    wait_for_text(err, "pass 1/");
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    REQUIRE(::kill(pid, sig.number) == 0);
    Outcome o = finish(pid, err, 30);
    CAPTURE(o.err);
    CHECK(o.exited);
    CHECK(o.code != 0);
    CHECK(o.code == 128 + sig.number);
    // "pt: interrupted (SIGxxx): wrote <file> holding N samples per pixel" (or "N to M" when a pass was cut).
    std::smatch m;
    REQUIRE(std::regex_search(o.err, m, std::regex(std::string(R"(interrupted \()") + sig.name +
                                                   R"(\): wrote (\S+) holding (\d+)( to (\d+))? samples per pixel)")));
    CHECK(m[1].str() == out.string());
    long lo = std::stol(m[2].str());
    long hi = m[4].matched ? std::stol(m[4].str()) : lo;
    CHECK(lo >= 1);
    CHECK(lo < 1000000);
    CHECK((hi == lo || hi == lo + 1));
    REQUIRE(fs::exists(out));
    pt::Image image = pt::read_image(out.string());
    CHECK(image.metadata["pt:spp"] == std::to_string(lo));
    CHECK(image.metadata["pt:spp_max"] == std::to_string(hi));
    // The partial image is an image: the lit sphere is there (its brightest point, facing the
    // light at distance 3.24, has radiance 0.8/pi * 10/3.24^2 = 0.24).
    float brightest = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) brightest = std::max(brightest, image.at(x, y, 1));
    }
    CHECK(brightest > 0.1f);
    // And no temporary file is left beside it.
    for (const std::string& name : listing(dir.path)) CHECK(name.find(".tmp") == std::string::npos);
  }
}

TEST_CASE("SIGTERM twice within half a second is one request: `timeout` sends it to pt and to its group") {
  TempDir dir("pt-cli");
  std::string scene = good_scene(dir);
  fs::path out = dir.path / "twice.exr";
  fs::path err = dir.path / "twice-stderr.txt";
  // A film large enough that writing it outlasts the 50 ms below.
  pid_t pid = start_pt({"render", scene, "--spp", "1000000", "--res", "1920x1080", "--threads", "2", "-o", out.string()}, err);
  wait_for_text(err, "pass 1/", 60);
  // `timeout` signals pt, then its process group: two SIGTERMs microseconds apart, delivered as one
  // or as two. The 50 ms make them two: the handler used to reset itself to the default action, and
  // the second signal killed pt with nothing written and nothing said.
  REQUIRE(::kill(pid, SIGTERM) == 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ::kill(pid, SIGTERM);  // may find pt gone already
  Outcome o = finish(pid, err, 30);
  CAPTURE(o.err);
  CHECK(o.exited);
  CHECK(o.code == 128 + SIGTERM);
  CHECK(o.err.find("interrupted (SIGTERM): wrote " + out.string()) != std::string::npos);
  CHECK(fs::exists(out));
}

TEST_CASE("--time stops after a whole pass") {
  TempDir dir("pt-cli");
  std::string scene = good_scene(dir);
  fs::path out = dir.path / "timed.exr";
  auto start = std::chrono::steady_clock::now();
  Outcome o = run_pt({"render", scene, "--spp", "1000000", "--res", "64x48", "--time", "1", "-o", out.string()}, dir);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CAPTURE(o.err);
  CHECK(o.exited);
  CHECK(o.code == 0);
  CHECK(seconds >= 1.0);
  CHECK(seconds < 20.0);  // stops near the budget, not at 10^6 spp
  std::smatch m;
  REQUIRE(std::regex_search(o.err, m, std::regex(R"(wrote (\S+) \((\d+) of 1000000 spp)")));
  long spp = std::stol(m[2].str());
  CHECK(spp >= 1);
  CHECK(spp < 1000000);
  pt::Image image = pt::read_image(out.string());
  // A whole pass: every pixel holds the same number of samples.
  CHECK(image.metadata["pt:spp"] == std::to_string(spp));
  CHECK(image.metadata["pt:spp_max"] == std::to_string(spp));
}

TEST_CASE("a good run: EXR with variance channels and metadata, a PNG, one summary line") {
  TempDir dir("pt-cli");
  std::string scene = good_scene(dir);
  fs::path exr = dir.path / "good.exr";
  Outcome o = run_pt({"render", scene, "-o", exr.string(), "--seed", "5"}, dir);
  CAPTURE(o.err);
  CHECK(o.exited);
  CHECK(o.code == 0);
  pt::Image image = pt::read_image(exr.string());
  CHECK(image.width == 16);
  CHECK(image.height == 12);
  CHECK(image.channels == std::vector<std::string>{"R", "G", "B", "variance.R", "variance.G", "variance.B"});
  CHECK(image.metadata["pt:spp"] == "2");
  CHECK(image.metadata["pt:seed"] == "5");
  CHECK(image.metadata["pt:integrator"] == "direct");
  CHECK(image.metadata["pt:settings"].find("16x12") != std::string::npos);
  CHECK(image.metadata["pt:scene_hash"].size() == 16);
  // -q: nothing at all on stderr.
  fs::path png = dir.path / "good.png";
  o = run_pt({"render", scene, "-q", "-o", png.string()}, dir);
  CHECK(o.code == 0);
  CHECK(o.err.empty());
  pt::Image p = pt::read_image(png.string());
  CHECK(p.channels.size() == 3);
}
