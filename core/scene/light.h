// Lights: point lights, emissive triangles and spheres (area lights), and the environment.
// Every emissive surface is a light; the light to sample is chosen in proportion to its power.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

namespace pt {

enum class LightType : uint8_t { kPoint, kTriangle, kSphere, kEnvironment };

struct Light {
  LightType type = LightType::kPoint;
  uint32_t index = 0;      // triangle or sphere index for area lights
  Vec3f position;          // point lights
  Spectrum intensity{0};   // point lights: W/sr
  float power = 0;         // luminance of the emitted power, for choosing lights
  // Triangle lights, precomputed at finalize so that sampling one costs no square root:
  // position = first vertex, edge1/edge2 from it, unit normal, area, and intensity = radiance.
  Vec3f edge1, edge2, normal;
  float area = 0;
};

// A sampled light direction as seen from a shading point.
struct LightSample {
  Spectrum radiance{0};  // arriving along -wi (intensity / r^2 for point lights)
  Vec3f wi;              // unit direction from the shading point toward the light
  Vec3f point, normal;   // point on the light and its normal (area lights)
  float distance = kInf; // along wi; kInf for the environment
  float pdf = 0;         // solid-angle density including the choice of light; 1 for point lights
  bool delta = false;    // point light: cannot be hit by BSDF sampling
};

}  // namespace pt
