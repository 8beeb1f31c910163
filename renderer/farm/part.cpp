#include "renderer/farm/part.h"

#include <numeric>
#include <regex>

#include "core/util/error.h"

namespace pt {

Part parse_part(const std::string& text, SplitKind split, const char* option) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d{1,7})/(\d{1,7}))"))) {
    throw Error(std::string(option) + " '" + text + "': expected K/N, part K (from 0) of N, e.g. 0/4");
  }
  Part part;
  part.split = split;
  part.index = std::stoi(m[1]);
  part.count = std::stoi(m[2]);
  if (part.count < 1) throw Error(std::string(option) + " '" + text + "': N must be at least 1");
  if (part.index >= part.count) {
    throw Error(std::string(option) + " '" + text + "': K must be below N (parts are numbered 0 to N-1)");
  }
  return part;
}

SampleRange part_samples(const std::optional<Part>& part, int spp) {
  if (!part || part->split != SplitKind::kSamples) return {0, spp};
  auto at = [&](int k) { return static_cast<int>(static_cast<int64_t>(spp) * k / part->count); };
  return {at(part->index), at(part->index + 1)};
}

PartRegion::PartRegion(const std::optional<Part>& part, int width, int height) {
  if (!part || part->split != SplitKind::kRegions) return;
  index_ = part->index;
  count_ = part->count;
  tiles_x_ = (width + kTile - 1) / kTile;
  tiles_ = static_cast<int64_t>(tiles_x_) * ((height + kTile - 1) / kTile);
  scatter_ = std::max<int64_t>(1, static_cast<int64_t>(0.6180339887498949 * static_cast<double>(tiles_)));
  while (std::gcd(scatter_, tiles_) != 1) ++scatter_;
}

std::string PartRegion::describe() const {
  if (count_ <= 1) return "all pixels";
  return std::to_string(kTile) + "x" + std::to_string(kTile) + " tiles t (raster order, " + std::to_string(tiles_x_) +
         " per row) with (t*" + std::to_string(scatter_) + " mod " + std::to_string(tiles_) + ") mod " +
         std::to_string(count_) + " = " + std::to_string(index_);
}

void check_part(const Part& part, int width, int height, int spp, const char* option) {
  if (part.split == SplitKind::kRegions) {
    int tiles = PartRegion(part, width, height).tiles();
    if (part.count > tiles) {
      throw Error(std::string(option) + " '" + part.name() + "': a " + std::to_string(width) + "x" +
                  std::to_string(height) + " image has " + std::to_string(tiles) + " tiles of " +
                  std::to_string(PartRegion::kTile) + "x" + std::to_string(PartRegion::kTile) +
                  ", so at most that many region parts");
    }
  } else if (part.count > spp) {
    throw Error(std::string(option) + " '" + part.name() + "': " + std::to_string(spp) +
                " samples per pixel split in at most " + std::to_string(spp) + " sample parts");
  }
}

}  // namespace pt
