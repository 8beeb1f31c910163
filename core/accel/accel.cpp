// The backend table: name -> constructor, no self-registration.
#include "core/accel/accel.h"

#include "core/accel/embree_accel.h"
#include "core/util/error.h"

namespace pt {

std::unique_ptr<Accel> make_bvh_accel(const class Scene& scene, TriangleTest test);

std::unique_ptr<Accel> make_accel(const Scene& scene, const AccelOptions& options) {
  switch (options.backend) {
    case Backend::kEmbree: return make_embree_accel(scene, options.embree_robust);
    case Backend::kBvh: return make_bvh_accel(scene, options.triangle_test);
  }
  throw Error("unknown backend");
}

Backend parse_backend(const std::string& name) {
  if (name == "embree") return Backend::kEmbree;
  if (name == "bvh") return Backend::kBvh;
  throw Error("unknown backend '" + name + "' (embree, bvh)");
}

TriangleTest parse_triangle_test(const std::string& name) {
  if (name == "mt") return TriangleTest::kMollerTrumbore;
  if (name == "watertight") return TriangleTest::kWatertight;
  throw Error("unknown triangle test '" + name + "' (mt, watertight)");
}

AccelOptions parse_accel_options(const std::string& backend, const std::string& triangle_test, bool embree_robust) {
  AccelOptions a;
  a.backend = parse_backend(backend);
  a.triangle_test = parse_triangle_test(triangle_test);
  a.embree_robust = embree_robust;
  return a;
}

}  // namespace pt
