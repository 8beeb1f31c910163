// The backend table: name -> constructor, no self-registration.
#include "core/accel/accel.h"

#include "core/accel/bvh_accel.h"
#include "core/accel/bvh_instances.h"
#include "core/accel/embree_accel.h"
#include "core/util/error.h"

namespace pt {

std::unique_ptr<Accel> make_accel(const Geometry& geometry, const AccelOptions& options) {
  switch (options.backend) {
    case Backend::kEmbree: return make_embree_accel(geometry, options.embree_robust);
    case Backend::kBvh:
      if (!geometry.instances().empty()) return make_instanced_bvh_accel(geometry, options.triangle_test);
      return make_bvh_accel(geometry, options.triangle_test);
  }
  throw Error("unknown backend");
}

}  // namespace pt
