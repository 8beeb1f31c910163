#include "renderer/output_format.h"

#include <algorithm>
#include <filesystem>

#include "core/util/error.h"

namespace pt {

OutputFormat output_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".exr") return OutputFormat::kExr;
  if (ext == ".hdr") return OutputFormat::kHdr;
  if (ext == ".png") return OutputFormat::kPng;
  if (ext == ".jpg" || ext == ".jpeg") return OutputFormat::kJpeg;
  std::string what = ext.empty() ? "no extension" : "unsupported output format '" + ext + "'";
  throw Error(path, what + " (pt writes " + output_extensions() + ")");
}

const char* output_extensions() { return ".exr, .hdr, .png, .jpg or .jpeg"; }

}  // namespace pt
