// Object instancing as the loader hands it on (SceneDesc::objects and
// instances): what stays instanced, what is placed as ordinary meshes, and
// what the render will allocate for it.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene_desc.h"

namespace tessera {

// The object's meshes placed by one instance, as ordinary meshes (the
// flattened form): vertices and normals mapped by render_from_object; a
// moving instance's vertices end where render_from_object_end puts them.
std::vector<MeshDesc> placed_meshes(const ObjectDesc& object, const InstanceDesc& instance);

bool instance_moves(const InstanceDesc& instance);

// An object instanced once costs nothing flattened and saves the render a
// level of traversal: such instances become ordinary meshes (appended to
// scene.meshes), objects nobody instances are dropped, and the rest stay
// instanced (objects renumbered in order).
void settle_instances(SceneDesc& scene);

// What the render stores for geometry: every mesh's and object's vertices
// and triangles once, and one placement per instance.
struct GeometryCount {
  uint64_t triangles = 0, vertices = 0, instances = 0;
};
GeometryCount count_geometry(const SceneDesc& scene);

}  // namespace tessera
