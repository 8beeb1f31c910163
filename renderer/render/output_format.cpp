#include "renderer/render/output_format.h"

#include "core/util/error.h"
#include "core/util/file_extension.h"

namespace pt {

OutputFormat output_format(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr") return OutputFormat::kExr;
  if (ext == ".hdr") return OutputFormat::kHdr;
  if (ext == ".png") return OutputFormat::kPng;
  if (ext == ".jpg" || ext == ".jpeg") return OutputFormat::kJpeg;
  std::string what = ext.empty() ? "no extension" : "unsupported output format '" + ext + "'";
  throw Error(path, what + " (pt writes " + output_extensions() + ")");
}

const char* output_extensions() { return ".exr, .hdr, .png, .jpg or .jpeg"; }

}  // namespace pt
