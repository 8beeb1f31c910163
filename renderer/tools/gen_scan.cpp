// The scan-like benchmark mesh (see gen_scan.h).
#include "renderer/tools/gen_scan.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "core/accel/accel.h"
#include "core/math/rng.h"
#include "core/geometry/geometry.h"
#include "core/util/error.h"
#include "renderer/tools/gen_dense.h"
#include "renderer/tools/gen_obj.h"

namespace pt {
namespace {

// The object: a body, a head, two long ears and a tail, each a displaced icosphere stretched into an
// ellipsoid. They overlap, so the union has creases and parts that hide each other from a scanner.
struct Blob {
  Vec3f center, stretch;
  float radius, amplitude;
  int level;
};
const Blob kBlobs[] = {
    {{0.0f, -0.3f, 0.0f}, {1.15f, 0.85f, 0.8f}, 0.62f, 0.15f, 6},
    {{0.42f, 0.38f, 0.12f}, {1.0f, 1.0f, 0.95f}, 0.36f, 0.12f, 6},
    {{0.3f, 0.8f, -0.02f}, {0.45f, 2.1f, 0.6f}, 0.14f, 0.1f, 5},
    {{0.62f, 0.76f, 0.22f}, {0.45f, 2.0f, 0.6f}, 0.14f, 0.1f, 5},
    {{-0.72f, -0.42f, -0.1f}, {1.0f, 1.0f, 1.0f}, 0.17f, 0.2f, 5},
};

Geometry object_geometry() {
  Mesh mesh;
  for (const Blob& b : kBlobs) {
    size_t first = mesh.positions.size();
    add_displaced_icosphere(mesh, b.level, Vec3f(0.0f), b.radius, b.amplitude, 0);
    for (size_t i = first; i < mesh.positions.size(); ++i) mesh.positions[i] = b.center + mesh.positions[i] * b.stretch;
  }
  return Geometry(std::move(mesh), {});
}

// Patches where returns drop out (dark or shiny spots); the phase differs per view, since whether a
// shiny spot returns depends on where the scanner stands.
bool drops_out(const Vec3f& p, int view) {
  float ph = 1.7f * static_cast<float>(view);
  float n = std::sin(5.1f * p.x + 1.3f + ph) * std::sin(4.3f * p.y + 0.2f) * std::sin(6.7f * p.z + 2.1f - ph);
  n += 0.5f * std::sin(13.0f * p.x + 0.4f) * std::sin(11.0f * p.y + 1.9f + ph) * std::sin(12.0f * p.z + 0.8f);
  return n > 0.55f;
}

constexpr float kDistance = 3.0f;                 // scanner to the object's centre
constexpr float kHalfFov = 0.41f;                 // radians; the object (radius ~1.1) fills the view
constexpr float kMinCos = 0.1045f;                // returns beyond 84 degrees of incidence are rejected
constexpr float kMaxStretch = 12.0f;              // edges longer than this many line spacings: a depth jump
constexpr float kRangeNoise = 6e-4f;              // standard deviation of the range, scene units
const float kElevations[] = {0.44f, -0.26f, 0.96f};  // radians, cycled over the views
// Line scanners sample densely along a scan line and sparsely between lines: each view's grid has
// `resolution` samples per line and resolution / anisotropy lines, and its lines are rolled by a
// different angle, so the long thin triangles lie across the world axes.
const int kAnisotropy[] = {3, 7, 14, 5};
constexpr float kRollStep = 0.65f;  // radians per view

}  // namespace

void add_scan_mesh(Mesh& out, const ScanOptions& options, uint32_t material) {
  if (options.views < 1 || options.views > 64) throw Error("scan views must be 1 to 64");
  if (options.resolution < 2 || options.resolution > 4096) throw Error("scan resolution must be 2 to 4096");
  Geometry object = object_geometry();
  AccelOptions ao;
  ao.backend = Backend::kEmbree;
  std::unique_ptr<Accel> accel = make_accel(object, ao);
  const int res = options.resolution;
  const Vec3f target(0.1f, 0.1f, 0.0f);
  const float tan_half = std::tan(kHalfFov);

  for (int view = 0; view < options.views; ++view) {
    float azimuth = 2.0f * kPi * (static_cast<float>(view) + 0.3f) / static_cast<float>(options.views);
    float elevation = kElevations[view % 3];
    Vec3f eye = target + Vec3f(std::cos(elevation) * std::cos(azimuth), std::sin(elevation),
                               std::cos(elevation) * std::sin(azimuth)) * kDistance;
    Vec3f forward = normalize(target - eye);
    Vec3f right0 = normalize(cross(forward, Vec3f(0.0f, 1.0f, 0.0f)));
    Vec3f up0 = cross(right0, forward);
    float roll = kRollStep * static_cast<float>(view);
    Vec3f right = right0 * std::cos(roll) + up0 * std::sin(roll);
    Vec3f up = up0 * std::cos(roll) - right0 * std::sin(roll);
    const int cols = res, rows = std::max(2, res / kAnisotropy[view % 4]);

    // One range sample per grid point: the surface point, or none.
    std::vector<Vec3f> point(static_cast<size_t>(cols) * rows);
    std::vector<uint8_t> valid(point.size(), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
      for (int j = range.begin(); j != range.end(); ++j) {
        for (int i = 0; i < cols; ++i) {
          float sx = ((static_cast<float>(i) + 0.5f) / static_cast<float>(cols) * 2.0f - 1.0f) * tan_half;
          float sy = ((static_cast<float>(j) + 0.5f) / static_cast<float>(rows) * 2.0f - 1.0f) * tan_half;
          Ray ray;
          ray.o = eye;
          ray.d = normalize(forward + right * sx + up * sy);
          auto hit = accel->intersect(ray);
          if (!hit) continue;
          Vec3f n = object.mesh().geometric_normal(hit->prim);
          if (std::abs(dot(n, ray.d)) < kMinCos * length(n)) continue;
          Vec3f p = ray.o + ray.d * hit->t;
          if (drops_out(p, view)) continue;
          // Range noise: Gaussian (Box-Muller) along the ray, seeded by view and sample.
          size_t k = static_cast<size_t>(j) * cols + i;
          Pcg32 rng(hash_combine(options.seed, (static_cast<uint64_t>(view) << 32) + k), 5);
          float u1 = std::max(rng.next_float(), 1e-7f), u2 = rng.next_float();
          float g = std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * kPi * u2);
          point[k] = ray.o + ray.d * (hit->t + kRangeNoise * g);
          valid[k] = 1;
        }
      }
    });

