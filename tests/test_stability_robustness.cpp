// The stability measurements of `pt bench stability` as regression tests. Asserted: the scaled
// offset (offset_ray_origin, Wächter & Binder 2019) never lets a ray re-hit the surface it leaves,
// at any tested distance from the origin; the watertight triangle test (Woop et al. 2013) never
// leaks through a shared edge or vertex; the OBJ loader rejects non-finite vertices. Every other
// count is printed, not asserted: those methods are known to fail and the numbers say how often.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>

#include "renderer/bench/stability.h"

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
TEST_CASE("non-finite vertices: the loader rejects them; what the backends do is printed") {
  std::string dir = (std::filesystem::temp_directory_path() / "pt-test-stability-nonfinite").string();
  std::vector<StabilityRow> rows = measure_nonfinite(dir);
  print(rows);
  for (const StabilityRow& r : rows) {
    if (r.method == "loader") {
      CAPTURE(r.variant);
      CHECK(r.failures == 0);
      CHECK(r.note.find("not a finite number") != std::string::npos);
    }
  }
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

TEST_CASE("the watertight test has zero leaks through shared edges and vertices") {
  StabilityOptions o;
  std::vector<StabilityRow> rows = measure_leaks(o);
  print(rows);
  bool watertight_ran = false;
  for (const StabilityRow& r : rows) {
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

TEST_CASE("degenerate triangles, grazing rays and sphere precision: counts printed") {
  StabilityOptions o;
  std::string dir = (std::filesystem::temp_directory_path() / "pt-test-stability-degenerate").string();
  std::vector<StabilityRow> rows = measure_degenerate(dir, o);
  std::filesystem::remove_all(dir);
  print(rows);
  for (const StabilityRow& r : rows) {
    if (r.method == "loader") CHECK(r.note.rfind("loaded", 0) == 0);  // degenerate input is legal, and counted
  }
  print(measure_grazing(o));
  print(measure_spheres(o));
}
