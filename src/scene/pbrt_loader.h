// Loading pbrt-v4 scene files (the subset Tessera renders; see pbrt_parser.h
// and the pbrt_* builders for what is supported and approximated).
#pragma once

#include <string>

#include "scene/scene_desc.h"

namespace tessera {

// Reads `path` and everything it includes. Throws SceneError ("file:line: problem").
SceneDesc load_pbrt_file(const std::string& path);

// Parses scene text; `name_for_errors` stands for the file name in messages
// and `base_dir` resolves relative Include/plymesh/image names.
SceneDesc load_pbrt_string(const std::string& text, const std::string& name_for_errors, const std::string& base_dir);

}  // namespace tessera