    // Triangulate the grid: two triangles per cell along its shorter diagonal, none across a hole or
    // a depth jump. Vertices are shared within the view.
    std::vector<uint32_t> index(point.size(), UINT32_MAX);
    auto vertex = [&](size_t k) {
      if (index[k] == UINT32_MAX) {
        index[k] = static_cast<uint32_t>(out.positions.size());
        out.positions.push_back(point[k]);
      }
      return index[k];
    };
    auto add = [&](size_t a, size_t b, size_t c) {
      if (!valid[a] || !valid[b] || !valid[c]) return;
      float spacing = length(point[a] - eye) * 2.0f * tan_half / static_cast<float>(rows);
      float limit = kMaxStretch * spacing;
      if (length(point[a] - point[b]) > limit || length(point[b] - point[c]) > limit ||
          length(point[c] - point[a]) > limit) {
        return;
      }
      out.indices.insert(out.indices.end(), {vertex(a), vertex(b), vertex(c)});
      out.material.push_back(material);
    };
    for (int j = 0; j + 1 < rows; ++j) {
      for (int i = 0; i + 1 < cols; ++i) {
        size_t a = static_cast<size_t>(j) * cols + i, b = a + 1, c = a + cols, d = c + 1;
        bool ad_shorter = valid[a] && valid[d] && valid[b] && valid[c] &&
                          length(point[a] - point[d]) < length(point[b] - point[c]);
        if (ad_shorter) {
          add(a, b, d);
          add(a, d, c);
        } else {
          add(a, b, c);
          add(b, d, c);
        }
      }
    }
  }
  if (!out.corner_normals.empty()) out.corner_normals.resize(out.indices.size());
  if (!out.corner_uvs.empty()) out.corner_uvs.resize(out.indices.size());
}

void write_scan_obj(const std::string& path, const ScanOptions& options) {
  Mesh mesh;
  add_scan_mesh(mesh, options, 0);
  write_mesh_obj(path, mesh,
                 "pt gen scan --views " + std::to_string(options.views) + " --resolution " +
                     std::to_string(options.resolution) + " --seed " + std::to_string(options.seed) +
                     ": simulated range scans, " + std::to_string(mesh.triangle_count()) + " triangles");
}

}  // namespace pt
