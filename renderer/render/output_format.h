// The image files `pt render` and `pt merge` write, chosen by the output's extension (any case):
//   .exr          OpenEXR, linear float radiance R, G, B and the AOV channels (--aov, aov.h)
//   .hdr          Radiance RGBE, linear radiance R, G, B
//   .png          8-bit sRGB, after --exposure and --tonemap (core/image/tonemap.h)
//   .jpg, .jpeg   the same as JPEG (lossy)
// Anything else is refused before rendering: one line naming the file and these extensions.
#pragma once
#include <string>

namespace pt {

enum class OutputFormat { kExr, kHdr, kPng, kJpeg };

// Throws pt::Error naming `path` when its extension is none of the above.
OutputFormat output_format(const std::string& path);
// 8-bit: exposure and tone mapping apply (PNG, JPEG); EXR and HDR hold linear radiance.
inline bool is_display_referred(OutputFormat f) { return f == OutputFormat::kPng || f == OutputFormat::kJpeg; }
const char* output_extensions();  // ".exr, .hdr, .png, .jpg or .jpeg", for help and messages

}  // namespace pt
