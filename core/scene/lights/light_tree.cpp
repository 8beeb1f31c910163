#include "core/scene/lights/light_tree.h"

#include <algorithm>
#include <limits>
#include <numeric>

namespace pt {
namespace {

constexpr float kOneMinus = 0x1.fffffep-1f;
constexpr int kBins = 12;
// Levels needed to split n items to leaves at the median: ceil(log2 n).
uint32_t median_levels(uint32_t n) {
  uint32_t levels = 0;
  while ((uint64_t(1) << levels) < n) ++levels;
  return levels;
}

// The build's cost of a cluster (the paper's section 5.1): power x orientation measure x surface
// area. The box is padded by a small fraction of the parent's size so that clusters of points or
// of coplanar lights still compare by their extent.
double cluster_cost(const LightBounds& b, float pad) {
  if (b.empty()) return 0.0;
  Vec3f e = b.box.extent() + Vec3f(pad);
  double area = 2.0 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
  return double(b.phi) * orientation_measure(b) * area;
}

}  // namespace

LightTree::LightTree(const std::vector<LightBounds>& bounds, const std::vector<float>& power,
                     const std::vector<LightGroupRange>& groups)
    : item_of_light_(bounds.size(), -1),
      share_(bounds.size(), 1.0f),
      share_before_(bounds.size(), 0.0f),
      item_of_group_(groups.size(), -1),
      infinite_pick_(bounds.size(), 0.0f) {
  // Items: every finite light alone, but a triangle group's members together.
  std::vector<int32_t> group_of(bounds.size(), -1);
  for (size_t g = 0; g < groups.size(); ++g) {
    for (uint32_t m = groups[g].first; m < groups[g].first + groups[g].count; ++m) group_of[m] = static_cast<int32_t>(g);
  }
  std::vector<LightBounds> item_bounds;
  double finite = 0, total = 0;
  for (size_t i = 0; i < bounds.size(); ++i) {
    total += std::max(0.0f, power[i]);
    if (bounds[i].empty()) {
      infinite_.push_back(static_cast<uint32_t>(i));
      continue;
    }
    finite += std::max(0.0f, bounds[i].phi);
    int32_t g = group_of[i];
    if (g >= 0 && groups[g].first != i) continue;  // a member after its group's first: in the first's item
    Item item;
    item.first = static_cast<uint32_t>(i);
    item.count = g >= 0 ? groups[g].count : 1;
    LightBounds b;
    for (uint32_t m = item.first; m < item.first + item.count; ++m) b = merge(b, bounds[m]);
    if (item.count > 1) {
      float before = 0;
      for (uint32_t m = item.first; m < item.first + item.count; ++m) {
        share_[m] = b.phi > 0 ? bounds[m].phi / b.phi : 1.0f / item.count;
        share_before_[m] = before;
        before += share_[m];
      }
    }
    for (uint32_t m = item.first; m < item.first + item.count; ++m) item_of_light_[m] = static_cast<int32_t>(items_.size());
    if (g >= 0) item_of_group_[g] = static_cast<int32_t>(items_.size());
    items_.push_back(item);
    item_bounds.push_back(b);
  }
  // The tree gets the finite lights' share of the power; each infinite light its own.
  tree_pick_ = items_.empty() ? 0.0f : total > 0 ? static_cast<float>(finite / total) : 1.0f;
  if (infinite_.empty() && !items_.empty()) tree_pick_ = 1.0f;
  double cumulative = tree_pick_;
  for (uint32_t i : infinite_) {
    float pick = total > 0 ? static_cast<float>(std::max(0.0f, power[i]) / total) : 1.0f / infinite_.size();
    if (items_.empty() && total <= 0) pick = 1.0f / infinite_.size();
    infinite_pick_[i] = pick;
    cumulative += pick;
    infinite_cdf_.push_back(static_cast<float>(cumulative));
  }
  if (!infinite_cdf_.empty()) infinite_cdf_.back() = 1.0f;
  if (items_.empty()) return;
  std::vector<Vec3f> centroids;
  for (const LightBounds& b : item_bounds) centroids.push_back(b.box.center());
  std::vector<uint32_t> order(items_.size());
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * items_.size() - 1);
  build(order, 0, static_cast<uint32_t>(order.size()), item_bounds, centroids, 0, 0);
}

