// `pt bench rays --bvh-variant SPEC`: BVH build settings other than the defaults, written
// "key=value,key=value", so that two trees can be timed in one process on the same rays (between
// two processes the same code scatters by up to 0.2 on a row on the reference machine, more than
// most settings change it).
#pragma once
#include <string>
#include <string_view>

#include "core/accel/bvh_build.h"

namespace pt {

// The defaults with SPEC's settings applied; throws Error naming the bad key or value. The keys:
// max_leaf, traversal_cost, pack_pair_cost, spatial_split_budget, large_leaf_area,
// float_tree_prims, float_node_growth (the fields of bvh::BuildOptions).
bvh::BuildOptions parse_bvh_variant(std::string_view spec);

// The settings' names and values, for the table's legend.
std::string describe_bvh_variant(std::string_view spec);

}  // namespace pt
