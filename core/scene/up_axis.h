// Which axis of a scene is up. The renderer's conventions (default camera, default lighting) are
// written for +y up; a Z-up model (many CAD and scan exports, Blender's own axes) names +z, and
// those conventions are turned to match instead of the model.
#pragma once
#include "core/math/vec.h"
#include "core/util/names.h"

namespace pt {

enum class UpAxis : uint8_t { kY, kZ };
inline constexpr NameTable<UpAxis, 2> kUpAxisNames{"up axis", {{{UpAxis::kY, "y"}, {UpAxis::kZ, "z"}}}};

inline Vec3f up_vector(UpAxis axis) { return axis == UpAxis::kZ ? Vec3f(0, 0, 1) : Vec3f(0, 1, 0); }

// A direction written for +y up, turned so that its +y lies along `axis`: for +z up, a quarter
// turn about +x, which takes the +y-up front (+z) to Blender's front (-y).
inline Vec3f from_y_up(UpAxis axis, const Vec3f& v) { return axis == UpAxis::kZ ? Vec3f(v.x, -v.z, v.y) : v; }

}  // namespace pt
