// tessera guide-viz SCENE: look inside a learned guide cache.
//  (a) the learned distribution at a point and normal, as an image of the
//      equal-area direction square (and its brightest bins on stdout);
//  (b) the seed thesis' diagnostic render: every path follows the highest-Q direction.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>

#include "app/commands.h"
#include "app/guide_setup.h"
#include "app/scene_loading.h"
#include "guidecache/guide_diagnostic.h"
#include "guidecache/guide_kinds.h"
#include "render/image_output.h"
#include "render/output_file.h"
#include "render/renderer.h"
#include "render/embree_backend.h"
#include "scene/sampler_setup.h"

namespace tessera {
namespace {

struct VizArgs {
  std::string scene, distribution, diagnostic;
  std::vector<double> point, normal;
  int64_t train_spp = 64, max_depth = 16, seed = 0;
  GuideArgs guide;
};

// An image that would hold NaN or Inf is not written: it would draw nothing
// a reader can trust, and say nothing of why.
void refuse_nonfinite(const std::vector<Float>& values, const std::string& what, const std::string& path) {
  size_t bad = 0;
  for (Float v : values) bad += std::isfinite(v) ? 0 : 1;
  if (bad > 0)
    throw std::runtime_error("guide-viz: " + std::to_string(bad) + " of " + std::to_string(values.size()) + " " + what +
                             " are not finite; " + path + " not written");
}

// The learned radiance per bin at a point: a table cell's values, or the network's answer there.
std::vector<Float> guide_values_at(Guide& guide, const Vec3& p, const Vec3& n, std::string* where, uint32_t* grid) {
  if (auto* field = dynamic_cast<GuideField*>(&guide)) {
    const int32_t cell = field->find_cell(p, n);
    *grid = field->config().grid;
    *where = "cell " + std::to_string(cell);
    const Float* q = field->cell_values(cell);
    return std::vector<Float>(q, q + *grid * *grid);
  }
  auto* neural = dynamic_cast<NeuralGuide*>(&guide);
  if (!neural) throw std::runtime_error("guide-viz: unknown guide");
  const NeuralGuideView view = neural->view();  // the path guide keeps a reference
  NeuralPathGuide pg(view);
  const int32_t s = pg.locate(p, n);
  *grid = kNeuralGrid;
  *where = "network";
  std::vector<Float> q(kNeuralBins);  // row-major, as the table's (the network numbers its bins by tiles)
  for (uint32_t r = 0; r < kNeuralGrid; ++r)
    for (uint32_t c = 0; c < kNeuralGrid; ++c) q[r * kNeuralGrid + c] = neural_site_q(view, pg.site[s], neural_bin_at(r, c));
  return q;
}

void write_distribution(const VizArgs& a, Guide& guide, const glm::dvec3& render_origin) {
  if (a.point.size() != 3 || a.normal.size() != 3)
    throw std::runtime_error("guide-viz: --distribution needs --point X Y Z and --normal X Y Z");
  // The point is in the scene file's world; the guide lives in render space (camera at the origin).
  const Vec3 p(a.point[0] - render_origin.x, a.point[1] - render_origin.y, a.point[2] - render_origin.z);
  Vec3 n(a.normal[0], a.normal[1], a.normal[2]);
  if (!(glm::length(n) > 0.f)) throw std::runtime_error("guide-viz: --normal must not be zero");
  n = glm::normalize(n);
  std::string where;
  uint32_t grid = 0;
  const std::vector<Float> values = guide_values_at(guide, p, n, &where, &grid);
  const uint32_t bins = grid * grid;
  const Float* q = values.data();
  refuse_nonfinite(values, "values at " + where, a.distribution);
  // Each bin becomes a block of pixels; the image is the equal-area square
  // (the centre is +z, the corners -z).
  const int32_t scale = std::max<int32_t>(1, 256 / static_cast<int32_t>(grid));
  ImageRgb img;
  img.width = img.height = static_cast<int32_t>(grid) * scale;
  img.rgb.assign(size_t(img.width) * img.height * 3, 0.f);
  for (int32_t y = 0; y < img.height; ++y)
    for (int32_t x = 0; x < img.width; ++x) {
      // Row 0 is the top of the image: v grows downwards as in the square.
      const uint32_t bin = uint32_t(y / scale) * grid + uint32_t(x / scale);
      for (int c = 0; c < 3; ++c) img.rgb[(size_t(y) * img.width + x) * 3 + c] = q[bin];
    }
  ExrMetadata meta;
  meta.strings["content"] = "learned incident radiance Q per direction bin (equal-area octahedral square)";
  meta.strings["guide"] = guide.mode() + " (" + where + ")";
  write_output(a.distribution, [&](const std::string& p) { write_exr(p, img, nullptr, meta); });
  std::vector<uint32_t> order(bins);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t i, uint32_t j) { return q[i] > q[j] || (q[i] == q[j] && i < j); });
  std::printf("%s at (%g, %g, %g), normal (%g, %g, %g); brightest bins:\n", where.c_str(), p.x, p.y, p.z, n.x, n.y, n.z);
  for (uint32_t k = 0; k < std::min<uint32_t>(5, bins); ++k) {
    const uint32_t b = order[k];
    Vec3 d = equal_area_square_to_sphere(Vec2((b % grid + 0.5f) / grid, (b / grid + 0.5f) / grid));
    std::printf("  bin %3u  dir (%+.3f, %+.3f, %+.3f)  Q %.6g\n", b, d.x, d.y, d.z, q[b]);
  }
  std::printf("wrote %s\n", a.distribution.c_str());
}

