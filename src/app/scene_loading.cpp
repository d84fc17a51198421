#include "app/scene_loading.h"

#include <cstdio>

#include "scene/builtin_scenes.h"
#include "scene/pbrt_loader.h"

namespace tessera {

SceneDesc load_scene_or_builtin(const std::string& path) {
  SceneDesc d = path.empty() ? load_builtin_cornell_box() : load_pbrt_file(path);
  if (d.source.empty()) d.source = path;
  for (const std::string& w : d.warnings) std::fprintf(stderr, "tessera: warning: %s\n", w.c_str());
  return d;
}

}  // namespace tessera
