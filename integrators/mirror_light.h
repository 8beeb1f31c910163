// Light sampling through flat mirrors by the method of images. A light seen from x in a plane
// mirror is the light seen from x's mirror image x' = reflect(x): sampling the light from x' gives
// the direction (reflected back) and the solid-angle density at x of the unfolded path x -> m -> y,
// whose length is |x' - y|. Virtual images of this kind go back to Wallace, Cohen & Greenberg, "A
// two-pass solution to the rendering equation" (SIGGRAPH 1987); for one planar specular vertex it
// is the exact solution that manifold next-event estimation (Hanika, Droske & Fascione, EGSR 2015)
// finds by Newton iteration. It holds for any flat mirror: Scene::mirror_planes() lists every
// plane of mirror triangles, one is chosen uniformly per sample, and the two rays x -> m (which
// must reach a triangle of that plane) and m -> y check visibility.
//
// Mirror spheres (Scene::mirror_spheres()) have no virtual image: a point y is chosen on a light as
// seen from the sphere's centre, the point m of the sphere that reflects y toward x is solved for,
// and the path's density at x follows from the reflected pencil's spreading (sphere_mirror.h). The
// caustics of a mirror sphere on diffuse surfaces are then light-sampled, where BSDF sampling finds
// them only by chance. Point and spot lights through a sphere are left out (as BSDF sampling can
// never find them, pt renders no caustic of theirs, as before).
//
// The path tracer finds the same paths (diffuse x, one mirror, an emitter) by BSDF sampling and
// weights both with the power heuristic, using mirror_light_pdf for the BSDF-sampled ones. One
// mirror (plane or sphere) is chosen uniformly per sample. Environment light through a mirror is
// left to BSDF sampling (weight 1 there).
#pragma once
#include "integrators/integrator.h"

namespace pt {

// Radiance from one light sample at the non-specular point sp through one mirror, weighted against
// BSDF sampling by the power heuristic. Zero when the scene has no mirrors to sample through.
Spectrum sample_light_via_mirror(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler,
                                 SampleInfo& info);

// Solid-angle density with which sample_light_via_mirror, called at x (geometric normal n), picks the
// emitting point si_light through mirror `mirror` (Scene::mirror_of), where BSDF sampling reached it by
// x -> m (the point on that mirror) -> si_light.
float mirror_light_pdf(const Scene& scene, const Vec3f& x, const Vec3f& n, int mirror, const Vec3f& m,
                       const SurfaceInteraction& si_light);

}  // namespace pt
