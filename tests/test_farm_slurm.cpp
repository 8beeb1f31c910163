// The Slurm path for real: a one-node cluster on localhost (munged, slurmctld, slurmd started by
// tests/slurm_one_node.sh in a temporary folder, stopped by their pids), a frame submitted through
// renderer/farm/pt-slurm as a job array of --part renders plus a dependent merge job, and the merged
// image compared with a one-machine render: bit-identical for regions, within merge.h's bound for
// sample ranges. Then a part killed by SIGTERM mid-render (as Slurm does at a time limit or on
// pre-emption), resubmitted with pt-slurm --resume and merged into the uninterrupted image. And a
// part written to a full disk. This test needs root and the slurm-wlm and munge packages; without
// them it FAILS with the reason, it never passes silently.
#include <doctest/doctest.h>
#include <stdlib.h>
#include <sys/mount.h>

#include <cmath>
#include <cstring>
#include <regex>

#include "core/image/image.h"
#include "renderer/farm/merge.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

const std::string kSource = PT_SOURCE_DIR;
const std::string kCornell = kSource + "/scenes/cornell-box";

// Runs a program to completion with stdout and stderr captured.
Outcome run(const std::string& program, const std::vector<std::string>& args, const fs::path& folder, double timeout_s) {
  static int serial = 0;
  fs::path out = folder / ("out" + std::to_string(serial) + ".txt"), err = folder / ("err" + std::to_string(serial) + ".txt");
  ++serial;
  return finish(start_program(program, args, err, out), err, timeout_s, out);
}

// The cluster: started in the constructor, stopped (by pid) in the destructor whatever happened.
class OneNodeSlurm {
 public:
  explicit OneNodeSlurm(const fs::path& folder) : folder_(folder) {
    fs::create_directories(folder_);
    Outcome o = run("/bin/bash", {script(), "start", folder_.string()}, folder_.parent_path(), 90);
    if (!(o.exited && o.code == 0)) {
      stop();  // whatever did start (the destructor of a half-made object does not run)
      FAIL("the farm test cannot run: a one-node Slurm did not start (" << o.err
                                                                       << "). It needs root and the Debian packages "
                                                                          "slurm-wlm and munge (cmake/packages.txt).");
    }
    ::setenv("SLURM_CONF", (folder_ / "slurm.conf").c_str(), 1);
  }
  ~OneNodeSlurm() {
    stop();
    ::unsetenv("SLURM_CONF");
  }
  OneNodeSlurm(const OneNodeSlurm&) = delete;
  OneNodeSlurm& operator=(const OneNodeSlurm&) = delete;

 private:
  static std::string script() { return kSource + "/tests/slurm_one_node.sh"; }
  void stop() { run("/bin/bash", {script(), "stop", folder_.string()}, folder_.parent_path(), 30); }
  fs::path folder_;
};

struct Submission {
  std::string parts_job, merge_job, image;
};

