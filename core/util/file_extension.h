// What a file's name says it holds: its extension, compared without regard to case.
#pragma once
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace pt {

// The extension of path, lower case, with its dot ("" if none).
inline std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace pt
