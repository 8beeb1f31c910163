#include "renderer/measure/converge.h"

#include "core/scene/loader.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/util/error.h"

namespace pt {

std::string ConvergeConfig::label() const {
  std::string b = kBackendNames.name(accel.backend);
  if (accel.backend == Backend::kBvh) b += std::string("-") + kTriangleTestNames.name(accel.triangle_test);
  if (accel.backend == Backend::kEmbree && accel.embree_robust) b += "-robust";
  std::string l = b + "/" + kIntegratorNames.name(integrator) + "/" + kStrategyNames.name(strategy) + "/" +
                  std::to_string(shadow_rays) + "sr/" + kSamplerNames.name(sampler);
  if (rr != RussianRoulette::kAuto) l += std::string("/rr-") + kRussianRouletteNames.name(rr);
  if (choices.sky_sampling != SkySampling::kAuto) l += std::string("/sky-") + kSkySamplingNames.name(choices.sky_sampling);
  if (choices.mirror_sampling != MirrorSampling::kAuto) {
    l += std::string("/mirrors-") + kMirrorSamplingNames.name(choices.mirror_sampling);
  }
  if (choices.light_sampling != LightSampling::kAuto) {
    l += std::string("/lights-") + kLightSamplingNames.name(choices.light_sampling);
  }
  if (choices.light_selection != LightSelection::kAuto) {
    l += std::string("/select-") + kLightSelectionNames.name(choices.light_selection);
  }
  if (splits != kSplitsAuto) l += "/splits-" + splits_name(splits);
  if (emitter_edges != kEmitterEdgesAuto) l += "/edges-" + emitter_edges_name(emitter_edges);
  if (adaptive) {
    char t[32];
    std::snprintf(t, sizeof t, "%g", adaptive_threshold);
    l += std::string("/adaptive-") + t;
  }
  return l;
}

JobOptions ConvergeConfig::job_options(const JobOptions& base) const {
  JobOptions o = base;
  o.accel = accel;
  o.integrator = integrator;
  o.strategy = strategy;
  o.shadow_rays = shadow_rays;
  o.sampler = sampler;
  o.rr = rr;
  o.sky_sampling = choices.sky_sampling;
  o.mirror_sampling = choices.mirror_sampling;
  o.light_sampling = choices.light_sampling;
  o.light_selection = choices.light_selection;
  o.splits = splits;
  o.emitter_edges = emitter_edges;
  o.adaptive = adaptive;
  o.adaptive_threshold = adaptive_threshold;
  return o;
}

ImageError image_error(const Film& film, const Image& ref) {
  if (ref.width != film.width() || ref.height != film.height() || ref.channel_count() < 3) {
    throw Error("the reference is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                " but the render is " + std::to_string(film.width()) + "x" + std::to_string(film.height()));
  }
  // The reference's own variance channels, where it has them, widen the block test's error bars.
  int ref_var[3] = {-1, -1, -1};
  for (size_t c = 0; c < ref.channel_count(); ++c) {
    for (int k = 0; k < 3; ++k) {
      if (ref.channels[c] == std::string("variance.") + "RGB"[k]) ref_var[k] = static_cast<int>(c);
    }
  }
  // One pass: per-pixel sums, and per 16x16 block the summed difference and variance.
  constexpr int kBlock = 16;
  const int blocks_x = (ref.width + kBlock - 1) / kBlock, blocks_y = (ref.height + kBlock - 1) / kBlock;
  std::vector<double> block_d(3 * static_cast<size_t>(blocks_x) * blocks_y), block_v(block_d.size());
  double se = 0, rel = 0, var = 0;
  for (int y = 0; y < ref.height; ++y) {
    for (int x = 0; x < ref.width; ++x) {
      Spectrum m = film.mean(x, y), v = film.variance_of_mean(x, y);
      size_t block = 3 * (static_cast<size_t>(y / kBlock) * blocks_x + x / kBlock);
      for (int c = 0; c < 3; ++c) {
        double r = ref.at(x, y, c), d = m[c] - r;
        se += d * d;
        rel += d * d / (r * r + 1e-2);
        var += v[c];
        block_d[block + c] += d;
        block_v[block + c] += v[c] + (ref_var[c] >= 0 ? ref.at(x, y, ref_var[c]) : 0.0);
      }
    }
  }
  double chi2 = 0;
  int blocks = 0;
  for (size_t i = 0; i < block_d.size(); ++i) {
    if (!(block_v[i] > 0)) continue;  // the sky: no noise, nothing to test
    chi2 += block_d[i] * block_d[i] / block_v[i];
    ++blocks;
  }
  double n = 3.0 * ref.width * ref.height;
  ImageError e;
  e.block_chi2 = blocks ? chi2 / blocks : 0;
  e.mse = se / n;
  e.rmse = std::sqrt(e.mse);
  e.rel_mse = rel / n;
  e.film_var = var / n;
  return e;
}

double mean_variance(const Image& image) {
  double sum = 0;
  size_t count = 0;
  for (size_t c = 0; c < image.channel_count(); ++c) {
    if (image.channels[c].rfind("variance.", 0) != 0) continue;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) sum += image.at(x, y, static_cast<int>(c)), ++count;
  }
  return count ? sum / count : 0.0;
}

std::vector<ConvergeRow> run_convergence(const std::shared_ptr<const Scene>& scene, const JobOptions& base,
                                         const std::vector<ConvergeConfig>& configs, const Image& reference,
                                         const ConvergeOptions& o,
                                         const std::function<void(const ConvergeRow&)>& on_row) {
  std::vector<ConvergeRow> rows;
  RenderControl control;
  control.threads = o.threads;
  for (const ConvergeConfig& config : configs) {
    // The sky, mirror and light strategies are the scene's (Scene::sampling_choices): a variant
    // that asks for others gets the scene loaded again with them.
    std::shared_ptr<const Scene> own = scene;
    JobOptions options = config.job_options(base);
    if (!(scene_choices(job_settings(scene->settings(), options)) == scene->settings().choices)) {
      SceneBuilder b = read_scene(base.scene_path.empty() ? scene->source() : base.scene_path);
      b.settings = job_settings(b.settings, options);
      b.settings.choices = scene_choices(b.settings);
      own = std::make_shared<const Scene>(std::move(b));
    }
    Job job = prepare_job(own, options);
    // Each sample count is its own render from sample index 0, so every point's time is what a
    // user asking for that many samples would wait (the series costs twice the largest render).
    for (int spp = o.min_spp; spp <= o.max_spp; spp *= 2) {
      job.render.spp = spp;
      RenderResult result = render(job, control);
      ConvergeRow row;
      row.config = config;
      row.spp = spp;
      row.seconds = result.seconds;
      row.build_seconds = job.accel->stats().build_seconds;
      row.rays = result.rays;
      row.error = image_error(result.film, reference);
      row.estimated_error = result.estimated_error;
      row.min_spp = result.film.min_count();
      row.max_spp = result.film.max_count();
      rows.push_back(row);
      if (on_row) on_row(row);
    }
  }
  return rows;
}

double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double n = static_cast<double>(x.size()), sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace pt
