#include "renderer/render/aov.h"

#include <sstream>

#include "core/util/error.h"
#include "core/accel/accel.h"
#include "core/scene/scene.h"
#include "integrators/visibility.h"

namespace pt {

AovSet AovSet::parse(const std::string& list) {
  AovSet set;
  set.variance = false;
  std::stringstream in(list);
  std::string name;
  bool any = false;
  while (std::getline(in, name, ',')) {
    any = true;
    if (name == "variance") set.variance = true;
    else if (name == "albedo") set.albedo = true;
    else if (name == "normal") set.normal = true;
    else if (name == "depth") set.depth = true;
    else if (name == "samples") set.samples = true;
    else if (name == "nonfinite") set.nonfinite = true;
    else if (name == "all") set = {true, true, true, true, true, true};
    else if (name == "none" && list == "none") set = {false, false, false, false, false, false};
    else throw Error("--aov '" + list + "': unknown AOV '" + name + "' (" + names() + ")");
  }
  if (!any) throw Error("--aov '" + list + "': expected a list of AOVs (" + names() + ")");
  return set;
}

std::string AovSet::names() { return "variance, albedo, normal, depth, samples, nonfinite; all; none"; }

std::vector<std::string> AovSet::channels() const {
  std::vector<std::string> c = {"R", "G", "B"};
  if (variance) c.insert(c.end(), {"variance.R", "variance.G", "variance.B"});
  if (albedo) c.insert(c.end(), {"albedo.R", "albedo.G", "albedo.B"});
  if (normal) c.insert(c.end(), {"N.X", "N.Y", "N.Z"});
  if (depth) c.push_back("depth.Z");
  if (samples) c.push_back("samples");
  if (nonfinite) c.push_back("nonfinite");
  return c;
}

FirstHit first_hit(const Scene& scene, const Accel& accel, const Ray& camera_ray, Sampler& sampler, SampleInfo& info) {
  FirstHit f;
  Ray ray = camera_ray;
  std::optional<Hit> hit = intersect_visible(scene, accel, ray, sampler, info);
  if (!hit) return f;
  SurfaceInteraction si = scene.interaction(ray, *hit);
  f.hit = true;
  f.albedo = scene.albedo(si);
  f.normal = si.ns;
  f.depth = length(si.p - camera_ray.o);
  return f;
}

}  // namespace pt
