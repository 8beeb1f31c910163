// `pt bench lights`: the cost of the light samplers (core/scene/lights/): building the light tree
// and choosing a light (with its pdf) from it and from the power distribution, at 10 to 1M
// synthetic emitters spread through a cube, one thread. Synthetic so that the count is all that
// varies: one-sided emitters facing random ways and omnidirectional ones, powers over 3 decades.
// Times are the thread's CPU time, not wall time: on a shared machine the wall clock measures the
// other jobs' load as much as the samplers.
#include <time.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/math/rng.h"
#include "core/scene/lights/light_tree.h"
#include "core/scene/lights/power_light_sampler.h"
#include "core/util/output_file.h"
#include "renderer/bench/bench.h"
#include "renderer/bench/bench_csv.h"

namespace pt {
namespace {

struct BenchLightsArgs {
  std::vector<size_t> counts{10, 100, 1000, 10000, 100000, 1000000};
  size_t samples = 1000000;
  std::string csv;
};

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
double seconds_since(double t0) { return thread_seconds() - t0; }

std::vector<LightBounds> emitters(size_t n, Pcg32& rng) {
  std::vector<LightBounds> out(n);
  float side = std::cbrt(static_cast<float>(n)) * 4.0f;  // about one emitter per 64 unit cubes
  for (size_t i = 0; i < n; ++i) {
    LightBounds& b = out[i];
    Vec3f c(side * rng.next_float(), side * rng.next_float(), side * rng.next_float());
    b.box.expand(c - Vec3f(0.3f));
    b.box.expand(c + Vec3f(0.3f));
    b.phi = std::pow(10.0f, 3 * rng.next_float());
    if (i % 4 == 0) {
      b.cos_o = -1;
    } else {
      float z = 2 * rng.next_float() - 1, a = 6.2831853f * rng.next_float(), r = std::sqrt(std::max(0.0f, 1 - z * z));
      b.axis = {r * std::cos(a), r * std::sin(a), z};
    }
  }
  return out;
}

int run_bench_lights(const BenchLightsArgs& args) {
  if (!args.csv.empty()) check_output_path(args.csv);  // before the measurements, not after
  std::ostringstream csv;
  csv << "emitters,tree_build_s,tree_nodes,tree_depth,tree_sample_ns,tree_pdf_ns,power_build_s,power_sample_ns\n";
  std::printf("%10s %12s %10s %6s %15s %12s %13s %16s\n", "emitters", "tree build s", "nodes", "depth", "tree sample ns",
              "tree pdf ns", "power build s", "power sample ns");
  for (size_t n : args.counts) {
    Pcg32 rng(n, 1);
    std::vector<LightBounds> bounds = emitters(n, rng);
    std::vector<float> power;
    for (const LightBounds& b : bounds) power.push_back(b.phi);
    auto t0 = thread_seconds();
    LightTree tree(bounds, power, {});
    double build = seconds_since(t0);
    t0 = thread_seconds();
    PowerLightSampler by_power(power, {});
    double power_build = seconds_since(t0);
    // Shading points through the same cube, with normals.
    float side = std::cbrt(static_cast<float>(n)) * 4.0f;
    std::vector<Vec3f> points, normals;
    for (int i = 0; i < 1024; ++i) {
      points.emplace_back(side * rng.next_float(), side * rng.next_float(), side * rng.next_float());
      float z = 2 * rng.next_float() - 1, a = 6.2831853f * rng.next_float(), r = std::sqrt(std::max(0.0f, 1 - z * z));
      normals.emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
    double sink = 0;
    std::vector<uint32_t> chosen;
    t0 = thread_seconds();
    for (size_t i = 0; i < args.samples; ++i) {
      LightChoice c;
      if (tree.sample(points[i & 1023], normals[i & 1023], rng.next_float(), c)) sink += c.pick, chosen.push_back(c.light);
    }
    double tree_sample = seconds_since(t0) / args.samples * 1e9;
    t0 = thread_seconds();
    for (size_t i = 0; i < chosen.size(); ++i) sink += tree.pdf(points[i & 1023], normals[i & 1023], chosen[i]);
    double tree_pdf = chosen.empty() ? 0 : seconds_since(t0) / chosen.size() * 1e9;
    t0 = thread_seconds();
    for (size_t i = 0; i < args.samples; ++i) {
      LightChoice c;
      if (by_power.sample(points[i & 1023], normals[i & 1023], rng.next_float(), c)) sink += c.pick;
    }
    double power_sample = seconds_since(t0) / args.samples * 1e9;
    std::printf("%10zu %12.4f %10zu %6d %15.1f %12.1f %13.4f %16.1f\n", n, build, tree.node_count(), tree.depth(), tree_sample,
                tree_pdf, power_build, power_sample);
    csv << n << "," << build << "," << tree.node_count() << "," << tree.depth() << "," << tree_sample << "," << tree_pdf
        << "," << power_build << "," << power_sample << "\n";
    if (sink == -1) std::printf(" ");  // keeps the samples observable
  }
  if (!args.csv.empty()) write_text_file(args.csv, csv.str());
  return 0;
}

}  // namespace

void add_bench_lights(CLI::App& bench, Action& action) {
  auto args = std::make_shared<BenchLightsArgs>();
  CLI::App* cmd = bench.add_subcommand("lights", "Light tree build and sampling cost against power selection, 10 to 1M emitters");
  cmd->add_option("--counts", args->counts, "Emitter counts (default 10,100,...,1000000)")
      ->delimiter(',')
      ->check(CLI::Range(size_t(1), size_t(1) << 24));
  cmd->add_option("--samples", args->samples, "Light choices timed per count (default 1000000)")
      ->check(CLI::Range(size_t(1), size_t(1) << 30));
  cmd->add_option("--csv", args->csv, "Also write the table as CSV to this file");
  cmd->callback([&action, args] { action = [args] { return run_bench_lights(*args); }; });
}

}  // namespace pt
