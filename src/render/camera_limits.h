// The camera's rays as the kernels make them (kernels/camera.h), checked
// once before rendering: every ray must start within the scene's limits
// (scene/scene_limits.h) and have a direction. A "lensradius" or an
// orthographic "screenwindow" of 2e18, or a camera transform that scales
// it there, would start rays Embree refuses; a "screenwindow", "fov" or
// "focaldistance" whose directions square past single precision's range
// normalises to no direction at all (pbrt-v4's Normalize too).
#pragma once

#include <glm/glm.hpp>
#include <string>

#include "kernels/scene_view.h"

namespace tessera {

// Throws SceneError naming `where` (the Camera directive's file:line) for a
// camera whose rays from the film's corners and centre, through the lens's
// edge, at the shutter's start and end, go beyond the limits. `origin`:
// render space's origin in the file's world (for the message).
void check_camera_limits(const CameraView& c, const std::string& where, const glm::dvec3& origin);

}  // namespace tessera
