// What the builders for materials, textures and lights need from the parser:
// the scene being filled, the name tables, and where the directive came from.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "scene/pbrt_params.h"
#include "scene/scene_desc.h"

namespace tessera {

// pbrt-v4 keeps named materials and textures global (not scoped by
// AttributeBegin/End); float and spectrum textures have separate namespaces.
struct NamedObjects {
  std::map<std::string, int32_t> materials;
  std::map<std::string, int32_t> float_textures;
  std::map<std::string, int32_t> spectrum_textures;
  std::map<std::string, int32_t> media;  // -1: a medium that is not simulated
  std::map<std::string, int32_t> images;  // key: resolved path + "|" + encoding (+ "|grey")
  // Nesting depth of every texture (1: reads no other texture) and of every
  // mix material (1: mixes two non-mix materials), checked against what the
  // kernels evaluate (kMaxTextureNesting, kMaxMixNesting).
  std::vector<int32_t> texture_depth;
  std::map<int32_t, int32_t> mix_depth;  // by material index; absent: not a mix
};

// Textures are evaluated recursively (a bounded stack, on a GPU too); mixes
// of mixes are resolved in a loop of this many steps (material_eval.h).
constexpr int32_t kMaxTextureNesting = 64;
constexpr int32_t kMaxMixNesting = 16;

struct DirectiveContext {
  SceneDesc& scene;
  NamedObjects& names;
  std::string where;          // "file:line" of the directive
  std::string including_dir;  // directory of the file holding it
  std::string search_dir;     // main scene file's directory

  void warn(const std::string& message) const { scene.warnings.push_back(where + ": " + message); }
  [[noreturn]] void fail(const std::string& problem) const { throw SceneError(where + ": " + problem); }
};

}  // namespace tessera
