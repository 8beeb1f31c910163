// Fault injection on the real `pt` binary (issue 11): a full filesystem (a small tmpfs, when we may
// mount one), a file-size limit (`ulimit -f`), SIGINT, SIGTERM and SIGHUP while loading and while
// rendering, outputs that name the scene's own inputs or something that is not a regular file, and
// temporaries left by a killed process. Each run must end non-zero (or 128 + signal with a valid
// partial image where the signal asks for it), with the previous file intact and no temporary left.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/image/image.h"
#include "obj_text.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

// One sphere lit by a point light, with noise enough that PNG does not compress it to nothing.
std::string lit_scene(const TempDir& dir, const std::string& name = "scene.json") {
  return dir.write(name, R"({"spheres": [{"center": [0, 0, 0], "radius": 1}],
    "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 40},
    "lights": [{"type": "point", "position": [0, 3, 3], "intensity": 10}],
    "environment": {"radiance": 0.2}, "render": {"resolution": [16, 12], "spp": 1, "integrator": "path"}})");
}

std::set<std::string> names_in(const fs::path& folder) {
  std::set<std::string> names;
  for (const std::string& n : listing(folder)) names.insert(n);
  return names;
}

// A tmpfs of `kib` KiB mounted on a fresh folder, when this process may mount (root with
// CAP_SYS_ADMIN); unmounted at the end.
struct SmallFilesystem {
  fs::path path;
  bool mounted = false;
  SmallFilesystem(const fs::path& where, int kib) : path(where) {
    fs::create_directories(path);
    std::string options = "size=" + std::to_string(kib) + "k";
    mounted = ::mount("tmpfs", path.c_str(), "tmpfs", 0, options.c_str()) == 0;
  }
  ~SmallFilesystem() {
    if (mounted) ::umount2(path.c_str(), MNT_DETACH);
  }
  // Fills what is left with one file.
  void fill(const std::string& name) {
    std::ofstream out(path / name, std::ios::binary);
    std::string block(4096, 'f');
    while (out.write(block.data(), block.size())) {
    }
  }
};

// The previous contents of every output, written before the faulty runs.
const std::string kPrevious = "the previous file, which must survive";

struct OutputRun {
  std::string name;                // output file in the faulty folder
  std::vector<std::string> args;   // the command, writing to <folder>/<name>
};

// The commands that write files: every image format, `pt gen dense` and a benchmark's CSV.
std::vector<OutputRun> output_runs(const std::string& scene, const fs::path& folder) {
  auto out = [&](const std::string& name) { return (folder / name).string(); };
  return {
      {"image.png", {"render", scene, "--res", "96x96", "--spp", "4", "-q", "-o", out("image.png")}},
      {"image.jpg", {"render", scene, "--res", "96x96", "--spp", "4", "-q", "-o", out("image.jpg")}},
      {"image.exr", {"render", scene, "--res", "96x96", "--spp", "4", "-q", "-o", out("image.exr")}},
      {"dense.obj", {"gen", "dense", out("dense.obj"), "--level", "4"}},
      {"rays.csv", {"bench", "rays", scene, "--rays", "2000", "--passes", "1", "--threads", "1", "--csv", out("rays.csv")}},
  };
}

// Runs each output command into `folder`, where every output already holds kPrevious and writes
// fail: exit 2 (not a signal), one error naming the output, the previous file intact, no temporary.
void check_failing_writes(const TempDir& dir, const fs::path& folder, const std::string& scene, const StartOptions& options,
                          const std::string& reason) {
  std::vector<OutputRun> runs = output_runs(scene, folder);
  std::set<std::string> before = names_in(folder);
  for (const OutputRun& r : runs) {
    CAPTURE(r.name);
    Outcome o = run_pt(r.args, dir, options);
    CAPTURE(o.err);
    CHECK(o.exited);  // not killed by SIGXFSZ
    CHECK(o.code == 2);
    CHECK(o.err.find("pt: error: " + (folder / r.name).string()) != std::string::npos);
    CHECK(o.err.find(reason) != std::string::npos);
    CHECK(read_file(folder / r.name) == kPrevious);
    CHECK(names_in(folder) == before);
  }
}

