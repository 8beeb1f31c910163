// Error against time: renders one scene at a doubling series of sample counts for each
// configuration and measures each image against a reference. Shared by `pt bench converge` and
// the convergence tests.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/image/image.h"
#include "core/scene/scene.h"
#include "renderer/render/film.h"
#include "renderer/render/job.h"

namespace pt {

struct ConvergeConfig {
  AccelOptions accel;  // backend; the triangle test (bvh) and Embree's robust flag
  IntegratorKind integrator = IntegratorKind::kPath;
  Strategy strategy = Strategy::kMis;
  int shadow_rays = 1;
  SamplerKind sampler = SamplerKind::kSobol;
  // Path-tracing variants: each appears in the label only when not the default (auto).
  RussianRoulette rr = RussianRoulette::kAuto;
  SceneChoices choices;  // the scene is loaded with them
  int splits = kSplitsAuto;
  int emitter_edges = kEmitterEdgesAuto;
  bool adaptive = false;
  double adaptive_threshold = 0.01;
  std::string label() const;  // e.g. "embree/path/mis/1sr/sobol", ".../rr-before-bounce"
  // This configuration's settings on top of `base` (the scene, resolution, depth and seed).
  JobOptions job_options(const JobOptions& base) const;
};

// Errors of one image against a reference, over every pixel and channel.
struct ImageError {
  double mse = 0;        // mean squared error
  double rmse = 0;       // sqrt(mse)
  double rel_mse = 0;    // mean of (x - ref)^2 / (ref^2 + 1e-2) (Rousselle et al. 2011)
  double film_var = 0;   // the film's own estimate of the mse: mean variance of the pixel mean
  // Bias check on 16x16 blocks: the mean over blocks and channels of z^2, z the difference of the
  // block means over its standard error (the film's variance, plus the reference's where it has
  // variance channels). About 1 when the render converges to the reference; a bias that sampling
  // decisions introduce (adaptive sampling) raises it above the uniform render's.
  double block_chi2 = 0;
};
ImageError image_error(const Film& film, const Image& reference);
double mean_variance(const Image& image);  // mean of the variance.* channels, 0 if there are none

struct ConvergeRow {
  ConvergeConfig config;
  int spp = 0;
  double seconds = 0;        // render() wall time, build excluded
  double build_seconds = 0;  // the backend's build, once per configuration
  uint64_t rays = 0;
  ImageError error;
  double estimated_error = -1;  // the film's own estimate (adaptive renders), else -1
  uint32_t min_spp = 0, max_spp = 0;
};

struct ConvergeOptions {
  int min_spp = 1, max_spp = 256;  // doubled from min to max
  int threads = 0;
};

// Renders `scene` for every configuration (a job from base + the configuration) at min_spp,
// 2 min_spp, ... max_spp and returns one row per render. `on_row` (optional) sees each row as it
// is made. Throws pt::Error when a backend is not available.
std::vector<ConvergeRow> run_convergence(const std::shared_ptr<const Scene>& scene, const JobOptions& base,
                                         const std::vector<ConvergeConfig>& configs, const Image& reference,
                                         const ConvergeOptions& options,
                                         const std::function<void(const ConvergeRow&)>& on_row = {});

// Least-squares slope of log(y) against log(x).
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace pt
