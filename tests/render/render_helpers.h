// Helpers for tests that render through the library (no subprocess).
#pragma once

#include <string>

#include "master/film.h"
#include "master/renderer.h"
#include "scene/pbrt_loader.h"
#include "worker/embree_backend.h"
#include "worker/scene_data.h"

namespace tessera::testing {

inline RenderResult render_desc(SceneDesc desc, RenderOptions opt) {
  opt.progress = false;
  opt.spp = static_cast<uint32_t>(desc.spp);  // the scene (as edited by the test) decides
  opt.max_depth = desc.max_depth;
  SceneData scene(std::move(desc));
  EmbreeScene embree(scene);
  return render(scene, embree, opt);
}

inline RenderResult render_text(const std::string& pbrt, RenderOptions opt = {}) {
  return render_desc(load_pbrt_string(pbrt, "<test>", "."), opt);
}

// Mean over all pixels and channels.
inline double image_mean(const ImageRgb& img) {
  double s = 0;
  for (float v : img.rgb) s += v;
  return s / img.rgb.size();
}

inline std::string source_dir() { return TESSERA_SOURCE_DIR; }

}  // namespace tessera::testing
