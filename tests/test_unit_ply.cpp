// PLY: ASCII and both binary byte orders give the same mesh; faces, strips, normals, uvs and
// colours are read as written; every validation rule refuses its bad file in one line.
#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "core/accel/accel.h"
#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/scene/ply_reader.h"
#include "core/util/error.h"
#include "temp_dir.h"

using namespace pt;

namespace {

// One square (a quad face) in the y = 0 plane, front face up, with normals, s/t and uchar colours,
// a property pt does not use (confidence) and an element it does not know (edge).
const char* kHeaderBody = R"(element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float s
property float t
property uchar red
property uchar green
property uchar blue
property float confidence
element face 1
property list uchar int vertex_indices
element edge 1
property int vertex1
property int vertex2
end_header
)";

struct V {
  float x, y, z, nx, ny, nz, s, t;
  uint8_t r, g, b;
  float confidence;
};
const V kVertices[4] = {{0, 0, 0, 0, 1, 0, 0, 0, 255, 0, 0, 0.5f},
                        {1, 0, 0, 0, 1, 0, 1, 0, 0, 255, 0, 0.5f},
                        {1, 0, -1, 0, 1, 0, 1, 1, 0, 0, 128, 0.5f},
                        {0, 0, -1, 0, 1, 0, 0, 1, 255, 255, 255, 0.5f}};

std::string ascii_square() {
  std::string s = std::string("ply\nformat ascii 1.0\ncomment made by a test\n") + kHeaderBody;
  for (const V& v : kVertices) {
    char line[256];
    std::snprintf(line, sizeof line, "%g %g %g %g %g %g %g %g %d %d %d %g\n", v.x, v.y, v.z, v.nx, v.ny, v.nz, v.s, v.t,
                  v.r, v.g, v.b, v.confidence);
    s += line;
  }
  return s + "4 0 1 2 3\n0 1\n";
}