// Waits until `pid` runs pt (not the forked test, whose doctest handlers would count) and has a
// handler for SIGINT: it is past start-up, in main. At most 30 s.
void wait_for_handlers(pid_t pid) {
  auto start = std::chrono::steady_clock::now();
  const fs::path binary = fs::canonical(PT_BINARY);
  const std::string proc = "/proc/" + std::to_string(pid);
  while (true) {
    std::error_code ec;
    bool is_pt = fs::read_symlink(proc + "/exe", ec) == binary;
    std::string status = read_file(proc + "/status");
    size_t at = status.find("SigCgt:");
    if (is_pt && at != std::string::npos && (std::stoull(status.substr(at + 7), nullptr, 16) & (1ull << (SIGINT - 1)))) return;
    REQUIRE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 30.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// An OBJ that takes many seconds to load: 1000 faces of 1024 vertices, each triangulated by
// tinyobjloader's ear clipping (about 1 µs per byte, 4 MB).
std::string slow_obj(const TempDir& dir) { return dir.write("slow.obj", pt::test::polygon_obj(1024, 1000)); }

struct Signal {
  int number;
  const char* name;
};
const Signal kSignals[] = {{SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"}};

}  // namespace

TEST_CASE("a full filesystem: every output fails in one line, the previous file intact, no temporary") {
  TempDir dir("pt-fault");
  std::string scene = lit_scene(dir);
  SmallFilesystem small(dir.path / "small", 256);
  if (!small.mounted) {
    MESSAGE("cannot mount a tmpfs here (not root?): the file-size-limit test below covers the same path");
    return;
  }
  for (const OutputRun& r : output_runs(scene, small.path)) std::ofstream(small.path / r.name) << kPrevious;
  small.fill("filler");
  check_failing_writes(dir, small.path, scene, {}, "No space left on device");
}

TEST_CASE("a file-size limit (ulimit -f): SIGXFSZ does not kill pt; the write fails like a full disk") {
  TempDir dir("pt-fault");
  std::string scene = lit_scene(dir);
  fs::path folder = dir.path / "limited";
  fs::create_directories(folder);
  for (const OutputRun& r : output_runs(scene, folder)) std::ofstream(folder / r.name) << kPrevious;
  StartOptions limited;
  limited.file_size_limit = 256;  // every output above is larger
  check_failing_writes(dir, folder, scene, limited, "File too large");
}

TEST_CASE("SIGINT, SIGTERM and SIGHUP while loading end pt at once; the previous file is untouched") {
  TempDir dir("pt-fault");
  std::string obj = slow_obj(dir);
  fs::path out = dir.path / "out.png";
  for (const Signal& sig : kSignals) {
    CAPTURE(sig.name);
    std::ofstream(out) << kPrevious;
    fs::path err = dir.path / "stderr.txt";
    pid_t pid = start_pt({"render", obj, "--res", "8x8", "--spp", "1", "-o", out.string()}, err);
    wait_for_handlers(pid);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // into the load
    REQUIRE(::kill(pid, sig.number) == 0);
    Outcome o = finish(pid, err, 120);
    CAPTURE(o.err);
    CHECK(o.exited);
    CHECK(o.code == 128 + sig.number);
    CHECK(o.err.find(std::string("interrupted (") + sig.name + "); nothing written") != std::string::npos);
    CHECK(o.err.find("rendering") == std::string::npos);
    // Loading this file takes many seconds; the signal must not wait for it.
    CHECK(o.seconds < 3.0);
    CHECK(read_file(out) == kPrevious);
    CHECK(names_in(dir.path) == std::set<std::string>{"out.png", "slow.obj", "stderr.txt"});
  }
}

TEST_CASE("SIGINT, SIGTERM and SIGHUP mid-render replace the previous file by the valid partial image") {
  TempDir dir("pt-fault");
  std::string scene = lit_scene(dir);
  fs::path out = dir.path / "out.exr";
  for (const Signal& sig : kSignals) {
    CAPTURE(sig.name);
    std::ofstream(out) << kPrevious;
    fs::path err = dir.path / "stderr.txt";
    fs::remove(err);  // the last run's "pass 1/" must not count
    pid_t pid = start_pt({"render", scene, "--spp", "1000000", "--res", "32x24", "--threads", "1", "-o", out.string()}, err);
    wait_for_text(err, "pass 1/");
    REQUIRE(::kill(pid, sig.number) == 0);
    Outcome o = finish(pid, err, 30);
    CAPTURE(o.err);
    CHECK(o.exited);
    CHECK(o.code == 128 + sig.number);
    pt::Image image = pt::read_image(out.string());
    CHECK(image.width == 32);
    CHECK(std::stol(image.metadata["pt:spp"]) >= 1);
    CHECK(names_in(dir.path) == std::set<std::string>{"out.exr", "scene.json", "stderr.txt"});
  }
}

TEST_CASE("an output that names one of the scene's inputs is refused before rendering") {
  TempDir dir("pt-fault");
  // A textured sphere under an environment map: both images are inputs.
  Outcome made = run_pt({"render", lit_scene(dir, "tmp.json"), "--res", "8x4", "-q", "-o", (dir.path / "tex.png").string()}, dir);
  REQUIRE(made.code == 0);
  REQUIRE(run_pt({"render", (dir.path / "tmp.json").string(), "--res", "8x4", "-q", "-o", (dir.path / "sky.exr").string()}, dir)
              .code == 0);
  fs::remove(dir.path / "tmp.json");
  std::string scene = dir.write("scene.json", R"({"materials": {"m": {"texture": "tex.png"}},
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}],
    "environment": {"file": "sky.exr"}, "render": {"resolution": [8, 8], "spp": 1}})");
  fs::create_hard_link(dir.path / "sky.exr", dir.path / "hard-link.exr");
  fs::create_symlink("tex.png", dir.path / "sym-link.png");
  fs::create_directories(dir.path / "sub");
  std::string tex_before = read_file(dir.path / "tex.png"), sky_before = read_file(dir.path / "sky.exr");
  std::set<std::string> before = names_in(dir.path);
  for (const std::string& output : {(dir.path / "tex.png").string(), (dir.path / "sky.exr").string(),
                                    (dir.path / "hard-link.exr").string(), (dir.path / "sym-link.png").string(),
                                    (dir.path / "sub" / ".." / "tex.png").string()}) {
    CAPTURE(output);
    Outcome o = run_pt({"render", scene, "-o", output}, dir);
    CAPTURE(o.err);
    CHECK(o.code == 2);
    CHECK(o.err.find("is one of the scene's own inputs") != std::string::npos);
    CHECK(o.err.find("rendering") == std::string::npos);
    CHECK(read_file(dir.path / "tex.png") == tex_before);
    CHECK(read_file(dir.path / "sky.exr") == sky_before);
    std::set<std::string> now = names_in(dir.path);
    now.erase("stderr.txt");
    before.erase("stderr.txt");
    CHECK(now == before);
  }
}

