#include "renderer/farm/part_file.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <regex>

#include "core/image/exr_file.h"
#include "core/scene/render_settings.h"
#include "core/util/error.h"

namespace pt {
namespace {

constexpr int kColour = 3;
// Channel order in the part image: R G B samples nonfinite, then per colour the four words.
constexpr int kSamples = 3, kNonfinite = 4, kWords = 5;
const char* const kWordLayers[4] = {"sum_hi", "sum_lo", "sumsq_hi", "sumsq_lo"};
const char* const kColourNames[kColour] = {"R", "G", "B"};
constexpr float kMaxExactCount = 16777216.0f;  // 2^24: every count up to it is exact in a float

std::vector<std::string> part_channels() {
  std::vector<std::string> names = {"R", "G", "B", "samples", "nonfinite"};
  for (const char* layer : kWordLayers) {
    for (const char* c : kColourNames) names.push_back(std::string(layer) + "." + c);
  }
  return names;
}

float word_as_float(uint32_t w) { return std::bit_cast<float>(w); }
uint32_t float_as_word(float f) { return std::bit_cast<uint32_t>(f); }

const std::string& key(const Image& image, const std::string& path, const std::string& name) {
  auto it = image.metadata.find(name);
  if (it == image.metadata.end()) throw Error(path, "not a complete pt part file: no " + name + " metadata");
  return it->second;
}

int to_int(const std::string& path, const std::string& name, const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"(\d{1,9})"))) throw Error(path, name + " '" + text + "' is not a count");
  return std::stoi(text);
}

std::string pixel_name(int x, int y) { return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

}  // namespace

PartLayout::PartLayout(const std::optional<Part>& part, int frame_width, int frame_height)
    : frame_w_(frame_width), frame_h_(frame_height), image_w_(frame_width), image_h_(frame_height) {
  if (!part || part->split != SplitKind::kRegions) return;
  PartRegion region(part, frame_width, frame_height);
  for (int t = 0; t < region.tiles(); ++t) {
    if (region.contains_tile(t)) tiles_.push_back(t);
  }
  packed_ = true;
  tiles_x_ = region.tiles_x();
  columns_ = std::max<size_t>(1, std::min<size_t>(tiles_.size(), static_cast<size_t>(tiles_x_)));
  image_w_ = static_cast<int>(columns_) * PartRegion::kTile;
  image_h_ = static_cast<int>((tiles_.size() + columns_ - 1) / columns_) * PartRegion::kTile;
}

Image part_image(const Film& film, const Part& part, std::map<std::string, std::string> metadata) {
  std::vector<std::string> names = part_channels();
  PartLayout layout(part, film.width(), film.height());
  Image image(layout.image_width(), layout.image_height(), names);
  image.uint32_bits.assign(names.size(), false);
  for (size_t c = kWords; c < names.size(); ++c) image.uint32_bits[c] = true;
  layout.for_each([&](int x, int y, int ix, int iy) {
    const Film::Pixel& p = film.pixel(x, y);
    if (static_cast<float>(p.count) > kMaxExactCount || static_cast<float>(p.nonfinite) > kMaxExactCount) {
      throw Error("a part holds at most 2^24 samples per pixel");
    }
    Spectrum mean = film.mean(x, y);
    // The viewable mean only; a double mean beyond float range is shown as the largest float.
    for (int c = 0; c < kColour; ++c) image.at(ix, iy, c) = std::min(mean[c], std::numeric_limits<float>::max());
    image.at(ix, iy, kSamples) = static_cast<float>(p.count);
    image.at(ix, iy, kNonfinite) = static_cast<float>(p.nonfinite);
    for (int c = 0; c < kColour; ++c) {
      uint64_t sum = std::bit_cast<uint64_t>(p.sum[c]), sum_sq = std::bit_cast<uint64_t>(p.sum_sq[c]);
      image.at(ix, iy, kWords + 0 * kColour + c) = word_as_float(static_cast<uint32_t>(sum >> 32));
      image.at(ix, iy, kWords + 1 * kColour + c) = word_as_float(static_cast<uint32_t>(sum));
      image.at(ix, iy, kWords + 2 * kColour + c) = word_as_float(static_cast<uint32_t>(sum_sq >> 32));
      image.at(ix, iy, kWords + 3 * kColour + c) = word_as_float(static_cast<uint32_t>(sum_sq));
    }
  });
  image.metadata = std::move(metadata);
  return image;
}

void write_part(const std::string& path, const Film& film, const Part& part,
                const std::map<std::string, std::string>& metadata) {
  // OpenEXR directly, uncompressed: a part never loads OpenImageIO (core/image/exr_file.h), and the
  // sums' low words are noise that no compressor shrinks.
  write_exr(path, part_image(film, part, metadata));
}

