#include "renderer/farm/merge.h"

#include <algorithm>

#include "core/util/error.h"
#include "renderer/farm/part_file.h"

namespace pt {
namespace {

// The part keys a merged image drops: it is a whole frame again.
const char* const kPartOnlyKeys[] = {"pt:part_format", "pt:part", "pt:samples", "pt:region",
                                     "pt:frame_spp",   "pt:frame", "pt:layout"};

}  // namespace

MergedParts merge_parts(const std::vector<std::string>& paths) {
  if (paths.empty()) throw Error("pt merge: no parts given");
  // Headers first: every check that needs no pixels is made before any pixel is read, and the
  // parts are then added in part order, so the result does not depend on the order given.
  std::vector<PartFile> headers;
  for (const std::string& path : paths) headers.push_back(read_part_header(path));
  const PartFile& first = headers.front();
  std::vector<const PartFile*> by_index(first.part.count, nullptr);
  for (const PartFile& h : headers) {
    std::string diff = identity_difference(h.metadata, first.metadata);
    if (!diff.empty()) throw Error(h.path, diff + " as in " + first.path + " (parts of different renders)");
    if (h.part.count != first.part.count) {
      throw Error(h.path, "is part " + h.part.name() + ", but " + first.path + " is part " + first.part.name() +
                              " (splits into different numbers of parts)");
    }
    if (h.width != first.width || h.height != first.height) throw Error(h.path, "differs in size from " + first.path);
    const PartFile*& slot = by_index[h.part.index];
    if (slot) throw Error(h.path, "duplicates part " + h.part.name() + " (also in " + slot->path + ")");
    slot = &h;
  }
  std::string missing;
  for (int k = 0; k < first.part.count; ++k) {
    if (!by_index[k]) missing += (missing.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(first.part.count);
  }
  if (!missing.empty()) {
    throw Error("missing part" + std::string(missing.find(',') == std::string::npos ? " " : "s ") + missing + " (given " +
                std::to_string(paths.size()) + " of " + std::to_string(first.part.count) + ", starting with " +
                first.path + ")");
  }

  MergedParts merged;
  merged.split = first.part.split;
  merged.parts = first.part.count;
  merged.film = Film(first.width, first.height);
  for (const PartFile* h : by_index) {
    // Each part's pixels go straight into the frame's film: the merge holds one frame, not N.
    PartFile part = read_part(h->path, &merged.film);
    // The header was read from the same file a moment ago; a file replaced in between is refused.
    if (part.metadata != h->metadata) throw Error(h->path, "changed while it was being merged");
    merged.frame_spp = part.frame_spp;
    uint32_t lo = part.taken_lo, hi = part.taken_hi;
    if (lo < static_cast<uint32_t>(part.samples.size())) {
      merged.short_parts.push_back(h->path + ": part " + part.part.name() + " holds " + std::to_string(lo) +
                                   (hi != lo ? " to " + std::to_string(hi) : "") + " of its " +
                                   std::to_string(part.samples.size()) + " samples per pixel");
    }
  }
  merged.metadata = first.metadata;
  for (const char* k : kPartOnlyKeys) merged.metadata.erase(k);
  merged.metadata["pt:spp"] = std::to_string(merged.film.min_count());
  merged.metadata["pt:spp_max"] = std::to_string(merged.film.max_count());
  merged.metadata["pt:merged"] = std::to_string(merged.parts) + " parts split by " + kSplitNames.name(merged.split);
  return merged;
}

}  // namespace pt
