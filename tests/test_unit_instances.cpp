// Instances: transforms and their inverses, the SceneBuilder API (add_mesh, add_instance,
// resolve_instances) and the JSON scene format's "instances" lists, with their mistakes.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "core/geometry/instance.h"
#include "core/math/rng.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "renderer/tools/gen_instances.h"
#include "temp_dir.h"

using namespace pt;

namespace {
LoadOptions no_studio() {
  LoadOptions o;
  o.studio = Studio::kNone;
  return o;
}
}  // namespace

namespace {

Transform random_transform(Pcg32& rng) {
  Vec3f s{0.2f + 3 * rng.next_float(), 0.2f + 3 * rng.next_float(), 0.2f + 3 * rng.next_float()};
  if (rng.next_float() < 0.3f) s.y = -s.y;
  Vec3f r{360 * rng.next_float(), 360 * rng.next_float(), 360 * rng.next_float()};
  Vec3f t{20 * rng.next_float() - 10, 20 * rng.next_float() - 10, 20 * rng.next_float() - 10};
  return Transform::translate(t) * Transform::rotate_axis(2, r.z) * Transform::rotate_axis(1, r.y) *
         Transform::rotate_axis(0, r.x) * Transform::scale(s);
}

// One triangle with normals and uvs, material m.
Mesh triangle_mesh(uint32_t m) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.indices = {0, 1, 2};
  mesh.material = {m};
  mesh.corner_normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  mesh.corner_uvs = {{0, 0}, {1, 0}, {0, 1}};
  return mesh;
}

const char* kTwoTriangleObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 1\nf 1/1/1 2/2/1 3/1/1\nf 1/1/1 3/2/1 4/2/1\n";

std::string read_file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("Transform::inverse undoes the transform; normals stay perpendicular to surfaces") {
  Pcg32 rng(7, 1);
  for (int k = 0; k < 200; ++k) {
    Transform t = random_transform(rng);
    REQUIRE(instance_transform_problem(t).empty());
    Transform inv = t.inverse();
    Vec3f p{4 * rng.next_float() - 2, 4 * rng.next_float() - 2, 4 * rng.next_float() - 2};
    Vec3f back = inv.point(t.point(p));
    CHECK(length(back - p) < 1e-5f * (1 + length(p)) * 20);
    // A tangent and the normal of the plane it lies in: still perpendicular after the transform.
    Vec3f a{1, 2, 3}, b{-2, 0.5f, 1};
    Vec3f n = cross(a, b);
    Vec3f ta = t.vector(a), tb = t.vector(b), tn = normalize(t.normal(n));
    CHECK(std::abs(dot(tn, normalize(ta))) < 1e-4f);
    CHECK(std::abs(dot(tn, normalize(tb))) < 1e-4f);
    // and on the side the transformed winding makes the front (mirroring reverses the winding).
    float side = dot(tn, cross(ta, tb));
    CHECK((t.flips_handedness() ? side < 0 : side > 0));
  }
}

TEST_CASE("instance_transform_problem: refuses non-finite and flattening transforms") {
  Transform t;
  CHECK(instance_transform_problem(t).empty());
  CHECK(instance_transform_problem(Transform::scale({1e-10f, 1e-10f, 1e-10f})).empty());  // tiny but not flat
  CHECK(instance_transform_problem(Transform::scale({1e10f, 1e-10f, 1})).empty());  // stretched, not flat
  Transform nearly_flat;  // two columns 1e-8 radians apart
  nearly_flat.m[0][1] = 1;
  nearly_flat.m[1][1] = 1e-8f;
  CHECK(instance_transform_problem(nearly_flat).find("singular") != std::string::npos);
  CHECK(instance_transform_problem(Transform::scale({1, 0, 1})).find("singular") != std::string::npos);
  Transform nan;
  nan.m[1][3] = std::nanf("");
  CHECK(instance_transform_problem(nan).find("non-finite") != std::string::npos);
  Transform inf;
  inf.m[0][0] = kInf;
  CHECK(instance_transform_problem(inf).find("non-finite") != std::string::npos);
  Transform shear;  // two equal columns: rank 2
  shear.m[0][1] = 1;
  shear.m[1][1] = 0;
  shear.m[0][0] = 1;
  shear.m[1][0] = 0;
  CHECK(instance_transform_problem(shear).find("singular") != std::string::npos);
}

