// Helpers for tests that render through the library (no subprocess).
#pragma once

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "render/film.h"
#include "render/renderer.h"
#include "scene/pbrt_loader.h"
#include "scene/sampler_setup.h"
#include "render/embree_backend.h"
#include "render/scene_data.h"

namespace tessera::testing {

inline RenderResult render_desc(SceneDesc desc, RenderOptions opt) {
  opt.progress = false;
  opt.spp = static_cast<uint32_t>(desc.spp);  // the scene (as edited by the test) decides
  opt.max_depth = desc.max_depth;
  opt.sampler = sampler_setup(desc);
  SceneData scene(std::move(desc));
  EmbreeBackend embree(scene);
  return render(scene, embree, opt);
}

inline std::string source_dir() { return TESSERA_SOURCE_DIR; }

// Options that render `scene` as its file says (depth, sampler), quietly,
// with the given spp and seed.
inline RenderOptions scene_options(const SceneData& scene, uint32_t spp, uint64_t seed) {
  RenderOptions opt;
  opt.progress = false;
  opt.spp = spp;
  opt.max_depth = scene.desc().max_depth;
  opt.sampler = sampler_setup(scene.desc());
  opt.seed = seed;
  return opt;
}

// A shipped scene (scenes/NAME.pbrt) at w x h.
inline SceneData shipped_scene(const std::string& name, int w, int h) {
  SceneDesc d = load_pbrt_file(source_dir() + "/scenes/" + name + ".pbrt");
  d.film.xres = w;
  d.film.yres = h;
  return SceneData(std::move(d));
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

// Bit-for-bit equality of two films (sums, second moments, counts, light-path splats).
inline bool films_identical(const Film& a, const Film& b) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size()) return false;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    if (std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(PixelAccum)) != 0) return false;
  if (a.light_paths != b.light_paths || a.splats.size() != b.splats.size()) return false;
  for (size_t i = 0; i < a.splats.size(); ++i)
    if (std::memcmp(&a.splats[i], &b.splats[i], sizeof(SplatAccum)) != 0) return false;
  return true;
}

// A file name in the temporary folder, unique to this process and `tag`,
// removed when the test ends (images the scenes of a test read).
class TempFile {
 public:
  explicit TempFile(const std::string& tag)
      : path_((std::filesystem::temp_directory_path() / ("tessera_" + tag + "_" + std::to_string(::getpid()))).string()) {}
  ~TempFile() { std::filesystem::remove(path_); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace tessera::testing
