// The stability measurements of `pt bench stability` as regression tests. Asserted: the scaled
// offset (offset_ray_origin, Wächter & Binder 2019) never lets a ray re-hit the surface it leaves,
// at any tested distance from the origin; the watertight triangle test (Woop et al. 2013) never
// leaks through a shared edge or vertex, nor does Embree's robust mode; the OBJ loader rejects
// non-finite vertices, and no backend returns a non-finite hit, hits a zero-area triangle or misses
// the good triangle beside broken ones; rays at 0.01 rad or more to a triangle hit it; ray/sphere
// hits match the double-precision answer for every radius and distance. The counts of methods that
// are known to fail (no or a fixed offset, Möller-Trumbore on shared edges, the most grazing rays)
// are printed, not asserted: the numbers say how often.
#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>

#include "core/math/rng.h"
#include "core/scene/scene.h"
#include "renderer/measure/stability.h"

using namespace pt;

namespace {

bool unavailable(const StabilityRow& r) { return r.note.rfind("unavailable", 0) == 0; }

void print(const std::vector<StabilityRow>& rows) {
  for (const StabilityRow& r : rows) {
    std::printf("%-18s %-26s %-15s %8g %6llu/%-6llu %s\n", r.test.c_str(), r.variant.c_str(), r.method.c_str(), r.distance,
                static_cast<unsigned long long>(r.failures), static_cast<unsigned long long>(r.trials), r.note.c_str());
  }
}

}  // namespace

// First in the file: it forks, which must happen before any worker thread exists.
TEST_CASE("non-finite vertices: the loader rejects them; backends handed them still hit only the valid triangle") {
  std::string dir = (std::filesystem::temp_directory_path() / "pt-test-stability-nonfinite").string();
  std::vector<StabilityRow> rows = measure_nonfinite(dir);
  print(rows);
  int backends = 0;
  for (const StabilityRow& r : rows) {
    CAPTURE(r.variant);
    CAPTURE(r.method);
    if (r.method == "loader") {
      CHECK(r.failures == 0);
      CHECK(r.note.find("not a finite number") != std::string::npos);
    } else if (!unavailable(r)) {
      // The valid triangle is hit, the broken ones never, and no hit carries a non-finite value.
      CHECK(r.trials > 0);
      CHECK(r.failures == 0);
      ++backends;
    }
  }
  CHECK(backends >= 2);
  std::filesystem::remove_all(dir);
}

TEST_CASE("the scaled offset has zero self-intersections at every distance") {
  StabilityOptions o;  // 1, 1e2, 1e4, 1e6
  std::vector<StabilityRow> rows = measure_self_intersection(o);
  print(rows);
  int checked = 0;
  for (const StabilityRow& r : rows) {
    if (unavailable(r) || r.variant.find("/scaled") == std::string::npos) continue;
    CAPTURE(r.variant);
    CAPTURE(r.method);
    CAPTURE(r.distance);
    CHECK(r.trials > 100);
    CHECK(r.failures == 0);
    ++checked;
  }
  CHECK(checked >= 2 * 2 * 4);  // triangles and spheres, at least the two Embree methods, 4 distances
}

