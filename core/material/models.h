// The registration of material models: the one list of them. A model is a struct (the material as
// loaded: parameters and texture slots) with
//   using Bsdf = <its BSDF at a shading point>;   static constexpr const char* kName;
//   static constexpr uint8_t kFlags;              the lobes it may have (BsdfFlags)
//   Bsdf at(const TextureLookup&) const;          its BSDF with the textures looked up
//   std::string describe() const;                 its parameters, for `pt info`
//   bool reads_textures() const;                  whether at() reads any texture slot
// in a file of its own in this folder. Adding one: its file, its entry below, its reader mapping
// (core/scene/scene_file.cpp, core/scene/obj_loader.cpp).
#pragma once
#include <array>
#include <string>
#include <string_view>
#include <variant>

#include "core/material/dielectric.h"
#include "core/material/diffuse.h"
#include "core/material/glossy.h"
#include "core/material/metallic_roughness.h"
#include "core/material/mirror.h"

namespace pt {

template <class... Models>
struct ModelList {
  using Material = std::variant<Models...>;
  using Bsdf = std::variant<typename Models::Bsdf...>;
  static constexpr std::array<const char*, sizeof...(Models)> kNames{Models::kName...};
};

using MaterialModels = ModelList<Diffuse, Mirror, Dielectric, Glossy, MetallicRoughness>;
using MaterialModel = MaterialModels::Material;

// The model's name ("diffuse", "glossy" ...), as scene files and `pt info` spell it.
inline const char* model_name(const MaterialModel& m) { return MaterialModels::kNames[m.index()]; }
inline bool is_model_name(std::string_view name) {
  for (const char* n : MaterialModels::kNames) {
    if (name == n) return true;
  }
  return false;
}
inline std::string model_list() {  // "diffuse, mirror, ..."
  std::string out;
  for (const char* n : MaterialModels::kNames) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}
// Lobes the material may show somewhere on its surface.
inline uint8_t model_flags(const MaterialModel& m) {
  return std::visit([](const auto& model) { return model.kFlags; }, m);
}

}  // namespace pt
