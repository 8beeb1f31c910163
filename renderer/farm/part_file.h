// A part file: one part of a split render (renderer/farm/part.h) as an EXR that carries, exactly, what
// `pt merge` and `pt render --resume` need. The film sums in double and EXR has no double channel,
// so each double is stored as its two 32-bit halves in UINT channels: reading a part back gives the
// film bit for bit, which is what makes a region merge and a resumed part bit-identical.
//
// Channels:
//   R, G, B                 float   the part's mean radiance (a viewable image; 0 where no sample)
//   samples                 float   finite samples in the sums (an integer, at most 2^24: exact)
//   nonfinite               float   samples dropped as NaN or infinite (taken = samples + nonfinite)
//   sum_hi.R/G/B, sum_lo.R/G/B      uint32  high and low words of the double sum of radiance
//   sumsq_hi.R/G/B, sumsq_lo.R/G/B  uint32  the same for the sum of squared radiance
// Layout (pt:layout):
//   "frame"  the whole frame (a sample split's parts hold every pixel);
//   "tiles"  a region part holds only its own 16x16 tiles, packed in the frame's raster order into
//            rows of min(tiles, tiles per frame row) tiles (slots past the frame's edge stay 0), so
//            the N parts of a frame together weigh one frame, however large N is.
// Metadata (named in image_metadata(), renderer/render/job.cpp): a render's pt:* keys (pt:scene_hash,
// pt:settings, pt:camera, pt:backend, pt:seed ...) and
//   pt:part_format "1", pt:part "K/N", pt:split "regions"|"samples", pt:samples "a-b" (the sample
//   indices of the range; a pixel holds [a, a + taken)), pt:frame_spp (the whole frame's spp),
//   pt:frame "WxH", pt:layout, pt:region (how the part's pixels were chosen).
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "renderer/render/film.h"
#include "renderer/farm/part.h"

namespace pt {

inline constexpr const char* kPartFormat = "1";

// The keys two parts of one render must agree on (and a resumed part with its render).
// The most telling first, so a message names the setting that differs; pt:settings catches the rest.
inline const std::vector<std::string> kPartIdentityKeys = {
    "pt:scene_hash", "pt:seed",   "pt:split",  "pt:frame_spp", "pt:integrator",
    "pt:sampler",    "pt:backend", "pt:camera", "pt:settings"};

struct PartFile {
  std::string path;
  Film film;  // the whole frame (zero outside a region part); empty when read_part added it elsewhere
  Part part;
  SampleRange samples;  // the part's range of sample indices
  int frame_spp = 0;
  int width = 0, height = 0;  // the frame's
  uint32_t taken_lo = 0, taken_hi = 0;  // least and most samples taken over the part's pixels
  std::map<std::string, std::string> metadata;
};

// Where a part's pixels sit in its image: the whole frame, or its tiles packed (see above).
class PartLayout {
 public:
  PartLayout(const std::optional<Part>& part, int frame_width, int frame_height);
  int image_width() const { return image_w_; }
  int image_height() const { return image_h_; }
  std::string name() const { return packed_ ? "tiles" : "frame"; }
  // Calls f(frame x, frame y, image x, image y) for every pixel of the part.
  template <class F>
  void for_each(F&& f) const {
    if (!packed_) {
      for (int y = 0; y < frame_h_; ++y) {
        for (int x = 0; x < frame_w_; ++x) f(x, y, x, y);
      }
      return;
    }
    constexpr int T = PartRegion::kTile;
    for (size_t j = 0; j < tiles_.size(); ++j) {
      int fx0 = tiles_[j] % tiles_x_ * T, fy0 = tiles_[j] / tiles_x_ * T;
      int ix0 = static_cast<int>(j % columns_) * T, iy0 = static_cast<int>(j / columns_) * T;
      for (int dy = 0; dy < T && fy0 + dy < frame_h_; ++dy) {
        for (int dx = 0; dx < T && fx0 + dx < frame_w_; ++dx) f(fx0 + dx, fy0 + dy, ix0 + dx, iy0 + dy);
      }
    }
  }

 private:
  bool packed_ = false;
  int frame_w_, frame_h_, image_w_, image_h_;
  int tiles_x_ = 1;
  size_t columns_ = 1;
  std::vector<int> tiles_;  // the part's tiles, in the frame's raster order
};

// The part's EXR image: the channels above in its layout, with `metadata` (the part keys).
Image part_image(const Film& film, const Part& part, std::map<std::string, std::string> metadata);
// Writes it atomically (write_image: a temporary beside `path`, renamed). Throws pt::Error.
void write_part(const std::string& path, const Film& film, const Part& part,
                const std::map<std::string, std::string>& metadata);

// Reads and checks a part: a pt part EXR with every channel and key above, counts that fit its
// sample range. Throws pt::Error naming the file otherwise (not an image, truncated, an ordinary
// render, another part format). With `add_to` (a frame-sized film) the part's pixels are added to
// it instead of being returned in PartFile::film, which a merge of many parts wants.
PartFile read_part(const std::string& path, Film* add_to = nullptr);
// The same checks on the header alone (no pixels read; PartFile::film stays empty).
PartFile read_part_header(const std::string& path);

// The first identity key on which `metadata` differs from `reference`, as "pt:seed is '2', not
// '1'", or "" when they agree.
std::string identity_difference(const std::map<std::string, std::string>& metadata,
                                const std::map<std::string, std::string>& reference);

}  // namespace pt
