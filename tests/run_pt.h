// Running the real `pt` binary (or any program, such as renderer/pt-slurm) from a test: start it
// with stdout and stderr to files, wait with a time limit (a hang fails the test), and read what
// it said and how it ended; several short runs at once with run_pt_all.
#pragma once
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
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
};

// Starts `program args...` with stdout to `out_path` and stderr to `err_path`; returns its pid.
inline pid_t start_program(const std::string& program, const std::vector<std::string>& args,
                           const std::filesystem::path& err_path, const std::filesystem::path& out_path = "/dev/null") {
  pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (err < 0 || out < 0) ::_exit(127);
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

inline pid_t start_pt(const std::vector<std::string>& args, const std::filesystem::path& err_path) {
  return start_program(PT_BINARY, args, err_path);
}

// Waits for the child; kills it (and reports the kill) if it outlives `timeout_s`.
inline Outcome finish(pid_t pid, const std::filesystem::path& err_path, double timeout_s = 60,
                      const std::filesystem::path& out_path = {}) {
  Outcome o;
  int status = 0;
  auto start = std::chrono::steady_clock::now();
  while (true) {
    pid_t r = ::waitpid(pid, &status, WNOHANG);
    REQUIRE(r >= 0);
    if (r == pid) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_s) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      FAIL("the program did not finish within " << timeout_s << " s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
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
