#include "renderer/render/emitter_edges.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "integrators/visibility.h"

namespace pt {
namespace {

// Seeds the views' sequences and the centre rays' (a surface of partial coverage draws a number)
// apart from the samples' own.
constexpr uint64_t kViewSalt = 0x3c6ef372fe94f82bULL;
constexpr uint64_t kCentreSalt = 0xa54ff53a5f1d36f1ULL;
// Neighbours whose emission differs by less than this fraction of the largest are one surface.
constexpr float kEdgeContrast = 0.1f;

// Emitters smaller than this many pixels across (in x or y) may fall between the centre rays.
constexpr float kSmallPixels = 2.0f;
// ... unless their box covers more pixels than this (long and thin across the image: the centre
// rays meet those).
constexpr float kSmallArea = 64.0f;

struct Seen {
  float value = 0;       // luminance of what the centre ray sees emitted, the sky included
  bool emitter = false;  // an emitting surface, seen from its emitting side
};

// Pixels [x0, x1] x [y0, y1], inclusive.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
};

// The pixels around an emitter too small for the centre rays, where the camera may see it: its
// box's image, dilated by a pixel, when the box is in front of the camera, a one-sided emitter
// faces it, and nothing blocks the ray from the camera to the box's centre short of the box.
// Empty otherwise (a larger emitter is found by the centre rays).
PixelRect small_emitter(const Accel& accel, const Camera::Basis& b, int width, int height, const LightBounds& lb,
                        uint64_t& rays) {
  PixelRect none;
  if (lb.empty()) return none;
  const Vec3f view = normalize(cross(b.right, b.down));  // right and down are both square to it
  const float rr = length_squared(b.right), dd = length_squared(b.down);
  float x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;
  for (int c = 0; c < 8; ++c) {
    Vec3f p{(c & 1) ? lb.box.hi.x : lb.box.lo.x, (c & 2) ? lb.box.hi.y : lb.box.lo.y,
            (c & 4) ? lb.box.hi.z : lb.box.lo.z};
    Vec3f v = p - b.origin, w;
    if (b.ortho) {
      w = v - b.forward * dot(v, b.forward);
    } else {
      float depth = dot(v, view);
      if (!(depth > 0)) return none;  // behind the camera: near, and the centre rays' business
      w = v * (dot(b.forward, view) / depth) - b.forward;
    }
    float fx = dot(w, b.right) / rr * static_cast<float>(width), fy = dot(w, b.down) / dd * static_cast<float>(height);
    x0 = std::min(x0, fx), x1 = std::max(x1, fx), y0 = std::min(y0, fy), y1 = std::max(y1, fy);
  }
  if (std::min(x1 - x0, y1 - y0) >= kSmallPixels || (x1 - x0) * (y1 - y0) > kSmallArea) return none;
  if (x1 < -1 || y1 < -1 || x0 > static_cast<float>(width) + 1 || y0 > static_cast<float>(height) + 1) return none;
  const Vec3f centre = lb.box.center();
  const Vec3f eye = b.ortho ? centre - b.forward * dot(centre - b.origin, b.forward) : b.origin;
  // A one-sided emitter (every normal along the axis, light within a hemisphere) turned away.
  if (lb.cos_o >= 1.0f && lb.cos_e <= 0.0f && dot(lb.axis, eye - centre) <= 0) return none;
  Ray ray;
  ray.o = eye;
  const Vec3f to = centre - eye;
  const float distance = length(to), radius = 0.5f * length(lb.box.extent());
  if (distance > radius) {
    ray.d = to / distance;
    ray.tmin = 0;
    ray.tmax = distance - radius;
    ++rays;
    if (accel.occluded(ray)) return none;
  }
  return {std::max(0, static_cast<int>(std::floor(x0)) - 1), std::max(0, static_cast<int>(std::floor(y0)) - 1),
          std::min(width - 1, static_cast<int>(std::floor(x1)) + 1),
          std::min(height - 1, static_cast<int>(std::floor(y1)) + 1)};
}

}  // namespace

EmitterEdges::EmitterEdges(const Scene& scene, const Accel& accel, const Camera& camera, int width, int height,
                           uint64_t seed, SamplerKind sampler, const PartRegion& region, uint64_t& rays) {
  const size_t n = static_cast<size_t>(width) * height;
  // The region's pixels and their neighbours: a part finds its border pixels' neighbours itself.
  auto near_region = [&](int x, int y) {
    for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny) {
      for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
        if (region.contains(nx, ny)) return true;
      }
    }
    return false;
  };
  const CameraRays camera_rays(camera, width, height, 1, scene.textured() && scene.textures().filtered());
  std::vector<Seen> seen(n);
  tbb::enumerable_thread_specific<uint64_t> traced(0);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        if (!near_region(x, y)) continue;
        const uint64_t pixel = static_cast<uint64_t>(y) * width + x;
        Ray ray = camera_rays(x, y, {0.5f, 0.5f});
        Sampler s(sampler, seed ^ kCentreSalt, pixel, 0);
        SampleInfo info;
        std::optional<Hit> hit = intersect_visible(scene, accel, ray, s, info);
        Seen& out = seen[pixel];
        if (!hit) {
          out.value = luminance(scene.environment_radiance(ray.d));
        } else {
          out.value = luminance(scene.emitted(scene.interaction(ray, *hit), -ray.d));
          out.emitter = out.value > 0;
        }
        traced.local() += info.rays;
      }
    }
  });
  for (uint64_t t : traced) rays += t;

  mask_.assign(n, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!region.contains(x, y)) continue;
      float lo = kInf, hi = 0;
      bool emitter = false;
      for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny) {
        for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
          const Seen& s = seen[static_cast<size_t>(ny) * width + nx];
          lo = std::min(lo, s.value);
          hi = std::max(hi, s.value);
          emitter = emitter || s.emitter;
        }
      }
      mask_[static_cast<size_t>(y) * width + x] = emitter && hi - lo > kEdgeContrast * hi;
    }
  }

  // Emitters too small for the centre rays: triangles and spheres (points and spots are not seen).
  const LightSet& lights = scene.light_set();
  const size_t triangles = lights.triangles().size(), count = triangles + lights.spheres().size();
  const Camera::Basis basis = camera.basis(static_cast<float>(width) / height);
  std::vector<PixelRect> rects(count);
  tbb::enumerable_thread_specific<uint64_t> tested(0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      LightBounds lb =
          i < triangles ? lights.triangles().lights()[i].bounds() : lights.spheres()[i - triangles].bounds();
      rects[i] = small_emitter(accel, basis, width, height, lb, tested.local());
    }
  });
  for (uint64_t t : tested) rays += t;
  for (const PixelRect& r : rects) {
    for (int y = r.y0; y <= r.y1; ++y) {
      for (int x = r.x0; x <= r.x1; ++x) {
        if (region.contains(x, y)) mask_[static_cast<size_t>(y) * width + x] = 1;
      }
    }
  }
}

size_t EmitterEdges::count() const { return static_cast<size_t>(std::count(mask_.begin(), mask_.end(), uint8_t{1})); }

void trace_views(const Scene& scene, const Accel& accel, const CameraRays& rays, SamplerKind sampler, uint64_t seed,
                 uint64_t pixel, uint32_t index, int x, int y, int views, SampleInfo& info) {
  for (int k = 0; k < views; ++k) {
    Sampler s(sampler, seed ^ kViewSalt, pixel, index * static_cast<uint32_t>(views) + static_cast<uint32_t>(k));
    info.seen_sum += seen_emission(scene, accel, rays(x, y, s.next2d()), s, info);
  }
  info.views = views;
}

}  // namespace pt