LightBounds LightTree::build(std::vector<uint32_t>& order, uint32_t begin, uint32_t end,
                             const std::vector<LightBounds>& item_bounds, const std::vector<Vec3f>& centroids,
                             uint64_t path, uint32_t depth) {
  uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  depth_ = std::max(depth_, static_cast<int>(depth));
  if (end - begin == 1) {
    Node& leaf = nodes_[index];
    leaf.leaf = true;
    leaf.index = order[begin];
    leaf.cone = light_cone(item_bounds[order[begin]]);
    items_[order[begin]].path = path;
    items_[order[begin]].depth = depth;
    return item_bounds[order[begin]];
  }
  BBox box, centroid_box;
  for (uint32_t i = begin; i < end; ++i) {
    box.expand(item_bounds[order[i]].box);
    centroid_box.expand(centroids[order[i]]);
  }
  Vec3f extent = centroid_box.extent();
  float pad = 1e-3f * length(box.extent());
  uint32_t mid = begin;
  // A leaf's path must fit its 64 bits: a binned split (which may peel off a single item) only while
  // median splits below it would still end within kMaxDepth levels.
  if (depth + 1 + median_levels(end - begin) < static_cast<uint32_t>(kMaxDepth)) {
    // Binned: along each axis, kBins bins of the centroids, and the cheapest of the planes between
    // them (the paper's cost, with its regularisation by the box's aspect along the axis).
    double best = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_plane = 0;
    Vec3f box_extent = box.extent();
    float longest = max_component(box_extent);
    for (int axis = 0; axis < 3; ++axis) {
      if (!(extent[axis] > 0)) continue;
      LightBounds bins[kBins];
      uint32_t counts[kBins] = {};
      float scale = kBins / extent[axis];
      for (uint32_t i = begin; i < end; ++i) {
        int b = std::min(kBins - 1, static_cast<int>((centroids[order[i]][axis] - centroid_box.lo[axis]) * scale));
        bins[b] = merge(bins[b], item_bounds[order[i]]);
        ++counts[b];
      }
      double right_cost[kBins];
      LightBounds right;
      for (int b = kBins - 1; b > 0; --b) {
        right = merge(right, bins[b]);
        right_cost[b] = cluster_cost(right, pad);
      }
      float kr = box_extent[axis] > 0 ? longest / box_extent[axis] : 1.0f;
      LightBounds left;
      uint32_t left_count = 0;
      for (int plane = 0; plane + 1 < kBins; ++plane) {
        left = merge(left, bins[plane]);
        left_count += counts[plane];
        if (left_count == 0 || left_count == end - begin) continue;  // one side empty: no split
        double cost = kr * (cluster_cost(left, pad) + right_cost[plane + 1]);
        if (cost < best) best = cost, best_axis = axis, best_plane = plane;
      }
    }
    if (best_axis >= 0) {
      float scale = kBins / extent[best_axis];
      auto it = std::partition(order.begin() + begin, order.begin() + end, [&](uint32_t item) {
        int b = std::min(kBins - 1, static_cast<int>((centroids[item][best_axis] - centroid_box.lo[best_axis]) * scale));
        return b <= best_plane;
      });
      mid = static_cast<uint32_t>(it - order.begin());
    }
  }
  if (mid == begin || mid == end) {
    // Deep, or no plane separates them: halves by count along the centroids' longest axis.
    int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](uint32_t a, uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  }
  LightBounds first = build(order, begin, mid, item_bounds, centroids, path, depth + 1);
  nodes_[index].index = static_cast<uint32_t>(nodes_.size());
  LightBounds bounds = merge(first, build(order, mid, end, item_bounds, centroids, path | (uint64_t(1) << depth), depth + 1));
  nodes_[index].cone = light_cone(bounds);
  return bounds;
}

