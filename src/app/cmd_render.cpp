// tessera render [SCENE.pbrt] ...
// Runs locally, or as a farm when started by mpirun (rank 0 = master).
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <regex>
#include <sstream>

#include "app/commands.h"
#include "app/farm_test_stop.h"
#include "app/guide_setup.h"
#include "app/scene_loading.h"
#include "comm/farm_protocol.h"
#include "comm/mpi_transport.h"
#include "comm/scene_wire.h"
#include "master/checkpoint.h"
#include "master/farm_master.h"
#include "render/image_output.h"
#include "render/interrupt.h"
#include "render/output_file.h"
#include "render/renderer.h"
#include "render/snapshots.h"
#include "render/stats_json.h"
#include "scene/pbrt_film.h"
#include "scene/sampler_setup.h"
#include "scene/scene_effects.h"
#include "app/memory_check.h"
#include "scene/object_instances.h"
#include "scene/light_paths.h"
#include "scene/load_stop.h"
#include "scene/spectral_choice.h"
#include "render/backends.h"
#include "render/cpu_affinity.h"
#include "worker/farm_worker.h"

namespace tessera {
namespace {

struct RenderArgs {
  std::string scene, output, preview, stats, res;
  int64_t spp = -1, max_depth = -1, threads = 0, tile = 16;
  std::string seed;  // "": the scene's; any 64-bit value (parse_seed)
  std::string sampler;  // "" = the scene's
  std::string light_sampler;  // "" = the scene's
  std::string spectral = "auto";
  std::string backend = "auto";  // auto, embree, bvh, cuda
  std::string light_paths = "auto";
  double time = 0.0;
  double target_error = 0.0;
  std::string snapshot_every;
  bool quiet = false, no_preview = false, full_specialisation = false;
  std::string checkpoint, resume;
  double checkpoint_every = 60.0;
  std::string guide_sync = "pass";
  double farm_lease = 30.0, farm_timeout = 600.0;
  GuideArgs guide;
};

// Every 64-bit seed is its own: a value out of range is an error, not
// clamped (which would give two seeds one image).
uint64_t parse_seed(const std::string& text) {
  static const std::regex re("^[0-9]{1,20}$");
  errno = 0;
  const bool digits = std::regex_match(text, re);
  const unsigned long long v = digits ? std::strtoull(text.c_str(), nullptr, 10) : 0;
  if (!digits || errno == ERANGE)
    throw std::runtime_error("--seed: expected an integer from 0 to 18446744073709551615, got '" + text + "'");
  return static_cast<uint64_t>(v);
}

void parse_resolution(const std::string& res, SceneDesc& d) {
  std::smatch m;
  // Up to 9 digits each (an int), so that a size too large is named as such.
  static const std::regex re("^([0-9]{1,9})x([0-9]{1,9})$");
  if (!std::regex_match(res, m, re) || std::stoll(m[1]) <= 0 || std::stoll(m[2]) <= 0)
    throw std::runtime_error("--res: expected WxH with positive integers, got '" + res + "'");
  const int64_t w = std::stoll(m[1]), h = std::stoll(m[2]);
  if (w > kMaxFilmDimension || h > kMaxFilmDimension || w * h > kMaxFilmPixels)
    throw std::runtime_error("--res: " + res + " is larger than supported (" + std::to_string(kMaxFilmPixels) + " pixels)");
  d.film.xres = static_cast<int32_t>(w);
  d.film.yres = static_cast<int32_t>(h);
}

// The scene as the command line amends it (resolution, depth, spp, seed).
SceneDesc load_desc(const RenderArgs& a) {
  SceneDesc desc = load_scene_or_builtin(a.scene);
  if (!a.res.empty()) parse_resolution(a.res, desc);
  if (a.max_depth >= 0) desc.max_depth = static_cast<int32_t>(a.max_depth);
  if (a.spp >= 0) desc.spp = static_cast<int32_t>(a.spp);
  if (!a.seed.empty()) desc.seed = parse_seed(a.seed);
  if (!a.sampler.empty()) desc.sampler = sampler_kind_named(a.sampler).value();  // CLI11 checked the name
  for (LightSamplerKind k : {LightSamplerKind::Bvh, LightSamplerKind::Power, LightSamplerKind::Uniform})
    if (a.light_sampler == light_sampler_name(k)) desc.light_sampler = k;  // CLI11 checked the name
  desc.spectral = a.spectral == "on" || (a.spectral == "auto" && !spectral_reason(desc).empty());
  return desc;
}

// A function of the arguments and the (amended) scene only: every rank of a
// farm derives the same options from the scene the master sends.
RenderOptions make_options(const RenderArgs& a, const SceneDesc& desc) {
  RenderOptions opt;
  // A time budget or a target error replaces the scene's sample count unless --spp is given too.
  opt.spp = (a.spp < 0 && (a.time > 0 || a.target_error > 0)) ? 0u : static_cast<uint32_t>(desc.spp);
  opt.time_budget_s = a.time;
  opt.target_error = a.target_error;
  opt.max_depth = desc.max_depth;
  opt.seed = desc.seed;
  opt.sampler = sampler_setup(desc);
  opt.threads = static_cast<int32_t>(a.threads);
  opt.tile_size = static_cast<int32_t>(a.tile);
  opt.progress = !a.quiet;
  opt.force_full_specialisation = a.full_specialisation;
  opt.light_paths = light_paths_enabled(desc, light_paths_mode_named(a.light_paths));
  apply_guide_render_options(a.guide, &opt);
  if (opt.spp == 0 && opt.time_budget_s <= 0 && opt.target_error <= 0)
    throw std::runtime_error("--spp 0 needs a --time budget or a --target-error");
  return opt;
}

struct OutputPaths {
  std::string exr, preview;
};

OutputPaths output_paths(const RenderArgs& a, const SceneDesc& desc) {
  OutputPaths o{a.output, a.preview};
  if (o.exr.empty()) {
    // The scene's Film filename, made an EXR (pbrt scenes often name a PNG).
    std::filesystem::path f = std::filesystem::path(desc.film.filename.empty() ? "tessera.exr" : desc.film.filename).filename();
    o.exr = f.replace_extension(".exr").string();
  }
  if (std::filesystem::path(o.exr).extension() != ".exr") throw std::runtime_error("-o: output must end in .exr, got '" + o.exr + "'");
  if (o.preview.empty() && !a.no_preview) o.preview = std::filesystem::path(o.exr).replace_extension(".png").string();
  return o;
}

Bytes guide_bytes(const Guide& guide, const SceneData& scene) {
  std::ostringstream s(std::ios::binary);
  guide.save(s, scene.fingerprint());
  const std::string str = s.str();
  return Bytes(str.begin(), str.end());
}

std::unique_ptr<Guide> guide_from_bytes(const Bytes& bytes, const SceneData& scene) {
  std::istringstream s(std::string(bytes.begin(), bytes.end()), std::ios::binary);
  std::unique_ptr<Guide> g = load_guide(s, scene.fingerprint());
  check_guide_fits_scene(*g, scene);
  return g;
}

// An exception's message for the one-line error ("std::bad_alloc" says little).
const char* error_text(const std::exception& e) {
  return dynamic_cast<const std::bad_alloc*>(&e) ? "out of memory" : e.what();
}

// No output may overwrite another or anything the render reads (the scene's
// files, --guide-in, --resume); a checkpoint may continue the one it resumes.
void check_outputs_apart(const RenderArgs& a, const OutputPaths& out, const SceneDesc& desc) {
  const std::vector<NamedPath> outputs = {
      {"-o", out.exr}, {"--preview", out.preview}, {"--stats", a.stats}, {"--checkpoint", a.checkpoint}, {"--guide-out", a.guide.out}};
  std::vector<NamedPath> inputs = {{"--guide-in", a.guide.in}, {"--resume", a.resume}};
  for (const std::string& f : desc.files_read) inputs.push_back({f == desc.source ? "the scene file" : "a file the scene reads", f});
  check_output_collisions(outputs, inputs, [](const NamedPath& o, const NamedPath& in) {
    return o.what == "--checkpoint" && in.what == "--resume";
  });
}

// Everything rank 0 (or a local run) decides before rendering.
struct MasterSetup {
  std::unique_ptr<SceneData> scene;
  RenderOptions opt;
  OutputPaths out;
  std::unique_ptr<Guide> guide;
  std::string guide_why;
  std::optional<Checkpoint> resume;
  uint64_t options_fingerprint = 0;
  SnapshotPolicy snapshots;
  std::string light_paths_obstacle;  // why a bidirectional integrator's light paths cannot be traced ("" if they can)
  std::string spectral_why;          // spectral_reason of the scene ("" if RGB would do), before SceneData empties the meshes
};

MasterSetup prepare_master(const RenderArgs& a, Bytes* scene_bytes) {
  MasterSetup m;
  SceneDesc desc = load_desc(a);
  m.opt = make_options(a, desc);
  m.out = output_paths(a, desc);
  check_output_path(m.out.exr, "-o");
  check_output_path(m.out.preview, "--preview");
  check_output_path(a.stats, "--stats", /*stdout_ok=*/true);
  check_output_path(a.checkpoint, "--checkpoint");
  check_output_path(a.guide.out, "--guide-out");
  check_outputs_apart(a, m.out, desc);
  // A resume holds the checkpoint's film twice more; --guide auto's trial two more
  // (the film before a pass, the unguided passes apart).
  const PixelBounds crop = film_pixel_bounds(desc.film);
  check_film_memory(crop.width(), crop.height(), m.opt.light_paths, !a.checkpoint.empty(),
                    (a.resume.empty() ? 0u : 2u) + (a.guide.mode == "auto" ? 2u : 0u));
  const GeometryCount geometry = count_geometry(desc);
  check_scene_memory(geometry.triangles, geometry.vertices, geometry.instances);
  if (!a.snapshot_every.empty()) m.snapshots = parse_snapshot_policy(a.snapshot_every);
  if (scene_bytes) *scene_bytes = encode_scene(desc);
  m.light_paths_obstacle = light_paths_obstacle(desc);  // reads the meshes, which SceneData empties
  m.spectral_why = spectral_reason(desc);                // so does rule (d) of --spectral auto
  m.scene = std::make_unique<SceneData>(std::move(desc));
  m.guide = make_guide(a.guide, *m.scene, &m.guide_why);
  // The default must not cost: a trial decides whether the guide pays.
  m.opt.guide_trial = m.guide && a.guide.mode == "auto";
  m.options_fingerprint = render_options_fingerprint(m.opt, m.scene->view().camera.width, m.scene->view().camera.height,
                                                     m.guide ? m.guide->mode() : "none") ^
                          m.scene->film_fingerprint();
  if (!a.resume.empty()) {
    if (!a.guide.in.empty()) throw std::runtime_error("--resume and --guide-in contradict each other (the checkpoint holds the guide)");
    m.resume = read_checkpoint(a.resume, m.scene->fingerprint(), m.options_fingerprint);
    if (m.guide) {
      try {
        m.guide = guide_from_bytes(m.resume->guide, *m.scene);
        check_guide_options(a.guide, *m.guide);
      } catch (const std::exception& e) {
        throw std::runtime_error("--resume " + a.resume + ": " + e.what());
      }
      if (a.guide.mix) m.guide->set_guide_prob(static_cast<Float>(*a.guide.mix));
      m.guide_why = "resumed from " + a.resume;
    }
  }
  return m;
}

void log_setup(const MasterSetup& m, uint32_t spec, int32_t ranks, int32_t machines) {
  const SceneData& scene = *m.scene;
  std::fprintf(stderr, "tessera: %s: %zu triangles, %u lights, %s, %s, max depth %d\n",
               scene.desc().source.c_str(), scene.num_triangles(), scene.view().num_lights,
               describe_film_size(scene.view().camera).c_str(),
               m.opt.spp > 0 ? (std::to_string(m.opt.spp) + " spp").c_str() : "unlimited spp", m.opt.max_depth);
  std::fprintf(stderr, "tessera: effects: %s; integrator specialisation: %s\n", describe_effects(scene.effects()).c_str(),
               describe_specialisation(spec).c_str());
  const std::string& why = m.spectral_why;
  std::fprintf(stderr, "tessera: transport: %s\n",
               scene.desc().spectral ? ("spectral (" + (why.empty() ? std::string("--spectral on") : why) + ")").c_str()
                                     : (why.empty() ? "rgb" : ("rgb (--spectral off; " + why + ")").c_str()));
  if (m.opt.light_paths) {
    std::fprintf(stderr, "tessera: caustics of area, point and spot lights seen through specular surfaces: traced from the lights\n");
  } else if (wants_bidirectional(scene.desc())) {
    const std::string& obstacle = m.light_paths_obstacle;
    std::fprintf(stderr, "tessera: integrator \"%s\": caustics from path tracing alone (%s)\n",
                 scene.desc().integrator.c_str(), obstacle.empty() ? "--light-paths off" : obstacle.c_str());
  }
  if (m.guide) {
    std::fprintf(stderr, "tessera: guiding: %s (%s), %s\n", m.guide->mode().c_str(), m.guide_why.c_str(),
                 describe_guide(*m.guide).c_str());
  } else {
    std::fprintf(stderr, "tessera: guiding: none (%s)\n", m.guide_why.c_str());
  }
  if (m.opt.target_error > 0) {
    std::string limits;
    char b[48];
    if (m.opt.spp > 0) limits += " or " + std::to_string(m.opt.spp) + " spp";
    if (m.opt.time_budget_s > 0) {
      std::snprintf(b, sizeof b, " or %g s", m.opt.time_budget_s);
      limits += b;
    }
    std::fprintf(stderr, "tessera: stops at estimated relMSE <= %g%s, whichever comes first%s\n", m.opt.target_error,
                 limits.c_str(), limits.empty() ? " (no --time or --spp limit: runs until then)" : "");
  }
  if (ranks > 1)
    std::fprintf(stderr, "tessera: farm: %d ranks on %d machine%s (rank 0 schedules and renders)\n", ranks, machines,
                 machines == 1 ? "" : "s");
  if (m.resume)
    std::fprintf(stderr, "tessera: resuming at %u spp (%u passes) from checkpoint\n", m.resume->so_far.stats.spp,
                 m.resume->so_far.stats.passes);
}

// What every image of this render records, final or snapshot.
ExrMetadata base_metadata(const MasterSetup& m, uint32_t spec) {
  ExrMetadata meta;
  meta.strings["seed"] = std::to_string(m.opt.seed);
  meta.strings["sampler"] = sampler_name(m.opt.sampler.kind);
  meta.strings["effects"] = describe_effects(m.scene->effects());
  meta.strings["transport"] = m.scene->desc().spectral ? "spectral" : "rgb";
  meta.strings["light_sampler"] = light_sampler_name(m.scene->desc().light_sampler);
  meta.strings["specialisation"] = describe_specialisation(spec);
  meta.strings["software"] = "tessera " TESSERA_VERSION;
  meta.strings["scene"] = m.scene->desc().source;
  const CameraView& c = m.scene->view().camera;
  if (c.film_width != c.width || c.film_height != c.height) {
    // pbrt-v4's crop: the image holds only these pixels of the full resolution.
    meta.strings["crop_pixel_bounds"] = std::to_string(c.film_x0) + " " + std::to_string(c.film_x0 + c.film_width) + " " +
                                        std::to_string(c.film_y0) + " " + std::to_string(c.film_y0 + c.film_height);
    meta.strings["full_resolution"] = std::to_string(c.width) + "x" + std::to_string(c.height);
  }
  return meta;
}

// "time (target relMSE 1e-05 not reached: estimated 0.00031, about 300s more would reach it)"
std::string describe_stop(const RenderStats& s) {
  char b[200];
  if (s.stop_reason == "target-error")
    std::snprintf(b, sizeof b, "target-error (estimated relMSE %.3g <= %.3g)", s.estimated_rel_mse, s.target_error);
  else if (s.target_error > 0 && s.estimated_rel_mse >= 0)
    // relMSE ~ 1/time: what reaching the target would have cost.
    std::snprintf(b, sizeof b, "%s (target relMSE %.3g not reached: estimated %.3g, about %.0fs more would reach it)",
                  s.stop_reason.c_str(), s.target_error, s.estimated_rel_mse,
                  s.seconds * (s.estimated_rel_mse / s.target_error - 1.0));
  else if (s.target_error > 0)
    std::snprintf(b, sizeof b, "%s (target relMSE %.3g not reached: too few samples to estimate it)", s.stop_reason.c_str(),
                  s.target_error);
  else if (s.stop_reason == "interrupted")
    std::snprintf(b, sizeof b, "an interrupt (SIGINT/SIGTERM): the image so far is written");
  else
    std::snprintf(b, sizeof b, "%s", s.stop_reason.c_str());
  return b;
}

// --guide auto's trial: each window's figures, then the decision and what it took out of the image.
void log_guide_trial(const GuideTrial& t) {
  if (t.state == GuideTrialState::Off) return;
  for (uint32_t k = 0; k < t.windows_done; ++k) {
    const GuideTrialWindow& w = t.window[k];
    std::fprintf(stderr,
                 "tessera: guide trial: window at %u spp (%s guide): relative variance x cost per sample %.3g guided, "
                 "%.3g unguided (relative variance %.3g and %.3g, cost %.3g and %.3g)\n",
                 w.start_spp, w.start_spp >= t.mature_spp ? "mature" : "young", w.inefficiency[1], w.inefficiency[0],
                 w.rel_var[1], w.rel_var[0], w.cost[1], w.cost[0]);
  }
  if (t.state == GuideTrialState::Pending) {
    std::fprintf(stderr, "tessera: guide trial: undecided when the render ended (guide %s)\n", t.guiding ? "on" : "off");
    return;
  }
  const bool kept = t.state == GuideTrialState::Kept;
  std::fprintf(stderr, "tessera: guide trial: guiding %s", kept ? "kept" : "switched off for the rest of the render");
  if (t.dropped_method >= 0)
    std::fprintf(stderr, "; the %s passes (%u spp) left the image, rendered again %s\n",
                 t.dropped_method == 1 ? "guided" : "unguided", t.dropped_spp, kept ? "guided" : "unguided");
  else
    std::fprintf(stderr, "; every sample stays in the image\n");
}

void write_outputs(const RenderArgs& a, const MasterSetup& m, const RenderResult& r, uint32_t spec,
                   const std::vector<SnapshotRecord>& snapshots) {
  const SceneData& scene = *m.scene;
  ImageRgb mean = film_mean(r.film), var = film_variance_of_mean(r.film);
  ExrMetadata meta = base_metadata(m, spec);
  add_render_metadata(&meta, r.stats);
  if (const uint64_t saturated = add_variance_metadata(&meta, var)) {
    std::fprintf(stderr,
                 "tessera: warning: the variance layer exceeds the float range in %llu pixels (radiance near 1e19 or "
                 "more): stored as the largest float; the stats' estimated relMSE (in double) stays valid\n",
                 static_cast<unsigned long long>(saturated));
  }
  write_output(m.out.exr, [&](const std::string& p) { write_exr(p, mean, &var, meta); });
  std::printf("wrote %s\n", m.out.exr.c_str());
  if (!m.out.preview.empty()) {
    write_output(m.out.preview, [&](const std::string& p) { write_png_preview(p, mean); });
    std::printf("wrote %s\n", m.out.preview.c_str());
  }
  const TileCounters& c = r.stats.counters;
  std::fprintf(stderr, "tessera: %u spp in %.2fs (%.2f Msamples/s, %.2f Mrays/s), stopped by %s",
               r.stats.spp, r.stats.seconds, c.samples / std::max(r.stats.seconds, 1e-9) * 1e-6,
               (c.path.rays + c.path.shadow_rays) / std::max(r.stats.seconds, 1e-9) * 1e-6, describe_stop(r.stats).c_str());
  if (r.stats.estimated_rel_mse >= 0) std::fprintf(stderr, "; estimated relMSE %.3g", r.stats.estimated_rel_mse);
  if (c.rejected_nonfinite || c.rejected_negative)
    std::fprintf(stderr, "; rejected %llu NaN/Inf and %llu negative samples",
                 static_cast<unsigned long long>(c.rejected_nonfinite), static_cast<unsigned long long>(c.rejected_negative));
  if (c.path.untraceable_rays)
    std::fprintf(stderr, "; %llu rays beyond the tracer's reach taken as misses",
                 static_cast<unsigned long long>(c.path.untraceable_rays));
  std::fputc('\n', stderr);
  if (m.guide && m.guide->mode() == "neural") {
    const NeuralGuideStats& n = r.stats.neural_guide;
    std::fprintf(stderr,
                 "tessera: guide: %llu parameters, %.2f MB with Adam's moments, %llu steps on %llu targets, loss %.4g, "
                 "%.3fs training, %.2f us per inference, %llu targets rejected\n",
                 static_cast<unsigned long long>(n.params), n.bytes / 1048576.0, static_cast<unsigned long long>(n.steps),
                 static_cast<unsigned long long>(n.targets), n.loss, n.train_seconds, n.inference_seconds * 1e6,
                 static_cast<unsigned long long>(n.rejected_nonfinite + n.rejected_large));
  } else if (m.guide) {
    const GuideFieldStats& g = r.stats.guide;
    std::fprintf(stderr, "tessera: guide: %llu cells, %.1f MB, %llu updates, %llu targets rejected%s\n",
                 static_cast<unsigned long long>(g.cells), g.bytes / 1048576.0, static_cast<unsigned long long>(g.updates),
                 static_cast<unsigned long long>(g.rejected_nonfinite + g.rejected_large),
                 g.budget_reached ? ", memory budget reached" : "");
    log_guide_trial(r.stats.guide_trial);
    if (r.stats.ranks > 1 && r.stats.guide_syncs > 0)
      std::fprintf(stderr, "tessera: guide sync: %u reductions of %.2f MB, %.3fs (%.1f%% of the render)\n",
                   r.stats.guide_syncs, r.stats.guide_sync_bytes / 1048576.0, r.stats.guide_sync_seconds,
                   100.0 * r.stats.guide_sync_seconds / std::max(r.stats.seconds, 1e-9));
  }
  if (!a.stats.empty()) {
    write_output(a.stats, [&](const std::string& p) {
      write_text_file(p, stats_to_json(r.stats, scene.desc().source, mean.width, mean.height, m.opt.seed, snapshots));
    });
    if (a.stats != "-") std::printf("wrote %s\n", a.stats.c_str());
  }
}

// Renders on this process (executor: its threads, or the farm) and writes
// the outputs; checkpoints after passes when asked.
RenderResult render_and_write(const RenderArgs& a, MasterSetup& m, PassExecutor& executor,
                              const std::function<void(RenderStats&)>& add_stats = {}) {
  const uint32_t spec = effective_specialisation(*m.scene, m.opt, m.guide.get());
  log_setup(m, spec, executor.ranks(), executor.machines());
  double last_checkpoint = m.resume ? m.resume->so_far.stats.seconds : 0.0;
  uint32_t checkpointed_spp = ~0u;  // spp of the last checkpoint this run wrote (none yet)
  std::optional<SnapshotWriter> snapshots;
  if (m.snapshots.enabled()) snapshots.emplace(m.snapshots, m.out.exr, base_metadata(m, spec), m.resume.has_value());
  PassEndHook hook;
  if (!a.checkpoint.empty() || snapshots) {
    hook = [&](const RenderResult& so_far, const Guide* guide) {
      if (snapshots) snapshots->on_pass_end(so_far);
      if (a.checkpoint.empty() || so_far.stats.seconds - last_checkpoint < a.checkpoint_every) return;
      write_checkpoint(a.checkpoint, so_far, guide, m.scene->fingerprint(), m.options_fingerprint);
      last_checkpoint = so_far.stats.seconds;
      checkpointed_spp = so_far.stats.spp;
    };
  }
  RenderResult r = render(*m.scene, executor, m.opt, m.guide.get(), m.resume ? &m.resume->so_far : nullptr, hook);
  if (r.stats.stop_reason == "interrupted" && r.stats.spp == 0) {
    // Interrupted while loading: an empty image must not replace earlier outputs.
    std::fprintf(stderr, "tessera: interrupted before the first pass: nothing written\n");
    return r;
  }
  // The finished render is a checkpoint too: --resume with a larger --spp continues it.
  if (!a.checkpoint.empty() && checkpointed_spp != r.stats.spp)
    write_checkpoint(a.checkpoint, r, m.guide.get(), m.scene->fingerprint(), m.options_fingerprint);
  if (add_stats) add_stats(r.stats);
  if (m.guide) save_guide(a.guide, *m.guide, *m.scene);
  write_outputs(a, m, r, spec, snapshots ? snapshots->records() : std::vector<SnapshotRecord>{});
  return r;
}

// This process's backend (--backend), built over the scene; the log says
// which and, for auto, why. auto falls back to Embree where the device it
// picked cannot take the scene (out of device memory, say).
std::unique_ptr<TileBackend> backend_for(const RenderArgs& a, const MasterSetup& m, bool log) {
  std::string why;
  std::string name = resolve_backend(a.backend, m.scene.get(), m.opt.light_paths, &why);
  std::unique_ptr<TileBackend> backend;
  try {
    backend = make_tile_backend(name, *m.scene, render_threads(m.opt), m.opt.light_paths);
  } catch (const std::exception& e) {
    if (a.backend != "auto" || name == "embree") throw;
    why = "auto: " + name + " failed: " + e.what();
    name = "embree";
    backend = make_tile_backend(name, *m.scene, render_threads(m.opt), m.opt.light_paths);
  }
  if (log) std::fprintf(stderr, "tessera: backend: %s%s%s\n", name.c_str(), why.empty() ? "" : " (", why.empty() ? "" : (why + ")").c_str());
  return backend;
}

int run_render_local(const RenderArgs& a) {
  resolve_backend(a.backend);  // an unavailable backend fails before the scene loads
  MasterSetup m = prepare_master(a, nullptr);
  std::unique_ptr<TileBackend> backend = backend_for(a, m, true);
  // The portable BVH and the device run the full integrator: the metadata
  // and stats say so.
  if (backend->serves_full_integrator()) m.opt.force_full_specialisation = true;
  LocalPassExecutor executor(*backend, render_threads(m.opt));
  render_and_write(a, m, executor);
  return 0;
}

// "30 s", "2.5 s".
std::string seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}

// Ends a finished farm whose silent ranks would hold it open: Open MPI's
// abort kills them (a stopped process too) and makes mpirun exit with the
// status given, the one the render earned. The kill sequence starts with
// SIGCONT and SIGTERM to every rank, this one included, which are then no
// longer requests to stop a render.
[[noreturn]] void end_job_without(const std::vector<SilentRank>& silent) {
  for (const SilentRank& r : silent)
    std::fprintf(stderr, "tessera: farm: rank %d silent for %.0f s; ending the job without it (every output is written)\n",
                 r.rank, r.silent_s);
  std::fflush(stderr);
  const int code = interrupt_requested() ? 130 : 0;
  for (int sig : {SIGINT, SIGTERM, SIGCONT}) std::signal(sig, SIG_DFL);
  MpiSession::abort(code);
}

// The master's part of a farm: renders and writes every output, then tells
// the workers to stop. A worker that stays silent holds the job open
// (mpirun waits for every rank), so the master ends the job without it,
// with the status the render earned: the outputs are whole by then.
void run_farm_master(const RenderArgs& a, MasterSetup& m, MpiSession& mpi, Transport& t, TileBackend& backend,
                     int32_t threads, bool sync) {
  FarmMasterOptions options;
  options.local_threads = std::max(1, threads);
  options.sync_guide = sync;
  options.lease_s = a.farm_lease;
  options.guide = m.guide.get();
  options.scene_fingerprint = m.scene->fingerprint();
  options.pause = farm_test_stop(0);
  FarmMaster farm(t, backend, options);
  if (!farm.backends_agree_bitwise())
    std::fprintf(stderr,
                 "tessera: farm: ranks render with %s: which rank renders a tile depends on timing, so the image is "
                 "reproducible statistically, not bit for bit (docs/farm.md)\n",
                 farm.backends().c_str());
  render_and_write(a, m, farm, [&](RenderStats& s) {
    s.guide_sync = a.guide_sync;
    s.guide_sync_seconds = farm.sync_seconds();
    s.guide_sync_bytes = farm.sync_bytes();
    s.guide_syncs = farm.syncs();
  });
  const std::vector<SilentRank> silent = farm.finish();
  if (!silent.empty()) end_job_without(silent);
  // Every worker that took part said bye, but one stopped before it is
  // through MPI_Finalize would still hold the job.
  mpi.end_within(a.farm_lease, interrupt_requested() ? 130 : 0,
                 "tessera: farm: a rank did not end within " + seconds_text(a.farm_lease) +
                     " of the render; ending the job without it (every output is written)");
}

// A worker's part of a farm: renders tiles until the master says stop.
void run_farm_worker_rank(const RenderArgs& a, MasterSetup& m, MpiSession& mpi, Transport& t, TileBackend& backend,
                          int32_t threads, bool sync) {
  const uint32_t spec = effective_specialisation(*m.scene, m.opt, m.guide.get());
  FarmWorkerOptions options;
  options.sync_guide = sync;
  options.threads = std::max(1, threads);
  options.timeout_s = a.farm_timeout;
  options.scene_fingerprint = m.scene->fingerprint();
  options.pause = farm_test_stop(t.rank());
  run_farm_worker(t, backend, make_tile_settings(m.opt, spec, m.guide != nullptr), m.guide, options);
  // The master said stop once every output was written.
  mpi.end_within(a.farm_timeout, interrupt_requested() ? 130 : 0,
                 "tessera: farm: rank " + std::to_string(t.rank()) + ": the job did not end within " +
                     seconds_text(a.farm_timeout) + " of the render; ending it (every output is written)");
}

// mpirun -np N tessera render ...: rank 0 parses the scene, sends it and the
// starting guide to every rank, schedules tiles, renders too, and writes
// all outputs; the other ranks render tiles.
int run_render_farm(const RenderArgs& a) {
  resolve_backend(a.backend);  // an unavailable backend fails before the farm starts
  MpiSession mpi;
  std::unique_ptr<Transport> t = mpi.world();
  const bool master = t->rank() == 0;
  const bool sync = a.guide_sync == "pass";

  FarmSetup setup;
  MasterSetup m;
  if (master) {
    try {
      m = prepare_master(a, &setup.scene);
      if (m.guide) setup.guide = guide_bytes(*m.guide, *m.scene);
    } catch (const std::exception& e) {
      // Printed before the workers hear of it: mpirun may end the job as
      // soon as they exit.
      std::fprintf(stderr, "tessera: error: %s\n", error_text(e));
      std::fflush(stderr);
      setup = FarmSetup{e.what(), {}, {}};
      Bytes b = encode(setup);
      t->broadcast(b, 0);  // the workers stop too
      return dynamic_cast<const SceneError*>(&e) ? 2 : 1;
    }
  }
  Bytes b = master ? encode(setup) : Bytes{};
  t->broadcast(b, 0);
  try {
    setup = decode<FarmSetup>(b);
    if (!setup.error.empty()) return 0;  // the master reports it and exits non-zero
    if (!master) {
      SceneDesc desc = decode_scene(setup.scene);
      m.opt = make_options(a, desc);
      m.scene = std::make_unique<SceneData>(std::move(desc));
    }
    // Every rank, the master included, starts from the guide in the bytes
    // it sent: identical fields everywhere.
    m.guide = setup.guide.empty() ? nullptr : guide_from_bytes(setup.guide, *m.scene);
    if (m.guide && a.guide.mix) m.guide->set_guide_prob(static_cast<Float>(*a.guide.mix));
    // Embree and oneTBB start their threads below: widen first.
    const bool widened = widen_affinity_if_alone(t->ranks_on_this_machine());
    if (widened && master)
      std::fprintf(stderr, "tessera: farm: rank 0 is alone on its machine; using all its cores (mpirun had bound it to fewer)\n");
    // Each rank renders with its own backend (a GPU where it has one).
    std::unique_ptr<TileBackend> backend = backend_for(a, m, master);
    const int32_t threads = render_threads(m.opt, t->ranks_on_this_machine());
    if (master) run_farm_master(a, m, mpi, *t, *backend, threads, sync);
    else run_farm_worker_rank(a, m, mpi, *t, *backend, threads, sync);
    return 0;
  } catch (const std::exception& e) {
    // A rank that fails mid-render cannot be waited for: end the whole job.
    std::fprintf(stderr, "tessera: error: rank %d: %s\n", t->rank(), error_text(e));
    std::fflush(stderr);
    MpiSession::abort(1);
  }
}

// Ctrl-C or SIGTERM: the render stops after its pass and writes what it has
// (render/interrupt.h); the exit status then says it was interrupted.
int run_render(const RenderArgs& a) {
  // Open MPI's launcher (not srun) starts its kill sequence with SIGCONT.
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  install_interrupt_handlers(std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr, rank == nullptr || std::string(rank) == "0");
  set_load_stop_check(interrupt_requested);  // a signal while the scene loads stops the load
  try {
    const int rc = launched_by_mpirun() ? run_render_farm(a) : run_render_local(a);
    return rc == 0 && interrupt_requested() ? 130 : rc;
  } catch (const LoadInterrupted& e) {
    std::fprintf(stderr, "tessera: %s\n", e.what());
    return 130;
  }
}

}  // namespace

