// `pt bench stability`: where intersection methods fail, as counts per method (see stability.h):
// leaks through shared edges and vertices, self-intersection of rays leaving a surface as the scene
// moves away from the origin, degenerate and non-finite input, grazing rays, sphere precision.
// Prints one table per test (failures/trials per distance from the origin) and writes CSV.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "core/util/error.h"
#include "renderer/bench/bench.h"
#include "renderer/bench/bench_csv.h"
#include "renderer/measure/stability.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

struct StabilityArgs {
  std::string csv = "stability.csv";
  std::string tests = "leaks,self-intersection,degenerate,non-finite,grazing,sphere";
  std::string distances = "1,1e2,1e4,1e6";
  int effort = 1;
  uint64_t seed = 1;
};

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

void print_table(const std::string& test, const std::vector<StabilityRow>& rows, const std::vector<double>& distances) {
  std::printf("\n%s\n", test.c_str());
  bool by_distance = false;
  for (const StabilityRow& r : rows) by_distance = by_distance || r.distance > 0;
  if (!by_distance) {
    std::printf("  %-26s %-16s %9s  %s\n", "variant", "method", "failures", "what happened");
    for (const StabilityRow& r : rows) {
      std::printf("  %-26s %-16s %9s  %s\n", r.variant.c_str(), r.method.c_str(),
                  r.trials ? (std::to_string(r.failures) + "/" + std::to_string(r.trials)).c_str() : "-", r.note.c_str());
    }
    return;
  }
  std::printf("  %-28s %-16s", "variant", "method");
  for (double d : distances) std::printf(" %13s", ("at " + std::to_string(static_cast<long long>(d))).c_str());
  std::printf("\n");
  // Keep the order rows were made in: variant, then method.
  std::vector<std::pair<std::string, std::string>> keys;
  std::set<std::pair<std::string, std::string>> seen;
  std::map<std::pair<std::string, std::string>, std::map<double, const StabilityRow*>> cells;
  for (const StabilityRow& r : rows) {
    auto key = std::make_pair(r.variant, r.method);
    if (seen.insert(key).second) keys.push_back(key);
    cells[key][r.distance] = &r;
  }
  std::stable_sort(keys.begin(), keys.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& key : keys) {
    std::printf("  %-28s %-16s", key.first.c_str(), key.second.c_str());
    for (double d : distances) {
      auto it = cells[key].find(d);
      std::string cell = "";
      if (it != cells[key].end()) {
        const StabilityRow& r = *it->second;
        cell = r.note.rfind("unavailable", 0) == 0 ? "n/a" : std::to_string(r.failures) + "/" + std::to_string(r.trials);
      }
      std::printf(" %13s", cell.c_str());
    }
    std::printf("\n");
  }
}

int run_stability(const StabilityArgs& a) {
  check_output_path(a.csv);  // before the measurements, not after
  StabilityOptions o;
  o.effort = a.effort;
  o.seed = a.seed;
  o.distances.clear();
  for (const std::string& d : split_list(a.distances)) {
    double v = 0;
    try {
      v = std::stod(d);
    } catch (const std::exception&) {
      throw Error("--distances '" + d + "': expected numbers, e.g. 1,1e2,1e4,1e6");
    }
    if (!(v > 0 && v < 1e30)) throw Error("--distances '" + d + "': expected a positive distance");
    o.distances.push_back(v);
  }
  std::set<std::string> tests;
  for (const std::string& t : split_list(a.tests)) {
    static const std::set<std::string> known = {"leaks", "self-intersection", "degenerate", "non-finite", "grazing", "sphere"};
    if (!known.count(t)) throw Error("--tests '" + t + "': leaks, self-intersection, degenerate, non-finite, grazing, sphere");
    tests.insert(t);
  }
  fs::path work = fs::temp_directory_path() / ("pt-stability-" + std::to_string(::getpid()));

  std::vector<std::pair<std::string, std::vector<StabilityRow>>> results;
  // Non-finite first: it forks, which is safe only before any worker thread exists.
  if (tests.count("non-finite")) results.push_back({"non-finite", measure_nonfinite(work.string())});
  if (tests.count("leaks")) results.push_back({"leaks", measure_leaks(o)});
  if (tests.count("self-intersection")) results.push_back({"self-intersection", measure_self_intersection(o)});
  if (tests.count("degenerate")) results.push_back({"degenerate", measure_degenerate(work.string(), o)});
  if (tests.count("grazing")) results.push_back({"grazing", measure_grazing(o)});
  if (tests.count("sphere")) results.push_back({"sphere", measure_spheres(o)});
  std::error_code ec;
  fs::remove_all(work, ec);

  std::ostringstream csv;
  csv << "test,variant,method,distance,trials,failures,note\n";
  for (const auto& [test, rows] : results) {
    print_table(test, rows, o.distances);
    for (const StabilityRow& r : rows) {
      csv << r.test << "," << csv_field(r.variant) << "," << r.method << "," << r.distance << "," << r.trials << ","
          << r.failures << "," << csv_field(r.note) << "\n";
    }
  }
  std::printf("\nfailures/trials; n/a: the backend could not be built. Notes per row in %s\n", a.csv.c_str());
  write_text_file(a.csv, csv.str());
  return 0;
}

}  // namespace

void add_bench_stability(CLI::App& bench, Action& action) {
  auto a = std::make_shared<StabilityArgs>();
  CLI::App* cmd = bench.add_subcommand("stability", "Where intersection methods fail: counts per method, table and CSV");
  cmd->add_option("--csv", a->csv, "CSV output (default: stability.csv)");
  cmd->add_option("--tests", a->tests, "Comma list: leaks,self-intersection,degenerate,non-finite,grazing,sphere");
  cmd->add_option("--distances", a->distances, "Comma list of distances from the origin (default 1,1e2,1e4,1e6)");
  cmd->add_option("--effort", a->effort, "Multiplies every test's ray count")->check(CLI::Range(1, 1000));
  cmd->add_option("--seed", a->seed, "Random seed");
  cmd->callback([&action, a] { action = [a] { return run_stability(*a); }; });
}

}  // namespace pt