TEST_CASE("the scaled offset: the SIMD form gives the paper's scalar form bit for bit") {
  // Wächter & Binder 2019, per component: a few ulps along n, or 1/65536 of n within 1/32 of the origin.
  auto scalar = [](float p, float n) {
    int32_t offset = static_cast<int32_t>(256.0f * n);
    int32_t bits = std::bit_cast<int32_t>(p);
    float moved = std::bit_cast<float>(bits + (p < 0 ? -offset : offset));
    return std::abs(p) < 1.0f / 32.0f ? p + (1.0f / 65536.0f) * n : moved;
  };
  Pcg32 rng(7, 11);
  int mismatches = 0;
  const float special[] = {0.0f, -0.0f, 1.0f / 32.0f, -1.0f / 32.0f, 1e-30f, -1e-30f, 3e38f, -3e38f};
  for (int i = 0; i < 200000; ++i) {
    // Coordinates across magnitudes 1e-6..1e6 of either sign, and the edge cases; unit normals.
    auto coord = [&]() {
      if (rng.next_float() < 0.05f) return special[static_cast<int>(rng.next_float() * 7.999f)];
      float m = std::pow(10.0f, -6.0f + 12.0f * rng.next_float());
      return rng.next_float() < 0.5f ? -m : m;
    };
    Vec3f p{coord(), coord(), coord()};
    Vec3f n = normalize(Vec3f(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
    Vec3f o = offset_ray_origin(p, n);
    for (int a = 0; a < 3; ++a) {
      if (std::bit_cast<uint32_t>(o[a]) != std::bit_cast<uint32_t>(scalar(p[a], n[a]))) ++mismatches;
    }
  }
  CHECK(mismatches == 0);
}

TEST_CASE("the watertight test and Embree's robust mode have zero leaks through shared edges and vertices") {
  StabilityOptions o;
  std::vector<StabilityRow> rows = measure_leaks(o);
  print(rows);
  bool watertight_ran = false;
  for (const StabilityRow& r : rows) {
    if (r.method == "embree-robust" && !unavailable(r)) {
      CAPTURE(r.variant);
      CAPTURE(r.distance);
      CHECK(r.failures == 0);
    }
    if (r.method != "bvh-watertight") continue;
    if (unavailable(r)) {
      MESSAGE("bvh backend not available: " << r.note);
      continue;
    }
    watertight_ran = true;
    CAPTURE(r.variant);
    CAPTURE(r.distance);
    CHECK(r.trials > 500);
    CHECK(r.failures == 0);
  }
  WARN(watertight_ran);
}

TEST_CASE("degenerate triangles: loaded and counted; never hit, never a non-finite hit, the good one always hit") {
  StabilityOptions o;
  std::string dir = (std::filesystem::temp_directory_path() / "pt-test-stability-degenerate").string();
  std::vector<StabilityRow> rows = measure_degenerate(dir, o);
  std::filesystem::remove_all(dir);
  print(rows);
  int backend_rows = 0;
  for (const StabilityRow& r : rows) {
    CAPTURE(r.variant);
    CAPTURE(r.method);
    if (r.method == "loader") {
      CHECK(r.note.rfind("loaded", 0) == 0);  // degenerate input is legal, and counted
      CHECK(r.note.find("1 counted degenerate") != std::string::npos);
      continue;
    }
    if (unavailable(r)) continue;
    ++backend_rows;
    CHECK(r.trials > 0);
    CHECK(r.failures == 0);  // zero-area triangles have no surface to hit; the good one is always hit
    CHECK(r.note.rfind("0 hits with non-finite", 0) == 0);
  }
  CHECK(backend_rows >= 2 * 4);
}

TEST_CASE("grazing rays at 0.01 rad or more hit the triangle at every distance; the rest printed") {
  StabilityOptions o;
  std::vector<StabilityRow> rows = measure_grazing(o);
  print(rows);
  int checked = 0;
  for (const StabilityRow& r : rows) {
    if (unavailable(r) || (r.variant != "angle=0.01" && r.variant != "angle=0.1")) continue;
    CAPTURE(r.variant);
    CAPTURE(r.method);
    CAPTURE(r.distance);
    CHECK(r.trials > 100);
    CHECK(r.failures == 0);  // the targets lie well inside the triangle: every ray must hit it
    ++checked;
  }
  CHECK(checked >= 2 * 2 * 4);
}

TEST_CASE("ray/sphere hits agree with the double-precision answer for every radius and distance") {
  StabilityOptions o;
  std::vector<StabilityRow> rows = measure_spheres(o);
  print(rows);
  int checked = 0;
  for (const StabilityRow& r : rows) {
    if (unavailable(r)) continue;
    CAPTURE(r.variant);
    CAPTURE(r.method);
    CAPTURE(r.distance);
    CHECK(r.failures == 0);
    checked += r.trials > 0;
  }
  CHECK(checked >= 2 * 2 * 5 * 3);  // both kinds, two methods at least, five radii, three distances at least
}
