// Scenes compiled into the binary, so that a bare `tessera render` works.
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

// The text of scenes/cornell-box.pbrt, embedded at build time.
const std::string& builtin_cornell_box_text();
SceneDesc load_builtin_cornell_box();

}  // namespace tessera