// renderer/farm/pt-slurm SCENE N ...; its printed job ids and image path.
Submission submit(const std::vector<std::string>& args, const fs::path& folder) {
  std::vector<std::string> all = {kSource + "/renderer/farm/pt-slurm", "--pt", PT_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  Outcome o = run("/bin/bash", all, folder, 120);
  CAPTURE(o.out);
  CAPTURE(o.err);
  REQUIRE(o.code == 0);
  std::smatch m;
  Submission s;
  REQUIRE(std::regex_search(o.out, m, std::regex(R"(parts job: (\d+))")));
  s.parts_job = m[1];
  REQUIRE(std::regex_search(o.out, m, std::regex(R"(merge job: (\d+))")));
  s.merge_job = m[1];
  REQUIRE(std::regex_search(o.out, m, std::regex(R"(image: (\S+))")));
  s.image = m[1];
  return s;
}

// Waits until none of `jobs` is queued or running (at most `timeout_s`).
void wait_for(const std::vector<std::string>& jobs, const fs::path& folder, double timeout_s) {
  std::string list;
  for (const std::string& j : jobs) list += (list.empty() ? "" : ",") + j;
  auto start = std::chrono::steady_clock::now();
  while (true) {
    Outcome q = run("/usr/bin/env", {"squeue", "-h", "-j", list}, folder, 30);
    if (q.code == 0 && q.out.find_first_not_of(" \n") == std::string::npos) return;
    REQUIRE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < timeout_s);
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
}

std::string job_state(const std::string& job, const fs::path& folder) {
  Outcome o = run("/usr/bin/env", {"scontrol", "show", "job", job}, folder, 30);
  std::smatch m;
  return std::regex_search(o.out, m, std::regex(R"(JobState=(\w+))")) ? m[1].str() : "unknown: " + o.out + o.err;
}

int64_t ulps(float a, float b) {
  auto key = [](float f) {
    int32_t i;
    std::memcpy(&i, &f, sizeof i);
    return i < 0 ? int64_t{INT32_MIN} - i : int64_t{i};
  };
  return std::llabs(key(a) - key(b));
}

bool same_pixels(const pt::Image& a, const pt::Image& b) {
  return a.width == b.width && a.height == b.height && a.channels == b.channels &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

// A merged sample split against the one-machine image: means within one float ulp, variances
// within merge.h's bound plus one ulp.
void check_within_bound(const pt::Image& merged, const pt::Image& single, double n) {
  REQUIRE(merged.channels == single.channels);
  REQUIRE(merged.channels.size() == 6);
  int64_t worst_mean = 0;
  double worst_variance = 0;
  for (int y = 0; y < single.height; ++y) {
    for (int x = 0; x < single.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        worst_mean = std::max(worst_mean, ulps(merged.at(x, y, c), single.at(x, y, c)));
        float va = merged.at(x, y, 3 + c), vb = single.at(x, y, 3 + c);
        float ulp = std::nextafter(std::max(va, vb), INFINITY) - std::max(va, vb);
        double allowed = pt::variance_merge_bound(vb, single.at(x, y, c), n) + ulp;
        worst_variance = std::max(worst_variance, std::abs(double(va) - double(vb)) / allowed);
      }
    }
  }
  CHECK(worst_mean <= 1);
  CHECK(worst_variance <= 1.0);
}

}  // namespace

