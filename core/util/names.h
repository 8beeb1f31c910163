// One name table per enum, converting both ways: a name from the command line or a scene file to
// the value (an error lists the choices), and a value back to its name for output and metadata.
#pragma once
#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/util/error.h"

namespace pt {

template <class E, size_t N>
struct NameTable {
  const char* what;  // what the names are of, for the error message: "strategy"
  std::array<std::pair<E, const char*>, N> entries;

  const char* name(E value) const {
    for (const auto& [v, n] : entries) {
      if (v == value) return n;
    }
    return "?";
  }
  bool contains(std::string_view name) const {
    for (const auto& entry : entries) {
      if (name == entry.second) return true;
    }
    return false;
  }
  E parse(std::string_view name) const {
    for (const auto& [v, n] : entries) {
      if (name == n) return v;
    }
    throw Error("unknown " + std::string(what) + " " + quote(name) + " (" + list() + ")");
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& entry : entries) out.emplace_back(entry.second);
    return out;
  }
  std::string list() const {  // "a, b, c"
    std::string out;
    for (const auto& entry : entries) out += (out.empty() ? "" : ", ") + std::string(entry.second);
    return out;
  }
};

}  // namespace pt
