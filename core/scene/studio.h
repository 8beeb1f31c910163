// The default lighting of a scene in which nothing emits (a bare OBJ): a "studio" that shows the
// model's form. A ground plane just under the model's bounds gives it a contact shadow and
// something to stand on; a sky whose radiance grows from the horizon to the zenith, with a sun
// 50 degrees up, to the left of the default view, gives light and shade. Everything below the
// horizon is black, since the ground hides it: no light is spent where the scene cannot use it.
// `--studio sky` leaves out the sun (soft light, no hard shadow); `--studio none` is the plain
// white environment of radiance 1 and no ground (what pt did before).
#pragma once
#include <cstdint>
#include <optional>

#include "core/scene/scene_builder.h"
#include "core/scene/up_axis.h"
#include "core/util/names.h"

namespace pt {

enum class Studio : uint8_t { kSun, kSky, kNone };
inline constexpr NameTable<Studio, 3> kStudioNames{
    "studio", {{{Studio::kSun, "sun"}, {Studio::kSky, "sky"}, {Studio::kNone, "none"}}}};

// Adds the ground and the sky (kSun, kSky) to `scene`, standing on `up`, and records them in
// scene.studio. The sun stands to the left of `view` (the direction from the model toward the
// camera; the front, +z turned to `up`, when none is known). The scene must have geometry.
void add_studio(SceneBuilder& scene, Studio studio, UpAxis up, std::optional<Vec3f> view = {});

// The studio's sky (with its sun, where `sun`): the sun stands to the left of `view` (the camera's
// position minus where it looks), or of the front where there is no view.
Environment studio_sky(bool sun, UpAxis up, std::optional<Vec3f> view);

}  // namespace pt