TEST_CASE("Slurm: a frame split by regions and by samples (N = 4) merges into the one-machine image; a part "
          "stopped by SIGTERM resumes exactly") {
  TempDir dir("pt-farm");
  fs::permissions(dir.path, fs::perms::others_exec | fs::perms::group_exec, fs::perm_options::add);  // munged reaches in
  OneNodeSlurm cluster(dir.path / "slurm");
  const std::vector<std::string> settings = {"--res", "64x48", "--spp", "16"};

  // Both splits in flight at once; meanwhile the one-machine reference renders here.
  std::vector<std::string> regions_args = {kCornell, "4", "-o", (dir.path / "regions.exr").string(), "--split", "regions"};
  std::vector<std::string> samples_args = {kCornell, "4", "-o", (dir.path / "samples.exr").string(), "--split", "samples"};
  regions_args.insert(regions_args.end(), settings.begin(), settings.end());
  samples_args.insert(samples_args.end(), settings.begin(), settings.end());
  Submission regions = submit(regions_args, dir.path), samples = submit(samples_args, dir.path);
  CHECK(regions.image == (dir.path / "regions.exr").string());
  fs::path single = dir.path / "single.exr";
  std::vector<std::string> local = {"render", kCornell, "-q", "-o", single.string()};
  local.insert(local.end(), settings.begin(), settings.end());
  REQUIRE(run_pt(local, dir).code == 0);
  wait_for({regions.parts_job, regions.merge_job, samples.parts_job, samples.merge_job}, dir.path, 300);
  CHECK(job_state(regions.merge_job, dir.path) == "COMPLETED");
  CHECK(job_state(samples.merge_job, dir.path) == "COMPLETED");
  CAPTURE(read_file(dir.path / "regions.exr.parts" / "merge.log"));
  CAPTURE(read_file(dir.path / "regions.exr.parts" / "part0.log"));
  pt::Image reference = pt::read_image(single.string());
  pt::Image by_regions = pt::read_image(regions.image), by_samples = pt::read_image(samples.image);
  CHECK(same_pixels(by_regions, reference));
  check_within_bound(by_samples, reference, 16);
  CHECK(by_regions.metadata["pt:merged"] == "4 parts split by regions");
  CHECK(by_samples.metadata["pt:merged"] == "4 parts split by samples");

  // Pre-emption: part 0 gets SIGTERM mid-render, writes what it has and fails (exit 143); the merge
  // is cancelled, not left waiting. pt-slurm --resume reruns the parts, each continuing its file.
  const std::vector<std::string> long_settings = {"--res", "48x48", "--spp", "2000"};
  std::vector<std::string> args = {kCornell, "2", "-o", (dir.path / "resumed.exr").string()};
  args.insert(args.end(), long_settings.begin(), long_settings.end());
  Submission first = submit(args, dir.path);
  fs::path parts = dir.path / "resumed.exr.parts";
  wait_for_text(parts / "part0.log", "pass 1/", 120);
  Outcome cancel = run("/usr/bin/env", {"scancel", "--batch", "--signal=TERM", first.parts_job + "_0"}, dir.path, 30);
  CAPTURE(cancel.err);
  REQUIRE(cancel.code == 0);
  // Meanwhile the uninterrupted reference.
  fs::path whole = dir.path / "whole.exr";
  std::vector<std::string> reference_args = {"render", kCornell, "-q", "-o", whole.string()};
  reference_args.insert(reference_args.end(), long_settings.begin(), long_settings.end());
  REQUIRE(run_pt(reference_args, dir, 300).code == 0);
  wait_for({first.parts_job, first.merge_job}, dir.path, 300);
  std::string log0 = read_file(parts / "part0.log");
  CAPTURE(log0);
  CHECK(log0.find("interrupted (SIGTERM): wrote " + (parts / "part0.exr").string()) != std::string::npos);
  CHECK(job_state(first.parts_job + "_0", dir.path) == "FAILED");
  CHECK(job_state(first.merge_job, dir.path) != "COMPLETED");
  CHECK_FALSE(fs::exists(dir.path / "resumed.exr"));
  pt::Image stopped = pt::read_image((parts / "part0.exr").string());
  long held = std::stol(stopped.metadata["pt:spp"]);
  CHECK(held >= 1);
  CHECK(held < 2000);

  args.insert(args.begin(), {"--resume", "--wait"});
  Submission again = submit(args, dir.path);
  CHECK(job_state(again.merge_job, dir.path) == "COMPLETED");
  CHECK(read_file(parts / "part0.log").find("resuming part 0/2 from " + (parts / "part0.exr").string() + ", which holds " +
                                            std::to_string(held)) != std::string::npos);
  CHECK(read_file(parts / "part1.log").find("nothing to do") != std::string::npos);
  CHECK(same_pixels(pt::read_image((dir.path / "resumed.exr").string()), pt::read_image(whole.string())));
}

TEST_CASE("a part or a merge written to a full disk: one line, exit 2, nothing left behind") {
  if (::geteuid() != 0) FAIL("the farm test must run as root (it mounts a small tmpfs to fill)");
  TempDir dir("pt-farm");
  fs::path full = dir.path / "full";
  fs::create_directories(full);
  REQUIRE_MESSAGE(::mount("tmpfs", full.c_str(), "tmpfs", 0, "size=64k") == 0,
                  "cannot mount a tmpfs (" << std::strerror(errno) << "): the farm test needs root");
  struct Unmount {
    fs::path p;
    ~Unmount() { ::umount2(p.c_str(), MNT_DETACH); }
  } unmount{full};
  // Parts of 96x64 (about 400 KB each) cannot fit in 64 KB.
  fs::path p0 = dir.path / "p0.exr", p1 = dir.path / "p1.exr";
  std::vector<std::string> base = {"render", kCornell, "--res", "96x64", "--spp", "2", "-q"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  std::vector<Outcome> done = run_pt_all({with({"--part", "0/2", "-o", p0.string()}), with({"--part", "1/2", "-o", p1.string()}),
                                          with({"--part", "0/2", "-o", (full / "p0.exr").string()})},
                                         dir);
  REQUIRE(done[0].code == 0);
  REQUIRE(done[1].code == 0);
  for (const Outcome& o : {done[2], run_pt({"merge", p0.string(), p1.string(), "-o", (full / "m.exr").string()}, dir)}) {
    CAPTURE(o.err);
    CHECK(o.exited);
    CHECK(o.code == 2);
    REQUIRE(o.err_lines.size() == 1);
    CHECK(o.err_lines[0].rfind("pt: error: " + full.string(), 0) == 0);
    CHECK(listing(full).empty());
  }
}
