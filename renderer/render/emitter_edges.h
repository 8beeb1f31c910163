// Extra camera rays for the pixels that see the edge of an emitter.
//
// A pixel half on a lamp of radiance 400 is noisy with where its camera samples land (its
// coverage), which no light sampling changes, and a whole path sample costs about four rays. In
// such a pixel each sample also traces `views` camera rays of its own to their first hit only and
// counts the mean of what they see emitted (or the sky where they escape) in place of what its own
// camera ray's first hit emits (SampleInfo::views); the path goes on from its own ray as before.
// Each view is uniform over the pixel, so the mean has the expectation of the term it replaces,
// and the estimate stays unbiased whatever the number of views, provided which pixels get views
// does not depend on the samples themselves. They are chosen here, before any sample, from one ray
// through each pixel's centre: a pixel gets views where the centre rays of it and its 8
// neighbours see some emitting surface and what they see emitted differs by more than a tenth of
// the largest (an edge; a pixel inside a lamp's image would gain nothing). Emitters less than two
// pixels across may fall between the centre rays (a street's far lamps): the pixels around the
// image of such an emitter's box get views too, unless it faces away or the ray from the camera
// to its box is blocked. The choice depends on
// the scene and the camera alone, so thread counts, parts (each finds its own pixels' neighbours)
// and resumed renders make the same one.
//
// The views of a pixel's sample i are the sample indices [i views, (i + 1) views) of a scrambled
// Sobol sequence of their own: an aligned block, stratified among themselves, and over the
// pixel's samples a point set `views` times denser than theirs (Burley 2020's index shuffle maps
// aligned power-of-two blocks to aligned blocks, as Sampler::split relies on).
#pragma once
#include <cstdint>
#include <vector>

#include "core/accel/accel.h"
#include "core/math/sampler.h"
#include "core/scene/scene.h"
#include "integrators/integrator.h"
#include "renderer/farm/part.h"
#include "renderer/render/camera_rays.h"

namespace pt {

class EmitterEdges {
 public:
  EmitterEdges() = default;  // no pixel gets views
  // The pixels of `region` (of a width x height image) that get views. Traces one ray through the
  // centre of each pixel of the region and of its border, and one toward each small emitter, in
  // parallel (call it inside the render's task arena); `rays` counts them.
  EmitterEdges(const Scene& scene, const Accel& accel, const Camera& camera, int width, int height, uint64_t seed,
               SamplerKind sampler, const PartRegion& region, uint64_t& rays);

  bool contains(uint64_t pixel) const { return !mask_.empty() && mask_[pixel]; }
  size_t count() const;

 private:
  std::vector<uint8_t> mask_;
};

// Traces the `views` views of sample `index` of `pixel` (the sequence of seed `seed`: the sample's
// own, Sampler's arguments) through pixel (x, y) and hands them to the integrator through `info`.
void trace_views(const Scene& scene, const Accel& accel, const CameraRays& rays, SamplerKind sampler, uint64_t seed,
                 uint64_t pixel, uint32_t index, int x, int y, int views, SampleInfo& info);

}  // namespace pt
