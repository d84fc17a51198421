// Writes the GPU check's fixtures (gpu_fixture.h) for the shipped Cornell
// box and door-ajar: run on a machine with the full build, read on one with
// a GPU (scripts/gpu_check.sh). Usage: make_gpu_fixtures OUT_DIR [SPP [WIDTHxHEIGHT]]
// (default 64 spp at 128x96: small enough for the host emulation's image on
// two cores; a larger image fills the device, which 128x96 does not)
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "gpu_fixture.h"
#include "device_pass.h"
#include "render/renderer.h"
#include "scene/pbrt_loader.h"
#include "scene/sampler_setup.h"
#include "render/bvh_build.h"
#include "render/device_backend.h"
#include "render/embree_backend.h"

int main(int argc, char** argv) {
  using namespace tessera;
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_gpu_fixtures OUT_DIR [SPP [WIDTHxHEIGHT]]\n");
    return 2;
  }
  const std::string out = argv[1];
  unsigned long spp_count = 64, width = 128, height = 96;
  const char* p = argc > 2 ? argv[2] : "64";
  if (!cuda_check::read_count(&p, 1ul << 20, &spp_count) || *p != '\0') {
    std::fprintf(stderr, "make_gpu_fixtures: SPP '%s' is not a count from 1 to 2^20\n", argv[2]);
    return 2;
  }
  const uint32_t spp = static_cast<uint32_t>(spp_count);
  p = argc > 3 ? argv[3] : "128x96";
  if (!cuda_check::read_count(&p, 8192, &width) || *p++ != 'x' || !cuda_check::read_count(&p, 8192, &height) ||
      *p != '\0') {
    std::fprintf(stderr, "make_gpu_fixtures: resolution '%s' is not WIDTHxHEIGHT (1 to 8192 each)\n", argv[3]);
    return 2;
  }
  std::filesystem::create_directories(out);
  try {
    for (const char* name : {"cornell-box", "door-ajar"}) {
      SceneDesc desc = load_pbrt_file(std::string(TESSERA_SOURCE_DIR) + "/scenes/" + name + ".pbrt");
      desc.film.xres = static_cast<int>(width);
      desc.film.yres = static_cast<int>(height);
      const SceneData scene(std::move(desc));
      RenderOptions opt;
      opt.seed = 5;
      opt.max_depth = scene.desc().max_depth;
      opt.sampler = sampler_setup(scene.desc());
      opt.force_full_specialisation = true;
      cuda_check::GpuFixture f;
      f.name = name;
      f.settings = make_tile_settings(opt, effective_specialisation(scene, opt, nullptr), false);
      f.width = scene.view().camera.film_width;
      f.height = scene.view().camera.film_height;
      f.spp = spp;
      f.lo = scene.bounds().lo;
      f.hi = scene.bounds().hi;
      f.lights = scene.view().num_lights;
      f.max_emitted = scene.max_emitted_radiance();
      f.host_threads = render_threads(opt);
      const BvhBuild bvh = build_bvh(scene.view());
      const PackedScene packed(scene.view(), bvh.view());
      DeviceBackend device(packed, open_emulated_device(f.host_threads));
      Film film(f.width, f.height);
      const auto t0 = std::chrono::steady_clock::now();
      cuda_check::render_film_pass(device, f.settings, film, 0, spp, f.host_threads);
      f.host_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      f.reference = film.pixels;
      {
        // Embree on the same threads, with the scene's own specialisation: the CPU figure users know.
        RenderOptions embree_opt = opt;
        embree_opt.force_full_specialisation = false;
        EmbreeBackend embree(scene);
        Film embree_film(f.width, f.height);
        const auto e0 = std::chrono::steady_clock::now();
        cuda_check::render_film_pass(embree, make_tile_settings(embree_opt, effective_specialisation(scene, embree_opt, nullptr), false),
                                     embree_film, 0, spp, f.host_threads);
        f.embree_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - e0).count();
      }
      const std::string path = out + "/" + name + ".fixture";
      cuda_check::save_fixture(path, f, packed);
      const double samples = double(f.width) * f.height * spp;
      std::printf("%s: %dx%d, %u spp on %d threads: emulated device %.3f Msamples/s, Embree %.3f Msamples/s\n",
                  path.c_str(), f.width, f.height, spp, f.host_threads, samples / f.host_seconds * 1e-6,
                  samples / f.embree_seconds * 1e-6);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_gpu_fixtures: %s\n", e.what());
    return 1;
  }
  return 0;
}