namespace {

// Everything a part's header says, checked: the keys, the frame, the layout, every channel of its
// type. `at` receives each of part_channels()'s index in the image.
PartFile parse_header(const Image& image, const std::string& path, std::vector<int>* at = nullptr) {
  auto format = image.metadata.find("pt:part_format");
  if (format == image.metadata.end()) {
    throw Error(path, "not a pt part file (no pt:part_format metadata; parts come from pt render --part K/N)");
  }
  if (format->second != kPartFormat) {
    throw Error(path, "part format '" + format->second + "', this pt reads format " + kPartFormat);
  }
  PartFile part;
  part.path = path;
  part.metadata = image.metadata;
  try {
    SplitKind split = kSplitNames.parse(key(image, path, "pt:split"));
    part.part = parse_part(key(image, path, "pt:part"), split, "pt:part");
  } catch (const Error& e) {
    if (std::string(e.what()).rfind(path, 0) == 0) throw;
    throw Error(path, e.what());
  }
  part.frame_spp = to_int(path, "pt:frame_spp", key(image, path, "pt:frame_spp"));
  if (part.frame_spp < 1) throw Error(path, "pt:frame_spp must be at least 1");
  part.samples = part_samples(part.part, part.frame_spp);
  if (key(image, path, "pt:samples") != part.samples.name()) {
    throw Error(path, "pt:samples '" + key(image, path, "pt:samples") + "' is not part " + part.part.name() +
                          "'s range " + part.samples.name() + " of " + std::to_string(part.frame_spp) + " spp");
  }
  std::smatch m;
  const std::string& frame = key(image, path, "pt:frame");
  if (!std::regex_match(frame, m, std::regex(R"((\d{1,5})x(\d{1,5}))")) ||
      !RenderSettings::valid_resolution(std::stol(m[1]), std::stol(m[2]))) {
    throw Error(path, "pt:frame '" + frame + "' is not a frame size pt renders");
  }
  part.width = std::stoi(m[1]);
  part.height = std::stoi(m[2]);
  PartLayout layout(part.part, part.width, part.height);
  if (key(image, path, "pt:layout") != layout.name() || image.width != layout.image_width() ||
      image.height != layout.image_height()) {
    throw Error(path, "a " + std::to_string(image.width) + "x" + std::to_string(image.height) + " '" +
                          key(image, path, "pt:layout") + "' image is not how part " + part.part.name() + " of a " +
                          frame + " frame is laid out");
  }
  for (const std::string& k : kPartIdentityKeys) key(image, path, k);
  std::vector<std::string> names = part_channels();
  std::vector<int> found(names.size(), -1);
  for (size_t i = 0; i < names.size(); ++i) {
    for (size_t c = 0; c < image.channels.size(); ++c) {
      if (image.channels[c] == names[i]) found[i] = static_cast<int>(c);
    }
    if (found[i] < 0) throw Error(path, "not a complete pt part file: no channel " + names[i]);
    if (image.is_uint32(found[i]) != (static_cast<int>(i) >= kWords)) {
      throw Error(path, "channel " + names[i] + " has the wrong type for a pt part");
    }
  }
  if (at) *at = found;
  return part;
}

}  // namespace

PartFile read_part_header(const std::string& path) { return parse_header(read_exr_header(path), path); }

PartFile read_part(const std::string& path, Film* add_to) {
  Image image = read_exr(path);
  std::vector<int> at;
  PartFile part = parse_header(image, path, &at);
  const std::string frame = std::to_string(part.width) + "x" + std::to_string(part.height);
  PartLayout layout(part.part, part.width, part.height);

  Film* film = add_to;
  if (!film) {
    part.film = Film(part.width, part.height);
    film = &part.film;
  } else if (film->width() != part.width || film->height() != part.height) {
    throw Error(path, "is a part of a " + frame + " frame, not " + std::to_string(film->width()) + "x" +
                          std::to_string(film->height()));
  }
  const uint32_t range = static_cast<uint32_t>(part.samples.size());
  uint32_t lo = UINT32_MAX, hi = 0;
  layout.for_each([&](int x, int y, int ix, int iy) {
    Film::Pixel p;
    float count = image.at(ix, iy, at[kSamples]), nonfinite = image.at(ix, iy, at[kNonfinite]);
    auto whole = [](float v) { return v >= 0 && v <= kMaxExactCount && v == std::floor(v); };
    if (!whole(count) || !whole(nonfinite)) throw Error(path, pixel_name(x, y) + " has a sample count that is not a whole number");
    p.count = static_cast<uint32_t>(count);
    p.nonfinite = static_cast<uint32_t>(nonfinite);
    if (p.count + p.nonfinite > range) {
      throw Error(path, pixel_name(x, y) + " holds more samples than part " + part.part.name() + " takes");
    }
    lo = std::min(lo, p.count + p.nonfinite);
    hi = std::max(hi, p.count + p.nonfinite);
    for (int c = 0; c < kColour; ++c) {
      auto word = [&](int layer) {
        return static_cast<uint64_t>(float_as_word(image.at(ix, iy, at[kWords + layer * kColour + c])));
      };
      p.sum[c] = std::bit_cast<double>(word(0) << 32 | word(1));
      p.sum_sq[c] = std::bit_cast<double>(word(2) << 32 | word(3));
      if (!std::isfinite(p.sum[c]) || !std::isfinite(p.sum_sq[c]) || p.sum_sq[c] < 0 ||
          (p.count == 0 && (p.sum[c] != 0 || p.sum_sq[c] != 0))) {
        throw Error(path, pixel_name(x, y) + " has corrupt sums");
      }
    }
    Film::Pixel& into = film->pixel(x, y);
    for (int c = 0; c < kColour; ++c) {
      into.sum[c] += p.sum[c];  // + 0.0 for a fresh film: exact
      into.sum_sq[c] += p.sum_sq[c];
    }
    into.count += p.count;
    into.nonfinite += p.nonfinite;
  });
  part.taken_lo = lo == UINT32_MAX ? 0 : lo;
  part.taken_hi = hi;
  return part;
}

std::string identity_difference(const std::map<std::string, std::string>& metadata,
                                const std::map<std::string, std::string>& reference) {
  for (const std::string& k : kPartIdentityKeys) {
    auto a = metadata.find(k), b = reference.find(k);
    std::string va = a == metadata.end() ? "(none)" : a->second, vb = b == reference.end() ? "(none)" : b->second;
    if (va != vb) return k + " is '" + va + "', not '" + vb + "'";
  }
  return "";
}

}  // namespace pt
