// A procedural stand-in for a raw 3D scan (no scanned mesh ships in Debian's archive): a statue-like
// object (overlapping displaced ellipsoids) is "range scanned" from several viewpoints, and each
// view's grid of range samples is triangulated the way scanner software does it. The mesh then has
// what makes scans hard for a BVH:
//  - long thin triangles: scan lines are sampled far more densely than the lines are spaced (as a
//    laser line scanner does), and stretched further where a view sees the surface at a grazing angle,
//  - density varying with distance and angle to each scanner,
//  - holes where the object hides itself, where returns are too grazing, and where patches drop
//    out (dark or shiny spots),
//  - overlapping sheets where views overlap (the raw scans are not merged), and range noise.
// Used by `pt gen scan` (which writes it as an OBJ) and directly by tests.
#pragma once
#include <cstdint>
#include <string>

#include "core/geometry/mesh.h"

namespace pt {

struct ScanOptions {
  int views = 8;          // scanner positions around and above the object
  int resolution = 1400;  // range samples per scan line; each view has resolution / 3 to / 14 lines
  uint64_t seed = 1;      // range noise and dropout pattern
};

// Appends the scanned object, within about [-1.05, 1.05]^3 around the origin, to `mesh`.
void add_scan_mesh(Mesh& mesh, const ScanOptions& options, uint32_t material);

// Writes the scan mesh as an OBJ (vertices and faces only) to `path`.
void write_scan_obj(const std::string& path, const ScanOptions& options);

}  // namespace pt
