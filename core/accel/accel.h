// The acceleration-structure contract: everything above it sees only closest-hit and occlusion
// queries. Two backends implement it: Embree (embree_accel.*) and the home-written BVH (bvh_accel.*).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/geometry/geometry.h"
#include "core/geometry/ray.h"
#include "core/util/names.h"

namespace pt {

struct AccelStats {
  double build_seconds = 0.0;
  size_t bytes = 0;  // memory held by the structure itself (not the shared scene buffers)
  size_t nodes = 0;
  size_t primitives = 0;
};

class Accel {
 public:
  virtual ~Accel() = default;
  virtual std::optional<Hit> intersect(const Ray& ray) const = 0;  // closest hit in (tmin, tmax)
  virtual bool occluded(const Ray& ray) const = 0;                 // any hit in (tmin, tmax)
  virtual AccelStats stats() const = 0;
  virtual std::string name() const = 0;
};

enum class Backend { kEmbree, kBvh };
inline constexpr NameTable<Backend, 2> kBackendNames{"backend", {{{Backend::kEmbree, "embree"}, {Backend::kBvh, "bvh"}}}};
enum class TriangleTest { kMollerTrumbore, kWatertight };
inline constexpr NameTable<TriangleTest, 2> kTriangleTestNames{
    "triangle test", {{{TriangleTest::kMollerTrumbore, "mt"}, {TriangleTest::kWatertight, "watertight"}}}};

struct AccelOptions {
  Backend backend = Backend::kEmbree;
  TriangleTest triangle_test = TriangleTest::kWatertight;      // BVH only
  bool embree_robust = false;                                   // RTC_SCENE_FLAG_ROBUST
};

std::unique_ptr<Accel> make_accel(const Geometry& geometry, const AccelOptions& options);

}  // namespace pt
