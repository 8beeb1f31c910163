#include "renderer/render/emitter_edges.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "integrators/visibility.h"

namespace pt {
namespace {

// Seeds the views' sequences and the centre rays' (a surface of partial coverage draws a number)
// apart from the samples' own.
constexpr uint64_t kViewSalt = 0x3c6ef372fe94f82bULL;
constexpr uint64_t kCentreSalt = 0xa54ff53a5f1d36f1ULL;
// Neighbours whose emission differs by less than this fraction of the largest are one surface.
constexpr float kEdgeContrast = 0.1f;

struct Seen {
  float value = 0;       // luminance of what the centre ray sees emitted, the sky included
  bool emitter = false;  // an emitting surface, seen from its emitting side
};

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
  const CameraRays camera_rays(camera, width, height, 1, scene.textured());
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
