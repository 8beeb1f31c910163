// Where ray/primitive intersection fails, counted per method (BVH with Möller-Trumbore, BVH with
// the watertight test, Embree, Embree with RTC_SCENE_FLAG_ROBUST). Shared by `pt bench stability`
// and the stability regression tests. Every "should hit" or "should miss" is decided in double
// precision on the exact float ray, so a count is the method's error, not the test's.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/accel/accel.h"

namespace pt {

struct StabilityMethod {
  std::string name;  // bvh-mt, bvh-watertight, embree, embree-robust
  AccelOptions options;
};
std::vector<StabilityMethod> stability_methods();

struct StabilityRow {
  std::string test;     // leaks, self-intersection, degenerate, non-finite, grazing, sphere
  std::string variant;  // what was varied within the test (ray target, offset method, radius ...)
  std::string method;   // a StabilityMethod name, or "loader"
  double distance = 0;  // how far the geometry was moved from the origin (0: not applicable)
  uint64_t trials = 0, failures = 0;
  std::string note;     // "unavailable: ..." when a backend cannot be built, or what was seen
};

struct StabilityOptions {
  std::vector<double> distances = {1, 1e2, 1e4, 1e6};
  int effort = 1;  // multiplies the number of rays of every test
  uint64_t seed = 1;
};

// Rays from inside closed convex meshes aimed exactly at their vertices and at points on their
// edges: each must hit (a miss is a crack in the surface).
std::vector<StabilityRow> measure_leaks(const StabilityOptions& o);

// Rays leaving a surface point (found by a primary ray, as a renderer finds it) into the
// hemisphere of the normal that hit the surface they left. Variants: no offset, a fixed offset of
// 1e-4 along the normal, and offset_ray_origin (Wächter & Binder, Ray Tracing Gems ch. 6).
std::vector<StabilityRow> measure_self_intersection(const StabilityOptions& o);

// Zero-area, collinear and repeated-vertex triangles: what the loader says (OBJ files written to
// `work_dir`) and whether each backend reports hits on them.
std::vector<StabilityRow> measure_degenerate(const std::string& work_dir, const StabilityOptions& o);

// Non-finite vertices: what the loader says (files in `work_dir`), and what each backend does when
// handed them anyway. The backends run in a forked child each, so a crash or a hang is reported
// instead of ending the benchmark; call this before anything starts worker threads.
std::vector<StabilityRow> measure_nonfinite(const std::string& work_dir);

// Rays meeting a triangle at grazing angles (1e-1 to 1e-5 radians): misses of interior points.
std::vector<StabilityRow> measure_grazing(const StabilityOptions& o);

// Spheres of radius 1e-4 to 1e4 far from the origin: wrong hit/miss answers, and hits whose
// point o + t d is off the surface by more than 1e-3 r.
std::vector<StabilityRow> measure_spheres(const StabilityOptions& o);

}  // namespace pt
