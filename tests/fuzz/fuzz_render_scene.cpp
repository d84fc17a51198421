// libFuzzer target over loading *and rendering* a scene: pbrt-v4 text
// through the loader (as the "scene" target), then, where it loads, the
// scene's flattening and checks (render/scene_data.h: camera limits, light
// limits), an Embree and a portable-BVH backend built over it, and a render
// on each (and on Embree with caustics traced from the lights, where the
// scene allows that). This is where hostile numbers that the loader lets
// through reach Embree: lens radii, screen windows, far and bright lights,
// media of nearly no density, huge transforms, many instances.
//
// The harness, not the loader, bounds the work: the film is clamped to at
// most 8x8 pixels (its crop window kept), 1 sample per pixel, paths to 5
// bounces, one thread; scenes over 200,000 triangles are skipped.
//
// A clear error (SceneError or another std::exception) is a correct
// answer; a crash, a sanitizer report, a hang or runaway memory is a
// finding. With TESSERA_FUZZ_FINITE set, so is a non-finite pixel in a
// finished render (off by default: emissions up to single precision's
// largest value are accepted, and a pixel's sum of them can overflow it:
// render_corpus/area-light-bright). scripts/fuzz.sh
// builds and runs it ("render" target); the suite replays
// tests/fuzz/render_corpus through it.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>

#include "render/backends.h"
#include "render/film.h"
#include "render/renderer.h"
#include "render/scene_data.h"
#include "scene/light_paths.h"
#include "scene/pbrt_loader.h"
#include "scene/sampler_setup.h"
#include "scene/spectral_choice.h"

namespace {

constexpr int32_t kMaxRes = 8, kMaxDepth = 5;
constexpr uint64_t kMaxTriangles = 200000;

void render_on(const tessera::SceneData& scene, const tessera::SceneDesc& desc, const char* backend_name,
               bool light_paths) {
  tessera::RenderOptions opt;
  opt.progress = false;
  opt.spp = 1;
  opt.max_pass_spp = 1;
  opt.max_depth = std::clamp(desc.max_depth, 0, kMaxDepth);
  opt.seed = desc.seed;
  opt.sampler = tessera::sampler_setup(desc);
  opt.threads = 1;
  opt.tile_size = kMaxRes;
  opt.light_paths = light_paths;
  std::unique_ptr<tessera::TileBackend> backend = tessera::make_tile_backend(backend_name, scene, 1, light_paths);
  opt.force_full_specialisation = backend->serves_full_integrator();  // as `tessera render` sets it
  const tessera::RenderResult r = tessera::render(scene, *backend, opt);
  if (!std::getenv("TESSERA_FUZZ_FINITE")) return;
  const tessera::ImageRgb mean = tessera::film_mean(r.film);
  for (float v : mean.rgb)
    if (!std::isfinite(v)) {
      std::fprintf(stderr, "fuzz_render_scene: a non-finite pixel from %s%s\n", backend_name,
                   light_paths ? " with light paths" : "");
      std::abort();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // Relative paths (Include, plymesh, imagemap) resolve against a folder
    // with nothing in it: they are missing-file errors.
    tessera::SceneDesc desc = tessera::load_pbrt_string(text, "<fuzz>", "/nonexistent-fuzz-dir");
    uint64_t triangles = 0;
    for (const tessera::MeshDesc& mesh : desc.meshes) triangles += mesh.indices.size() / 3;
    if (triangles > kMaxTriangles) return 0;
    desc.film.xres = std::clamp(desc.film.xres, 1, kMaxRes);
    desc.film.yres = std::clamp(desc.film.yres, 1, kMaxRes);
    desc.spp = 1;
    desc.spectral = !tessera::spectral_reason(desc).empty();  // --spectral auto
    const bool auto_paths = tessera::light_paths_enabled(desc, tessera::LightPathsMode::Auto);
    const bool can_paths = tessera::light_paths_obstacle(desc).empty();  // --light-paths on would render
    const tessera::SceneDesc kept = desc;  // SceneData empties the meshes; the options read the rest
    const tessera::SceneData scene(std::move(desc));
    render_on(scene, kept, "embree", auto_paths);
    render_on(scene, kept, "bvh", false);
    if (can_paths && !auto_paths) render_on(scene, kept, "embree", true);
  } catch (const std::exception& e) {
    // A clear error is the right answer to a scene that cannot render.
    std::fprintf(stderr, "fuzz_render_scene: refused: %s\n", e.what());
  }
  return 0;
}
