// Placeholder until the BVH issue lands: the backend is named but refuses to run.
#include "core/accel/bvh_accel.h"

#include "core/util/error.h"

namespace pt {

std::unique_ptr<Accel> make_bvh_accel(const Scene&, TriangleTest) {
  throw Error("the bvh backend is not built yet; use --backend embree");
}

}  // namespace pt
