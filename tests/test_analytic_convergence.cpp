// Convergence against closed-form references (scenes/analytic, renderer/measure/analytic.h): with
// independent samples the RMSE of a Monte Carlo estimate falls as N^-1/2, so on log-log axes the
// slope of RMSE against samples per pixel must be -0.5 +- 0.1, for every backend that can be built.
// A biased reference (or a biased renderer) flattens the slope as N grows, so the same check also
// guards the references. The Owen-scrambled Sobol sampler is reported too: on these smooth
// integrands it converges faster than N^-1/2, which is the point of using it.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>

#include "core/scene/loader.h"
#include "renderer/measure/analytic.h"
#include "renderer/measure/converge.h"

using namespace pt;

namespace {

struct Case {
  const char* scene;
  const char* integrator;
  const char* strategy;
};
// One per closed form; the furnace also exercises multi-bounce path tracing.
const Case kCases[] = {
    {"furnace", "path", "mis"},
    {"rect-light", "direct", "mis"},
    {"sphere-light", "direct", "light"},
    {"sphere-env", "direct", "mis"},
};

bool backend_available(const Scene& scene, const std::string& backend) {
  AccelOptions o;
  o.backend = kBackendNames.parse(backend);
  try {
    make_accel(scene.geometry(), o);
    return true;
  } catch (const std::exception& e) {
    MESSAGE("backend " << backend << " not tested: " << e.what());
    return false;
  }
}

// The environments here are constant, which pt leaves to BSDF sampling by default (the furnace is
// then exact, a zero-variance estimate with no rate to measure): the rates measured are those of
// the environment light-sampled and weighted by MIS.
std::shared_ptr<const Scene> load_case(const Case& c) {
  SceneBuilder b = read_scene(std::string(PT_SOURCE_DIR) + "/scenes/analytic/" + c.scene);
  b.settings.choices.sky_sampling = SkySampling::kLight;
  return std::make_shared<const Scene>(std::move(b));
}

}  // namespace

TEST_CASE("RMSE falls as N^-0.5 against the closed-form references, for every backend") {
  const int kRes = 32;
  ConvergeOptions o;
  o.min_spp = 4;
  o.max_spp = 256;
  o.threads = 2;
  for (const Case& c : kCases) {
    auto scene = load_case(c);
    JobOptions base;
    base.resolution = std::to_string(kRes) + "x" + std::to_string(kRes);
    base.seed = 0;
    base.integrator = kIntegratorNames.parse(c.integrator);
    Image ref = analytic_reference(prepare_job(scene, base));
    for (const char* backend : {"embree", "bvh"}) {
      if (!backend_available(*scene, backend)) continue;
      for (const char* sampler : {"independent", "sobol"}) {
        ConvergeConfig config;
        config.accel.backend = kBackendNames.parse(backend);
        config.integrator = kIntegratorNames.parse(c.integrator);
        config.strategy = kStrategyNames.parse(c.strategy);
        config.sampler = kSamplerNames.parse(sampler);
        config.choices.sky_sampling = SkySampling::kLight;
        std::vector<ConvergeRow> rows = run_convergence(scene, base, {config}, ref, o);
        std::vector<double> spp, rmse;
        for (const ConvergeRow& r : rows) spp.push_back(r.spp), rmse.push_back(r.error.rmse);
        double slope = log_log_slope(spp, rmse);
        const ImageError& last = rows.back().error;
        std::printf("%-13s %-40s slope %.3f  rmse(%d spp) %.3e  film sqrt(var) %.3e\n", c.scene, config.label().c_str(),
                    slope, o.max_spp, last.rmse, std::sqrt(last.film_var));
        CAPTURE(c.scene);
        CAPTURE(config.label());
        if (std::string(sampler) == "independent") {
          CHECK(std::abs(slope + 0.5) <= 0.1);
          // Unbiased reference and renderer: the measured MSE is what the film's own variance
          // predicts (3072 pixel-channels; the bound is several standard errors wide).
          CHECK(last.mse / last.film_var == doctest::Approx(1.0).epsilon(0.3));
        } else {
          CHECK(slope <= -0.4);  // never slower than plain Monte Carlo
        }
      }
    }
  }
}

TEST_CASE("the closed-form recogniser refuses scenes it cannot answer") {
  Scene cornell = load_scene(std::string(PT_SOURCE_DIR) + "/scenes/cornell-box");
  CHECK_THROWS(analytic_case(cornell, IntegratorKind::kPath, 8));
  auto furnace = load_case(kCases[0]);
  CHECK(analytic_case(*furnace, IntegratorKind::kPath, 64) == "furnace");
  CHECK_THROWS(analytic_case(*furnace, IntegratorKind::kDirect, 64));  // concave: direct lighting is not exact
  CHECK_THROWS(analytic_case(*furnace, IntegratorKind::kPath, 4));     // paths cut too early lose energy
}
