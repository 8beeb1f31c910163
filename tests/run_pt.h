// Running the real `pt` binary (or any program, such as renderer/farm/pt-slurm) from a test: start it
// with stdout and stderr to files (in a working folder, under a file-size limit), wait with a time
// limit (a hang fails the test), and read what it said, how it ended and its peak memory; several
// short runs at once with run_pt_all, or Batch for the bad-input contract.
#pragma once
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "temp_dir.h"

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Outcome {
  bool exited = false;  // false: killed by a signal (a crash, or our timeout)
  int code = -1;
  int signal = 0;
  std::string err, out;
  std::vector<std::string> err_lines;
  long max_rss_kb = 0;  // peak resident memory of the run
  double seconds = 0;   // from the call to finish() to the exit
};

struct StartOptions {
  std::filesystem::path cwd;   // empty: the test's own
  rlim_t file_size_limit = 0;  // RLIMIT_FSIZE in bytes (`ulimit -f`); 0: none
};

// Starts `program args...` with stdout to `out_path` and stderr to `err_path`; returns its pid.
inline pid_t start_program(const std::string& program, const std::vector<std::string>& args,
                           const std::filesystem::path& err_path, const std::filesystem::path& out_path = "/dev/null",
                           const StartOptions& options = {}) {
  pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (err < 0 || out < 0) ::_exit(127);
    if (!options.cwd.empty() && ::chdir(options.cwd.c_str()) != 0) ::_exit(127);
    if (options.file_size_limit > 0) {
      rlimit limit{options.file_size_limit, options.file_size_limit};
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(127);
    }
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    std::vector<char*> argv;
    std::string binary = program;
    argv.push_back(binary.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

inline pid_t start_pt(const std::vector<std::string>& args, const std::filesystem::path& err_path,
                      const StartOptions& options = {}) {
  return start_program(PT_BINARY, args, err_path, "/dev/null", options);
}

// Waits until the file at `path` holds `text` (a running pt's stderr saying "pass 1/"), at most
// `timeout_s` (a failed requirement beyond).
inline void wait_for_text(const std::filesystem::path& path, const std::string& text, double timeout_s = 30) {
  auto start = std::chrono::steady_clock::now();
  while (read_file(path).find(text) == std::string::npos) {
    REQUIRE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < timeout_s);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// Waits for the child; kills it (a failed check; the outcome says killed) if it outlives `timeout_s`.
inline Outcome finish(pid_t pid, const std::filesystem::path& err_path, double timeout_s = 60,
                      const std::filesystem::path& out_path = {}) {
  Outcome o;
  int status = 0;
  auto start = std::chrono::steady_clock::now();
  while (true) {
    rusage usage{};
    pid_t r = ::wait4(pid, &status, WNOHANG, &usage);
    REQUIRE(r >= 0);
    if (r == pid) {
      o.max_rss_kb = usage.ru_maxrss;
      break;
    }
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_s) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      // A check, not FAIL: a batch must still reap its other runs rather than leave them running.
      FAIL_CHECK("the program did not finish within " << timeout_s << " s");
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.exited = WIFEXITED(status);
  o.code = o.exited ? WEXITSTATUS(status) : -1;
  o.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  o.err = read_file(err_path);
  if (!out_path.empty()) o.out = read_file(out_path);
  std::istringstream lines(o.err);
  for (std::string line; std::getline(lines, line);) o.err_lines.push_back(line);
  return o;
}

// One run of pt, stdout and stderr captured.
inline Outcome run_pt(const std::vector<std::string>& args, const TempDir& dir, double timeout_s = 60) {
  std::filesystem::path err = dir.path / "stderr.txt", out = dir.path / "stdout.txt";
  return finish(start_program(PT_BINARY, args, err, out), err, timeout_s, out);
}
// The same in a working folder or under a file-size limit.
inline Outcome run_pt(const std::vector<std::string>& args, const TempDir& dir, const StartOptions& options) {
  std::filesystem::path err = dir.path / "stderr.txt", out = dir.path / "stdout.txt";
  return finish(start_program(PT_BINARY, args, err, out, options), err, 60, out);
}
using PtRun = Outcome;

// Files in `folder` (the output folder of a failed run must stay empty).
inline std::vector<std::string> listing(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(folder)) names.push_back(e.path().filename().string());
  return names;
}

// Runs `pt` with each argument list, up to `in_flight` at a time (most of a short run is the
// dynamic loader, so they overlap well); the outcomes in the order given.
inline std::vector<Outcome> run_pt_all(const std::vector<std::vector<std::string>>& commands, const TempDir& dir,
                                       size_t in_flight = 6, double timeout_s = 120) {
  std::vector<Outcome> outcomes(commands.size());
  for (size_t first = 0; first < commands.size(); first += in_flight) {
    size_t last = std::min(commands.size(), first + in_flight);
    std::vector<pid_t> pids;
    auto err = [&](size_t i) { return dir.path / ("stderr-all-" + std::to_string(i) + ".txt"); };
    auto out = [&](size_t i) { return dir.path / ("stdout-all-" + std::to_string(i) + ".txt"); };
    for (size_t i = first; i < last; ++i) pids.push_back(start_program(PT_BINARY, commands[i], err(i), out(i)));
    for (size_t i = first; i < last; ++i) outcomes[i] = finish(pids[i - first], err(i), timeout_s, out(i));
  }
  return outcomes;
}

// Bad-input runs of `pt render <args> -o <fresh folder>/out.png`, started a few at a time (most
// of a run is the dynamic loader and waiting on it, so they overlap well), then each checked
// against the contract: exit status 2 (not a signal), one line "pt: error: ..." containing each
// of `expected`, and nothing written to its output folder.
class Batch {
 public:
  explicit Batch(const TempDir& dir) : dir_(dir) {}
  void add(std::vector<std::string> args, std::vector<std::string> expected) {
    Run r;
    r.out_dir = dir_.path / ("out" + std::to_string(runs_.size()));
    r.err_path = dir_.path / ("stderr" + std::to_string(runs_.size()) + ".txt");
    std::filesystem::create_directories(r.out_dir);
    bool has_output = false;
    for (const std::string& a : args) has_output = has_output || a == "-o";
    if (!has_output) {
      args.push_back("-o");
      args.push_back((r.out_dir / "out.png").string());
    }
    args.insert(args.begin(), "render");
    r.args = std::move(args);
    r.expected = std::move(expected);
    runs_.push_back(std::move(r));
  }
  // Runs them, checks each, and returns their outcomes in the order they were added.
  std::vector<Outcome> run() {
    constexpr size_t kInFlight = 6;
    std::vector<Outcome> outcomes(runs_.size());
    for (size_t first = 0; first < runs_.size(); first += kInFlight) {
      size_t last = std::min(runs_.size(), first + kInFlight);
      std::vector<pid_t> pids;
      for (size_t i = first; i < last; ++i) pids.push_back(start_pt(runs_[i].args, runs_[i].err_path));
      for (size_t i = first; i < last; ++i) outcomes[i] = finish(pids[i - first], runs_[i].err_path);
    }
    for (size_t i = 0; i < runs_.size(); ++i) check(runs_[i], outcomes[i]);
    runs_.clear();
    return outcomes;
  }

 private:
  struct Run {
    std::vector<std::string> args, expected;
    std::filesystem::path out_dir, err_path;
  };
  static void check(const Run& r, const Outcome& o) {
    std::string command;
    for (const std::string& a : r.args) command += a + " ";
    CAPTURE(command);
    CAPTURE(o.err);
    CHECK(o.exited);  // not killed by a signal (segfault, abort)
    CHECK(o.code == 2);
    REQUIRE(o.err_lines.size() == 1);
    CHECK(o.err_lines[0].rfind("pt: error: ", 0) == 0);
    for (const std::string& e : r.expected) CHECK(o.err_lines[0].find(e) != std::string::npos);
    CHECK(listing(r.out_dir).empty());
  }
  const TempDir& dir_;
  std::vector<Run> runs_;
};
