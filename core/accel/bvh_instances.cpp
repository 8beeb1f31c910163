#include "core/accel/bvh_instances.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/accel/bvh_accel.h"
#include "core/accel/bvh_build.h"
#include "core/geometry/geometry.h"
#include "core/geometry/instance.h"

namespace pt {
namespace {

// Robust slab test of one box (Ize, "Robust BVH Ray Traversal", JCGT 2013: the exit distance scaled
// by 1 + 2 gamma(3)), as the wide nodes of the bottom level are tested.
constexpr float kFarScale = 1.0f + 6.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f);

struct Slab {
  Vec3f o, inv;
  explicit Slab(const Ray& r) : o(r.o) {
    for (int a = 0; a < 3; ++a) {
      float d = r.d[a];
      if (std::abs(d) < 1e-30f) d = std::copysign(1e-30f, d);
      inv[a] = 1.0f / d;
    }
  }
  // Entry distance into `b` within [tmin, tmax], or a negative number when the ray misses it.
  float enter(const BBox& b, float tmin, float tmax) const {
    float tn = tmin, tf = tmax;
    for (int a = 0; a < 3; ++a) {
      float t0 = (b.lo[a] - o[a]) * inv[a], t1 = (b.hi[a] - o[a]) * inv[a];
      tn = std::max(tn, std::min(t0, t1));
      tf = std::min(tf, std::max(t0, t1));
    }
    return tn <= tf * kFarScale ? tn : -1.0f;
  }
};

// Depth of the top-level tree: at most 40 SAH levels plus 32 halvings (bvh_build.cpp).
constexpr int kStackSize = 80;

class InstancedBvh final : public Accel {
 public:
  InstancedBvh(const Geometry& geometry, TriangleTest test) : geometry_(geometry), test_(test) {
    auto start = std::chrono::steady_clock::now();
    world_ = make_bvh_accel(geometry, test);
    std::vector<BBox> object_bounds;
    for (const Geometry& object : geometry.objects()) {
      objects_.push_back(make_bvh_accel(object, test));
      object_bounds.push_back(object.mesh().bounds());
    }
    const std::vector<Instance>& instances = geometry.instances();
    bvh::PrimRefs refs;
    refs.reserve(instances.size());
    for (size_t i = 0; i < instances.size(); ++i) {
      BBox b = transform_bounds(object_bounds[instances[i].mesh], instances[i].to_world);
      if (b.empty()) continue;  // an instance of an empty mesh
      refs.push_back(bvh::PrimRef{b.lo, static_cast<uint32_t>(i), b.hi, bvh::PrimKind::kTriangle});
    }
    // An instance costs a whole bottom-level traversal: leaves of one or two, a node test is cheap.
    bvh::BuildOptions options;
    options.max_leaf = 2;
    options.traversal_cost = 0.25f;
    top_ = bvh::build_bvh2(std::move(refs), options);
    stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    AccelStats w = world_->stats();
    stats_.bytes = w.bytes + top_.nodes.size() * sizeof(bvh::Node2) + top_.prims.size() * sizeof(bvh::PrimRef);
    stats_.nodes = w.nodes + top_.nodes.size();
    stats_.primitives = w.primitives;
    for (const auto& o : objects_) {
      AccelStats s = o->stats();
      stats_.bytes += s.bytes;
      stats_.nodes += s.nodes;
    }
    for (const Instance& i : instances) stats_.primitives += geometry.objects()[i.mesh].mesh().triangle_count();
  }

  std::optional<Hit> intersect(const Ray& ray) const override {
    std::optional<Hit> best = world_->intersect(ray);
    float tmax = best ? best->t : ray.tmax;
    if (top_.nodes.empty()) return best;
    Slab slab(ray);
    struct Entry {
      uint32_t node;
      float t;
    };
    Entry stack[kStackSize];
    int sp = 0;
    uint32_t cur = 0;
    if (slab.enter(top_.nodes[0].box, ray.tmin, tmax) < 0) return best;
    for (;;) {
      const bvh::Node2& n = top_.nodes[cur];
      if (n.leaf()) {
        for (uint32_t k = 0; k < n.count; ++k) {
          uint32_t inst = top_.prims[n.offset + k].index;
          if (std::optional<Hit> h = intersect_instance(inst, ray, tmax)) {
            best = h;
            tmax = h->t;
          }
        }
      } else {
        uint32_t a = cur + 1, b = n.offset;
        float ta = slab.enter(top_.nodes[a].box, ray.tmin, tmax), tb = slab.enter(top_.nodes[b].box, ray.tmin, tmax);
        if (ta >= 0 && tb >= 0) {
          if (tb < ta) std::swap(a, b), std::swap(ta, tb);
          stack[sp++] = {b, tb};
          cur = a;
          continue;
        }
        if (ta >= 0 || tb >= 0) {
          cur = ta >= 0 ? a : b;
          continue;
        }
      }
      for (;;) {
        if (sp == 0) return best;
        Entry e = stack[--sp];
        if (e.t <= tmax) {
          cur = e.node;
          break;
        }
      }
    }
  }

  bool occluded(const Ray& ray) const override {
    if (world_->occluded(ray)) return true;
    if (top_.nodes.empty()) return false;
    Slab slab(ray);
    uint32_t stack[kStackSize];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
      uint32_t cur = stack[--sp];
      const bvh::Node2& n = top_.nodes[cur];
      if (slab.enter(n.box, ray.tmin, ray.tmax) < 0) continue;
      if (n.leaf()) {
        for (uint32_t k = 0; k < n.count; ++k) {
          if (occluded_instance(top_.prims[n.offset + k].index, ray)) return true;
        }
      } else {
        stack[sp++] = n.offset;
        stack[sp++] = cur + 1;
      }
    }
    return false;
  }

  AccelStats stats() const override { return stats_; }
  std::string name() const override {
    return test_ == TriangleTest::kWatertight ? "bvh (watertight, two levels)" : "bvh (two levels)";
  }

 private:
  Ray to_object(uint32_t inst, const Ray& ray, float tmax) const {
    const Instance& i = geometry_.instances()[inst];
    Ray r;
    r.o = i.to_object.point(ray.o);
    r.d = i.to_object.vector(ray.d);
    r.tmin = ray.tmin;
    r.tmax = tmax;
    return r;
  }
  std::optional<Hit> intersect_instance(uint32_t inst, const Ray& ray, float tmax) const {
    std::optional<Hit> h = objects_[geometry_.instances()[inst].mesh]->intersect(to_object(inst, ray, tmax));
    if (h) h->inst = inst;
    return h;
  }
  bool occluded_instance(uint32_t inst, const Ray& ray) const {
    return objects_[geometry_.instances()[inst].mesh]->occluded(to_object(inst, ray, ray.tmax));
  }

  const Geometry& geometry_;
  TriangleTest test_;
  std::unique_ptr<Accel> world_;
  std::vector<std::unique_ptr<Accel>> objects_;  // one per instanced mesh, in its own space
  bvh::Bvh2 top_;                                // over the instances' world boxes
  AccelStats stats_;
};

}  // namespace

std::unique_ptr<Accel> make_instanced_bvh_accel(const Geometry& geometry, TriangleTest test) {
  return std::make_unique<InstancedBvh>(geometry, test);
}

}  // namespace pt
