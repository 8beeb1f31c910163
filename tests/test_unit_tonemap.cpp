// The tone curves of 8-bit outputs (core/image/tonemap.h) against the values their authors state:
// Narkowicz's ACES fit maps 1 to about 0.8 and reaches white where its rational equals 1
// (x = (0.56 + sqrt(0.56^2 + 4 * 0.08 * 0.14)) / 0.16); Hable's curve is 0 at 0 and white at W / 2.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "core/image/tonemap.h"

using namespace pt;

TEST_CASE("tone curves: fixed points, white points, monotone, and no NaN out") {
  CHECK(tonemap(0.5f, Tonemap::kClip) == 0.5f);
  CHECK(tonemap(3.0f, Tonemap::kClip) == 1.0f);
  CHECK(tonemap(1.0f, Tonemap::kAces) == doctest::Approx(2.54 / 3.16));
  const double aces_white = (0.56 + std::sqrt(0.56 * 0.56 + 4 * 0.08 * 0.14)) / 0.16;
  CHECK(tonemap(static_cast<float>(aces_white * 0.99), Tonemap::kAces) < 1.0f);
  CHECK(tonemap(static_cast<float>(aces_white * 1.01), Tonemap::kAces) == 1.0f);
  CHECK(tonemap(5.6f, Tonemap::kFilmic) == doctest::Approx(1.0f));
  CHECK(tonemap(5.0f, Tonemap::kFilmic) < 0.99f);
  for (Tonemap t : {Tonemap::kClip, Tonemap::kAces, Tonemap::kFilmic}) {
    CAPTURE(kTonemapNames.name(t));
    CHECK(tonemap(0.0f, t) == 0.0f);
    CHECK(tonemap(-1.0f, t) == 0.0f);
    CHECK(tonemap(std::numeric_limits<float>::quiet_NaN(), t) == 0.0f);
    CHECK(tonemap(std::numeric_limits<float>::infinity(), t) == 1.0f);
    CHECK(tonemap(1e30f, t) == 1.0f);
    float previous = 0.0f;
    for (float x = 0.001f; x < 20.0f; x *= 1.05f) {
      float y = tonemap(x, t);
      CHECK(y >= previous);
      CHECK(y <= 1.0f);
      previous = y;
    }
  }
  // The shoulders: a value above 1 keeps detail under aces and filmic, burns out under clip.
  CHECK(tonemap(2.0f, Tonemap::kAces) < tonemap(4.0f, Tonemap::kAces));
  CHECK(tonemap(2.0f, Tonemap::kFilmic) < tonemap(4.0f, Tonemap::kFilmic));
}

TEST_CASE("apply_tonemap: exposure in stops, colour channels only") {
  Image image(2, 1, {"R", "G", "B", "variance.R"});
  image.at(0, 0, 0) = 0.25f;
  image.at(1, 0, 1) = 0.1f;
  image.at(0, 0, 3) = 9.0f;
  image.metadata.emplace("key", std::string(8, 'v'));
  apply_tonemap(image, Tonemap::kClip, 1.0f);
  CHECK(image.channels == std::vector<std::string>{"R", "G", "B"});
  CHECK(image.at(0, 0, 0) == 0.5f);
  CHECK(image.at(1, 0, 1) == doctest::Approx(0.2f));
  CHECK(image.metadata.at("key") == std::string(8, 'v'));
}
