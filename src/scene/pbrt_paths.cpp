#include "scene/pbrt_paths.h"

#include <filesystem>

namespace tessera {

std::string resolve_scene_path(const std::string& name, const std::string& including_dir,
                               const std::string& search_dir) {
  namespace fs = std::filesystem;
  fs::path p(name);
  if (p.is_absolute()) return name;
  fs::path first = fs::path(including_dir.empty() ? "." : including_dir) / p;
  std::error_code ec;
  if (fs::exists(first, ec)) return first.lexically_normal().string();
  if (!search_dir.empty()) {
    fs::path second = fs::path(search_dir) / p;
    if (fs::exists(second, ec)) return second.lexically_normal().string();
  }
  return first.lexically_normal().string();
}

std::string directory_of(const std::string& path) {
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

}  // namespace tessera
