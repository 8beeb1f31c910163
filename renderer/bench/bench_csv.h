// Small helpers for the benchmarks' CSV files: comma lists on the command line, and files written
// to a temporary name and renamed (DESIGN.md: a failure never leaves a half-written output).
#pragma once
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pt {

inline std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size()) {
    size_t comma = s.find(',', start);
    std::string item = s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!item.empty()) out.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// Through OutputFile: every write checked, a temporary renamed into place only when complete.
inline void write_text_file(const std::string& path, const std::string& text) { write_file(path, text); }

}  // namespace pt
