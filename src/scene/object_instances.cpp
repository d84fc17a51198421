#include "scene/object_instances.h"

#include "scene/pbrt_shapes.h"

namespace tessera {

bool instance_moves(const InstanceDesc& instance) {
  return instance.render_from_object_end != instance.render_from_object;
}

std::vector<MeshDesc> placed_meshes(const ObjectDesc& object, const InstanceDesc& instance) {
  std::vector<MeshDesc> out;
  out.reserve(object.meshes.size());
  const bool moves = instance_moves(instance);
  for (const MeshDesc& def : object.meshes) {
    MeshDesc copy = def;
    transform_mesh(copy, instance.render_from_object);
    if (moves) {  // its end: the definition (at its own end, if it moves too) under the end map
      MeshDesc end = def;
      if (end.p_end.empty()) end.p_end = end.p, end.n_end = end.n;
      transform_mesh(end, instance.render_from_object_end);
      copy.p_end = std::move(end.p_end);
      copy.n_end = std::move(end.n_end);
    }
    copy.where = instance.where;
    out.push_back(std::move(copy));
  }
  return out;
}

void settle_instances(SceneDesc& scene) {
  std::vector<uint32_t> uses(scene.objects.size(), 0);
  for (const InstanceDesc& inst : scene.instances) ++uses[inst.object];
  std::vector<InstanceDesc> kept;
  std::vector<MeshDesc> meshes;
  size_t next = 0;  // of scene.meshes, in file order
  for (const InstanceDesc& inst : scene.instances) {
    if (uses[inst.object] >= 2) {
      kept.push_back(inst);
      continue;
    }
    for (; next < inst.meshes_before && next < scene.meshes.size(); ++next) meshes.push_back(std::move(scene.meshes[next]));
    for (MeshDesc& m : placed_meshes(scene.objects[inst.object], inst)) meshes.push_back(std::move(m));
  }
  if (meshes.empty()) meshes = std::move(scene.meshes);  // nothing flattened (or only at the end)
  else
    for (; next < scene.meshes.size(); ++next) meshes.push_back(std::move(scene.meshes[next]));
  scene.meshes = std::move(meshes);
  std::vector<uint32_t> renumbered(scene.objects.size(), 0);
  std::vector<ObjectDesc> objects;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    if (uses[i] < 2) continue;
    renumbered[i] = static_cast<uint32_t>(objects.size());
    objects.push_back(std::move(scene.objects[i]));
  }
  for (InstanceDesc& inst : kept) inst.object = renumbered[inst.object];
  scene.objects = std::move(objects);
  scene.instances = std::move(kept);
}

GeometryCount count_geometry(const SceneDesc& scene) {
  GeometryCount c;
  auto add = [&](const MeshDesc& m) {
    c.triangles += m.indices.size() / 3;
    c.vertices += m.p.size();
  };
  for (const MeshDesc& m : scene.meshes) add(m);
  for (const ObjectDesc& o : scene.objects)
    for (const MeshDesc& m : o.meshes) add(m);
  c.instances = scene.instances.size();
  return c;
}

}  // namespace tessera
