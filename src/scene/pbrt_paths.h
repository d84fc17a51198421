// Where a file named in a scene lives.
#pragma once

#include <string>

namespace tessera {

// Relative names are looked up next to the file that names them first, then in
// the main scene file's directory (pbrt-v4 resolves everything against the
// latter; exporters that write nested Includes rely on either). Returns the
// first candidate that exists, else the first candidate, so errors name it.
std::string resolve_scene_path(const std::string& name, const std::string& including_dir,
                               const std::string& search_dir);

// Directory part of a path ("." when there is none).
std::string directory_of(const std::string& path);

}  // namespace tessera
