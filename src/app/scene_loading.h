// Shared by the subcommands: load a scene file or the built-in Cornell box,
// and print the loader's warnings.
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

SceneDesc load_scene_or_builtin(const std::string& path);

}  // namespace tessera
