// `pt bench rays SCENE`: the speed of the two backends side by side on the same ray batches, and
// whether they agree; first the shape statistics of the scene's triangles (triangle_stats.h).
//
// Batches (each --rays long, generated once, shared by both backends):
//   primary  camera rays through uniformly random film positions (closest hit)
//   shadow   from primary hits toward points chosen by Scene::sample_light (any hit); where no light
//            can be sampled at all, along the diffuse rays (ambient occlusion, any hit)
//   diffuse  cosine-distributed directions about the geometric normal at primary hits (closest hit)
// Secondary rays start at primary hits found by Embree, cycling through them when there are fewer
// hits than rays. Each (batch, backend, thread count) runs one warm-up pass and --passes timed
// passes, the backends alternating pass by pass; the table shows the best pass, the least disturbed
// by other work on the machine. Single-thread passes are timed by the thread's CPU time, so that
// time the thread spends waiting for a core on a loaded machine does not count; parallel passes by
// wall time.
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/accel/bvh_accel.h"
#include "core/math/frame.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "core/util/error.h"
#include "renderer/bench/bench.h"
#include "renderer/bench/triangle_stats.h"
#include "renderer/commands/cli_options.h"
#include "renderer/bench/bench_csv.h"
#include "renderer/bench/bvh_variant.h"
#include "renderer/render/job.h"

