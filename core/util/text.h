// Small text helpers the model loaders share: splitting a line into blank-separated tokens, and a
// short list of names for a warning.
#pragma once
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/error.h"

namespace pt {

// The tokens of `line`, separated by spaces and tabs only (as OBJ, MTL and PLY text is: any other
// byte, a CR or a NUL included, is part of a token).
inline std::vector<std::string> split_blanks(std::string_view line) {
  std::vector<std::string> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) tokens.emplace_back(line.substr(start, i - start));
  }
  return tokens;
}

// At most 8 items, each cut (error.h), "and N more": a file with a million different unknown
// statements gives a short warning, not a million-name line.
inline std::string join_names(const std::set<std::string>& items) {
  constexpr size_t kShown = 8;
  std::string out;
  size_t shown = 0;
  for (const auto& s : items) {
    if (shown++ == kShown) break;
    out += (out.empty() ? "" : ", ") + cut(s);
  }
  if (items.size() > kShown) out += " and " + std::to_string(items.size() - kShown) + " more";
  return out;
}

}  // namespace pt