template <class T>
void put(std::string& out, T value, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

std::string binary_square(bool big) {
  std::string s = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") + " 1.0\n" + kHeaderBody;
  for (const V& v : kVertices) {
    for (float f : {v.x, v.y, v.z, v.nx, v.ny, v.nz, v.s, v.t}) put(s, f, big);
    for (uint8_t c : {v.r, v.g, v.b}) put(s, c, big);
    put(s, v.confidence, big);
  }
  put(s, uint8_t(4), big);
  for (int32_t i : {0, 1, 2, 3}) put(s, i, big);
  put(s, int32_t(0), big);
  put(s, int32_t(1), big);
  return s;
}

void check_square(const PlyMesh& m) {
  REQUIRE(m.positions.size() == 4);
  CHECK(m.positions[2].x == 1);
  CHECK(m.positions[2].z == -1);
  CHECK(m.faces == 1);
  REQUIRE(m.triangles == std::vector<uint32_t>{0, 1, 2, 0, 2, 3});  // a fan
  REQUIRE(m.normals.size() == 4);
  CHECK(m.normals[1].y == 1);
  REQUIRE(m.uvs.size() == 4);
  CHECK(m.uvs[2].x == 1);
  CHECK(m.uvs[2].y == 1);
  REQUIRE(m.colors.size() == 4);
  CHECK(m.colors[0].x == doctest::Approx(1));
  CHECK(m.colors[0].y == 0);
  CHECK(m.colors[2].z == doctest::Approx(srgb_decode(128.0f / 255.0f)));  // uchar colours are sRGB
  CHECK(m.ignored.count("vertex.confidence") == 1);
  CHECK(m.ignored.count("edge") == 1);
}

std::string error_of(const std::string& text, const std::string& name = "bad.ply") {
  try {
    parse_ply(name, text);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("PLY: ASCII, binary little- and big-endian read the same square") {
  check_square(parse_ply("a.ply", ascii_square()));
  PlyMesh le = parse_ply("le.ply", binary_square(false));
  PlyMesh be = parse_ply("be.ply", binary_square(true));
  check_square(le);
  check_square(be);
  CHECK(le.format == "binary_little_endian");
  CHECK(be.format == "binary_big_endian");
  // CRLF line endings in an ASCII file read the same.
  std::string crlf;
  for (char c : ascii_square()) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  check_square(parse_ply("crlf.ply", crlf));
}

TEST_CASE("PLY: u/v and texture_u/texture_v name texture coordinates; float colours are linear") {
  for (const char* names : {"u v", "texture_u texture_v"}) {
    std::string a = names, u = a.substr(0, a.find(' ')), v = a.substr(a.find(' ') + 1);
    std::string text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
                       "property float " + u + "\nproperty float " + v +
                       "\nproperty float red\nproperty float green\nproperty float blue\n"
                       "element face 1\nproperty list uchar uint vertex_index\nend_header\n"
                       "0 0 0 0.25 0.5 0.5 0.25 1\n1 0 0 0 0 0 0 0\n0 1 0 0 0 0 0 0\n3 0 1 2\n";
    PlyMesh m = parse_ply("uv.ply", text);
    REQUIRE(m.uvs.size() == 3);
    CHECK(m.uvs[0].x == 0.25f);
    CHECK(m.uvs[0].y == 0.5f);
    CHECK(m.colors[0].x == 0.5f);
    CHECK(m.colors[0].y == 0.25f);
    CHECK(m.triangles.size() == 3);
  }
}

TEST_CASE("PLY: part of a normal, uv or colour is named as ignored, not dropped silently") {
  std::string text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                     "property float nx\nproperty float u\nproperty uchar red\n"
                     "element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
                     "0 0 0 1 0.5 255\n1 0 0 1 0.5 255\n0 1 0 1 0.5 255\n3 0 1 2\n";
  PlyMesh m = parse_ply("partial.ply", text);
  CHECK(m.normals.empty());
  CHECK(m.uvs.empty());
  CHECK(m.colors.empty());
  CHECK(m.triangles.size() == 3);
  CHECK(m.ignored.count("vertex.nx (a normal needs nx, ny and nz)") == 1);
  CHECK(m.ignored.count("vertex.u (a uv needs both coordinates)") == 1);
  CHECK(m.ignored.count("vertex.red (a colour needs red, green and blue)") == 1);
}

TEST_CASE("PLY: triangle strips, with -1 restarting a strip and repeated indices giving no triangle") {
  std::string text = "ply\nformat ascii 1.0\nelement vertex 7\nproperty float x\nproperty float y\nproperty float z\n"
                     "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0\n0 1 0\n1 1 0\n5 5 0\n6 5 0\n5 6 0\n"
                     "9 0 1 2 3 3 -1 4 5 6\n";
  PlyMesh m = parse_ply("strip.ply", text);
  // (0 1 2), (2 1 3) turned round to keep the winding, (3 3 .) dropped, then (4 5 6).
  CHECK(m.triangles == std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 4, 5, 6});
  CHECK(m.strips == 2);
}

TEST_CASE("PLY: every validation rule refuses its file in one line naming it") {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";
  struct Case {
    std::string text, expected;
  } cases[] = {
      {"plx\nformat ascii 1.0\n", "bad.ply: not a PLY file"},
      {"ply\nelement vertex 0\nend_header\n", "no 'format' line"},
      {"ply\nformat ascii 1.0\nelement vertex 1\n", "no 'end_header'"},
      {"ply\nformat utf8 1.0\n", "bad.ply:2: unknown PLY format 'utf8'"},
      {"ply\nformat ascii 2.0\n", "bad.ply:2: PLY version '2.0'"},
      {"ply\nformat ascii 1.0\nproperty float x\n", "bad.ply:3: 'property' before any 'element'"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float128 x\n", "bad.ply:4: unknown PLY type 'float128'"},
      {"ply\nformat ascii 1.0\nelement vertex -3\n", "bad.ply:3: element 'vertex' count '-3'"},
      {"ply\nformat ascii 1.0\nelement vertex 99999999999\n", "bad.ply:3: element 'vertex' count"},
      {"ply\nformat ascii 1.0\nbogus line\n", "bad.ply:3: unknown PLY header line 'bogus'"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n", "bad.ply:4: a list's count type"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar float vertex_indices\n", "bad.ply:4: 'vertex_indices' of 'face' must be a list of integers"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\n", "bad.ply:4: 'x' of 'vertex' must be a single value"},
      // counts the body cannot hold: refused from the header, before any allocation
      {"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
       "bad.ply:3: the header promises 4000000000 'vertex' elements"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nend_header\n" +
           std::string(100, '\1'),
       "bad.ply:3: the header promises 1000 'vertex' elements"},
      {"ply\nformat ascii 1.0\nelement vertex 2\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n", "has no properties"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 1 2\n", "no 'vertex' element"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nend_header\n0 0\n1 0\n0 1\n",
       "bad.ply:3: element 'vertex' needs properties x, y and z"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty int flags\nend_header\n" + verts + "7\n",
       "bad.ply:7: element 'face' has no vertex_indices list"},
      // the body
      {head + verts + "3 0 1 3\n", "bad.ply:13: vertex index 3 but the file has 3 vertices"},
      {head + verts + "3 0 -1 2\n", "bad.ply:13: vertex index -1"},
      {head + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "bad.ply:11: vertex property 'y' is not a finite number"},
      {head + "0 0 0\n1 1e39 0\n0 1 0\n3 0 1 2\n", "bad.ply:11: vertex property 'y' is not a finite number"},
      {head + "0 0 0\n1 abc 0\n0 1 0\n3 0 1 2\n", "bad.ply:11: 'abc' is not a number"},
      {head + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "bad.ply:11: too few values"},
      {head + "0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n", "bad.ply:10: 4 values on the line"},
      {head + verts + "2 0 1\n", "bad.ply:13: a face with 2 vertices"},
      {head + verts + "5 0 1 2\n", "bad.ply:13: a list of 5 indices runs past"},
      {head + verts + "3 0 1 2.5\n", "bad.ply:13: '2.5' is not an integer"},
      {head + verts + "300 0 1 2\n", "bad.ply:13: '300' does not fit the type 'uchar'"},
      {head + verts, "bad.ply:7: the header promises 1 'face' elements, more than the file's 18 body bytes"},
      {head + verts + "\n\n\n", "ends before element 'face' 0 of 1 (truncated)"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "property uchar red\nproperty uchar green\nproperty float blue\nend_header\n0 0 0 0 0 2\n1 0 0 0 0 0\n0 1 0 0 0 0\n",
       "bad.ply:11: colour 'blue' outside [0, 1]"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n" + verts,
       "no faces (a point cloud?)"},
      {head + verts + "3 0 0 0\n", "faces make no triangle"},
      // A second vertex list: its arrays sized by the first overran (found by attack).
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
       "property uchar green\nproperty uchar blue\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1 2 3\n" + verts + "3 0 1 2\n",
       "bad.ply:10: a second element 'vertex' (the first is on line 3)"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" +
           verts + "3 0 1 2\n3 0 1 2\n",
       "bad.ply:9: a second element 'face' (the first is on line 7)"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.text);
    std::string e = error_of(c.text);
    CHECK_MESSAGE(e.find(c.expected) != std::string::npos, e);
    CHECK(e.find('\n') == std::string::npos);
  }
}

TEST_CASE("PLY: binary errors name the element and its index") {
  std::string good = binary_square(false);
  // Truncated inside the face's index list, and inside the last element.
  std::string cut_list = good.substr(0, good.size() - 8 - 6);
  CHECK(error_of(cut_list).find("element 'face' 0: a list of 4 indices runs past the end of the file") != std::string::npos);
  std::string cut_body = good.substr(0, good.size() - 4);
  CHECK(error_of(cut_body).find("element 'edge' 0: the file ends inside this element (truncated)") != std::string::npos);
  // An index out of range: the face's third index (after the count byte and two ints) set to 9.
  std::string bad = good;
  size_t face = bad.size() - 8 - 17;
  int32_t nine = 9;
  std::memcpy(&bad[face + 1 + 8], &nine, 4);
  CHECK(error_of(bad).find("element 'face' 0: vertex index 9 but the file has 4 vertices") != std::string::npos);
  // A non-finite coordinate in vertex 1.
  std::string inf = good;
  size_t header = inf.find("end_header\n") + 11;
  float infinity = INFINITY;
  std::memcpy(&inf[header + 39 + 4], &infinity, 4);  // vertex 1's y (39 bytes a vertex)
  CHECK(error_of(inf).find("element 'vertex' 1: vertex property 'y' is not a finite number") != std::string::npos);
  // A list whose count runs past the end of the file.
  std::string list = good;
  list[face] = char(200);
  CHECK(error_of(list).find("element 'face' 0: a list of 200 indices runs past the end") != std::string::npos);
}

TEST_CASE("PLY: read_scene renders a PLY as an OBJ, vertex colours as the diffuse colour") {
  TempDir dir("pt-ply");
  std::string path = dir.write("square.ply", binary_square(false));
  Scene scene = load_scene(path);
  // The square and the studio (nothing emits).
  CHECK(scene.studio().has_value());
  CHECK(scene.studio()->first_triangle == 2);
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  auto shade = [&](float x, float z) {
    Ray ray{{x, 10, z}, {0, -1, 0}};
    std::optional<Hit> hit = accel->intersect(ray);
    REQUIRE(hit.has_value());
    return scene.interaction(ray, *hit);
  };
  // Near corner 0 (red) and corner 3 (white): the vertex colours interpolated.
  SurfaceInteraction a = shade(0.01f, -0.01f);
  CHECK(scene.albedo(a).x == doctest::Approx(1).epsilon(0.03));
  CHECK(scene.albedo(a).y < 0.05f);
  SurfaceInteraction w = shade(0.01f, -0.99f);
  CHECK(min_component(scene.albedo(w)) > 0.95f);
  CHECK(scene.bsdf(w).albedo().x == scene.albedo(w).x);
  // Normals and uvs came along.
  CHECK(a.ns.y == doctest::Approx(1));
  CHECK(a.uv.x == doctest::Approx(0.01f).epsilon(0.01));
  // The unused property and element are named once.
  size_t notes = 0;
  for (const std::string& n : scene.notes()) notes += n.find("vertex.confidence") != std::string::npos;
  CHECK(notes == 1);
}

TEST_CASE("PLY: a JSON scene places a PLY; a material override drops its colours; unknown kinds are refused") {
  TempDir dir("pt-ply");
  dir.write("square.ply", ascii_square());
  dir.write("model.gltf.txt", "{}");
  std::string scene_file = dir.write("scene.json", R"({"materials": {"grey": {"albedo": 0.5}},
    "objects": [{"file": "square.ply", "translate": [0, 1, 0]},
                {"file": "square.ply", "scale": [-1, 1, 1], "material": "grey"},
                {"file": "square.ply", "instances": [{"translate": [5, 0, 0]}, {"translate": [7, 0, 0]}]}],
    "lights": [{"type": "point", "position": [0, 3, 0], "intensity": 1}]})");
  Scene scene = load_scene(scene_file);
  // The first two objects are baked into the world mesh; the third stays one mesh, placed twice.
  CHECK(scene.geometry().mesh().triangle_count() == 4);
  // The first object's colours; none for the second's triangles (read as white past the end).
  CHECK(scene.geometry().mesh().corner_colors.size() == 6);
  CHECK(scene.geometry().mesh().corner_colors[0].y == 0);  // vertex 0: red
  REQUIRE(scene.geometry().instances().size() == 2);
  const Mesh& placed = scene.geometry().instance_mesh(1);
  CHECK(placed.triangle_count() == 2);
  CHECK(placed.corner_colors.size() == 6);  // the instanced mesh keeps its colours
  CHECK(placed.corner_colors[0].y == 0);
  CHECK(scene.geometry().mesh().positions[0].y == 1);
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  Ray down{{-0.5f, 10, -0.5f}, {0, -1, 0}};
  auto hit = accel->intersect(down);
  REQUIRE(hit.has_value());
  SurfaceInteraction si = scene.interaction(down, *hit);
  CHECK(si.ng.y > 0.99f);  // the mirrored copy still faces up
  CHECK(scene.albedo(si).x == 0.5f);
  std::string gltf = dir.write("gltf.json", R"({"objects": [{"file": "x.gltf", "instances": [{"translate": [1, 0, 0]}]}]})");
  try {
    load_scene(gltf);
    FAIL("instances of a glTF file were accepted");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find("gltf.json: /objects/0/instances: a glTF file places its meshes by its own nodes") !=
          std::string::npos);
  }
  std::string unknown = dir.write("unknown.json", R"({"objects": [{"file": "model.gltf.txt"}]})");
  try {
    load_scene(unknown);
    FAIL("an unknown object file kind was accepted");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find("unknown.json: /objects/0/file: unknown kind of object file '.txt'") != std::string::npos);
  }
}