namespace pt {
namespace {

struct BenchRaysArgs {
  std::string path;
  std::string backend = "both";
  TriangleTest triangle_test = TriangleTest::kWatertight;
  bool embree_robust = false;
  size_t rays = size_t(1) << 20;
  int passes = 3;
  int builds = 1;
  std::vector<std::string> kinds{"primary", "shadow", "diffuse"};
  int threads = 0;
  uint64_t seed = 1;
  std::string csv;
  std::string disagreements;
  std::vector<std::string> bvh_variants;  // more BVHs, each built with these settings (bvh_variant.h)
  std::string from = "all";               // where secondary rays start: all, ground, model
  ViewOptions view;
};

enum class Kind { kPrimary, kShadow, kDiffuse };
const char* kind_name(Kind k) { return k == Kind::kPrimary ? "primary" : (k == Kind::kShadow ? "shadow" : "diffuse"); }

struct Batch {
  Kind kind;
  std::vector<Ray> rays;
};

// What one backend returned for one ray, for the agreement count.
struct Answer {
  float t = kInf;  // kInf: miss; for shadow rays 0 = occluded
  uint32_t geom = 0, prim = 0;
  float u = 0, v = 0;
  uint32_t inst = kNoInstance;
};

template <class F>
void for_rays(size_t n, bool parallel, F&& f) {
  if (!parallel) {
    f(size_t(0), n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 2048),
                    [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
}

// The calling thread's CPU time for a single-thread pass, the monotonic clock for a parallel one.
double pass_clock(bool parallel) {
  timespec ts;
  clock_gettime(parallel ? CLOCK_MONOTONIC : CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// One pass; returns seconds. The hit count goes to `sink` so the work cannot be optimised away.
double run_pass(const Accel& accel, const Batch& batch, bool parallel, std::atomic<uint64_t>& sink) {
  double start = pass_clock(parallel);
  for_rays(batch.rays.size(), parallel, [&](size_t begin, size_t end) {
    uint64_t hits = 0;
    if (batch.kind == Kind::kShadow) {
      for (size_t i = begin; i < end; ++i) hits += accel.occluded(batch.rays[i]);
    } else {
      for (size_t i = begin; i < end; ++i) hits += accel.intersect(batch.rays[i]).has_value();
    }
    sink.fetch_add(hits, std::memory_order_relaxed);
  });
  return pass_clock(parallel) - start;
}

std::vector<Answer> answers(const Accel& accel, const Batch& batch) {
  std::vector<Answer> out(batch.rays.size());
  for_rays(batch.rays.size(), true, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if (batch.kind == Kind::kShadow) {
        out[i].t = accel.occluded(batch.rays[i]) ? 0.0f : kInf;
      } else if (auto h = accel.intersect(batch.rays[i])) {
        out[i] = {h->t, h->geom, h->prim, h->u, h->v, h->inst};
      }
    }
  });
  return out;
}

struct Agreement {
  size_t hit_miss = 0, prim = 0, t = 0;
  size_t a_missed = 0;  // of hit_miss: rays the first backend (Embree) missed and the second hit
};

Agreement compare(const std::vector<Answer>& a, const std::vector<Answer>& b) {
  Agreement g;
  for (size_t i = 0; i < a.size(); ++i) {
    bool ha = a[i].t < kInf, hb = b[i].t < kInf;
    if (ha != hb) {
      ++g.hit_miss;
      g.a_missed += hb;
    } else if (ha && (a[i].geom != b[i].geom || a[i].prim != b[i].prim || a[i].inst != b[i].inst)) {
      ++g.prim;
    } else if (ha && std::abs(a[i].t - b[i].t) > 1e-4f * std::max(std::abs(a[i].t), std::abs(b[i].t))) {
      ++g.t;
    }
  }
  return g;
}

// `from`: secondary rays start at every primary hit ("all"), or only at those on the default
// studio's ground ("ground") or on the rest of the scene ("model"). The two sets can cost the
// backends differently: under the studio, rays that leave the ground visit two or three nodes and
// rays that leave the model many, and a row over both is their mix (docs/bvh.md, Build 2).
std::vector<Batch> make_batches(const Scene& scene, const Camera::Basis& basis, const Accel& reference, size_t n,
                                uint64_t seed, const std::string& from, const std::string& path) {
  std::vector<Batch> batches(3);
  batches[0].kind = Kind::kPrimary;
  batches[1].kind = Kind::kShadow;
  batches[2].kind = Kind::kDiffuse;
  std::vector<Ray>& primary = batches[0].rays;
  primary.resize(n);
  for_rays(n, true, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      Pcg32 rng(hash_combine(seed, i), 1);
      primary[i] = Camera::ray(basis, Vec2f(rng.next_float(), rng.next_float()));
    }
  });
  // Primary hits, as surface points with the geometric normal turned toward the camera.
  struct Surface {
    Vec3f p, n;
  };
  std::vector<Answer> ref = answers(reference, batches[0]);
  std::vector<Surface> surfaces;
  for (size_t i = 0; i < n; ++i) {
    if (!(ref[i].t < kInf)) continue;
    if (from != "all") {
      bool ground = scene.studio() && ref[i].geom == kGeomTriangles && ref[i].inst == kNoInstance &&
                    ref[i].prim >= scene.studio()->first_triangle;
      if (ground != (from == "ground")) continue;
    }
    Hit h{ref[i].t, ref[i].geom, ref[i].prim, ref[i].u, ref[i].v, ref[i].inst};
    SurfaceInteraction si = scene.interaction(primary[i], h);
    Vec3f ng = dot(si.ng, primary[i].d) > 0 ? -si.ng : si.ng;
    surfaces.push_back({si.p, ng});
  }
  if (surfaces.empty() && from != "all") {
    throw Error(path, "--from " + from + ": no primary ray hits " +
                          (from == "ground" ? std::string(scene.studio() ? "the studio's ground" : "a studio's ground: the scene has none (--studio none, or it emits light)")
                                            : std::string("anything but the studio's ground")));
  }
  if (surfaces.empty()) return {batches[0]};

  std::vector<Ray>& shadow = batches[1].rays;
  std::vector<Ray>& diffuse = batches[2].rays;
  shadow.resize(n);
  diffuse.resize(n);
  std::vector<uint8_t> shadow_ok(n, 0);
  for_rays(n, true, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const Surface& sf = surfaces[i % surfaces.size()];
      Pcg32 rng(hash_combine(seed + 1, i), 2);
      Frame frame(sf.n);
      Ray d;
      d.o = offset_ray_origin(sf.p, sf.n);
      d.d = frame.to_world(square_to_cosine_hemisphere(Vec2f(rng.next_float(), rng.next_float())));
      diffuse[i] = d;
      for (int attempt = 0; attempt < 16 && !shadow_ok[i]; ++attempt) {
        LightSample ls;
        if (!scene.sample_light(sf.p, sf.n, rng.next_float(), Vec2f(rng.next_float(), rng.next_float()), ls)) continue;
        if (std::isinf(ls.distance)) {
          Ray r;
          r.o = offset_ray_origin(sf.p, sf.n);
          r.d = ls.wi;
          shadow[i] = r;
        } else {
          shadow[i] = shadow_ray_to(sf.p, sf.n, ls.point);
        }
        shadow_ok[i] = 1;
      }
    }
  });
  // Drop the few points where no light sample could be drawn (e.g. behind every emitter).
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i)
    if (shadow_ok[i]) shadow[kept++] = shadow[i];
  shadow.resize(kept);
  // Nothing to sample as a light (a plain sky left to BSDF sampling, `--studio none`): the shadow
  // batch becomes ambient-occlusion rays, any hit along the diffuse rays' directions, so that every
  // scene has an any-hit row.
  if (shadow.empty()) shadow = diffuse;
  return batches;
}

