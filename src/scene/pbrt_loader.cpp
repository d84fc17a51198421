#include "scene/pbrt_loader.h"

#include <filesystem>

#include <sstream>

#include "scene/pbrt_parser.h"
#include "scene/pbrt_paths.h"
#include "scene/scene_file.h"

namespace tessera {
namespace {

SceneDesc load_pbrt_stream(std::istream& in, const std::string& name_for_errors, const std::string& base_dir) {
  PbrtParser parser(base_dir);
  const int last_line = parser.parse_stream(in, name_for_errors, base_dir);
  SceneDesc scene = parser.finish(name_for_errors, last_line);
  scene.source = name_for_errors;
  return scene;
}

}  // namespace

SceneDesc load_pbrt_string(const std::string& text, const std::string& name_for_errors, const std::string& base_dir) {
  std::istringstream in(text);
  return load_pbrt_stream(in, name_for_errors, base_dir);
}

SceneDesc load_pbrt_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path + ":1: a folder, not a scene file");
  std::unique_ptr<std::istream> in = open_scene_file(path);
  if (!in || !*in) throw SceneError(path + ":1: cannot open scene file");
  SceneDesc desc = load_pbrt_stream(*in, path, directory_of(path));
  desc.files_read.insert(desc.files_read.begin(), path);
  return desc;
}

}  // namespace tessera
