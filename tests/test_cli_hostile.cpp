// The real `pt` binary on hostile input (issue 11): files that would be read forever or take
// quadratic time, text that talks past the validator, headers that claim gigabytes, geometry Embree
// cannot trace, values that overflow the image, tokens that would flood or corrupt the terminal.
// Each is refused in one line with exit 2 and nothing written, or rendered correctly with a warning.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "obj_text.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

// A PNG of a few dozen bytes whose header claims width x height RGB pixels (a valid IHDR with its
// CRC and a short IDAT, so the reader gets as far as allocating).
std::string png_claiming(uint32_t width, uint32_t height) {
  auto crc32 = [](const std::string& bytes) {
    uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
      c ^= b;
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
  };
  auto be32 = [](uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    return be32(static_cast<uint32_t>(data.size())) + type + data + be32(crc32(type + data));
  };
  std::string ihdr = be32(width) + be32(height) + std::string("\x08\x02\x00\x00\x00", 5);
  // zlib stream of a stored (uncompressed) block of 16 zero bytes.
  std::string idat("\x78\x01\x01\x10\x00\xef\xff", 7);
  idat += std::string(16, '\0') + std::string("\x00\x10\x00\x01", 4);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", idat) + chunk("IEND", "");
}

std::string textured_sphere_scene(const std::string& texture) {
  return R"({"materials": {"m": {"texture": ")" + texture + R"("}},
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}],
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40},
    "lights": [{"type": "point", "position": [0, 3, 3], "intensity": 10}], "render": {"resolution": [8, 8], "spp": 1}})";
}

}  // namespace

TEST_CASE("FIFOs, devices and symbolic link loops are refused, never read forever") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  REQUIRE(::mkfifo((dir.path / "fifo.obj").c_str(), 0644) == 0);
  batch.add({(dir.path / "fifo.obj").string()}, {"fifo.obj", "not a regular file"});
  REQUIRE(::mkfifo((dir.path / "fifo.json").c_str(), 0644) == 0);
  batch.add({(dir.path / "fifo.json").string()}, {"fifo.json", "not a regular file"});
  fs::create_symlink("/dev/zero", dir.path / "zero.obj");
  batch.add({(dir.path / "zero.obj").string()}, {"zero.obj", "not a regular file"});
  // As a texture, an environment map and a material library.
  REQUIRE(::mkfifo((dir.path / "fifo.png").c_str(), 0644) == 0);
  batch.add({dir.write("fifo-texture.json", textured_sphere_scene("fifo.png"))}, {"fifo.png", "not a regular file"});
  fs::create_symlink("/dev/urandom", dir.path / "random.png");
  batch.add({dir.write("random-texture.json", textured_sphere_scene("random.png"))}, {"random.png", "not a regular file"});
  fs::create_symlink("/dev/zero", dir.path / "zero.exr");
  batch.add({dir.write("zero-sky.json", R"({"spheres": [{"center": [0, 0, 0], "radius": 1}], "environment": {"file": "zero.exr"}})")},
            {"zero.exr", "not a regular file"});
  REQUIRE(::mkfifo((dir.path / "fifo.mtl").c_str(), 0644) == 0);
  batch.add({dir.write("fifo-mtl.obj", "mtllib fifo.mtl\n" + std::string(kTriangle) + "f 1 2 3\n")}, {"fifo.mtl", "not a regular file"});
  // Symbolic link loops: the usual one line and exit 2, not a raw "filesystem error" with exit 1.
  fs::create_symlink("loop2.obj", dir.path / "loop1.obj");
  fs::create_symlink("loop1.obj", dir.path / "loop2.obj");
  batch.add({(dir.path / "loop1.obj").string()}, {"loop1.obj", "symbolic links"});
  fs::create_symlink("loop.png", dir.path / "loop.png");
  batch.add({dir.write("loop-texture.json", textured_sphere_scene("loop.png"))}, {"loop.png", "symbolic links"});
  fs::create_symlink("loopdir", dir.path / "loopdir");
  batch.add({(dir.path / "loopdir").string()}, {"loopdir", "symbolic links"});
  batch.run();
}

TEST_CASE("a face with too many vertices is refused at once, not triangulated in quadratic time") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  std::string big = dir.write("big-face.obj", pt::test::polygon_obj(65536));
  batch.add({big}, {big + ":65537:", "65536 vertices"});
  batch.run();
  // 1024 is the documented limit: that face renders.
  std::string ok = dir.write("ok-face.obj", pt::test::polygon_obj(1024));
  Outcome o = run_pt({"render", ok, "--res", "8x8", "--spp", "1", "-q", "-o", (dir.path / "ok.png").string()}, dir);
  CAPTURE(o.err);
  CHECK(o.code == 0);
}

