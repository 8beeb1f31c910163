// The stability experiments on bad input: degenerate triangles and non-finite values in an OBJ,
// each loaded (in a child process, so a crash is counted rather than fatal) and traced.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "core/scene/loader.h"
#include "core/scene/scene.h"
#include "core/util/error.h"
#include "renderer/measure/stability.h"
#include "renderer/measure/stability_scenes.h"

namespace pt {
namespace fs = std::filesystem;
using namespace stability;

std::vector<StabilityRow> measure_degenerate(const std::string& work_dir, const StabilityOptions& o) {
  std::vector<StabilityRow> rows;
  const std::string good = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const std::pair<const char*, const char*> kFiles[] = {
      {"repeated-vertex", "v 2 0 0\nv 3 0 0\nf 4 5 4\n"},
      {"collinear", "v 2 1 0\nv 3 1 0\nv 4 1 0\nf 4 5 6\n"},
      {"one-point", "v 2 2 0\nf 4 4 4\n"},
      {"sliver-1e-30", "v 2 3 0\nv 3 3 0\nv 2.5 3.000000000000000000000000000001 0\nf 4 5 6\n"},
  };
  fs::create_directories(work_dir);
  for (const auto& [name, body] : kFiles) {
    std::string path = (fs::path(work_dir) / (std::string(name) + ".obj")).string();
    std::ofstream(path) << good << body;
    StabilityRow row{"degenerate", name, "loader", 0, 1, 0, ""};
    try {
      Scene s = load_scene(path);
      row.note = "loaded: " + std::to_string(s.mesh().triangle_count()) + " triangles, " +
                 std::to_string(s.degenerate_triangles()) + " counted degenerate (pt info shows it)";
    } catch (const std::exception& e) {
      row.note = std::string("rejected: ") + e.what();
    }
    rows.push_back(row);
  }

  // The backends: one good triangle and the three degenerate kinds, with rays from above aimed at
  // the degenerate ones' vertices and along their lines. A hit there is a hit on nothing.
  std::vector<Vec3f> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},        // good
                          {2, 0, 0}, {3, 0, 0}, {2, 0, 0},        // repeated vertex
                          {2, 1, 0}, {3, 1, 0}, {4, 1, 0},        // collinear
                          {2, 2, 0}, {2, 2, 0}, {2, 2, 0}};       // one point
  std::vector<uint32_t> idx(p.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<uint32_t>(i);
  Geometry scene = triangles(p, idx);
  const char* kinds[] = {"repeated-vertex", "collinear", "one-point"};
  Pcg32 rng(o.seed, 31);
  struct Aim {
    Ray ray;
    int kind;  // 0..2 degenerate triangle, -1 the good one
  };
  std::vector<Aim> aims;
  for (int k = 0; k < 200 * o.effort; ++k) {
    for (int kind = -1; kind < 3; ++kind) {
      Vec3f target;
      if (kind < 0) {
        Vec2f b = square_to_triangle({rng.next_float(), rng.next_float()});
        target = p[1] * b.x + p[2] * b.y;
      } else {
        const Vec3f& a = p[3 + 3 * kind];
        const Vec3f& c = p[3 + 3 * kind + (kind == 1 ? 2 : 1)];
        target = a + (c - a) * (k % 4 == 0 ? 0.0f : rng.next_float());
      }
      Vec3f from = (D3(target) + D3(rng.next_double() - 0.5, rng.next_double() - 0.5, 1.0)).f();
      Ray r;
      r.o = from;
      r.d = normalize(target - from);
      aims.push_back({r, kind});
    }
  }
  for (const StabilityMethod& m : stability_methods()) {
    Built b = build(scene, m);
    for (int kind = -1; kind < 3; ++kind) {
      std::string variant = kind < 0 ? "good-triangle-misses" : std::string(kinds[kind]) + "-hits";
      if (!b.accel) {
        rows.push_back(unavailable("degenerate", variant, m, 0, b.error));
        continue;
      }
      StabilityRow row{"degenerate", variant, m.name, 0, 0, 0, ""};
      uint64_t nonfinite = 0;
      for (const Aim& a : aims) {
        if (a.kind != kind) continue;
        ++row.trials;
        std::optional<Hit> hit = b.accel->intersect(a.ray);
        if (hit && !(std::isfinite(hit->t) && std::isfinite(hit->u) && std::isfinite(hit->v))) ++nonfinite;
        if (kind < 0) {
          row.failures += !hit || hit->prim != 0;
        } else {
          row.failures += hit && hit->prim != 0;
        }
      }
      row.note = std::to_string(nonfinite) + " hits with non-finite t/u/v";
      rows.push_back(row);
    }
  }
  return rows;
}

