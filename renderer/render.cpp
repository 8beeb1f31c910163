#include "renderer/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "core/util/error.h"

namespace pt {

RenderResult render(const Scene& scene, const Accel& accel, const Integrator& integrator, const RenderOptions& o,
                    const RenderControl& control) {
  RenderResult result;
  if (control.resume && (control.resume->width() != o.width || control.resume->height() != o.height)) {
    throw Error("the film to resume is " + std::to_string(control.resume->width()) + "x" +
                std::to_string(control.resume->height()) + ", the render " + std::to_string(o.width) + "x" +
                std::to_string(o.height));
  }
  result.film = control.resume ? *control.resume : Film(o.width, o.height);
  // A part renders its pixels (region split) over its sample indices (sample split); a resumed
  // film goes on from the first index some pixel of the part has not taken.
  const SampleRange samples = part_samples(o.part, o.spp);
  const PartRegion region(o.part, o.width, o.height);
  int first = samples.end;
  for (int y = 0; y < o.height; ++y) {
    for (int x = 0; x < o.width; ++x) {
      if (region.contains(x, y)) first = std::min<int>(first, samples.begin + static_cast<int>(result.film.taken(x, y)));
    }
  }
  result.passes = first - samples.begin;
  const int tiles_x = (o.width + control.tile_size - 1) / control.tile_size;
  const int tiles_y = (o.height + control.tile_size - 1) / control.tile_size;
  // The tiles with pixels of the part, found once: a region part's passes skip the others whole.
  std::vector<int> work;
  for (int tile = 0; tile < tiles_x * tiles_y; ++tile) {
    int x0 = (tile % tiles_x) * control.tile_size, y0 = (tile / tiles_x) * control.tile_size;
    int x1 = std::min(x0 + control.tile_size, o.width), y1 = std::min(y0 + control.tile_size, o.height);
    bool any = false;
    for (int y = y0; y < y1 && !any; ++y) {
      for (int x = x0; x < x1 && !any; ++x) any = region.contains(x, y);
    }
    if (any) work.push_back(tile);
  }
  const int tiles = static_cast<int>(work.size());
  const Camera::Basis basis = o.camera.basis(static_cast<float>(o.width) / o.height);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

  struct Counters {
    uint64_t rays = 0, nonfinite = 0;
  };
  tbb::enumerable_thread_specific<Counters> counters;
  std::atomic<bool> stopped{false};
  tbb::task_arena arena(control.threads > 0 ? control.threads : tbb::task_arena::automatic);

  for (int pass = first; pass < samples.end; ++pass) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& range) {
        Counters& local = counters.local();
        for (int i = range.begin(); i != range.end(); ++i) {
          if (control.cancel && control.cancel->load(std::memory_order_relaxed)) {
            stopped = true;
            return;
          }
          const int tile = work[i];
          int x0 = (tile % tiles_x) * control.tile_size, y0 = (tile / tiles_x) * control.tile_size;
          int x1 = std::min(x0 + control.tile_size, o.width), y1 = std::min(y0 + control.tile_size, o.height);
          for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
              if (!region.contains(x, y)) continue;
              if (samples.begin + static_cast<int64_t>(result.film.taken(x, y)) != pass) continue;  // resumed: has it
              uint64_t pixel = static_cast<uint64_t>(y) * o.width + x;
              Sampler sampler(o.sampler, o.seed, pixel, static_cast<uint32_t>(pass));
              Vec2f jitter = sampler.next2d();
              Vec2f film{(x + jitter.x) / o.width, (y + jitter.y) / o.height};
              Ray ray = Camera::ray(basis, film);
              SampleInfo info;
              Spectrum L = integrator.Li(ray, scene, accel, sampler, info);
              local.rays += info.rays;
              if (!result.film.add(x, y, L)) ++local.nonfinite;
            }
          }
        }
      }, tbb::simple_partitioner());
    });
    if (stopped) {
      result.interrupted = true;
      break;
    }
    result.passes = pass + 1 - samples.begin;
    uint64_t rays = 0;
    for (const Counters& c : counters) rays += c.rays;
    if (control.on_pass) control.on_pass(result.passes, samples.size(), elapsed(), rays);
    if (control.time_budget > 0 && elapsed() >= control.time_budget) break;
  }
  result.seconds = elapsed();
  for (const Counters& c : counters) {
    result.rays += c.rays;
    result.nonfinite += c.nonfinite;
  }
  return result;
}

}  // namespace pt
