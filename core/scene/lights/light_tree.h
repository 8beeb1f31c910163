// The light hierarchy: a BVH over the emitters, each node with the bounding box, power and
// orientation cone of what it holds (light_bounds.h), after Conty Estevez & Kulla, "Importance
// Sampling of Many Lights with Adaptive Tree Splitting" (HPG 2018), the design pbrt-v4's
// BVHLightSampler and Cycles' light tree follow. It is built binary (the paper's binned cost) and
// collapsed to four children per node, whose importances are evaluated together
// (light_cones4.h): a descent takes half the levels, each one evaluation of four lanes. A light is
// chosen by descending from the root, taking each child with probability proportional to its
// importance at the shading point (power over squared distance, the emitters' orientation, the
// point's normal). The pdf of a given light is the product of the same choices along its path,
// found from its leaf upward and multiplied from the root down as the descent does, so MIS sees
// exactly the probability the descent gave. Infinitely distant lights (the environment,
// directional lights) are outside the tree and keep their share of the total power.
#pragma once
#include <cstdint>
#include <vector>

#include "core/scene/lights/light_bounds.h"
#include "core/scene/lights/light_cones4.h"
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
  int depth() const { return depth_; }                   // levels of four-child nodes below the root

 private:
  static constexpr uint32_t kLeaf = 0x80000000u;  // a child that is an item (a leaf), not a node
  static constexpr uint32_t kNone = 0xffffffffu;
  struct Node {
    LightCones4 children;     // the children's bounds, one lane each (empty lanes have no power)
    uint32_t child[4] = {kNone, kNone, kNone, kNone};  // a node's index, or kLeaf | an item's
    uint32_t parent = kNone;  // the node whose child this is, in lane `lane`
    uint32_t lane = 0;
  };
  struct Item {
    uint32_t first = 0, count = 1;  // lights first .. first + count - 1
    uint32_t node = 0, lane = 0;    // the node whose child it is, in that lane
  };
  // The binary tree the build makes before it is collapsed to four children per node.
  struct BinaryNode {
    LightBounds bounds;
    uint32_t second = 0;  // interior: the second child (the first follows the node)
    uint32_t item = kNone;  // a leaf's item
  };
  static constexpr int kMaxDepth = 64;

  // Builds the binary subtree of order[begin, end) into `binary` and returns its bounds.
  LightBounds build(std::vector<BinaryNode>& binary, std::vector<uint32_t>& order, uint32_t begin, uint32_t end,
                    const std::vector<LightBounds>& item_bounds, const std::vector<Vec3f>& centroids, uint32_t depth);
  // Makes the node holding binary node b's children (and their children, up to four), below
  // `parent` in `lane`; returns its index.
  uint32_t collapse(const std::vector<BinaryNode>& binary, uint32_t b, uint32_t parent, uint32_t lane, int depth);
  // The weights of node's children at (p, n): their importances, or where all are zero below the
  // root (its bounds were looser than theirs), their powers. False at the root where no child can
  // light p.
  bool weights(uint32_t node, const Vec3f& p, const Vec3f& n, float w[4]) const;
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