struct Timing {
  double best = 0;  // seconds of the best timed pass
};

int run_bench_rays(const BenchRaysArgs& args) {
  if (!args.csv.empty()) check_output_path(args.csv);  // before the measurements, not after
  if (!args.disagreements.empty()) {
    if (args.backend != "both") throw Error("--disagreements compares the two backends: it needs --backend both");
    check_output_path(args.disagreements);
  }
  std::vector<BvhVariant> variants;
  for (const std::string& spec : args.bvh_variants) variants.push_back(parse_bvh_variant(spec));
  if (!variants.empty() && args.backend == "embree") throw Error("--bvh-variant builds more BVHs: it needs --backend both or bvh");
  int threads = args.threads > 0 ? args.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
  // The job gives the scene and its camera exactly as `pt render` sees them, and the Embree
  // backend, whose primary hits start the secondary rays (so every run of a scene uses the same rays).
  JobOptions jo;
  jo.scene_path = args.path;
  jo.accel.triangle_test = args.triangle_test;
  jo.accel.embree_robust = args.embree_robust;
  jo.view = args.view;
  Job job = prepare_job(jo);
  const Scene& scene = *job.scene;
  print_notes(scene);
  const RenderOptions& view = job.render;
  Camera::Basis basis = view.camera.basis(static_cast<float>(view.width) / view.height);

  std::vector<std::unique_ptr<Accel>> accels;
  std::vector<std::string> names;
  std::unique_ptr<Accel> embree = std::move(job.accel);
  const Accel& reference = *embree;
  std::vector<Batch> batches = make_batches(scene, basis, reference, args.rays, args.seed, args.from, args.path);
  std::erase_if(batches, [&](const Batch& b) { return std::find(args.kinds.begin(), args.kinds.end(), kind_name(b.kind)) == args.kinds.end(); });
  if (args.backend != "bvh") {
    accels.push_back(std::move(embree));
    names.push_back("embree");
  }
  // Column a's backend, built afresh (the --builds loop builds each column again).
  auto build = [&](size_t a) -> std::unique_ptr<Accel> {
    AccelOptions o = job.accel_options;
    o.backend = names[a] == "embree" ? Backend::kEmbree : Backend::kBvh;
    size_t first_variant = args.backend == "bvh" ? 1 : 2;  // the variants follow the default BVH
    if (a < first_variant) return make_accel(scene.geometry(), o);
    return make_variant_accel(scene.geometry(), o.triangle_test, variants[a - first_variant]);
  };
  if (!variants.empty() && !scene.geometry().instances().empty()) {
    throw Error(args.path, "--bvh-variant: the scene has instances, whose two-level BVH takes no build settings");
  }
  if (args.backend != "embree") {
    AccelOptions o = job.accel_options;
    o.backend = Backend::kBvh;
    accels.push_back(make_accel(scene.geometry(), o));
    names.push_back(accels.back()->name());
    for (size_t v = 0; v < variants.size(); ++v) {
      names.push_back("bvh#" + std::to_string(v + 1));
      accels.push_back(build(accels.size()));
    }
  }
  embree.reset();

  std::printf("pt bench rays: %s: %zu triangles, %zu spheres; %zu rays per batch; best of %d passes after a warm-up (1 thread: CPU time)",
              args.path.c_str(), scene.mesh().triangle_count(), scene.spheres().size(), args.rays, args.passes);
  if (args.builds > 1) std::printf("; build: best of %d", args.builds);
  if (args.from != "all") std::printf("; shadow and diffuse rays from the %s only", args.from == "ground" ? "studio's ground" : "model (not the ground)");
  std::printf("\n");
  for (size_t v = 0; v < args.bvh_variants.size(); ++v)
    std::printf("bvh#%zu: the BVH built with %s\n", v + 1, describe_bvh_variant(args.bvh_variants[v]).c_str());
  std::printf("%s", format_triangle_stats(triangle_stats(scene.mesh())).c_str());

  // rows of the table: label, kind, threads, value per backend
  struct Row {
    std::string metric, kind, threads;
    std::vector<double> values;
    bool higher_is_better;
  };
  std::vector<Row> rows;
  {
    Row build_row{"build_seconds", "", "", {}, false}, memory{"memory_mb", "", "", {}, false};
    for (const auto& a : accels) {
      build_row.values.push_back(a->stats().build_seconds);
      memory.values.push_back(a->stats().bytes / 1048576.0);
    }
    // --builds N: the best of N builds per backend, alternating like the ray passes (one build of a
    // second or two is the row most disturbed by other work on the machine).
    for (int b = 1; b < args.builds; ++b) {
      for (size_t a = 0; a < accels.size(); ++a) {
        build_row.values[a] = std::min(build_row.values[a], build(a)->stats().build_seconds);
      }
    }
    rows.push_back(build_row);
    rows.push_back(memory);
  }
  std::atomic<uint64_t> sink{0};
  for (int parallel = 0; parallel < 2; ++parallel) {
    if (parallel && threads == 1) break;
    for (const Batch& batch : batches) {
      Row row{"mrays_per_s", kind_name(batch.kind), std::to_string(parallel ? threads : 1), {}, true};
      std::vector<double> best(accels.size(), kInf);
      for (size_t a = 0; a < accels.size(); ++a) run_pass(*accels[a], batch, parallel, sink);  // warm-up
      // Backends alternate pass by pass, so a disturbance on the machine hits both alike.
      for (int p = 0; p < args.passes; ++p) {
        for (size_t a = 0; a < accels.size(); ++a) best[a] = std::min(best[a], run_pass(*accels[a], batch, parallel, sink));
      }
      for (double s : best) row.values.push_back(batch.rays.size() / s * 1e-6);
      rows.push_back(row);
    }
  }

  // With Embree in the first column, each BVH column's time (or size) over Embree's.
  bool both = accels.size() >= 2 && names[0] == "embree";
  auto ratio = [](const Row& r, size_t a) { return r.higher_is_better ? r.values[0] / r.values[a] : r.values[a] / r.values[0]; };
  std::printf("\n%-24s", "");
  for (const std::string& n : names) std::printf(" %14s", n.c_str());
  if (both) {
    std::printf(" %14s", "bvh/embree time");
    for (size_t a = 2; a < names.size(); ++a) std::printf(" %14s", (names[a] + "/embree").c_str());
  }
  std::printf("\n");
  for (const Row& r : rows) {
    std::string label = r.metric == "mrays_per_s" ? r.kind + " Mrays/s (" + r.threads + (r.threads == "1" ? " thread)" : " threads)")
                        : r.metric == "build_seconds" ? "build (s)" : "memory (MB)";
    std::printf("%-24s", label.c_str());
    for (double v : r.values) std::printf(" %14.3f", v);
    if (both) {
      for (size_t a = 1; a < names.size(); ++a) std::printf(" %14.2f", ratio(r, a));
    }
    std::printf("\n");
  }

  std::vector<std::pair<std::string, Agreement>> agreement;
  // The rays one backend hits (or finds occluded) and the other does not, exactly (hexadecimal
  // floats), with what each returned: for checking who is right (renderer/tools/exact_ray.py).
  std::ostringstream differing;
  differing << "kind,ray,ox,oy,oz,dx,dy,dz,tmin,tmax";
  for (size_t a = 0; a < std::min<size_t>(2, names.size()); ++a) {
    const std::string& n = names[a];
    // Quoted where a backend's name holds a comma ("bvh (watertight, two levels)"), as CSV readers expect.
    const char* q = n.find(',') != std::string::npos ? "\"" : "";
    for (const char* field : {"_t", "_geom", "_prim", "_inst"}) differing << "," << q << n << field << q;
  }
  differing << "\n";
  auto hex = [](float x) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%a", static_cast<double>(x));
    return std::string(buf);
  };
  if (both) {
    std::printf("\nagreement (rays where the backends differ):\n");
    for (const Batch& batch : batches) {
      std::vector<Answer> a = answers(*accels[0], batch), b = answers(*accels[1], batch);
      Agreement g = compare(a, b);
      // The variants against Embree too: another tree must not change an answer either.
      for (size_t k = 2; k < accels.size(); ++k) {
        Agreement gk = compare(a, answers(*accels[k], batch));
        std::printf("  %-8s %s: %zu hit/miss (embree missed %zu, %s missed %zu), %zu primitive, %zu t beyond 1e-4 relative\n",
                    kind_name(batch.kind), names[k].c_str(), gk.hit_miss, gk.a_missed, names[k].c_str(),
                    gk.hit_miss - gk.a_missed, gk.prim, gk.t);
      }
      for (size_t i = 0; i < a.size(); ++i) {
        if ((a[i].t < kInf) == (b[i].t < kInf)) continue;
        const Ray& r = batch.rays[i];
        differing << kind_name(batch.kind) << "," << i << "," << hex(r.o.x) << "," << hex(r.o.y) << "," << hex(r.o.z) << ","
                  << hex(r.d.x) << "," << hex(r.d.y) << "," << hex(r.d.z) << "," << hex(r.tmin) << "," << hex(r.tmax);
        for (const Answer* x : {&a[i], &b[i]}) {
          differing << "," << hex(x->t) << "," << x->geom << "," << x->prim << ",";
          if (x->inst != kNoInstance) differing << x->inst;
        }
        differing << "\n";
      }
      agreement.emplace_back(kind_name(batch.kind), g);
      // Which one let the ray through: on a shadow ray, "missed" is "found no occluder".
      std::string who = g.hit_miss == 0 ? "" : " (" + names[0] + " missed " + std::to_string(g.a_missed) + ", " + names[1] +
                                                    " missed " + std::to_string(g.hit_miss - g.a_missed) + ")";
      if (batch.kind == Kind::kShadow) {
        std::printf("  %-8s %zu%s of %zu occlusion answers\n", kind_name(batch.kind), g.hit_miss, who.c_str(), batch.rays.size());
      } else {
        std::printf("  %-8s %zu hit/miss%s, %zu primitive, %zu t beyond 1e-4 relative, of %zu rays\n",
                    kind_name(batch.kind), g.hit_miss, who.c_str(), g.prim, g.t, batch.rays.size());
      }
    }
  }

  if (!args.csv.empty()) {
    std::ostringstream f;
    f << "metric,kind,threads";
    for (const std::string& n : names) f << "," << n;
    if (both) {
      f << ",bvh_over_embree_time";
      for (size_t a = 2; a < names.size(); ++a) f << ",bvh_" << (a - 1) << "_over_embree_time";
    }
    f << "\n";
    for (const Row& r : rows) {
      f << r.metric << "," << r.kind << "," << r.threads;
      for (double v : r.values) f << "," << v;
      if (both) {
        for (size_t a = 1; a < names.size(); ++a) f << "," << ratio(r, a);
      }
      f << "\n";
    }
    for (const auto& [kind, g] : agreement) {
      f << "disagree_hit_miss," << kind << ",," << g.hit_miss << ",,\n";
      f << "embree_missed," << kind << ",," << g.a_missed << ",,\n";
      f << "disagree_prim," << kind << ",," << g.prim << ",,\n";
      f << "disagree_t," << kind << ",," << g.t << ",,\n";
    }
    write_text_file(args.csv, f.str());
  }
  if (!args.disagreements.empty()) write_text_file(args.disagreements, differing.str());
  return sink.load() == uint64_t(-1) ? 1 : 0;  // never true; keeps the passes observable
}

}  // namespace

