// The BVH of a scene with instances, two levels, compiled with each instruction set's traversal
// (included by bvh_accel_sse42.cpp, _avx2.cpp and _avx512.cpp after bvh_traversal.h). The bottom
// level is the ordinary tree, one per instanced mesh in the mesh's own space and one over the
// world-space mesh and spheres; the top level is the same 8-wide tree over the instances' world
// boxes, whose leaves list instances. A ray that reaches an instance is taken into the mesh's space
// by the instance's inverse transform and traced there by the mesh's own traversal, called
// directly; with an affine transform and the direction left unnormalised, t means the same
// distance along the ray in both spaces, so the closest hit so far bounds the next instance's ray.
#pragma once
#include <chrono>
#include <memory>
#include <vector>

#include "core/accel/bvh_traversal.h"
#include "core/geometry/instance.h"

namespace pt::bvh {
inline namespace PT_BVH_ISA {
namespace traversal {

// What a ray needs of an instance, in one cache line, stored in the top level's leaf order: the
// time of a two-level traversal went mostly to waiting for the instance's transform (perf: two thirds
// of trace_instances' samples on its first load), which then took two dependent misses (the leaf's
// instance index, then the Instance).
//
// The ray's origin goes into the mesh's space as to_object's linear part times (o - the instance's
// world position), not as to_object applied whole: for a ray leaving (or passing near) an instance
// far from the world's origin, o and the position are close, their difference exact (Sterbenz) and
// the product rounded at the mesh's scale; the whole transform adds a translation of the world's
// magnitude and rounds there. On the field of instances 150 units out the origin moved up to
// 1e-5 (about 64 ulps of the mesh's coordinates), a rounding that put a ray starting near a
// surface on its other side or let a ray near an edge through (renderer/tools/exact_ray.py on the
// disagreements). The linear part is kept apart from a Transform to keep the record in 64 bytes.
struct alignas(64) InstanceRecord {
  float linear[3][3];  // to_object's linear part
  Vec3f origin;        // to_world's translation: the mesh's origin in the world
  uint32_t mesh = 0, id = 0;

  InstanceRecord(const Instance& inst, uint32_t index)
      : origin(inst.to_world.m[0][3], inst.to_world.m[1][3], inst.to_world.m[2][3]), mesh(inst.mesh), id(index) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) linear[i][j] = inst.to_object.m[i][j];
    }
  }
  Vec3f vector(const Vec3f& v) const {
    return {linear[0][0] * v.x + linear[0][1] * v.y + linear[0][2] * v.z,
            linear[1][0] * v.x + linear[1][1] * v.y + linear[1][2] * v.z,
            linear[2][0] * v.x + linear[2][1] * v.y + linear[2][2] * v.z};
  }
  Vec3f point(const Vec3f& p) const { return vector(p - origin); }
};

template <TriangleTest kTest>
struct InstanceLeaves {
  std::vector<InstanceRecord> records;                    // by the top level's leaf slots
  std::vector<std::unique_ptr<BvhAccel<kTest>>> objects;  // one per instanced mesh, in its own space
};

template <TriangleTest kTest>
bool trace_instances(const InstanceLeaves<kTest>& leaves, uint32_t first, uint32_t count, const Ray& ray, Hit& hit,
                     bool any_hit) {
  bool found = false;
  for (uint32_t i = first; i < first + count; ++i) {
    const InstanceRecord& inst = leaves.records[i];
    Ray r;
    r.o = inst.point(ray.o);
    r.d = inst.vector(ray.d);
    r.tmin = ray.tmin;
    r.tmax = hit.t;
    Hit h;
    const BvhAccel<kTest>& object = *leaves.objects[inst.mesh];
    if (any_hit) {
      if (object.template traverse<true>(r, h)) return true;
    } else if (object.template traverse<false>(r, h)) {
      hit = h;
      hit.inst = inst.id;
      found = true;
    }
  }
  return found;
}

template <TriangleTest kTest>
class TwoLevelAccel final : public Accel {
 public:
  explicit TwoLevelAccel(const Geometry& geometry) : world_(geometry, BuildOptions{}) {
    auto start = std::chrono::steady_clock::now();
    std::vector<BBox> object_bounds;
    for (const Geometry& object : geometry.objects()) {
      leaves_.objects.push_back(std::make_unique<BvhAccel<kTest>>(object, BuildOptions{}));
      object_bounds.push_back(object.mesh().bounds());
    }
    const std::vector<Instance>& instances = geometry.instances();
    PrimRefs refs;
    refs.reserve(instances.size());
    for (size_t i = 0; i < instances.size(); ++i) {
      BBox b = transform_bounds(object_bounds[instances[i].mesh], instances[i].to_world);
      if (b.empty()) continue;  // an instance of an empty mesh
      refs.push_back(PrimRef{b.lo, static_cast<uint32_t>(i), b.hi, PrimKind::kSphere});
    }
    // An instance costs a whole bottom-level traversal: a leaf holds one (on the field of 10,000
    // instances, leaves of one with a node cost of 1 were 0.8-0.95x the time of leaves of two with
    // 0.25, and of up to four).
    BuildOptions top;
    top.max_leaf = 1;
    top.traversal_cost = 1.0f;
    top_ = std::make_unique<BvhAccel<kTest>>(geometry, std::move(refs), top, &leaves_);
    for (uint32_t id : top_->leaf_slots()) leaves_.records.emplace_back(instances[id], id);
    AccelStats w = world_.stats();
    stats_.build_seconds = w.build_seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats_.bytes = w.bytes + top_->stats().bytes + leaves_.records.size() * sizeof(InstanceRecord);
    stats_.nodes = w.nodes + top_->stats().nodes;
    stats_.primitives = w.primitives;
    for (const auto& o : leaves_.objects) {
      AccelStats s = o->stats();
      stats_.bytes += s.bytes;
      stats_.nodes += s.nodes;
    }
    for (const Instance& i : instances) stats_.primitives += geometry.objects()[i.mesh].mesh().triangle_count();
  }

  std::optional<Hit> intersect(const Ray& ray) const override {
    Hit world;
    bool found = world_.template traverse<false>(ray, world);
    Ray r = ray;
    if (found) r.tmax = world.t;
    Hit hit;
    if (top_->template traverse<false>(r, hit)) return hit;
    if (found) return world;
    return std::nullopt;
  }

  bool occluded(const Ray& ray) const override {
    Hit hit;
    return world_.template traverse<true>(ray, hit) || top_->template traverse<true>(ray, hit);
  }

  AccelStats stats() const override { return stats_; }
  std::string name() const override {
    return kTest == TriangleTest::kWatertight ? "bvh (watertight, two levels)" : "bvh (two levels)";
  }

 private:
  BvhAccel<kTest> world_;
  InstanceLeaves<kTest> leaves_;
  std::unique_ptr<BvhAccel<kTest>> top_;  // over the instances' world boxes
  AccelStats stats_;
};

}  // namespace traversal

// The two-level BVH with this instruction set's kernels.
inline std::unique_ptr<Accel> make_two_level_accel(const Geometry& geometry, TriangleTest test) {
  if (test == TriangleTest::kWatertight) return std::make_unique<traversal::TwoLevelAccel<TriangleTest::kWatertight>>(geometry);
  return std::make_unique<traversal::TwoLevelAccel<TriangleTest::kMollerTrumbore>>(geometry);
}

}  // namespace PT_BVH_ISA
}  // namespace pt::bvh
