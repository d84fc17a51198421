// tessera render [SCENE.pbrt] ...
#include <cstdio>
#include <filesystem>
#include <regex>

#include "app/commands.h"
#include "app/guide_setup.h"
#include "app/scene_loading.h"
#include "master/image_output.h"
#include "master/renderer.h"
#include "master/stats_json.h"
#include "scene/scene_effects.h"

namespace tessera {
namespace {

struct RenderArgs {
  std::string scene, output, preview, stats, res;
  int64_t spp = -1, max_depth = -1, threads = 0, tile = 16;
  int64_t seed = -1;
  double time = 0.0;
  bool quiet = false, no_preview = false, full_specialisation = false;
  GuideArgs guide;
};

void parse_resolution(const std::string& res, SceneDesc& d) {
  std::smatch m;
  static const std::regex re("^([0-9]{1,5})x([0-9]{1,5})$");
  if (!std::regex_match(res, m, re) || std::stoi(m[1]) <= 0 || std::stoi(m[2]) <= 0)
    throw std::runtime_error("--res: expected WxH with positive integers, got '" + res + "'");
  const int64_t w = std::stoi(m[1]), h = std::stoi(m[2]);
  if (w > kMaxFilmDimension || h > kMaxFilmDimension || w * h > kMaxFilmPixels)
    throw std::runtime_error("--res: " + res + " is larger than supported (" + std::to_string(kMaxFilmPixels) + " pixels)");
  d.film.xres = static_cast<int32_t>(w);
  d.film.yres = static_cast<int32_t>(h);
}

int run_render(const RenderArgs& a) {
  SceneDesc desc = load_scene_or_builtin(a.scene);
  if (!a.res.empty()) parse_resolution(a.res, desc);
  if (a.max_depth >= 0) desc.max_depth = static_cast<int32_t>(a.max_depth);
  if (a.spp >= 0) desc.spp = static_cast<int32_t>(a.spp);
  if (a.seed >= 0) desc.seed = static_cast<uint64_t>(a.seed);

  RenderOptions opt;
  opt.spp = (a.spp < 0 && a.time > 0) ? 0u : static_cast<uint32_t>(desc.spp);
  opt.time_budget_s = a.time;
  opt.max_depth = desc.max_depth;
  opt.seed = desc.seed;
  opt.threads = static_cast<int32_t>(a.threads);
  opt.tile_size = static_cast<int32_t>(a.tile);
  opt.progress = !a.quiet;
  opt.force_full_specialisation = a.full_specialisation;
  apply_guide_render_options(a.guide, &opt);
  if (opt.spp == 0 && opt.time_budget_s <= 0) throw std::runtime_error("--spp 0 needs a --time budget");

  std::string out = a.output;
  if (out.empty()) {
    // The scene's Film filename, made an EXR (pbrt scenes often name a PNG).
    std::filesystem::path f = std::filesystem::path(desc.film.filename.empty() ? "tessera.exr" : desc.film.filename).filename();
    out = f.replace_extension(".exr").string();
  }
  if (std::filesystem::path(out).extension() != ".exr") throw std::runtime_error("-o: output must end in .exr, got '" + out + "'");
  std::string preview = a.preview;
  if (preview.empty() && !a.no_preview) preview = std::filesystem::path(out).replace_extension(".png").string();

  SceneData scene(std::move(desc));
  std::string guide_why;
  std::unique_ptr<GuideField> guide = make_guide(a.guide, scene, &guide_why);
  const uint32_t spec = effective_specialisation(scene, opt, guide != nullptr);
  std::fprintf(stderr, "tessera: %s: %zu triangles, %u lights, %dx%d, %s, max depth %d\n",
               scene.desc().source.c_str(), scene.num_triangles(), scene.view().num_lights, scene.view().camera.width,
               scene.view().camera.height,
               opt.spp > 0 ? (std::to_string(opt.spp) + " spp").c_str() : "unlimited spp", opt.max_depth);
  std::fprintf(stderr, "tessera: effects: %s; integrator specialisation: %s\n", describe_effects(scene.effects()).c_str(),
               describe_specialisation(spec).c_str());
  if (guide) {
    std::fprintf(stderr, "tessera: guiding: %s (%s), %u direction bins, %s light selection, budget %.0f MB\n",
                 guide->config().target == GuideTarget::QLearning ? "qlearning" : "qtable", guide_why.c_str(),
                 guide->config().grid * guide->config().grid, guide->learned_lights() ? "learned" : "power-based",
                 guide->config().budget_bytes / 1048576.0);
  } else {
    std::fprintf(stderr, "tessera: guiding: none (%s)\n", guide_why.c_str());
  }
  EmbreeScene embree(scene);
  RenderResult r = render(scene, embree, opt, guide.get());
  if (guide) save_guide(a.guide, *guide, scene);

  ImageRgb mean = film_mean(r.film), var = film_variance_of_mean(r.film);
  ExrMetadata meta;
  meta.numbers["spp"] = r.stats.spp;
  meta.numbers["seconds"] = r.stats.seconds;
  meta.strings["seed"] = std::to_string(opt.seed);
  meta.strings["effects"] = describe_effects(scene.effects());
  meta.strings["specialisation"] = describe_specialisation(spec);
  meta.strings["guide"] = r.stats.guide_mode;
  meta.strings["software"] = "tessera " TESSERA_VERSION;
  meta.strings["scene"] = scene.desc().source;
  write_exr(out, mean, &var, meta);
  std::printf("wrote %s\n", out.c_str());
  if (!preview.empty()) {
    write_png_preview(preview, mean);
    std::printf("wrote %s\n", preview.c_str());
  }
  const TileCounters& c = r.stats.counters;
  std::fprintf(stderr, "tessera: %u spp in %.2fs (%.2f Msamples/s, %.2f Mrays/s), stopped by %s",
               r.stats.spp, r.stats.seconds, c.samples / std::max(r.stats.seconds, 1e-9) * 1e-6,
               (c.path.rays + c.path.shadow_rays) / std::max(r.stats.seconds, 1e-9) * 1e-6, r.stats.stop_reason.c_str());
  if (c.rejected_nonfinite || c.rejected_negative)
    std::fprintf(stderr, "; rejected %llu NaN/Inf and %llu negative samples",
                 static_cast<unsigned long long>(c.rejected_nonfinite), static_cast<unsigned long long>(c.rejected_negative));
  std::fputc('\n', stderr);
  if (guide) {
    const GuideFieldStats& g = r.stats.guide;
    std::fprintf(stderr, "tessera: guide: %llu cells, %.1f MB, %llu updates, %llu targets rejected%s\n",
                 static_cast<unsigned long long>(g.cells), g.bytes / 1048576.0, static_cast<unsigned long long>(g.updates),
                 static_cast<unsigned long long>(g.rejected_nonfinite + g.rejected_large),
                 g.budget_reached ? ", memory budget reached" : "");
  }
  if (!a.stats.empty()) {
    write_text_file(a.stats, stats_to_json(r.stats, scene.desc().source, mean.width, mean.height, opt.seed));
    std::printf("wrote %s\n", a.stats.c_str());
  }
  return 0;
}

}  // namespace

CommandRunner add_render_command(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* c = app.add_subcommand("render", "Render a pbrt-v4 scene (default: the built-in Cornell box) to OpenEXR + PNG");
  c->add_option("scene", a->scene, "Scene file in pbrt-v4 syntax (omit for the built-in Cornell box)");
  c->add_option("-o,--output", a->output, "Output EXR (default: the scene's Film filename in the current directory)");
  c->add_option("--spp", a->spp, "Samples per pixel (overrides the scene's Sampler)")->check(CLI::Range(0, 1 << 30));
  c->add_option("--time", a->time, "Time budget in seconds: render whole passes until it is spent")->check(CLI::PositiveNumber);
  c->add_option("--res", a->res, "Resolution WxH (overrides the scene's Film)");
  c->add_option("--max-depth", a->max_depth, "Maximum path depth, counted as pbrt-v4 does (overrides the Integrator)")->check(CLI::Range(0, 1 << 20));
  c->add_option("--seed", a->seed, "Random seed (same seed -> bit-identical image)")->check(CLI::NonNegativeNumber);
  c->add_option("--threads", a->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 4096));
  c->add_option("--tile", a->tile, "Tile size in pixels")->check(CLI::Range(1, 4096));
  c->add_option("--stats", a->stats, "Write render statistics as JSON");
  c->add_option("--preview", a->preview, "sRGB PNG preview (default: beside the EXR)");
  c->add_flag("--no-preview", a->no_preview, "Do not write a PNG preview");
  c->add_flag("-q,--quiet", a->quiet, "No progress output");
  c->add_flag("--full-specialisation", a->full_specialisation,
              "Run the integrator compiled for every effect instead of the scene's effects set (for benchmarks)");
  add_guide_options(c, a->guide);
  return [a] { return run_render(*a); };
}

}  // namespace tessera