void add_bench_rays(CLI::App& bench, Action& action) {
  auto args = std::make_shared<BenchRaysArgs>();
  CLI::App* cmd = bench.add_subcommand("rays", "Ray throughput of Embree and the BVH on the same rays, and their agreement");
  cmd->add_option("scene", args->path, "Scene: an .obj file, a .json scene file, or a folder holding scene.json")->required();
  cmd->add_option("--backend", args->backend, "both (default), embree or bvh")->check(CLI::IsMember({"both", "embree", "bvh"}));
  add_name_option(*cmd, "--triangle-test", args->triangle_test, kTriangleTestNames,
                  "BVH triangle test: watertight (default) or mt");
  cmd->add_flag("--embree-robust", args->embree_robust, "Build Embree's scene with RTC_SCENE_FLAG_ROBUST");
  cmd->add_option("--rays", args->rays, "Rays per batch (default 1048576)")->check(CLI::Range(size_t(1), size_t(1) << 28));
  cmd->add_option("--passes", args->passes, "Timed passes per batch (default 3)")->check(CLI::Range(1, 1000));
  cmd->add_option("--builds", args->builds, "Builds per backend; the build row shows the best (default 1)")->check(CLI::Range(1, 100));
  cmd->add_option("--kinds", args->kinds, "Ray batches to time: any of primary, shadow, diffuse (default all)")
      ->check(CLI::IsMember({"primary", "shadow", "diffuse"}))
      ->delimiter(',');
  cmd->add_option("--threads", args->threads, "Threads for the parallel runs (default: all cores)")->check(CLI::Range(1, 1024));
  cmd->add_option("--seed", args->seed, "Seed of the ray batches");
  cmd->add_option("--from", args->from,
                  "Where shadow and diffuse rays start: all primary hits (default), only those on the default studio's "
                  "ground (ground), or only the others (model)")
      ->check(CLI::IsMember({"all", "ground", "model"}));
  cmd->add_option("--csv", args->csv, "Also write the table as CSV to this file");
  cmd->add_option("--disagreements", args->disagreements,
                  "Write the rays one backend hits and the other misses, as CSV with exact (hexadecimal) floats and each "
                  "backend's answer, to this file (renderer/tools/exact_ray.py checks them)");
  cmd->add_option("--bvh-variant", args->bvh_variants,
                  "Also time a BVH built with these settings, e.g. max_leaf=8,traversal_cost=1.5 (keys: " +
                      bvh_variant_build_keys() +
                      "), or the kernels it runs: kernels=sse4.2, avx2, avx512, or experiment in a build "
                  "with -DPT_BVH_EXPERIMENT=ON; repeat for more. Columns bvh#1, bvh#2...: in one process, on the same "
                  "rays, passes alternating")
      ->allow_extra_args(false);
  add_view_options(*cmd, args->view);
  cmd->callback([&action, args] { action = [args] { return run_bench_rays(*args); }; });
}

}  // namespace pt
