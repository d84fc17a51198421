// pbrt-v4 shapes as world-space triangle meshes.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scene/displacement.h"
#include "scene/pbrt_params.h"
#include "scene/scene_desc.h"

namespace tessera {

struct ShapeContext {
  std::string where;          // "file:line" of the Shape directive
  std::string including_dir;  // directory of the file holding the directive
  std::string search_dir;     // main scene file's directory
  Mat4 world_from_object{1.f};
  bool reverse_orientation = false;
  std::vector<std::string>* warnings = nullptr;
  std::vector<std::string>* files_read = nullptr;  // the mesh files it reads are added here
  // A named float texture as a function of uv (plymesh displacement);
  // throws SceneError for an unknown name. Unset: displacement is an error.
  std::function<DisplacementFn(const std::string& name)> float_texture;
};

// trianglemesh, plymesh, bilinearmesh, sphere, disk. Other shapes: a warning
// and nullopt. Throws SceneError for malformed data (bad index, bad counts,
// missing file, non-finite coordinates). The result has material/area_light unset.
std::optional<MeshDesc> make_shape_mesh(const std::string& type, const ParamSet& params, const ShapeContext& ctx);

// Moves a world-space mesh by `m` (object instancing): positions, normals by
// the inverse transpose, and flip_normals toggled when `m` mirrors.
void transform_mesh(MeshDesc& mesh, const Mat4& m);

// Motion blur: the mesh's positions and normals at the end of the transform
// interval, `end_from_start` applied to those at its start.
void add_motion(MeshDesc& mesh, const Mat4& end_from_start);

bool swaps_handedness(const Mat4& m);

}  // namespace tessera
