// AOVs ("arbitrary output variables"): the channels a beauty EXR may carry beside R, G, B, chosen
// with `pt render --aov LIST`. Names follow the compositors' layer.channel convention, and albedo
// and N are the auxiliary inputs of denoisers such as Open Image Denoise:
//   variance.R/G/B  the variance of the mean radiance (sample variance / samples)       [default]
//   albedo.R/G/B    first-hit reflectance, texture included (what `--integrator albedo` renders)
//   N.X/Y/Z         first-hit world-space shading normal, not remapped (0 where the ray escapes)
//   depth.Z         distance from the camera to the first hit, averaged over the samples that hit
//                   something; 0 where none did
//   samples         samples averaged into R, G, B (an integer)
//   nonfinite       samples dropped because they were NaN or infinite (an integer)
// albedo, N and depth average, like R, G, B, every sample the pixel took (a miss counts 0), so they
// are antialiased like the beauty. They come from the beauty sample's own camera ray and random
// numbers (a partly transparent surface is kept or passed exactly as the beauty's path did), so
// they cost one extra first-hit query per sample, and nothing when not asked for.
#pragma once
#include <string>
#include <vector>

#include "core/math/vec.h"

namespace pt {

class Accel;
class Sampler;
class Scene;
struct Ray;
struct SampleInfo;

struct AovSet {
  bool variance = true;  // the default: what the EXR carried before --aov
  bool albedo = false, normal = false, depth = false;
  bool samples = false, nonfinite = false;

  // "albedo,normal,depth", "all" or "none" (R, G, B only). Throws pt::Error naming --aov.
  static AovSet parse(const std::string& list);
  static std::string names();  // the names parse() takes, for --help and messages
  bool first_hit() const { return albedo || normal || depth; }  // needs the extra query
  std::vector<std::string> channels() const;  // in file order, R, G, B first
};

// What a sample's camera ray sees first.
struct FirstHit {
  bool hit = false;
  Spectrum albedo = Spectrum(0.0f);
  Vec3f normal = Vec3f(0.0f);  // shading normal, world space
  float depth = 0;             // distance from the ray's origin
};

// The first surface `camera_ray` keeps, found as the albedo and normals integrators find it (with
// `sampler` in the state the integrator's Li() starts from, the same surface as the beauty's).
FirstHit first_hit(const Scene& scene, const Accel& accel, const Ray& camera_ray, Sampler& sampler, SampleInfo& info);

}  // namespace pt