void write_diagnostic(const VizArgs& a, const SceneData& scene, const EmbreeBackend& embree, Guide& guide) {
  const SceneView& s = scene.view();
  GuideViews views;
  guide.views(&views);
  const GuideView& g = views.table;
  const NeuralGuideView& nv = views.neural;
  const bool neural = guide.mode() == "neural";
  const EmbreeTracer tracer = embree.tracer();
  ImageRgb img;
  img.width = s.camera.width;
  img.height = s.camera.height;
  img.rgb.assign(size_t(img.width) * img.height * 3, 0.f);
  tbb::parallel_for(0, img.height, [&](int32_t y) {
    for (int32_t x = 0; x < img.width; ++x) {
      Ray ray = generate_camera_ray(s.camera, Vec2(x + 0.5f, y + 0.5f));
      Rgb L;
      if (neural) {
        NeuralPathGuide pg(nv);
        L = trace_greedy_path(s, pg, tracer, ray, static_cast<int32_t>(a.max_depth));
      } else {
        TablePathGuide pg{g};
        L = trace_greedy_path(s, pg, tracer, ray, static_cast<int32_t>(a.max_depth));
      }
      for (int c = 0; c < 3; ++c) img.rgb[(size_t(y) * img.width + x) * 3 + c] = L[c];
    }
  });
  refuse_nonfinite(img.rgb, "greedy paths", a.diagnostic);
  ExrMetadata meta;
  meta.strings["content"] = "greedy paths along the highest learned Q (diagnostic, not a rendering)";
  write_output(a.diagnostic, [&](const std::string& p) { write_exr(p, img, nullptr, meta); });
  write_output(std::filesystem::path(a.diagnostic).replace_extension(".png").string(),
               [&](const std::string& p) { write_png_preview(p, img); });
  std::printf("wrote %s\n", a.diagnostic.c_str());
}

int run_guide_viz(VizArgs a) {
  if (a.distribution.empty() && a.diagnostic.empty())
    throw std::runtime_error("guide-viz: nothing to do; give --distribution FILE.exr and/or --diagnostic FILE.exr");
  check_output_path(a.distribution, "--distribution");
  check_output_path(a.diagnostic, "--diagnostic");
  SceneData scene(load_scene_or_builtin(a.scene));
  std::vector<NamedPath> inputs = {{"--guide-in", a.guide.in}};
  for (const std::string& f : scene.desc().files_read) inputs.push_back({"a file the scene reads", f});
  const std::string png = a.diagnostic.empty() ? "" : std::filesystem::path(a.diagnostic).replace_extension(".png").string();
  check_output_collisions({{"--distribution", a.distribution}, {"--diagnostic", a.diagnostic}, {"--diagnostic's PNG", png}},
                          inputs);
  EmbreeBackend embree(scene);
  // Without a file to load, something must be learned: the table unless
  // --guide neural, or --neural-* options, ask for the network.
  if (!a.guide.in.empty()) a.guide.mode = "auto";  // the file says which kind
  else if (a.guide.mode == "auto" || a.guide.mode == "none")
    a.guide.mode = a.guide.neural_given.empty() ? "qtable" : "neural";
  std::string why;
  std::unique_ptr<Guide> field = make_guide(a.guide, scene, &why);
  if (a.guide.in.empty()) {
    // No saved cache: learn one now with a short guided render.
    RenderOptions opt;
    opt.spp = static_cast<uint32_t>(a.train_spp);
    opt.max_depth = scene.desc().max_depth;
    opt.seed = static_cast<uint64_t>(a.seed);
    opt.sampler = sampler_setup(scene.desc());
    opt.progress = false;
    apply_guide_render_options(a.guide, &opt);
    render(scene, embree, opt, field.get());
    std::printf("trained the %s guide with %lld spp\n", field->mode().c_str(), static_cast<long long>(a.train_spp));
  }
  if (!a.distribution.empty()) write_distribution(a, *field, scene.desc().render_origin);
  if (!a.diagnostic.empty()) write_diagnostic(a, scene, embree, *field);
  save_guide(a.guide, *field, scene);
  return 0;
}

}  // namespace

CommandRunner add_guide_viz_command(CLI::App& app) {
  auto a = std::make_shared<VizArgs>();
  CLI::App* c = app.add_subcommand("guide-viz", "Inspect a learned guide: its distribution at a point, or greedy diagnostic paths");
  c->add_option("scene", a->scene, "Scene file in pbrt-v4 syntax (omit for the built-in Cornell box)");
  c->add_option("--distribution", a->distribution, "Write the learned distribution at --point/--normal (EXR)");
  c->add_option("--point", a->point, "Point X Y Z (world space)")->expected(3);
  c->add_option("--normal", a->normal, "Surface normal X Y Z at the point (the side being lit)")->expected(3);
  c->add_option("--diagnostic", a->diagnostic, "Write the highest-Q greedy-path render (EXR + PNG)");
  c->add_option("--train-spp", a->train_spp, "Without --guide-in: learn with a guided render of this many spp")
      ->check(CLI::Range(1, 1 << 20));
  c->add_option("--max-depth", a->max_depth, "Greedy path length")->check(CLI::Range(1, 1024));
  c->add_option("--seed", a->seed, "Seed of the training render")->check(CLI::NonNegativeNumber);
  add_guide_options(c, a->guide);
  return [a] { return run_guide_viz(*a); };
}

}  // namespace tessera
