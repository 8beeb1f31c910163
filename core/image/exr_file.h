// EXR files read and written with OpenEXR itself, exactly: float and UINT channels (an Image's
// uint32_bits) and string metadata. For the rendered images (image.h's write_image sends .exr here)
// and the part files of split renders
// (renderer/farm/part_file.h), which must not load OpenImageIO: a part renders in a process that reads no
// other image, and OpenImageIO's start-up cost would be most of its fixed cost
// (core/image/image_module.h). Other images go through image.h.
#pragma once
#include <string>

#include "core/image/image.h"

namespace pt {

// Encodes in memory and writes through OutputFile (core/util/output_file.h): every write checked, a
// temporary renamed over `path` only when complete, nothing but a regular file replaced; on failure
// the previous file is intact and no temporary is left. Throws pt::Error naming `path`.
// `compression` takes OpenImageIO's names (none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab);
// part files use none: the sums' low words do not compress anyway.
void write_exr(const std::string& path, const Image& image, const std::string& compression = "none");

// The whole file, or only its header (size, channel names, uint32_bits, metadata; no pixels).
// Channels come in the file's order (alphabetical). Throws pt::Error naming the file for a missing
// or non-regular file, anything that is not a complete EXR, or one larger than a frame pt renders.
Image read_exr(const std::string& path);
Image read_exr_header(const std::string& path);

}  // namespace pt
