// Bounds on values a scene file may give, past what parsing alone refuses.
#pragma once

namespace pt {

// The largest colour, radiance or light intensity component: float holds 3.4e38, and a pixel sums
// such a value times geometry terms over many samples. Beyond it a render came out black, every
// sample infinite or NaN and dropped; refusing it at load names the value instead.
constexpr double kMaxRadiance = 1e30;
constexpr const char* kMaxRadianceText = "1e30";

}  // namespace pt
