// The subdivided icosahedron on the unit sphere: closed, every vertex shared by its neighbours (each
// edge midpoint is made once), 20 * 4^level triangles. A template so the benchmark mesh builds it in
// float and the stability benchmark in double from the one definition; V needs +, * and normalize().
#pragma once
#include <cmath>
#include <cstdint>
#include <algorithm>
#include <unordered_map>
#include <vector>

namespace pt {

template <class V>
void unit_icosphere(int level, std::vector<V>& verts, std::vector<uint32_t>& tris) {
  using S = decltype(V().x);
  const S t = (S(1) + std::sqrt(S(5))) * S(0.5);  // the golden ratio, in V's precision
  verts = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
           {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (V& v : verts) v = normalize(v);
  tris = {0, 11, 5, 0, 5,  1,  0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
          4, 11, 10, 2, 10, 7,  6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
          6, 8,  3,  8, 9,  4,  9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  // Loop-style 1-to-4 split; each edge's midpoint is looked up by its vertex pair, so it is made once.
  for (int l = 0; l < level; ++l) {
    std::unordered_map<uint64_t, uint32_t> midpoint;
    midpoint.reserve(tris.size());
    auto mid = [&](uint32_t a, uint32_t b) {
      uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      auto [it, inserted] = midpoint.try_emplace(key, static_cast<uint32_t>(verts.size()));
      if (inserted) verts.push_back(normalize(verts[a] + verts[b]));
      return it->second;
    };
    std::vector<uint32_t> next;
    next.reserve(tris.size() * 4);
    for (size_t i = 0; i < tris.size(); i += 3) {
      uint32_t a = tris[i], b = tris[i + 1], c = tris[i + 2];
      uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    tris.swap(next);
  }
}

}  // namespace pt