TEST_CASE("SceneBuilder: a mesh placed once is baked into world space; unknown meshes and bad transforms refused") {
  SceneBuilder b;
  b.source = "test";
  uint32_t m = b.default_material();
  uint32_t id = b.add_mesh(triangle_mesh(m));
  CHECK(id == 0);
  CHECK_THROWS_WITH_AS(b.add_instance(1, Transform()), doctest::Contains("mesh 1"), Error);
  CHECK_THROWS_WITH_AS(b.add_instance(id, Transform::scale({1, 1, 0})), doctest::Contains("singular"), Error);
  CHECK(b.instances.empty());
  Transform mirror = Transform::translate({0, 0, 5}) * Transform::scale({-2, 2, 2});
  b.add_instance(id, mirror);
  b.add_mesh(triangle_mesh(m));  // placed nowhere: dropped
  b.resolve_instances();
  CHECK(b.meshes.empty());
  CHECK(b.instances.empty());
  REQUIRE(b.mesh.triangle_count() == 1);
  // The mirror reverses the winding, so the front face (and the corner normals) still agree.
  Vec3f ng = normalize(b.mesh.geometric_normal(0));
  CHECK(ng.z == doctest::Approx(1.0f));
  for (int c = 0; c < 3; ++c) CHECK(dot(b.mesh.corner_normals[c], ng) == doctest::Approx(1.0f));
  CHECK(b.mesh.vertex(0, 0) == Vec3f(0, 0, 5));
  CHECK(b.mesh.corner_uvs.size() == 3);
  CHECK(b.geometry_bounds().lo.x == -2.0f);
  b.resolve_instances();  // again: nothing left to do
  CHECK(b.mesh.triangle_count() == 1);
}

TEST_CASE("JSON: an object's instances list places one OBJ many times; one instance equals the plain object") {
  TempDir dir("pt-instances");
  dir.write("quad.obj", kTwoTriangleObj);
  // The same transform given as an object's own, and as its single instance.
  const char* transform = R"("scale": [2, -1, 0.5], "rotate": [10, 20, 30], "translate": [1, 2, 3])";
  std::string plain = dir.write("plain.json", std::string(R"({"objects": [{"file": "quad.obj", )") + transform + "}]}");
  std::string once = dir.write("once.json", std::string(R"({"objects": [{"file": "quad.obj", "instances": [{)") + transform + "}]}]}");
  SceneBuilder a = read_scene(plain, no_studio());
  SceneBuilder b = read_scene(once, no_studio());
  REQUIRE(a.mesh.triangle_count() == 2);
  REQUIRE(b.mesh.triangle_count() == 2);
  CHECK(a.mesh.positions.size() == b.mesh.positions.size());
  for (size_t i = 0; i < a.mesh.positions.size(); ++i) CHECK(a.mesh.positions[i] == b.mesh.positions[i]);
  CHECK(a.mesh.indices == b.mesh.indices);
  CHECK(a.mesh.corner_uvs.size() == b.mesh.corner_uvs.size());
  for (size_t i = 0; i < a.mesh.corner_normals.size(); ++i) {
    CHECK(length(a.mesh.corner_normals[i] - b.mesh.corner_normals[i]) < 1e-6f);
  }

  // Three placements, one with a matrix, under the object's own translation.
  std::string three = dir.write("three.json", R"({"objects": [{"file": "quad.obj", "translate": [0, 10, 0], "instances": [
      {}, {"translate": [5, 0, 0]}, {"matrix": [2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, -3,  0, 0, 0, 1]}]}]})");
  Scene s = load_scene(three, no_studio());
  BBox bounds = s.bounds();
  CHECK(bounds.lo == Vec3f(0, 10, -3));
  CHECK(bounds.hi == Vec3f(6, 12, 0));
  CHECK(s.inputs().size() == 2);  // the OBJ is read once
  // Placed three times: one mesh, three instances, nothing baked.
  CHECK(s.geometry().instances().size() == 3);
  CHECK(s.geometry().objects().size() == 1);
  CHECK(s.mesh().triangle_count() == 0);
  CHECK(s.geometry().world_triangle_count() == 6);
}

TEST_CASE("JSON: mistakes in instances are errors naming the place") {
  TempDir dir("pt-instances");
  dir.write("quad.obj", kTwoTriangleObj);
  struct Case {
    const char* json;
    const char* expect;
  } cases[] = {
      {R"({"objects": [{"file": "quad.obj", "instances": []}]})", "/objects/0/instances: expected a non-empty array"},
      {R"({"objects": [{"file": "quad.obj", "instances": {"translate": [0, 0, 0]}}]})", "/objects/0/instances: expected"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{}, {"scale": [1, 0, 1]}]}]})", "/objects/0/instances/1/scale: a zero scale"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{"translate": [0, 1e39, 0]}]}]})", "/objects/0/instances/0/translate/1: expected a finite number"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}]}]})", "/objects/0/instances/0/matrix: expected an array of 12 or 16"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0]}]}]})", "/objects/0/instances/0: the transform is singular"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]}]}]})", "/objects/0/instances/0/matrix/14: the last row must be 0 0 0 1"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, "x"]}]}]})", "/objects/0/instances/0/matrix/11: expected a number"},
      {R"({"objects": [{"file": "quad.obj", "instances": [{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0], "translate": [0, 0, 0]}]}]})", "/objects/0/instances/0/matrix: a 'matrix' replaces"},
      {R"({"objects": [{"file": "quad.obj", "scale": 1e-30, "instances": [{"scale": 1e-30}]}]})", "/objects/0/instances/0: the transform is singular: it flattens the object (with the object's own transform)"},
      {R"({"objects": [{"file": "missing.obj", "instances": [{}, {}]}]})", "missing.obj"},
  };
  for (const Case& c : cases) {
    std::string text = c.json;
    CAPTURE(text);
    std::string file = dir.write("bad.json", text);
    try {
      load_scene(file);
      FAIL("expected pt::Error");
    } catch (const Error& e) {
      std::string what = e.what();
      CAPTURE(what);
      CHECK(what.find(c.expect) != std::string::npos);
      CHECK(what.find('\n') == std::string::npos);
    }
  }
}

