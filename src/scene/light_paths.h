// When caustics are traced from the lights (integrator/light_paths.h): pbrt-v4
// scenes that ask for a bidirectional integrator (bdpt, mlt, sppm,
// lighttracer) get them by default, because their authors chose those
// integrators for light a camera path cannot find. The light tracer needs a
// pinhole camera and a static scene, and a light it can start
// from (area, point or spot).
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

enum class LightPathsMode { Auto, On, Off };

// "auto", "on", "off"; nullopt-free: the command line checks the name.
LightPathsMode light_paths_mode_named(const std::string& name);

// Why the light tracer cannot run on this scene ("" when it can).
std::string light_paths_obstacle(const SceneDesc& desc);

// Whether to trace light paths. Throws for On when light_paths_obstacle says no.
bool light_paths_enabled(const SceneDesc& desc, LightPathsMode mode);

// Whether an Integrator type is a bidirectional method (bdpt, mlt, sppm, lighttracer).
bool bidirectional_integrator(const std::string& type);
// Whether the scene's Integrator directive asks for one.
bool wants_bidirectional(const SceneDesc& desc);

}  // namespace tessera
