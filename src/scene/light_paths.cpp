#include "scene/light_paths.h"

#include <stdexcept>

namespace tessera {

LightPathsMode light_paths_mode_named(const std::string& name) {
  if (name == "on") return LightPathsMode::On;
  if (name == "off") return LightPathsMode::Off;
  if (name == "auto" || name.empty()) return LightPathsMode::Auto;
  throw std::invalid_argument("--light-paths: expected auto, on or off, got '" + name + "'");
}

bool bidirectional_integrator(const std::string& type) {
  return type == "bdpt" || type == "mlt" || type == "sppm" || type == "lighttracer";
}

bool wants_bidirectional(const SceneDesc& desc) { return bidirectional_integrator(desc.integrator); }

std::string light_paths_obstacle(const SceneDesc& desc) {
  if (desc.camera.projection != CameraProjection::Perspective) return "the camera is not a perspective camera";
  if (desc.camera.lens_radius > 0.f) return "the camera has a lens (depth of field)";
  if (desc.camera.world_from_camera_end != desc.camera.world_from_camera) return "the camera moves";
  for (const MeshDesc& m : desc.meshes)
    if (!m.p_end.empty()) return "a shape moves";
  for (const InstanceDesc& inst : desc.instances)
    if (inst.render_from_object_end != inst.render_from_object) return "a shape moves";
  for (const ObjectDesc& o : desc.objects)
    for (const MeshDesc& m : o.meshes)
      if (!m.p_end.empty()) return "a shape moves";
  // Light paths connect to the camera through BSDFs evaluated the other way
  // round: the subsurface exit lobe and hair's offset from wo are not
  // reciprocal.
  for (const Material& m : desc.materials)
    if (m.type == MaterialType::Subsurface || m.type == MaterialType::Hair)
      return "the scene has a subsurface or hair material";
  bool light = !desc.area_lights.empty();
  for (const Light& l : desc.lights)
    light = light || l.type == LightType::Point || l.type == LightType::Spot || l.type == LightType::Goniometric ||
            l.type == LightType::Projection;
  if (!light) return "the scene has no area, point, spot, goniometric or projection light";
  return "";
}

bool light_paths_enabled(const SceneDesc& desc, LightPathsMode mode) {
  if (mode == LightPathsMode::Off) return false;
  const std::string obstacle = light_paths_obstacle(desc);
  if (mode == LightPathsMode::On) {
    if (!obstacle.empty()) throw std::runtime_error("--light-paths on: " + obstacle);
    return true;
  }
  return wants_bidirectional(desc) && obstacle.empty();
}

}  // namespace tessera