CommandRunner add_render_command(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* c = app.add_subcommand("render", "Render a pbrt-v4 scene (default: the built-in Cornell box) to OpenEXR + PNG; under mpirun, as a farm");
  c->add_option("scene", a->scene, "Scene file in pbrt-v4 syntax (omit for the built-in Cornell box)");
  c->add_option("--backend", a->backend,
                "What renders the tiles: auto (cuda where there is a device and the scene and guide can go there, else embree), "
                "embree, bvh (the GPU's BVH on the CPU), cuda, emulated-device (the GPU's kernel on the CPU, for "
                "testing); bvh, cuda and emulated-device run the full integrator")
      ->check(CLI::IsMember({"auto", "embree", "bvh", "cuda", "emulated-device"}));
  c->add_option("-o,--output", a->output, "Output EXR (default: the scene's Film filename in the current directory)");
  c->add_option("--spp", a->spp, "Samples per pixel (overrides the scene's Sampler)")->check(CLI::Range(0, 1 << 30));
  c->add_option("--time", a->time, "Time budget in seconds: render passes until it is spent, the last cut to the samples that fit")->check(positive_number());
  c->add_option("--target-error", a->target_error,
                 "Stop after the first pass whose estimated relMSE is at or below this (with --time or --spp: whichever comes first)")
      ->check(positive_number());
  c->add_option("--snapshot-every", a->snapshot_every,
                "Write the image so far every SECONDS, or at doubling sample counts ('doubling'), into <output>-snapshots/");
  c->add_option("--res", a->res, "Resolution WxH (overrides the scene's Film)");
  c->add_option("--max-depth", a->max_depth, "Maximum path depth, counted as pbrt-v4 does (overrides the Integrator)")->check(CLI::Range(0, 1 << 20));
  c->add_option("--seed", a->seed, "Random seed, 0 to 2^64-1 (same seed -> bit-identical image)");
  c->add_option("--sampler", a->sampler,
                "zsobol | paddedsobol | sobol | stratified | independent | halton (pbrt-v4's samplers; sobol is drawn as paddedsobol); default: the scene's Sampler")
      ->check(CLI::IsMember({"zsobol", "paddedsobol", "sobol", "stratified", "independent", "halton"}));
  c->add_option("--light-sampler", a->light_sampler,
                "bvh | power | uniform: how next-event estimation picks a light (pbrt-v4's lightsampler); default: the scene's Integrator, else bvh")
      ->check(CLI::IsMember({"bvh", "power", "uniform"}));
  c->add_option("--spectral", a->spectral,
                "on: paths carry sampled wavelengths and colours become pbrt-v4's spectra; off: paths carry RGB; "
                "auto (default): spectral where it changes the picture (measured spectra, strongly coloured lights, "
                "saturated reflectances over several bounces; tessera info says which)")
      ->check(CLI::IsMember({"on", "off", "auto"}));
  c->add_option("--light-paths", a->light_paths,
                "Trace caustics of small lights seen through glass or mirrors from the lights: on, off, or auto (default: "
                "where the scene's Integrator is bdpt, mlt, sppm or lighttracer)")
      ->check(CLI::IsMember({"on", "off", "auto"}));
  c->add_option("--threads", a->threads, "Worker threads per process (0 = all cores, shared out among the ranks on a machine)")->check(CLI::Range(0, 4096));
  c->add_option("--tile", a->tile, "Tile size in pixels")->check(CLI::Range(1, 4096));
  c->add_option("--stats", a->stats, "Write render statistics as JSON");
  c->add_option("--preview", a->preview, "sRGB PNG preview (default: beside the EXR)");
  c->add_flag("--no-preview", a->no_preview, "Do not write a PNG preview");
  c->add_flag("-q,--quiet", a->quiet, "No progress output");
  c->add_flag("--full-specialisation", a->full_specialisation,
              "Run the integrator compiled for every effect instead of the scene's effects set (for benchmarks)");
  c->add_option("--checkpoint", a->checkpoint, "Write the render's state to this file (atomically) every --checkpoint-every seconds and at the end");
  c->add_option("--checkpoint-every", a->checkpoint_every, "Seconds between checkpoints (0 = after every pass)")->check(CLI::NonNegativeNumber);
  c->add_option("--resume", a->resume, "Continue a render from a checkpoint (same scene and options; any number of ranks)");
  c->add_option("--guide-sync", a->guide_sync, "Farm: share the guide's learning among the ranks after every pass (pass) or let each rank learn alone (off)")
      ->check(CLI::IsMember({"pass", "off"}));
  c->add_option("--farm-lease", a->farm_lease,
                "Farm: seconds a worker may stay silent while the master waits for its tiles or learning; then its "
                "tiles go to the other ranks (the image stays the same) and it rejoins when it is heard from (default 30)")
      ->check(positive_number());
  c->add_option("--farm-timeout", a->farm_timeout,
                "Farm: seconds a worker waits for a silent master (rank 0, which holds the image) before it ends the "
                "job, non-zero, for a --resume from the last checkpoint (default 600)")
      ->check(positive_number());
  add_guide_options(c, a->guide);
  return [a] { return run_render(*a); };
}

}  // namespace tessera
