#include "renderer/render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/util/error.h"
#include "renderer/render/emitter_edges.h"

namespace pt {

namespace {

constexpr uint64_t kOddSeed = 0x9e3779b97f4a7c15ULL;

// Adaptive sampling's decision (RenderOptions::adaptive), made afresh at every check from the
// film alone, with `passes` passes done. A pixel is sampled while both hold:
// - the mean estimated error of its 8 neighbours (Film::estimated_error2: from the half buffers of
//   a target error, else from the sample variance) is at or above the threshold, so a pixel turns
//   back on when its neighbourhood turns out noisier than it looked. Since the mean of the
//   neighbour means is about the image's mean error, the image's estimate cannot stay above the
//   threshold with every pixel off;
// - it holds fewer than share * (passes + 2) samples (the next check comes 2 passes later), where
//   its share is in proportion to the standard deviation of its neighbourhood's samples. For a
//   given number of samples, the allocation in proportion to each stratum's deviation minimises
//   the summed variance (Neyman 1934); stopping at a threshold alone spends samples in proportion
//   to the variance, which on the hexagonal room cost more than it saved (docs/cycles.md).
// Only neighbours decide: a pixel's own samples deciding how many it gets would bias it.
// Returns whether any pixel is not yet below the threshold (the render goes on while one is).
bool update_active(const Film& film, const RenderOptions& o, int passes, bool may_stop, int tile_size,
                   std::vector<uint8_t>& active, std::vector<uint8_t>& tile_active) {
  const int w = o.width, h = o.height;
  const size_t n = static_cast<size_t>(w) * h;
  std::vector<double> e2(n), u(n);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      e2[i] = film.estimated_error2(x, y);
      // The variance of one sample over the square root of the value, as Cycles' adaptive
      // sampling weighs its error: between absolute error (bright pixels dominate) and relative
      // error (dark pixels dominate), and the one of the three that cut the squared error in both
      // metrics on the hexagonal room (docs/cycles.md).
      const Film::Pixel& p = film.pixel(x, y);
      double v = 0;
      for (int c = 0; c < 3 && p.count >= 2; ++c) v += Film::sample_variance(p, c) / (std::abs(p.sum[c] / p.count) + 1e-2);
      u[i] = v / 3;
    }
  }
  // The deviation of each pixel's neighbourhood: a 5x5 window without the pixel itself. One pixel's
  // variance after a few samples is too noisy to allocate by (caustic paths are rare and bright);
  // on the hexagonal room 3x3 and 9x9 windows did no better (docs/cycles.md).
  constexpr int kShareRadius = 2;
  std::vector<double> dev(n);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double sum = 0;
      int count = 0;
      for (int ny = std::max(0, y - kShareRadius); ny <= std::min(h - 1, y + kShareRadius); ++ny) {
        for (int nx = std::max(0, x - kShareRadius); nx <= std::min(w - 1, x + kShareRadius); ++nx) {
          if (nx == x && ny == y) continue;
          sum += u[static_cast<size_t>(ny) * w + nx];
          ++count;
        }
      }
      dev[static_cast<size_t>(y) * w + x] = count > 0 ? std::sqrt(sum / count) : 0.0;
    }
  }
  // The noisiest tenth of the pixels get every pass, the others their share of it, and no pixel
  // less than an eighth (a neighbourhood that looked flat may not be). The noisiest twentieth did
  // no better on the hexagonal room.
  constexpr double kFullShareQuantile = 0.9, kMinShare = 0.125;
  std::vector<double> sorted = dev;
  auto q = sorted.begin() + static_cast<std::ptrdiff_t>(kFullShareQuantile * static_cast<double>(n - 1));
  std::nth_element(sorted.begin(), q, sorted.end());
  const double full = *q;

  const double limit = o.adaptive_threshold * o.adaptive_threshold;
  std::fill(tile_active.begin(), tile_active.end(), 0);
  const int tiles_x = (w + tile_size - 1) / tile_size;
  bool any = false;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      size_t i = static_cast<size_t>(y) * w + x;
      double sum = 0;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          sum += e2[static_cast<size_t>(ny) * w + nx];
          ++count;
        }
      }
      // A 1x1 image has no neighbours: it runs to the sample limit.
      const bool converged = may_stop && count > 0 && sum / count < limit;
      const double share = full > 0 ? std::clamp(dev[i] / full, kMinShare, 1.0) : 1.0;
      active[i] = !converged && film.taken(x, y) < share * (passes + 2);
      if (converged) continue;
      // A pixel behind its share this time is not done: the run goes on while any pixel is not.
      any = true;
      if (active[i]) tile_active[(y / tile_size) * tiles_x + x / tile_size] = 1;
    }
  }
  return any;
}

}  // namespace

