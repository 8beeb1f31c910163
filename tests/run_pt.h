// Runs the real `pt` binary through the shell for the CLI tests that check good runs: exit status,
// stdout and stderr captured in files of a TempDir. (test_cli_bad_input.cpp has its own runner
// with timeouts and signals.)
#pragma once
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <vector>

#include "temp_dir.h"

struct PtRun {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Arguments are passed in single quotes; none of the tests' arguments contains one. `tag` names
// the files that capture the output, so that runs can go in parallel (run_pt_all).
inline PtRun run_pt(const std::vector<std::string>& args, const TempDir& dir, const std::string& tag = "pt") {
  std::string command = std::string("'") + PT_BINARY + "'";
  for (const std::string& a : args) command += " '" + a + "'";
  auto out = dir.path / (tag + "-stdout.txt"), err = dir.path / (tag + "-stderr.txt");
  command += " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
  int status = std::system(command.c_str());
  PtRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Several runs at once: most of a short run is the dynamic loader, which overlaps well.
inline std::vector<PtRun> run_pt_all(const std::vector<std::vector<std::string>>& runs, const TempDir& dir) {
  std::vector<std::future<PtRun>> started;
  for (size_t i = 0; i < runs.size(); ++i) {
    started.push_back(std::async(std::launch::async, [&, i] { return run_pt(runs[i], dir, "run" + std::to_string(i)); }));
  }
  std::vector<PtRun> out;
  for (auto& f : started) out.push_back(f.get());
  return out;
}
