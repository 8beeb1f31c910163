// The camera on the command line: --look-from/--look-at/--up/--fov give the image the same camera
// written in the scene file gives, `pt info` prints the camera as flags that reproduce the image,
// --up-axis z turns the default camera for Z-up models, and bad camera flags are one-line errors.
#include <doctest/doctest.h>

#include <regex>

#include "core/image/image.h"
#include "run_pt.h"

namespace fs = std::filesystem;

namespace {

// The pixels of two images are the same, bit for bit.
void check_same_pixels(const std::string& a, const std::string& b) {
  pt::Image x = pt::read_image(a), y = pt::read_image(b);
  REQUIRE(x.width == y.width);
  REQUIRE(x.height == y.height);
  REQUIRE(x.channels == y.channels);
  size_t differ = 0;
  for (size_t i = 0; i < x.pixels.size(); ++i) differ += x.pixels[i] != y.pixels[i];
  CHECK(differ == 0);
}

double mean_green(const std::string& path) {
  pt::Image img = pt::read_image(path);
  double sum = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) sum += img.at(x, y, 1);
  }
  return sum / (img.width * img.height);
}

const char* kBody = R"("spheres": [{"center": [0, 1, 0], "radius": 1}, {"center": [2, 0.5, -1], "radius": 0.5}],
  "lights": [{"type": "point", "position": [2, 5, 4], "intensity": 40}],
  "render": {"resolution": [40, 30], "spp": 4})";

}  // namespace

TEST_CASE("camera flags give the same image as the same camera in the scene file") {
  TempDir dir("pt-cli-view");
  std::string with_camera = dir.write("with/scene.json", std::string("{") + R"("camera": {"position": [-1.5, 2.25, 6],
    "look_at": [0.5, 0.75, -0.25], "up": [0.1, 1, 0], "fov": 33.5}, )" + kBody + "}");
  std::string without = dir.write("without/scene.json", std::string("{") + kBody + "}");
  std::string a = (dir.path / "a.exr").string(), b = (dir.path / "b.exr").string();
  PtRun ra = run_pt({"render", with_camera, "-q", "-o", a}, dir);
  CHECK(ra.code == 0);
  PtRun rb = run_pt({"render", without, "-q", "-o", b, "--look-from", "-1.5,2.25,6", "--look-at", "0.5,0.75,-0.25",
                     "--up", "0.1,1,0", "--fov", "33.5"},
                    dir);
  CAPTURE(rb.err);
  CHECK(rb.code == 0);
  check_same_pixels(a, b);
  // The image records the camera as flags.
  CHECK(pt::read_image(b).metadata["pt:camera"] == "--look-from -1.5,2.25,6 --look-at 0.5,0.75,-0.25 --up 0.1,1,0 --fov 33.5");
  // One flag replaces one part of the scene file's camera: a narrower field of view zooms in.
  std::string c = (dir.path / "c.exr").string();
  CHECK(run_pt({"render", with_camera, "-q", "-o", c, "--fov", "10"}, dir).code == 0);
  CHECK(pt::read_image(c).metadata["pt:camera"] == "--look-from -1.5,2.25,6 --look-at 0.5,0.75,-0.25 --up 0.1,1,0 --fov 10");
}

TEST_CASE("pt info prints the camera as flags that reproduce the default camera's image") {
  TempDir dir("pt-cli-view");
  // An OBJ off the origin with no camera: the default camera frames it.
  std::string obj = dir.write("box.obj",
                              "v 10 0 3\nv 12 0 3\nv 12 1 3\nv 10 1 3\nv 10 0 2\nv 12 0 2\nv 12 1 2\nv 10 1 2\n"
                              "f 1 2 3 4\nf 6 5 8 7\nf 2 6 7 3\nf 5 1 4 8\nf 4 3 7 8\nf 5 6 2 1\n");
  for (const char* axis : {"y", "z"}) {
    CAPTURE(axis);
    PtRun info = run_pt({"info", obj, "--up-axis", axis, "--res", "32x24"}, dir);
    REQUIRE(info.code == 0);
    std::smatch m;
    REQUIRE(std::regex_search(info.out, m, std::regex(R"(as flags +(--look-from (\S+) --look-at (\S+) --up (\S+) --fov (\S+)))")));
    std::string up = m[4].str();
    CHECK(up == (std::string(axis) == "z" ? "0,0,1" : "0,1,0"));
    // The default camera is above the model in the up axis's sense, and in front of it: +z for
    // +y up, -y (Blender's front) for +z up.
    float from[3];
    REQUIRE(std::sscanf(m[2].str().c_str(), "%f,%f,%f", &from[0], &from[1], &from[2]) == 3);
    if (std::string(axis) == "y") {
      CHECK(from[2] > 3);
      CHECK(from[1] > 0.5f);
    } else {
      CHECK(from[1] < 0);
      CHECK(from[2] > 2.5f);
    }
    std::string a = (dir.path / "default.exr").string(), b = (dir.path / "pasted.exr").string();
    CHECK(run_pt({"render", obj, "-q", "--up-axis", axis, "--res", "32x24", "--spp", "2", "-o", a}, dir).code == 0);
    std::vector<std::string> args = {"render", obj, "-q", "--up-axis", axis, "--res", "32x24", "--spp", "2", "-o", b};
    std::istringstream flags(m[1].str());
    for (std::string f; flags >> f;) args.push_back(f);
    PtRun r = run_pt(args, dir);
    CAPTURE(r.err);
    CHECK(r.code == 0);
    check_same_pixels(a, b);
    CHECK(mean_green(a) > 0);
  }
}

TEST_CASE("a bad camera flag is a one-line error naming the flag, before any rendering") {
  // The flags' checks are unit-tested (test_unit_view.cpp); here the path from the command line.
  TempDir dir("pt-cli-view");
  std::string scene = dir.write("s/scene.json", std::string("{") + kBody + "}");
  std::vector<PtRun> results = run_pt_all({{"render", scene, "-o", (dir.path / "out.png").string(), "--look-from", "1,2"},
                                           {"render", scene, "-o", (dir.path / "out.png").string(), "--up-axis", "x"}},
                                          dir);
  const char* expected[] = {"--look-from '1,2'", "--up-axis"};
  for (size_t i = 0; i < results.size(); ++i) {
    CAPTURE(results[i].err);
    CHECK(results[i].code == 2);
    CHECK(std::count(results[i].err.begin(), results[i].err.end(), '\n') == 1);
    CHECK(results[i].err.find(expected[i]) != std::string::npos);
  }
  CHECK_FALSE(fs::exists(dir.path / "out.png"));
}
