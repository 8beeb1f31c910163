#include "renderer/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>


namespace pt {

RenderResult render(const Scene& scene, const Accel& accel, const Integrator& integrator, const RenderOptions& o,
                    const RenderControl& control) {
  RenderResult result;
  result.film = Film(o.width, o.height);
  const int tiles_x = (o.width + control.tile_size - 1) / control.tile_size;
  const int tiles_y = (o.height + control.tile_size - 1) / control.tile_size;
  const int tiles = tiles_x * tiles_y;
  const Camera::Basis basis = o.camera.basis(static_cast<float>(o.width) / o.height);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

  struct Counters {
    uint64_t rays = 0, nonfinite = 0;
  };
  tbb::enumerable_thread_specific<Counters> counters;
  std::atomic<bool> stopped{false};
  tbb::task_arena arena(control.threads > 0 ? control.threads : tbb::task_arena::automatic);

  for (int pass = 0; pass < o.spp; ++pass) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& range) {
        Counters& local = counters.local();
        for (int tile = range.begin(); tile != range.end(); ++tile) {
          if (control.cancel && control.cancel->load(std::memory_order_relaxed)) {
            stopped = true;
            return;
          }
          int x0 = (tile % tiles_x) * control.tile_size, y0 = (tile / tiles_x) * control.tile_size;
          int x1 = std::min(x0 + control.tile_size, o.width), y1 = std::min(y0 + control.tile_size, o.height);
          for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
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
    result.passes = pass + 1;
    uint64_t rays = 0;
    for (const Counters& c : counters) rays += c.rays;
    if (control.on_pass) control.on_pass(result.passes, o.spp, elapsed(), rays);
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