TEST_CASE("the validator sees the lines and the material libraries tinyobjloader reads") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  // Lone CR line ends: a "nan" on the second line, which a \n-only reader saw as part of a comment.
  std::string cr = dir.write("cr.obj", "# exported\rv nan 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r");
  batch.add({cr}, {cr + ":2:", "nan"});
  std::string crlf = dir.write("crlf.obj", "# exported\r\nv 0 0 0\r\nv 1 inf 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
  batch.add({crlf}, {crlf + ":3:", "inf"});
  // `mtllib a.mtl b.mtl`: two libraries; a.mtl is missing, so tinyobjloader reads b.mtl.
  dir.write("b.mtl", "newmtl m\nKd nan 1 1\n");
  std::string two = dir.write("two-libs.obj", "mtllib a.mtl b.mtl\n" + std::string(kTriangle) + "usemtl m\nf 1 2 3\n");
  batch.add({two}, {(dir.path / "b.mtl").string() + ":2:"});
  // A bad MTL with lone CRs.
  dir.write("cr.mtl", "newmtl m\rKd 0.5 0.5 0.5\rKe 1 nan 1\r");
  std::string cr_mtl = dir.write("cr-mtl.obj", "mtllib cr.mtl\n" + std::string(kTriangle) + "usemtl m\nf 1 2 3\n");
  batch.add({cr_mtl}, {(dir.path / "cr.mtl").string() + ":3:"});
  // Numbers tinyobjloader would read differently from strtod.
  std::string hex = dir.write("hex.obj", "v 0 0 0\nv 0x10 0 0\nv 0 1 0\nf 1 2 3\n");
  batch.add({hex}, {hex + ":2:", "0x10"});
  // A vertical tab is not a separator for tinyobjloader: "v\v1 2 3" is no vertex to it.
  std::string vt = dir.write("vtab.obj", "v\v0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  batch.add({vt}, {vt + ":1:"});
  batch.run();

  // When the first library exists, tinyobjloader reads only it: the second is named as not read.
  dir.write("good.mtl", "newmtl m\nKd 0.5 0.5 0.5\n");
  std::string first = dir.write("first-exists.obj", "mtllib good.mtl b.mtl\n" + std::string(kTriangle) + "usemtl m\nf 1 2 3\n");
  Outcome o = run_pt({"info", first}, dir);
  CAPTURE(o.err);
  CHECK(o.code == 0);
  CHECK(o.err.find("not read: 'b.mtl'") != std::string::npos);
}

TEST_CASE("image headers are checked before allocation and the file is named; oversized inputs cost no memory") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  dir.write("claims-200M.png", png_claiming(20000, 10000));
  std::string big = dir.write("big-texture.json", textured_sphere_scene("claims-200M.png"));
  batch.add({big}, {"claims-200M.png", "Mpixels"});
  dir.write("claims-1e12.png", png_claiming(1000000, 1000000));
  std::string huge = dir.write("huge-texture.json", textured_sphere_scene("claims-1e12.png"));
  batch.add({huge}, {"claims-1e12.png", "Mpixels"});
  // Within the limit (128 Mpixels) but holding almost nothing: read a strip at a time, it fails
  // after allocating only what the file really holds.
  dir.write("claims-128M.png", png_claiming(16000, 8000));
  std::string truncated = dir.write("truncated-texture.json", textured_sphere_scene("claims-128M.png"));
  batch.add({truncated}, {"claims-128M.png"});
  // A sparse 1 GiB OBJ (all NUL bytes) and JSON scene file.
  for (const char* name : {"sparse.obj", "sparse.json"}) {
    fs::path p = dir.path / name;
    std::ofstream(p).close();
    fs::resize_file(p, uint64_t(1) << 30);
  }
  batch.add({(dir.path / "sparse.obj").string()}, {"sparse.obj:1:", "NUL"});
  batch.add({(dir.path / "sparse.json").string()}, {"sparse.json", "at most"});
  std::vector<Outcome> outcomes = batch.run();
  // Peak memory of each run: pt itself (its libraries) takes ~140 MB; the headers claim 1.6 GB
  // (float RGB of 128 Mpixels) and more, and the sparse files 1 GiB.
  for (const Outcome& o : outcomes) {
    CAPTURE(o.err);
    CHECK(o.max_rss_kb < 600 * 1024);
  }
}

