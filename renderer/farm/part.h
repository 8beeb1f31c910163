// A part of a split render (`pt render --part K/N --split regions|samples`): which pixels, or which
// sample indices, part K of N renders. The parts merge (renderer/farm/merge.h) into the image the whole
// render makes on one machine:
//   regions  each pixel is rendered whole by exactly one part, so the merge is bit-identical;
//   samples  every part renders every pixel, part K taking sample indices [K*spp/N, (K+1)*spp/N)
//            of the same deterministic sequence (the Sampler is keyed by seed, pixel and index),
//            so the merge differs from the one-machine image only by the order its double sums
//            were added in (the bound is in renderer/farm/merge.h).
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "core/util/names.h"

namespace pt {

enum class SplitKind : uint8_t { kRegions, kSamples };
inline constexpr NameTable<SplitKind, 2> kSplitNames{
    "split", {{{SplitKind::kRegions, "regions"}, {SplitKind::kSamples, "samples"}}}};

struct Part {
  SplitKind split = SplitKind::kRegions;
  int index = 0;  // K, 0 <= K < N
  int count = 1;  // N
  std::string name() const { return std::to_string(index) + "/" + std::to_string(count); }
};

// "K/N" (0 <= K < N) -> the part. Throws pt::Error naming `option` on N = 0, K >= N, or a
// malformed value.
Part parse_part(const std::string& text, SplitKind split, const char* option = "--part");

// Sample indices [begin, end) every pixel of a part takes.
struct SampleRange {
  int begin = 0, end = 0;
  int size() const { return end - begin; }
  std::string name() const { return std::to_string(begin) + "-" + std::to_string(end); }
};
SampleRange part_samples(const std::optional<Part>& part, int spp);

// The pixels of a part. Regions are 16x16 tiles (numbered in raster order, t = 0 .. T-1) dealt out
// by a golden-ratio scatter, tile t going to part ((t * P) mod T) mod N with P the first integer
// from 0.618 T up that is coprime to T: a permutation, so each part gets floor(T/N) or ceil(T/N)
// tiles, spread over the whole frame (a part's cost is then close to the frame's average, which a
// band of rows would not be). A sample split's parts hold every pixel.
class PartRegion {
 public:
  static constexpr int kTile = 16;
  PartRegion() = default;  // every pixel
  PartRegion(const std::optional<Part>& part, int width, int height);
  bool contains(int x, int y) const { return contains_tile(static_cast<int64_t>(y / kTile) * tiles_x_ + x / kTile); }
  int tiles() const { return static_cast<int>(tiles_); }
  int tiles_x() const { return tiles_x_; }
  // Whether tile t (raster order, 16x16) is the part's.
  bool contains_tile(int64_t t) const { return count_ <= 1 || static_cast<int>((t * scatter_ % tiles_) % count_) == index_; }
  // How the part's pixels are chosen, exactly, for the file's pt:region key.
  std::string describe() const;

 private:
  int index_ = 0, count_ = 1;
  int tiles_x_ = 1;
  int64_t tiles_ = 1, scatter_ = 1;
};

// Throws pt::Error (naming `option`) when some part of this split would be empty: more region
// parts than 16x16 tiles, or more sample parts than samples per pixel.
void check_part(const Part& part, int width, int height, int spp, const char* option = "--part");

}  // namespace pt
