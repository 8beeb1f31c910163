// Rays through partly transparent surfaces (Material::opacity < 1), by stochastic transparency.
//
// A camera or bounce ray that hits a surface of coverage c keeps the hit with probability c and
// otherwise goes straight on, unchanged: the surface contributes c of its own look and lets 1 - c
// of what lies behind it through, in expectation, so the estimate stays unbiased (Enderton et al.,
// "Stochastic Transparency", I3D 2010, do the same per fragment). A shadow ray carries the
// product of (1 - c) over the partial surfaces it crosses and 0 at an opaque one: the expectation
// of the same coin flips, computed exactly, so shadows get no extra noise and draw no random
// numbers. Light sampling and its MIS weights are unchanged (densities do not depend on
// visibility); a BSDF-sampled ray that passes a partial surface finds the light with probability
// (1 - c), which is the transmittance light sampling applies. Both backends see the same walk: it
// is made of ordinary closest-hit queries. Scenes without partial coverage pay one branch.
#pragma once
#include <optional>

#include "integrators/integrator.h"

namespace pt {

// The closest hit that is kept. `ray` becomes the segment that found it: its origin moves past the
// surfaces the ray went through (the direction is unchanged), so hit.t refers to it.
std::optional<Hit> intersect_visible(const Scene& scene, const Accel& accel, Ray& ray, Sampler& sampler,
                                     SampleInfo& info);

// The fraction of light that travels along `shadow` (tmin to tmax): 0 or 1 in a scene without
// partial coverage, where it is one occlusion query.
float transmittance(const Scene& scene, const Accel& accel, const Ray& shadow, SampleInfo& info);

}  // namespace pt
