// Closed-form reference images: scenes whose radiance is known exactly, recognised from their
// structure (not from a name), so `pt bench converge --reference analytic` measures error against
// an answer nobody chose. The scenes live in scenes/analytic/.
//
// furnace       every surface white Lambertian (albedo 1), a constant environment L, path tracing:
//               radiance is L everywhere, whatever the geometry (L = const solves the rendering
//               equation). Paths cut at max_depth lose at most P(no escape in max_depth bounces).
// rect-light    a diffuse plane (albedo kd) under emissive polygons (radiance Le): irradiance from
//               Lambert's polygon formula, E = Le/2 |sum_i theta_i n.(v_i x v_i+1)/|v_i x v_i+1||,
//               radiance kd/pi E (Lambert, Photometria 1760; Arvo, "Applications of Irradiance
//               Tensors", SIGGRAPH 1995, eq. 3).
// sphere-light  a diffuse plane under an emissive sphere: E = pi Le sin^2(alpha) cos(theta), alpha
//               the half-angle the sphere subtends and theta its centre's angle from the normal,
//               valid when the sphere is wholly above the plane.
// sphere-env    a diffuse sphere (albedo kd) under a constant environment L: a convex object sees
//               only the sky, so it shows kd L and the background L; pixels on the silhouette are
//               integrated exactly over their area (per scanline, in closed form).
// The reference is the pixel average over the same film-space square the renderer jitters over.
#pragma once
#include <string>

#include "core/image/image.h"
#include "core/scene/render_settings.h"
#include "core/scene/scene.h"
#include "renderer/render/job.h"

namespace pt {

// Which closed-form case the scene is, or throws pt::Error saying why it is none of them.
// `integrator` and `max_depth` matter: the furnace needs path tracing deep enough to escape.
std::string analytic_case(const Scene& scene, IntegratorKind integrator, int max_depth);

// The exact per-pixel image (R, G, B) of the job: its scene, camera, size, integrator and depth.
// Throws pt::Error if the scene is not closed-form or the camera sees something the formula does
// not cover.
Image analytic_reference(const Job& job);

}  // namespace pt
