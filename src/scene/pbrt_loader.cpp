#include "scene/pbrt_loader.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "scene/pbrt_parser.h"
#include "scene/pbrt_paths.h"

namespace tessera {
namespace {

// Line number of the file's last line, for end-of-file messages.
int last_line_of(const std::string& text) {
  int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  if (!text.empty() && text.back() != '\n') ++lines;
  return std::max(lines, 1);
}

}  // namespace

SceneDesc load_pbrt_string(const std::string& text, const std::string& name_for_errors, const std::string& base_dir) {
  PbrtParser parser(base_dir);
  parser.parse_text(text, name_for_errors, base_dir);
  SceneDesc scene = parser.finish(name_for_errors, last_line_of(text));
  scene.source = name_for_errors;
  return scene;
}

SceneDesc load_pbrt_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ":1: cannot open scene file");
  std::stringstream text;
  text << in.rdbuf();
  return load_pbrt_string(text.str(), path, directory_of(path));
}

}  // namespace tessera
