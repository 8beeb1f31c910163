// Tone mapping for 8-bit outputs (PNG, JPEG): scene-linear radiance, scaled by 2^exposure, to
// display-linear values in [0, 1], which the writer then encodes with the sRGB transfer curve.
// Applied per channel.
//   clip    min(x, 1): exact up to 1, highlights burn out (the default; what pt always did)
//   aces    Narkowicz's fit of the ACES reference rendering transform (K. Narkowicz, "ACES Filmic
//           Tone Mapping Curve", 2016): y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14),
//           clamped to [0, 1]; his pre-exposed fit, so 1 maps to 0.80 and white is reached at 7.24
//   filmic  Hable's filmic curve from Uncharted 2 (J. Hable, "Filmic Tonemapping Operators",
//           2010): f(x) = (x (A x + C B) + D E) / (x (A x + B) + D F) - E / F with A 0.15, B 0.50,
//           C 0.10, D 0.20, E 0.02, F 0.30; y = f(2 x) / f(11.2), white at 5.6
// EXR and HDR outputs stay linear: neither exposure nor the curve applies to them.
#pragma once
#include "core/image/image.h"
#include "core/util/names.h"

namespace pt {

enum class Tonemap { kClip, kAces, kFilmic };
inline constexpr NameTable<Tonemap, 3> kTonemapNames{
    "tone map", {{{Tonemap::kClip, "clip"}, {Tonemap::kAces, "aces"}, {Tonemap::kFilmic, "filmic"}}}};

// One value, already exposed, to [0, 1]. NaN and negative values give 0.
float tonemap(float linear, Tonemap curve);

// R, G, B (the first three channels) of `image` scaled by 2^exposure and tone mapped, in place; the
// other channels are dropped, as an 8-bit file holds colour only.
void apply_tonemap(Image& image, Tonemap curve, float exposure_stops);

}  // namespace pt
