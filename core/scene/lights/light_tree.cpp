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
  std::vector<BinaryNode> binary;
  binary.reserve(2 * items_.size() - 1);
  build(binary, order, 0, static_cast<uint32_t>(order.size()), item_bounds, centroids, 0);
  nodes_.reserve(items_.size() / 2 + 1);
  if (binary.size() == 1) {
    // One item: a root with one child.
    nodes_.emplace_back();
    nodes_[0].children.set(0, light_cone(binary[0].bounds));
    nodes_[0].child[0] = kLeaf | binary[0].item;
    items_[binary[0].item].node = 0;
    items_[binary[0].item].lane = 0;
    return;
  }
  collapse(binary, 0, kNone, 0, 0);
}

LightBounds LightTree::build(std::vector<BinaryNode>& binary, std::vector<uint32_t>& order, uint32_t begin,
                             uint32_t end, const std::vector<LightBounds>& item_bounds,
                             const std::vector<Vec3f>& centroids, uint32_t depth) {
  uint32_t index = static_cast<uint32_t>(binary.size());
  binary.emplace_back();
  if (end - begin == 1) {
    binary[index].item = order[begin];
    binary[index].bounds = item_bounds[order[begin]];
    return binary[index].bounds;
  }
  BBox box, centroid_box;
  for (uint32_t i = begin; i < end; ++i) {
    box.expand(item_bounds[order[i]].box);
    centroid_box.expand(centroids[order[i]]);
  }
  Vec3f extent = centroid_box.extent();
  float pad = 1e-3f * length(box.extent());
  uint32_t mid = begin;
  // The depth stays within kMaxDepth (so that a build is O(n log n), and item_pdf's path fits its
  // array): a binned split (which may peel off a single item) only while median splits below it
  // would still end within kMaxDepth levels.
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
  LightBounds first = build(binary, order, begin, mid, item_bounds, centroids, depth + 1);
  binary[index].second = static_cast<uint32_t>(binary.size());
  binary[index].bounds = merge(first, build(binary, order, mid, end, item_bounds, centroids, depth + 1));
  return binary[index].bounds;
}

uint32_t LightTree::collapse(const std::vector<BinaryNode>& binary, uint32_t b, uint32_t parent, uint32_t lane,
                             int depth) {
  // The binary node's two children, then, while there is room, the interior child of the highest
  // cost (the loosest cluster) replaced by its own two, so that each level decides among up to four.
  uint32_t kids[4] = {b + 1, binary[b].second, kNone, kNone};
  int count = 2;
  float pad = 1e-3f * length(binary[b].bounds.box.extent());
  while (count < 4) {
    int open = -1;
    double worst = -1;
    for (int k = 0; k < count; ++k) {
      if (binary[kids[k]].item != kNone) continue;
      double cost = cluster_cost(binary[kids[k]].bounds, pad);
      if (cost > worst) worst = cost, open = k;
    }
    if (open < 0) break;
    uint32_t opened = kids[open];
    for (int k = count; k > open + 1; --k) kids[k] = kids[k - 1];
    kids[open] = opened + 1;
    kids[open + 1] = binary[opened].second;
    ++count;
  }
  uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_[index].parent = parent;
  nodes_[index].lane = lane;
  depth_ = std::max(depth_, depth);
  for (int k = 0; k < count; ++k) {
    const BinaryNode& kid = binary[kids[k]];
    nodes_[index].children.set(k, light_cone(kid.bounds));
    if (kid.item != kNone) {
      nodes_[index].child[k] = kLeaf | kid.item;
      items_[kid.item].node = index;
      items_[kid.item].lane = static_cast<uint32_t>(k);
    } else {
      uint32_t c = collapse(binary, kids[k], index, static_cast<uint32_t>(k), depth + 1);
      nodes_[index].child[k] = c;
    }
  }
  return index;
}


bool LightTree::weights(uint32_t node, const Vec3f& p, const Vec3f& n, float w[4]) const {
  const LightCones4& c = nodes_[node].children;
  importance4(c, p, n, w);
  if ((w[0] + w[1]) + (w[2] + w[3]) > 0) return true;
  // Every child's importance is zero where their parent's was not (its box and cone are looser
  // than theirs): no light below can reach p, and the choice goes by their power, so that
  // wherever the root's children can reach p the pdfs of the tree's lights sum to one (a sample
  // there lights nothing, as a failed descent would, and sample and pdf still agree).
  if (node == 0) return false;
  for (int k = 0; k < 4; ++k) w[k] = c.phi[k];
  if (!((w[0] + w[1]) + (w[2] + w[3]) > 0)) {
    for (int k = 0; k < 4; ++k) w[k] = nodes_[node].child[k] != kNone ? 1.0f : 0.0f;  // lights of no power
  }
  return true;
}

bool LightTree::sample(const Vec3f& p, const Vec3f& n, float u, LightChoice& c) const {
  if (u < tree_pick_) {
    float pick = tree_pick_;
    u = std::min(u / tree_pick_, kOneMinus);
    uint32_t node = 0, child = 0;
    for (;;) {
      float w[4];
      if (!weights(node, p, n, w)) return false;  // no light of the tree can reach p
      float sum = (w[0] + w[1]) + (w[2] + w[3]);
      // The lane whose share of [0, sum) holds u * sum: the number of lanes' upper ends at or below
      // it (a zero-weight lane ends where the one before it does, so none lands on it), counted
      // without branches, which the random choice would mispredict.
      float t = u * sum;
      float ends[4] = {0.0f, w[0], 0.0f, 0.0f};
      ends[2] = ends[1] + w[1];
      ends[3] = ends[2] + w[2];
      int k = int(t >= ends[1]) + int(t >= ends[2]) + int(t >= ends[3]);
      while (k > 0 && !(w[k] > 0)) --k;  // t rounded up past the last lane of any weight
      float before = ends[k];
      pick *= w[k] / sum;
      u = std::clamp((t - before) / w[k], 0.0f, kOneMinus);
      child = nodes_[node].child[k];
      if (child & kLeaf) break;
      node = child;
    }
    const Item& item = items_[child & ~kLeaf];
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

float LightTree::item_pdf(const Vec3f& p, const Vec3f& n, uint32_t item) const {
  // The choices from the leaf up to the root, then multiplied from the root down, in the order
  // (and so with the rounding) of sample().
  float choice[kMaxDepth + 1];
  int levels = 0;
  uint32_t node = items_[item].node, lane = items_[item].lane;
  for (;;) {
    float w[4];
    if (!weights(node, p, n, w)) return 0.0f;
    choice[levels++] = w[lane] / ((w[0] + w[1]) + (w[2] + w[3]));
    if (nodes_[node].parent == kNone) break;
    lane = nodes_[node].lane;
    node = nodes_[node].parent;
  }
  float pick = tree_pick_;
  while (levels > 0) pick *= choice[--levels];
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