TEST_CASE("geometry beyond what Embree can trace is refused in render and info, not an abort") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  std::string far = dir.write("far.obj", "v 0 0 0\nv 1e18 0 0\nv 0 1 0\nf 1 2 3\n");
  batch.add({far}, {far, "beyond"});
  std::string sphere = dir.write("big-sphere.json", R"({"spheres": [{"center": [0, 0, 0], "radius": 1e38}]})");
  batch.add({sphere}, {sphere, "beyond"});
  std::string quad = dir.write("big-quad.json", R"({"spheres": [{"center": [0, 0, 0], "radius": 1}],
    "lights": [{"type": "quad", "corners": [[-1e38, 5, -1e38], [1e38, 5, -1e38], [1e38, 5, 1e38], [-1e38, 5, 1e38]], "radiance": 1}]})");
  batch.add({quad}, {quad, "beyond"});
  std::string camera = dir.write("far-camera.json", R"({"spheres": [{"center": [0, 0, 0], "radius": 1}],
    "camera": {"position": [0, 0, 1e30], "look_at": [0, 0, 0]}})");
  batch.add({camera}, {camera, "camera"});
  // Within the limit, but framed at an extreme aspect ratio the default camera would stand too far
  // (without the studio, whose ground, laid before the camera is chosen, would be named first).
  std::string tall = dir.write("tall.obj", "v 0 0 0\nv 1e14 0 0\nv 0 1e14 0\nf 1 2 3\n");
  batch.add({tall, "--res", "1x16384", "--studio", "none"}, {tall, "camera"});
  // The model fits, but the studio's ground, which reaches far beyond it, would not: named as such.
  std::string big = dir.write("big.obj", "v 0 0 0\nv 1e12 0 0\nv 0 1e12 0\nf 1 2 3\n");
  batch.add({big}, {big, "studio's ground", "beyond"});
  batch.run();
  Outcome plain = run_pt({"render", big, "--studio", "none", "--spp", "1", "--res", "8x8", "-o", (dir.path / "big.png").string()}, dir);
  CAPTURE(plain.err);
  CHECK(plain.code == 0);
  for (const std::string& scene : {far, sphere}) {
    Outcome o = run_pt({"info", scene}, dir);
    CAPTURE(o.err);
    CHECK(o.exited);
    CHECK(o.code == 2);
    CHECK(o.err.find("beyond") != std::string::npos);
  }
}

TEST_CASE("output that would lie: infinite variance is clamped with a warning, all-NaN renders name the cause") {
  TempDir dir("pt-hostile");
  // An emitter of 1e25: its variance of the mean squares past the float range.
  std::string bright = dir.write("bright.json", R"({"materials": {"e": {"emission": 1e25, "albedo": 0.5}},
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "e"}, {"center": [2.5, 0, 0], "radius": 1}],
    "camera": {"position": [0, 0, 6], "look_at": [0, 0, 0], "fov": 60},
    "render": {"resolution": [16, 16], "spp": 8, "integrator": "path"}})");
  fs::path exr = dir.path / "bright.exr";
  Outcome o = run_pt({"render", bright, "-q", "-o", exr.string()}, dir);
  CAPTURE(o.err);
  CHECK(o.code == 0);
  CHECK(o.err.find("clamped") != std::string::npos);
  pt::Image image = pt::read_image(exr.string());  // read_image refuses non-finite values
  CHECK(image.channels.size() == 6);

  // A light of the largest intensity a scene may give (1e30) 1e-5 above a floor seen from just
  // above it: I / d^2 overflows to infinity in every sample. No signal came, so "interrupted" would
  // be a lie. (A radiance of 3e38 did it before such values were refused at load.)
  Batch batch(dir);
  std::string nan_scene = dir.write("overflow.json", R"({"spheres": [{"center": [0, -1, 0], "radius": 1}],
    "lights": [{"type": "point", "position": [0, 0.00001, 0], "intensity": 1e30}],
    "camera": {"position": [0, 0.001, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 1}, "render": {"resolution": [8, 8], "spp": 2}})");
  batch.add({nan_scene, "-q"}, {nan_scene, "NaN or infinite"});
  batch.run();
}