bool LightTree::sample(const Vec3f& p, const Vec3f& n, float u, LightChoice& c) const {
  if (u < tree_pick_) {
    float pick = tree_pick_;
    u = std::min(u / tree_pick_, kOneMinus);
    if (!(importance(nodes_[0].cone, p, n) > 0)) return false;  // no light of the tree can reach p
    uint32_t node = 0;
    while (!nodes_[node].leaf) {
      uint32_t a = node + 1, b = nodes_[node].index;
      float pa = first_child_probability(node, p, n);
      if (u < pa) {
        u = std::min(u / pa, kOneMinus);
        pick *= pa;
        node = a;
      } else {
        u = std::min((u - pa) / (1.0f - pa), kOneMinus);
        pick *= 1.0f - pa;
        node = b;
      }
    }
    const Item& item = items_[nodes_[node].index];
    uint32_t light = item.first;
    if (item.count > 1) {
      // A triangle group: its member by power, u remapped within it.
      while (light + 1 < item.first + item.count && u >= share_before_[light + 1]) ++light;
      u = share_[light] > 0 ? std::min((u - share_before_[light]) / share_[light], kOneMinus) : 0.0f;
    }
    c.group_pick = pick;  // a triangle's group (of one, or of the item's lights)
    c.group_offset = pick * share_before_[light];
    c.light = light;
    c.pick = pick * share_[light];
    c.u_rest = u;
    return c.pick > 0;
  }
  if (infinite_.empty()) return false;
  size_t k = std::upper_bound(infinite_cdf_.begin(), infinite_cdf_.end(), u) - infinite_cdf_.begin();
  k = std::min(k, infinite_.size() - 1);
  c.light = infinite_[k];
  c.pick = infinite_pick_[c.light];
  c.u_rest = 0;
  return c.pick > 0;
}

// Both children can have zero importance at a point where their parent's had some (the parent's
// box and cone are looser than theirs): no light below can then reach p, and the choice goes by
// their power, so that wherever the root can reach p the pdfs of the tree's lights sum to one
// (a sample there lights nothing, as a failed descent would, and sample and pdf still agree).
float LightTree::first_child_probability(uint32_t node, const Vec3f& p, const Vec3f& n) const {
  const LightCone& a = nodes_[node + 1].cone;
  const LightCone& b = nodes_[nodes_[node].index].cone;
  float ia = importance(a, p, n), ib = importance(b, p, n);
  if (!(ia + ib > 0)) ia = a.phi, ib = b.phi;
  return ia + ib > 0 ? ia / (ia + ib) : 0.5f;
}

float LightTree::item_pdf(const Vec3f& p, const Vec3f& n, uint32_t item) const {
  const Item& it = items_[item];
  float pick = tree_pick_;
  if (!(importance(nodes_[0].cone, p, n) > 0)) return 0.0f;
  uint32_t node = 0;
  for (uint32_t d = 0; d < it.depth; ++d) {
    uint32_t a = node + 1, b = nodes_[node].index;
    float pa = first_child_probability(node, p, n);
    if ((it.path >> d) & 1) {
      pick *= 1.0f - pa;
      node = b;
    } else {
      pick *= pa;
      node = a;
    }
  }
  return pick;
}

float LightTree::pdf(const Vec3f& p, const Vec3f& n, uint32_t light) const {
  int32_t item = item_of_light_[light];
  if (item < 0) return infinite_pick_[light];
  return item_pdf(p, n, static_cast<uint32_t>(item)) * share_[light];
}

float LightTree::group_pdf(const Vec3f& p, const Vec3f& n, uint32_t group) const {
  return item_pdf(p, n, static_cast<uint32_t>(item_of_group_[group]));
}

}  // namespace pt