RenderResult render(const Scene& scene, const Accel& accel, const Integrator& integrator, const RenderOptions& o,
                    const RenderControl& control) {
  RenderResult result;
  if (control.resume && (control.resume->width() != o.width || control.resume->height() != o.height)) {
    throw Error("the film to resume is " + std::to_string(control.resume->width()) + "x" +
                std::to_string(control.resume->height()) + ", the render " + std::to_string(o.width) + "x" +
                std::to_string(o.height));
  }
  result.film = control.resume ? *control.resume : Film(o.width, o.height);
  if (o.first_hit && !result.film.has_first_hit()) {
    if (control.resume) throw Error("a resumed film carries no first-hit AOVs (albedo, normal, depth)");
    result.film.enable_first_hit();
  }
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
  // Ray differentials for filtered texture lookups; a scene without surface textures, or whose
  // lookups are bilinear at the hit (--texture-filter bilinear), has no use for them. The extra
  // views of emitter_edges.h stand for strata `views` times smaller.
  const bool differentials = scene.textured() && scene.textures().filtered();
  const CameraRays camera_rays(o.camera, o.width, o.height, o.spp, differentials);
  const int views = std::clamp(o.emitter_edges, 0, kMaxEmitterEdges);
  const CameraRays view_rays(o.camera, o.width, o.height, o.spp * std::max(views, 1), differentials);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

  struct Counters {
    uint64_t rays = 0, nonfinite = 0;
  };
  tbb::enumerable_thread_specific<Counters> counters;
  std::atomic<bool> stopped{false};
  tbb::task_arena arena(control.threads > 0 ? control.threads : tbb::task_arena::automatic);
  const bool estimate = o.adaptive || o.target_error > 0;
  if (estimate && (o.part || control.resume)) {
    throw Error("adaptive sampling and --target-error decide from the whole frame's film: not with --part or --resume");
  }
  // Only a target error needs the half buffers, whose two independent sequences cost 4-6% of the
  // MSE at equal samples on the hexagonal room (docs/cycles.md): adaptive sampling alone decides from the
  // sample variance (update_active) and keeps each pixel's samples in one sequence.
  const bool halves = o.target_error > 0;
  if (halves) result.film.enable_error_estimate();
  // Pixels still sampled (adaptive sampling), and per tile whether any is.
  std::vector<uint8_t> active(estimate ? static_cast<size_t>(o.width) * o.height : 0, 1);
  std::vector<uint8_t> tile_active(estimate ? tiles_x * tiles_y : 0, 1);
  // The pixels at an emitter's edge, found before any sample (so not from them: emitter_edges.h).
  EmitterEdges edges;
  if (views > 0) {
    uint64_t centre_rays = 0;
    arena.execute([&] { edges = EmitterEdges(scene, accel, o.camera, o.width, o.height, o.seed, o.sampler, region, centre_rays); });
    counters.local().rays += centre_rays;
  }

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
          if (estimate && !tile_active[tile]) continue;
          int x0 = (tile % tiles_x) * control.tile_size, y0 = (tile / tiles_x) * control.tile_size;
          int x1 = std::min(x0 + control.tile_size, o.width), y1 = std::min(y0 + control.tile_size, o.height);
          for (int y = y0; y < y1; ++y) {
            // Also checked per row: where a sample takes milliseconds (a large texture read in
            // pieces), a tile took 20 s to notice SIGTERM. A pixel's sample count says what it
            // holds, so a tile cut short is written (and resumed) as it is.
            if (y > y0 && control.cancel && control.cancel->load(std::memory_order_relaxed)) {
              stopped = true;
              return;
            }
            for (int x = x0; x < x1; ++x) {
              if (!region.contains(x, y)) continue;
              uint64_t pixel = static_cast<uint64_t>(y) * o.width + x;
              // A pixel's next sample is the one after those it holds: the pass number, unless it
              // was resumed ahead of the others (then it waits) or adaptive sampling skipped it in
              // earlier passes (then it runs through its own sequence without gaps).
              const int64_t next = samples.begin + static_cast<int64_t>(result.film.taken(x, y));
              if (estimate ? !active[pixel] : next != pass) continue;
              const uint32_t index = static_cast<uint32_t>(next);
              // With the half buffers, even and odd samples are two independent sequences (each
              // its own scrambled Sobol sequence over index / 2): the half-buffer estimate
              // (Film::relative_error2) is then unbiased for the error of the mean. Within one
              // Sobol sequence the halves interleave and their difference overstated the error
              // 2.2-2.4x (measured on scenes/analytic/rect-light), which made renders overshoot
              // a target error several times over.
              const uint64_t sequence = halves ? o.seed ^ ((index & 1u) ? kOddSeed : 0) : o.seed;
              const uint32_t position = halves ? index >> 1 : index;
              Sampler sampler(o.sampler, sequence, pixel, position);
              Ray ray = camera_rays(x, y, sampler.next2d());
              SampleInfo info;
              if (edges.contains(pixel)) trace_views(scene, accel, view_rays, o.sampler, sequence, pixel, position, x, y, views, info);
              if (o.first_hit) {
                Sampler copy = sampler;  // the state Li() starts from: the beauty's own first hit
                result.film.add_first_hit(x, y, first_hit(scene, accel, ray, copy, info));
              }
              Spectrum L = integrator.Li(ray, scene, accel, sampler, info);
              local.rays += info.rays;
              if (!result.film.add(x, y, L, index)) ++local.nonfinite;
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
    const int first_check = std::max(2, std::min(o.adaptive_min_spp, o.adaptive_share_min_spp));
    if (estimate && result.passes >= first_check && result.passes % 2 == 0) {
      const bool may_stop = result.passes >= std::max(2, o.adaptive_min_spp);
      if (may_stop && o.target_error > 0 && result.film.estimated_error() <= o.target_error) {
        result.reached_target = true;
        break;
      }
      // Every pixel converged: nothing left to sample.
      if (o.adaptive && !update_active(result.film, o, result.passes, may_stop, control.tile_size, active, tile_active)) {
        break;
      }
    }
  }
  if (estimate) result.estimated_error = result.film.estimated_error();
  result.seconds = elapsed();
  for (const Counters& c : counters) {
    result.rays += c.rays;
    result.nonfinite += c.nonfinite;
  }
  return result;
}

}  // namespace pt
