#include "core/scene/scene_builder.h"

#include "core/util/error.h"

namespace pt {

uint32_t SceneBuilder::add_mesh(Mesh m) {
  meshes.push_back(std::move(m));
  return static_cast<uint32_t>(meshes.size() - 1);
}

void SceneBuilder::add_instance(uint32_t mesh_id, const Transform& to_world) {
  if (mesh_id >= meshes.size()) {
    throw Error(source, "an instance of mesh " + std::to_string(mesh_id) + ", but there are " +
                            std::to_string(meshes.size()) + " meshes");
  }
  std::string problem = instance_transform_problem(to_world);
  if (!problem.empty()) throw Error(source, "an instance of mesh " + std::to_string(mesh_id) + ": " + problem);
  instances.push_back({mesh_id, to_world, to_world.inverse()});
}

void SceneBuilder::resolve_instances() {
  if (meshes.empty() && instances.empty()) return;
  std::vector<uint32_t> uses(meshes.size(), 0);
  for (const Instance& i : instances) ++uses[i.mesh];
  std::vector<uint32_t> renumber(meshes.size(), UINT32_MAX);
  std::vector<Mesh> kept;
  for (size_t m = 0; m < meshes.size(); ++m) {
    if (uses[m] >= 2) {
      renumber[m] = static_cast<uint32_t>(kept.size());
      kept.push_back(std::move(meshes[m]));
    }
  }
  std::vector<Instance> placed;
  for (const Instance& i : instances) {
    if (renumber[i.mesh] == UINT32_MAX) {
      append_transformed(mesh, meshes[i.mesh], i.to_world);
    } else {
      placed.push_back({renumber[i.mesh], i.to_world, i.to_object});
    }
  }
  meshes = std::move(kept);
  instances = std::move(placed);
}

BBox SceneBuilder::geometry_bounds() const {
  BBox b = mesh.bounds();
  std::vector<const Mesh*> object_meshes;
  for (const Mesh& m : meshes) object_meshes.push_back(&m);
  b.expand(instances_bounds(object_meshes, instances));
  for (const Sphere& s : spheres) b.expand(s.bounds());
  return b;
}

}  // namespace pt
