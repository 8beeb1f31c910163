// A large instanced scene for measuring instancing: a JSON scene file (or a binary glTF holding the
// mesh once and one node per copy) placing one mesh file many times over a square field, each copy
// turned about the vertical and scaled (`pt gen instances`).
// The same placements can be written as one object per copy instead, which the loader bakes into
// world space: the flattened scene to compare the instanced one against.
#pragma once
#include <cstdint>
#include <string>

namespace pt {

struct InstanceFieldOptions {
  std::string mesh;        // the object file placed (read once here, for its bounds)
  int count = 10000;       // copies
  uint64_t seed = 1;       // turns, scales and jitter
  bool flatten = false;    // one object per copy instead of one object with an instances list
};

// Writes the scene file `path`, .json or .glb (through OutputFile). Throws pt::Error naming the file at fault.
void write_instance_field(const std::string& path, const InstanceFieldOptions& options);

}  // namespace pt
