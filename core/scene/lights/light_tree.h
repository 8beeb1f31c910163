// The light hierarchy: a BVH over the emitters, each node with the bounding box, power and
// orientation cone of what it holds (light_bounds.h), after Conty Estevez & Kulla, "Importance
// Sampling of Many Lights with Adaptive Tree Splitting" (HPG 2018), the design pbrt-v4's
// BVHLightSampler and Cycles' light tree follow. A light is chosen by descending from the root,
// taking each child with probability proportional to its importance at the shading point (power
// over squared distance, the emitters' orientation, the point's normal). The pdf of a given light is
// the product of the same choices along its path, which each light's leaf records as bits, so
// MIS sees exactly the probability the descent gave. Infinitely distant lights (the environment,
// directional lights) are outside the tree and keep their share of the total power.
#pragma once
#include <cstdint>
#include <vector>

#include "core/scene/lights/light_bounds.h"
#include "core/scene/lights/light_sampler.h"

namespace pt {

class LightTree final : public LightSampler {
 public:
  // bounds[i]: light i's (LightSet::lights() order), empty for infinitely distant lights, whose
  // power is power[i]; groups: the TriangleGroups' members, which share a leaf (bounds are then
  // merged, and a member is chosen in its leaf by power). Built in O(n log n) (binned, 12 bins).
  LightTree(const std::vector<LightBounds>& bounds, const std::vector<float>& power,
            const std::vector<LightGroupRange>& groups);

  bool sample(const Vec3f& p, const Vec3f& n, float u, LightChoice& c) const override;
  float pdf(const Vec3f& p, const Vec3f& n, uint32_t light) const override;
  float group_pdf(const Vec3f& p, const Vec3f& n, uint32_t group) const override;
  float infinite_pdf(uint32_t light) const override { return infinite_pick_[light]; }

  size_t node_count() const { return nodes_.size(); }
  size_t emitter_count() const { return items_.size(); }  // leaves: lights, a triangle group counting once
  int depth() const { return depth_; }

 private:
  struct Node {
    LightCone cone;
    uint32_t index = 0;  // interior: the second child (the first follows the node); leaf: the item
    bool leaf = false;
  };
  struct Item {
    uint32_t first = 0, count = 1;  // lights first .. first + count - 1
    uint64_t path = 0;              // the choices from the root to its leaf, bit d = 1: the second child at depth d
    uint32_t depth = 0;
  };
  static constexpr int kMaxDepth = 64;

  // Builds the subtree of order[begin, end) and returns its bounds.
  LightBounds build(std::vector<uint32_t>& order, uint32_t begin, uint32_t end, const std::vector<LightBounds>& item_bounds,
                    const std::vector<Vec3f>& centroids, uint64_t path, uint32_t depth);
  // The probability of descending from interior node `node` to its first child at (p, n).
  float first_child_probability(uint32_t node, const Vec3f& p, const Vec3f& n) const;
  // The probability that the descent at (p, n) reaches item i's leaf.
  float item_pdf(const Vec3f& p, const Vec3f& n, uint32_t item) const;

  std::vector<Node> nodes_;
  std::vector<Item> items_;
  std::vector<int32_t> item_of_light_;   // per light: its item, or -1 (an infinite light)
  std::vector<float> share_;             // per light: its share of its item's power (1 but in groups)
  std::vector<float> share_before_;      // per light: the summed shares of its item's lights before it
  std::vector<int32_t> item_of_group_;   // per group
  std::vector<uint32_t> infinite_;       // the infinite lights, in order
  std::vector<float> infinite_pick_;     // per light: its probability if infinite, else 0
  std::vector<float> infinite_cdf_;      // over infinite_, starting at tree_pick_
  float tree_pick_ = 0;                  // the probability of descending the tree at all
  int depth_ = 0;
};

}  // namespace pt