TEST_CASE("outputs that are not regular files are never replaced") {
  TempDir dir("pt-fault");
  std::string scene = lit_scene(dir);
  REQUIRE(::mkfifo((dir.path / "fifo.png").c_str(), 0644) == 0);
  REQUIRE(::mkfifo((dir.path / "fifo.obj").c_str(), 0644) == 0);
  std::vector<std::pair<std::string, std::vector<std::string>>> runs = {
      {"fifo.png", {"render", scene, "-o", (dir.path / "fifo.png").string()}},
      {"fifo.obj", {"gen", "dense", (dir.path / "fifo.obj").string(), "--level", "1"}},
  };
  if (::geteuid() == 0) {
    // /dev/null's numbers, in our own folder: what `-o /dev/null` would have replaced as root.
    REQUIRE(::mknod((dir.path / "null.png").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0);
    REQUIRE(::mknod((dir.path / "null.obj").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0);
    runs.push_back({"null.png", {"render", scene, "-o", (dir.path / "null.png").string()}});
    runs.push_back({"null.obj", {"gen", "dense", (dir.path / "null.obj").string(), "--level", "1"}});
  }
  for (const auto& [name, args] : runs) {
    CAPTURE(name);
    Outcome o = run_pt(args, dir);
    CAPTURE(o.err);
    CHECK(o.code == 2);
    CHECK(o.err.find("not a regular file") != std::string::npos);
    fs::file_status st = fs::symlink_status(dir.path / name);
    CHECK((fs::is_fifo(st) || fs::is_character_file(st)));
    for (const std::string& n : listing(dir.path)) CHECK(n.find("tmp") == std::string::npos);
  }
}

TEST_CASE("temporaries left by a killed pt on this host are removed by the next run in that folder") {
  TempDir dir("pt-fault");
  std::string scene = lit_scene(dir);
  pid_t dead = ::fork();
  REQUIRE(dead >= 0);
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  std::string stale = ".out.png." + std::string(host) + "-" + std::to_string(dead) + ".pt-tmp";
  std::string live = ".out.png." + std::string(host) + "-" + std::to_string(::getpid()) + ".pt-tmp";
  std::ofstream(dir.path / stale) << "half an image";
  std::ofstream(dir.path / live) << "a write in progress";
  Outcome o = run_pt({"render", scene, "-q", "-o", (dir.path / "out.png").string()}, dir);
  CHECK(o.code == 0);
  CHECK_FALSE(fs::exists(dir.path / stale));
  CHECK(fs::exists(dir.path / live));
  CHECK(fs::exists(dir.path / "out.png"));
}
