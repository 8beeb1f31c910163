// The one exception type for bad input: it carries the file and line so main can print one line.
#pragma once
#include <stdexcept>
#include <string>

namespace pt {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(const std::string& file, const std::string& message)
      : std::runtime_error(file + ": " + message) {}
  Error(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + message) {}
};

}  // namespace pt
