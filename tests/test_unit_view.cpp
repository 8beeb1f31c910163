// The render camera as the job decides it from the command line's view options: each flag
// replaces one part of the scene file's or the default camera, --up-axis z turns the default
// camera, and every mistake is an error naming the flag.
#include <doctest/doctest.h>

#include "core/util/error.h"
#include "renderer/render/job.h"
#include "scene_helpers.h"

using namespace pt;
using namespace pt::test;

namespace {

// A box (by default from (0,0,0) to (2,1,3)), lit, with or without a camera of its own.
std::shared_ptr<const Scene> box_scene(bool with_camera, Vec3f lo = {0, 0, 0}, Vec3f hi = {2, 1, 3}) {
  SceneBuilder scene;
  add_box(scene, lo, hi, add_material(scene, diffuse(Spectrum(0.5f))), false);
  scene.environment = Environment(Spectrum(1.0f));
  if (with_camera) set_view(scene, {1, 2, 9}, {1, 0.5f, 1.5f}, 35, 64, 48);
  return finish(std::move(scene));
}

Camera camera_of(const std::shared_ptr<const Scene>& scene, const ViewOptions& view) {
  JobOptions o;
  o.view = view;
  return prepare_job(scene, o).render.camera;
}

// View options from flag/value pairs, as the command line gives them.
ViewOptions view_from(const std::vector<std::pair<std::string, std::string>>& flags) {
  ViewOptions v;
  for (const auto& [flag, value] : flags) {
    if (flag == "--look-from") v.look_from = value;
    if (flag == "--look-at") v.look_at = value;
    if (flag == "--up") v.up = value;
    if (flag == "--fov") v.fov = std::stof(value);
    if (flag == "--up-axis") v.up_axis = kUpAxisNames.parse(value);
  }
  return v;
}

}  // namespace

TEST_CASE("view options: each flag replaces its part of the camera") {
  auto scene = box_scene(true);
  ViewOptions v;
  v.fov = 12.5f;
  Camera c = camera_of(scene, v);
  CHECK(c.position == Vec3f(1, 2, 9));
  CHECK(c.look_at == Vec3f(1, 0.5f, 1.5f));
  CHECK(c.vfov_degrees == 12.5f);
  v.look_from = "-4,5e-1,2.25";
  v.look_at = "0,0,-1";
  v.up = "0,1,0.5";
  c = camera_of(scene, v);
  CHECK(c.position == Vec3f(-4, 0.5f, 2.25f));
  CHECK(c.look_at == Vec3f(0, 0, -1));
  CHECK(c.up == Vec3f(0, 1, 0.5f));
  // The flags string reads back as the same camera.
  CHECK(camera_flags(c) == "--look-from -4,0.5,2.25 --look-at 0,0,-1 --up 0,1,0.5 --fov 12.5");
}

TEST_CASE("view options: without a scene camera, --look-from looks at the centre of the bounds") {
  ViewOptions v;
  v.look_from = "10,10,10";
  Camera c = camera_of(box_scene(false), v);
  CHECK(c.position == Vec3f(10, 10, 10));
  CHECK(c.look_at == Vec3f(1, 0.5f, 1.5f));
  CHECK(c.up == Vec3f(0, 1, 0));
}

TEST_CASE("view options: --up-axis z turns the default camera; --fov narrows its framing") {
  // The same box, as a Y-up and as a Z-up file would hold it: (x, y, z) -> (x, -z, y).
  auto scene = box_scene(false), turned = box_scene(false, {0, -3, 0}, {2, 0, 1});
  Camera y = camera_of(scene, view_from({}));
  ViewOptions v = view_from({{"--up-axis", "z"}});
  Camera z = camera_of(turned, v);
  CHECK(y.up == Vec3f(0, 1, 0));
  CHECK(z.up == Vec3f(0, 0, 1));
  Vec3f dy = normalize(y.position - y.look_at), dz = normalize(z.position - z.look_at);
  // Above the model along its up axis.
  CHECK(dy.y > 0.1f);
  CHECK(dz.z > 0.1f);
  // The same view of the same model, turned with it.
  CHECK(dz.x == doctest::Approx(dy.x));
  CHECK(dz.y == doctest::Approx(-dy.z));
  CHECK(dz.z == doctest::Approx(dy.y));
  v.fov = 20;
  Camera narrow = camera_of(turned, v);
  CHECK(narrow.vfov_degrees == 20);
  CHECK(length(narrow.position - narrow.look_at) > 1.5f * length(z.position - z.look_at));  // backs off to fit
}

TEST_CASE("view options: mistakes name the flag") {
  auto scene = box_scene(true);
  struct Case {
    std::vector<std::pair<std::string, std::string>> flags;
    const char* expected;
  } cases[] = {
      {{{"--look-from", "1,2"}}, "--look-from '1,2'"},
      {{{"--look-from", "1,2,3,4"}}, "--look-from '1,2,3,4'"},
      {{{"--look-at", "a,b,c"}}, "--look-at 'a,b,c'"},
      {{{"--look-at", "1,nan,3"}}, "--look-at '1,nan,3'"},
      {{{"--look-from", "0,1,5"}, {"--look-at", "0,1,5"}}, "--look-from and --look-at"},
      {{{"--look-from", "0,5,0"}, {"--look-at", "0,0,0"}}, "parallel"},
      {{{"--up", "0,0,0"}}, "--up '0,0,0'"},
      {{{"--fov", "180"}}, "--fov"},
      {{{"--fov", "-3"}}, "--fov"},
      {{{"--up-axis", "x"}}, "up axis 'x'"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.expected);
    CHECK_THROWS_WITH_AS(camera_of(scene, view_from(c.flags)), doctest::Contains(c.expected), Error);
  }
}
