// The renderer: progressive passes of one sample per pixel over tiles, in parallel with TBB.
// Deterministic: a sample's random numbers depend on (seed, pixel, sample index) only, and each
// pixel accumulates its samples in index order, so any thread count gives the same image.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>

#include "core/accel/accel.h"
#include "core/math/sampler.h"
#include "core/scene/camera.h"
#include "core/scene/scene.h"
#include "integrators/integrator.h"
#include "renderer/render/film.h"
#include "renderer/farm/part.h"

namespace pt {

// What the image is: size, samples, seed, sampler, camera. A render job (job.h) makes it from the
// settings; nothing else fills it in.
struct RenderOptions {
  int width = 0, height = 0;
  int spp = 1;
  uint64_t seed = 0;
  SamplerKind sampler = SamplerKind::kSobol;
  Camera camera;
  std::optional<Part> part;  // one part of a split render (part.h): its pixels or its sample range
  // Adaptive sampling: at every even pass count from adaptive_share_min_spp passes on, a pixel is
  // skipped while it is ahead of its share of the passes, a share in proportion to its
  // neighbourhood's deviation; from adaptive_min_spp on, also while the mean estimated relative error
  // of its 8 neighbours is below adaptive_threshold^2 (render.cpp). Sharing needs a rough
  // deviation only (a 5x5 window's samples), stopping a reliable error estimate, hence the two
  // starts. Its neighbours decide, not its own samples, which would bias it. The decision is taken
  // between passes from the film alone, and a pixel's samples are numbered by the pixel, so the
  // image stays independent of the thread count.
  bool adaptive = false;
  double adaptive_threshold = 0.01;
  int adaptive_min_spp = 16;
  int adaptive_share_min_spp = 4;
  // Stop once Film::estimated_error() <= target_error (checked at the same points); 0 = never.
  double target_error = 0;
  // Also sum the first-hit AOVs (albedo, normal, depth; aov.h) of every sample: one more first-hit
  // query per sample, made with a copy of the sample's random numbers so the beauty is unchanged.
  bool first_hit = false;
  // Extra camera rays per sample in the pixels at an emitter's edge (emitter_edges.h); 0 = none.
  int emitter_edges = 0;
};

// How the render runs, which never changes the pixels of a completed pass: threads, tiles, limits,
// cancellation and progress.
struct RenderControl {
  int threads = 0;                 // 0: all cores
  double time_budget = 0;          // seconds; 0 = none. Stops after the pass that crosses it.
  int tile_size = 16;
  const std::atomic<bool>* cancel = nullptr;  // set (e.g. by SIGINT) to stop at the next tile
  // Called after every pass with (passes done, total passes, seconds so far, rays so far).
  std::function<void(int, int, double, uint64_t)> on_pass;
  // Continue this film (a part read back by --resume, same size): each pixel goes on from the
  // next sample index it has not taken, so the result is the uninterrupted render's, bit for bit.
  const Film* resume = nullptr;
};

struct RenderResult {
  Film film;
  int passes = 0;            // of the part's sample range (render.part), counted from its start
  bool interrupted = false;  // cancelled mid-way: pixels hold `passes` or `passes + 1` samples
  double seconds = 0;
  uint64_t rays = 0;
  double estimated_error = -1;  // Film::estimated_error() at the end when estimated, else -1
  bool reached_target = false;
  uint64_t nonfinite = 0;  // samples dropped because the integrator returned NaN or Inf
};

RenderResult render(const Scene& scene, const Accel& accel, const Integrator& integrator, const RenderOptions& options,
                    const RenderControl& control = {});

}  // namespace pt