TEST_CASE("pt gen instances: one object with an instances list, or the same placements flattened") {
  TempDir dir("pt-instances");
  std::string obj = dir.write("meshes/quad.obj", kTwoTriangleObj);
  std::string inst = (dir.path / "field.json").string(), flat = (dir.path / "flat.json").string();
  InstanceFieldOptions o;
  o.mesh = obj;
  o.count = 40;
  write_instance_field(inst, o);
  o.flatten = true;
  write_instance_field(flat, o);
  CHECK(read_file_text(inst).find("\"file\": \"meshes/quad.obj\"") != std::string::npos);
  Scene a = load_scene(inst, no_studio());
  Scene b = load_scene(flat, no_studio());
  CHECK(a.geometry().instances().size() == 40);
  CHECK(a.mesh().triangle_count() == 0);
  CHECK(b.geometry().instances().empty());
  CHECK(b.mesh().triangle_count() == 80);
  CHECK(a.geometry().world_triangle_count() == 80);
  // The same placements: the same bounds, exactly (each vertex transformed alike).
  CHECK(a.bounds().lo == b.bounds().lo);
  CHECK(a.bounds().hi == b.bounds().hi);
  CHECK(a.bounds().lo.y == doctest::Approx(0.0f).scale(1.0f));  // the copies stand on y = 0
  // Mistakes: a missing mesh, no copies.
  o.mesh = (dir.path / "missing.obj").string();
  CHECK_THROWS_WITH_AS(write_instance_field(inst, o), doctest::Contains("missing.obj"), Error);
  o.mesh = obj;
  o.count = 0;
  CHECK_THROWS_AS(write_instance_field(inst, o), Error);
  CHECK(a.geometry().instances().size() == 40);
}

TEST_CASE("pt gen instances: a .glb of the same field places the same copies, with a camera") {
  TempDir dir("pt-instances");
  std::string obj = dir.write("quad.obj", kTwoTriangleObj);
  std::string json_path = (dir.path / "field.json").string(), glb = (dir.path / "field.glb").string(),
              flat = (dir.path / "flat.glb").string();
  InstanceFieldOptions o;
  o.mesh = obj;
  o.count = 25;
  write_instance_field(json_path, o);
  write_instance_field(glb, o);
  o.flatten = true;
  write_instance_field(flat, o);
  Scene a = load_scene(json_path, no_studio());
  Scene b = load_scene(glb, no_studio());
  Scene c = load_scene(flat, no_studio());
  CHECK(b.geometry().instances().size() == 25);
  CHECK(b.geometry().world_triangle_count() == 50);
  CHECK(c.geometry().instances().empty());
  CHECK(c.mesh().triangle_count() == 50);
  for (int k = 0; k < 3; ++k) {
    CHECK(b.bounds().lo[k] == doctest::Approx(a.bounds().lo[k]).epsilon(1e-5));
    CHECK(b.bounds().hi[k] == doctest::Approx(a.bounds().hi[k]).epsilon(1e-5));
    CHECK(c.bounds().hi[k] == doctest::Approx(a.bounds().hi[k]).epsilon(1e-5));
  }
  // The glTF's camera is the JSON scene's: the same eye and view direction.
  REQUIRE(a.camera().has_value());
  REQUIRE(b.camera().has_value());
  CHECK(length(b.camera()->position - a.camera()->position) < 1e-3f * length(a.camera()->position));
  const Vec3f da = normalize(a.camera()->look_at - a.camera()->position), db = normalize(b.camera()->look_at - b.camera()->position);
  CHECK(dot(da, db) > 0.9999f);
  o.flatten = false;
  CHECK_THROWS_WITH_AS(write_instance_field((dir.path / "field.gltf").string(), o), doctest::Contains(".glb"), Error);
}
