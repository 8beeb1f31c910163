#include "renderer/bench/bvh_variant.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>

#include "core/accel/bvh_accel.h"
#include "core/util/error.h"

namespace pt {
namespace {

std::string trim(std::string_view s) {
  size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string_view::npos ? std::string() : std::string(s.substr(b, e - b + 1));
}

std::string shortest(double x) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", x);
  return buf;
}

// A finite number in [lo, hi], the whole of `text`.
double number(const std::string& key, const std::string& text, double lo, double hi) {
  double v = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v) || v < lo || v > hi) {
    throw Error("--bvh-variant: " + key + "=" + text + ": expected a number in [" + shortest(lo) + ", " + shortest(hi) + "]");
  }
  return v;
}

double integer(const std::string& key, const std::string& text, double lo, double hi) {
  double v = number(key, text, lo, hi);
  if (v != std::floor(v)) throw Error("--bvh-variant: " + key + "=" + text + ": expected a whole number");
  return v;
}

// kernels=NAME: an instruction set's copy this CPU runs, or the experimental one where it is built.
void set_kernels(BvhVariant& variant, const std::string& key, const std::string& value) {
  if (value == "experiment") {
    if (!bvh::experiment_kernels_built())
      throw Error("--bvh-variant: " + key + "=experiment: this pt has no experimental kernels (configure with -DPT_BVH_EXPERIMENT=ON)");
    if (!bvh::isa_supported(bvh::Isa::kAvx512))
      throw Error("--bvh-variant: " + key + "=experiment: the experimental kernels need AVX-512, which this CPU lacks");
    variant.kernels = VariantKernels::kExperiment;
    return;
  }
  for (bvh::Isa isa : bvh::kIsas) {
    if (value != bvh::isa_name(isa)) continue;
    if (!bvh::isa_supported(isa)) throw Error("--bvh-variant: " + key + "=" + value + ": this CPU does not run these kernels");
    variant.kernels = VariantKernels::kIsa;
    variant.isa = isa;
    return;
  }
  throw Error("--bvh-variant: " + key + "=" + value + ": expected sse4.2, avx2, avx512 or experiment");
}

using Setter = std::function<void(const std::string&, const std::string&)>;

// Every key of a spec and what it sets in `variant`: the one list that parsing, the error for an
// unknown key and the option's help read.
std::map<std::string, Setter> setters_for(BvhVariant& variant) {
  // The lambdas hold pointers: they outlive this call (the references here would not).
  bvh::BuildOptions* o = &variant.options;
  BvhVariant* target = &variant;
  // Ranges: a leaf holds at most 15 packs (60 triangles; bvh_build.h); the costs are relative to one
  // pack test.
  return {
      {"max_leaf", [o](const std::string& k, const std::string& v) { o->max_leaf = static_cast<int>(integer(k, v, 1, 60)); }},
      {"traversal_cost", [o](const std::string& k, const std::string& v) { o->traversal_cost = static_cast<float>(number(k, v, 0.01, 100)); }},
      {"pack_pair_cost", [o](const std::string& k, const std::string& v) { o->pack_pair_cost = static_cast<float>(number(k, v, 0.01, 100)); }},
      {"spatial_split_budget", [o](const std::string& k, const std::string& v) { o->spatial_split_budget = static_cast<float>(number(k, v, 0, 4)); }},
      {"spatial_split_misses", [o](const std::string& k, const std::string& v) { o->spatial_split_misses = static_cast<int>(integer(k, v, 0, 1e9)); }},
      {"spatial_split_outliers", [o](const std::string& k, const std::string& v) { o->spatial_split_outliers = static_cast<float>(number(k, v, 0, 1)); }},
      {"large_leaf_area", [o](const std::string& k, const std::string& v) { o->large_leaf_area = static_cast<float>(number(k, v, 0, 1)); }},
      {"float_tree_prims", [o](const std::string& k, const std::string& v) { o->float_tree_prims = static_cast<size_t>(integer(k, v, 0, 1e15)); }},
      {"float_node_growth", [o](const std::string& k, const std::string& v) { o->float_node_growth = static_cast<float>(number(k, v, 0, 1e6)); }},
      {"collapse_node_cost", [o](const std::string& k, const std::string& v) { o->collapse_node_cost = static_cast<float>(number(k, v, 0, 100)); }},
      {"large_leaf_flat", [o](const std::string& k, const std::string& v) { o->large_leaf_flat = integer(k, v, 0, 1) != 0; }},
      {"split_planes", [o](const std::string& k, const std::string& v) { o->split_planes = integer(k, v, 0, 1) != 0; }},
      {"kernels", [target](const std::string& k, const std::string& v) { set_kernels(*target, k, v); }},
  };
}

std::string join_keys(const std::map<std::string, Setter>& setters, bool with_kernels) {
  std::string known;
  for (const auto& [name, setter] : setters) {
    if (name == "kernels" && !with_kernels) continue;
    known += (known.empty() ? "" : ", ") + name;
  }
  return known;
}

}  // namespace

std::string bvh_variant_build_keys() {
  BvhVariant variant;
  return join_keys(setters_for(variant), false);
}

BvhVariant parse_bvh_variant(std::string_view spec) {
  BvhVariant variant;
  const std::map<std::string, Setter> setters = setters_for(variant);
  if (trim(spec).empty()) throw Error("--bvh-variant: empty; give key=value settings, e.g. max_leaf=8,traversal_cost=1.5");
  size_t start = 0;
  while (start <= spec.size()) {
    size_t comma = spec.find(',', start);
    std::string_view item = spec.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    size_t eq = item.find('=');
    std::string key = trim(item.substr(0, eq));
    auto it = setters.find(key);
    if (eq == std::string_view::npos || it == setters.end()) {
      throw Error("--bvh-variant: '" + std::string(item) + "': expected key=value with a key of " + join_keys(setters, true));
    }
    it->second(key, trim(item.substr(eq + 1)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return variant;
}

std::unique_ptr<Accel> make_variant_accel(const Geometry& geometry, TriangleTest test, const BvhVariant& variant) {
  switch (variant.kernels) {
    case VariantKernels::kIsa: return bvh::make_bvh_accel_isa(geometry, test, variant.options, variant.isa);
    case VariantKernels::kExperiment: return bvh::make_accel_experiment(geometry, test, variant.options);
    case VariantKernels::kActive: break;
  }
  return make_bvh_accel(geometry, test, variant.options);
}

std::string describe_bvh_variant(std::string_view spec) {
  std::string out;
  for (char c : spec) {
    if (c == ' ' || c == '\t') continue;
    out += c == ',' ? ' ' : c;
  }
  return out;
}

}  // namespace pt