std::vector<StabilityRow> measure_nonfinite(const std::string& work_dir) {
  std::vector<StabilityRow> rows;
  const std::string good = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const std::pair<const char*, const char*> kFiles[] = {
      {"nan", "v nan 0 0\nv 3 0 0\nv 2 1 0\nf 4 5 6\n"},
      {"inf", "v 2 0 0\nv inf 0 0\nv 2 1 0\nf 4 5 6\n"},
      {"overflow-1e39", "v 2 0 0\nv 1e39 0 0\nv 2 1 0\nf 4 5 6\n"},
      {"not-a-number", "v 2 0 0\nv abc 0 0\nv 2 1 0\nf 4 5 6\n"},
  };
  fs::create_directories(work_dir);
  for (const auto& [name, body] : kFiles) {
    std::string path = (fs::path(work_dir) / (std::string(name) + ".obj")).string();
    std::ofstream(path) << good << body;
    StabilityRow row{"non-finite", name, "loader", 0, 1, 0, ""};
    try {
      load_scene(path);
      row.failures = 1;  // accepted input that has no meaning
      row.note = "accepted";
    } catch (const std::exception& e) {
      row.note = std::string("rejected: ") + e.what();
    }
    rows.push_back(row);
  }

  // Past the loader: a scene with a NaN and an infinite vertex handed to each backend directly.
  // Each runs in a child process (fork before any worker thread exists) with a 20 s alarm.
  for (const StabilityMethod& m : stability_methods()) {
    int fds[2];
    if (pipe(fds) != 0) throw Error("pipe failed");
    std::fflush(nullptr);
    pid_t pid = fork();
    if (pid < 0) throw Error("fork failed");
    if (pid == 0) {
      close(fds[0]);
      alarm(20);
      const float nan = std::nanf(""), inf = kInf;
      // Geometry alone: a Scene would reject exactly this input.
      Geometry s = triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {nan, 0, 0}, {3, 0, 0}, {2, 1, 0}, {2, 0, 0}, {inf, 0, 0}, {2, 2, 0}},
                             {0, 1, 2, 3, 4, 5, 6, 7, 8});
      char out[256];
      try {
        std::unique_ptr<Accel> accel = make_accel(s, m.options);
        Pcg32 rng(7, 41);
        int good_misses = 0, bad_hits = 0, nonfinite = 0;
        const int kRays = 1000;
        for (int i = 0; i < kRays; ++i) {
          Vec2f b = square_to_triangle({rng.next_float(), rng.next_float()});
          Vec3f target = Vec3f(1, 0, 0) * b.x + Vec3f(0, 1, 0) * b.y;
          Ray r;
          r.o = target + Vec3f(0.1f, 0.1f, 1.0f);
          r.d = normalize(target - r.o);
          std::optional<Hit> h = accel->intersect(r);
          good_misses += !h || h->prim != 0;
          // Rays where the broken triangles' finite parts lie.
          Vec3f t2 = {2.0f + 2 * rng.next_float(), 2 * rng.next_float(), 0.0f};
          r.o = t2 + Vec3f(0, 0, 1);
          r.d = {0, 0, -1};
          h = accel->intersect(r);
          bad_hits += h && h->prim != 0;
          if (h && !(std::isfinite(h->t) && std::isfinite(h->u) && std::isfinite(h->v))) ++nonfinite;
          bad_hits += accel->occluded(r) && !(t2.x < 1 && t2.y < 1);
        }
        std::snprintf(out, sizeof out, "ok %d %d %d %d\n", kRays, good_misses, bad_hits, nonfinite);
      } catch (const std::exception& e) {
        std::snprintf(out, sizeof out, "error %.200s\n", e.what());
      }
      ssize_t unused = write(fds[1], out, std::strlen(out));
      (void)unused;
      _exit(0);
    }
    close(fds[1]);
    std::string text;
    char buf[256];
    ssize_t n;
    while ((n = read(fds[0], buf, sizeof buf)) > 0) text.append(buf, static_cast<size_t>(n));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    StabilityRow row{"non-finite", "nan-and-inf-vertices", m.name, 0, 0, 0, ""};
    int rays = 0, misses = 0, bad = 0, nonfinite = 0;
    if (WIFSIGNALED(status)) {
      row.trials = 1;
      row.failures = 1;
      row.note = WTERMSIG(status) == SIGALRM ? "hung (killed after 20 s)" : "crashed (signal " + std::to_string(WTERMSIG(status)) + ")";
    } else if (std::sscanf(text.c_str(), "ok %d %d %d %d", &rays, &misses, &bad, &nonfinite) == 4) {
      row.trials = 2 * static_cast<uint64_t>(rays);
      row.failures = static_cast<uint64_t>(misses + bad);
      row.note = "valid triangle missed " + std::to_string(misses) + "x, hits on broken triangles " + std::to_string(bad) +
                 ", non-finite hit values " + std::to_string(nonfinite);
    } else {
      row.note = text.rfind("error ", 0) == 0 ? "refused: " + text.substr(6, text.size() - 7) : "no answer";
      if (row.note.find("not built") != std::string::npos) row.note = "unavailable: " + row.note;
    }
    rows.push_back(row);
  }
  return rows;
}


}  // namespace pt