TEST_CASE("command-line values that are accepted but meaningless are refused") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  std::string scene = dir.write("tri.obj", std::string(kTriangle) + "f 1 2 3\n");
  batch.add({scene, "--exposure", "nan"}, {"--exposure", "nan"});
  batch.add({scene, "--exposure", "1e400"}, {"--exposure"});
  batch.add({scene, "--time", "nan"}, {"--time", "nan"});
  batch.add({scene, "--time", "inf"}, {"--time"});
  batch.add({scene, "--seed", "-1"}, {"--seed", "-1"});
  batch.add({scene, "--seed", "18446744073709551616"}, {"--seed"});  // 2^64
  batch.add({scene, "--seed", "0x10"}, {"--seed"});
  batch.run();
  // The largest seed is taken as it is, not clamped.
  fs::path exr = dir.path / "seed.exr";
  Outcome o = run_pt({"render", scene, "--res", "4x4", "--spp", "1", "-q", "--seed", "18446744073709551615", "-o", exr.string()}, dir);
  CHECK(o.code == 0);
  CHECK(pt::read_image(exr.string()).metadata["pt:seed"] == "18446744073709551615");
}

TEST_CASE("messages: quoted tokens are capped and escaped, undefined materials are named") {
  TempDir dir("pt-hostile");
  Batch batch(dir);
  std::string long_number = dir.write("long-number.obj", "v 0 0 " + std::string(1 << 19, '7') + "x\n");
  batch.add({long_number}, {long_number + ":1:", "bytes)"});
  // A newline and a terminal escape sequence in a material name.
  std::string escape = dir.write("escape.json", "{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"red\\n\\u001b[2Jx\"}]}");
  batch.add({escape}, {escape, "\\n\\x1b[2J"});
  std::vector<Outcome> outcomes = batch.run();
  for (const Outcome& o : outcomes) {
    CHECK(o.err.size() < 1000);
    CHECK(o.err.find('\x1b') == std::string::npos);
  }
  // usemtl naming a material no library defines: a warning with the name and the line.
  dir.write("one.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
  std::string typo = dir.write("typo.obj", "mtllib one.mtl\n" + std::string(kTriangle) + "usemtl rde\nf 1 2 3\n");
  Outcome o = run_pt({"info", typo}, dir);
  CAPTURE(o.err);
  CHECK(o.code == 0);
  CHECK(o.err.find("'rde' (line 5)") != std::string::npos);
  CHECK(o.err.find("no material library defines") != std::string::npos);
}

TEST_CASE("pt info lists names from the files escaped: a terminal escape in an MTL material's name") {
  // Found by the fuzzer (seed 2026120402, mutant 481: a byte of street.mtl flipped to 0x02): `pt
  // info` printed material names as read, where every other line goes through printable().
  TempDir dir("pt-hostile");
  dir.write("esc.mtl", std::string("newmtl red\x1b[2J\x02x\nKd 0.8 0.1 0.1\n"));
  std::string obj = dir.write("esc.obj", "mtllib esc.mtl\n" + std::string(kTriangle) + "usemtl red\x1b[2J\x02x\nf 1 2 3\n");
  Outcome o = run_pt({"info", obj, "--studio", "none"}, dir);
  CAPTURE(o.err);
  REQUIRE(o.code == 0);
  CHECK(o.out.find("red\\x1b[2J\\x02x") != std::string::npos);
  for (const std::string* text : {&o.out, &o.err}) {
    for (unsigned char c : *text) {
      if (c == '\n') continue;
      CHECK_MESSAGE((c >= 0x20 && c != 0x7f), "a control character " << int(c));
    }
  }
}

TEST_CASE("default output names come from the scene's folder or file name") {
  TempDir dir("pt-hostile");
  fs::path scene_dir = dir.path / "my-scene";
  dir.write("my-scene/scene.json", R"({"spheres": [{"center": [0, 0, 0], "radius": 1}],
    "lights": [{"type": "point", "position": [0, 3, 3], "intensity": 10}], "render": {"resolution": [4, 4], "spp": 1}})");
  dir.write("my-scene/tri.obj", std::string(kTriangle) + "f 1 2 3\n");
  struct Case {
    std::vector<std::string> args;
    fs::path cwd;
    std::string expected;
  } cases[] = {
      {{"./scene.json"}, scene_dir, "my-scene.png"},
      {{"."}, scene_dir, "my-scene.png"},
      {{"my-scene/"}, dir.path, "my-scene.png"},
      {{"my-scene/scene.json"}, dir.path, "my-scene.png"},
      {{"./tri.obj"}, scene_dir, "tri.png"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args[0]);
    std::vector<std::string> args = {"render"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    args.push_back("-q");
    Outcome o = run_pt(args, dir, {c.cwd});
    CAPTURE(o.err);
    CHECK(o.code == 0);
    CHECK(fs::exists(c.cwd / c.expected));
    fs::remove(c.cwd / c.expected);
    for (const std::string& name : listing(c.cwd)) CHECK(name[0] != '.');  // no hidden "..png"
  }
}
