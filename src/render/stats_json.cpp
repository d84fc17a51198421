#include "render/stats_json.h"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "render/renderer.h"
#include "scene/scene_effects.h"

namespace tessera {

// Written with nlohmann-json (keys in insertion order): strings are escaped
// as JSON requires, and a number that is not finite becomes null (JSON has
// no NaN or Infinity).
std::string stats_to_json(const RenderStats& s, const std::string& scene, int32_t width, int32_t height, uint64_t seed,
                          const std::vector<SnapshotRecord>& snapshots) {
  const TileCounters& c = s.counters;
  const double paths = static_cast<double>(c.samples);
  const double rays = static_cast<double>(c.path.rays + c.path.shadow_rays);
  const double secs = s.seconds > 0 ? s.seconds : 1e-9;
  nlohmann::ordered_json j;
  j["tessera_version"] = (TESSERA_VERSION);
  j["scene"] = (scene);
  j["width"] = (uint64_t(width));
  j["height"] = (uint64_t(height));
  j["seed"] = (seed);
  j["threads"] = (uint64_t(s.threads));
  j["ranks"] = (uint64_t(s.ranks));
  j["machines"] = (uint64_t(s.machines));
  if (s.resumed_at_spp > 0) j["resumed_at_spp"] = (uint64_t(s.resumed_at_spp));
  j["spp"] = (uint64_t(s.spp));
  j["passes"] = (uint64_t(s.passes));
  j["seconds"] = (s.seconds);
  j["stop_reason"] = (s.stop_reason);
  if (s.target_error > 0) j["target_error"] = (s.target_error);
  // -1 when too few samples per pixel to estimate it.
  j["estimated_relmse"] = (s.estimated_rel_mse);
  j["pass_end_seconds"] = (s.pass_end_seconds);
  j["paths"] = (c.samples);
  j["rays"] = (c.path.rays + c.path.shadow_rays);
  j["camera_and_bounce_rays"] = (c.path.rays);
  j["shadow_rays"] = (c.path.shadow_rays);
  j["samples_per_second"] = (paths / secs);
  j["rays_per_second"] = (rays / secs);
  j["mean_path_length"] = (paths > 0 ? c.path.vertices / paths : 0.0);
  j["medium_vertices"] = (c.path.medium_vertices);  // scattering events in media (0 without media)
  // Light-traced caustics (0 unless --light-paths): paths traced, pixel
  // contributions made, and emitter hits the path tracer left to them.
  j["light_paths"] = (c.path.light_paths);
  j["light_path_splats"] = (c.path.light_splats);
  j["caustic_emission_left_to_light_paths"] = (c.path.caustic_emission_skipped);
  j["zero_contribution_fraction"] = (paths > 0 ? c.zero_radiance / paths : 0.0);
  j["nonfinite_samples_rejected"] = (c.rejected_nonfinite);
  j["negative_samples_clamped"] = (c.rejected_negative);
  j["interface_crossings"] = (c.path.interface_skips);
  // Rays the tracer refused (kernels/ray_guard.h: beyond +-1.844e18 or not
  // finite), answered as misses or as occluded.
  j["untraceable_rays"] = (c.path.untraceable_rays);
  j["effects"] = (describe_effects(s.effects));
  j["specialisation"] = (describe_specialisation(s.specialisation));
  j["transport"] = (s.spectral ? "spectral" : "rgb");
  j["backend"] = s.backend;
  j["guide"] = (s.guide_mode);
  if (s.guide_mode != "none") {
    j["guide_cache_bytes"] = (s.guide.bytes);
    j["guide_cells"] = (s.guide.cells);
    j["guide_updates"] = (s.guide.updates);
    j["guide_splits"] = (s.guide.splits);
    j["guide_budget_reached"] = s.guide.budget_reached;
    j["guide_targets_rejected_nonfinite"] = (s.guide.rejected_nonfinite);
    j["guide_targets_rejected_large"] = (s.guide.rejected_large);
    j["guide_fold_seconds"] = (s.guide_fold_seconds);
    if (s.guide_mode == "neural") {
      const NeuralGuideStats& n = s.neural_guide;
      j["guide_neural_params"] = n.params;
      j["guide_neural_steps"] = n.steps;
      j["guide_neural_targets"] = n.targets;
      j["guide_neural_targets_dropped"] = n.dropped;
      j["guide_neural_gradient_words_clamped"] = n.gradient_clamped;
      j["guide_neural_nonfinite_gradients"] = n.nonfinite_gradients;
      j["guide_neural_loss"] = n.loss;
      j["guide_neural_mix"] = n.mix_weight;
      j["guide_neural_mix_vertices"] = n.mix_vertices;
      j["guide_neural_mix_out_of_range"] = n.mix_rejected;
      j["guide_neural_train_seconds"] = n.train_seconds;
      j["guide_neural_inference_us"] = n.inference_seconds * 1e6;
      j["guide_neural_sites_reused"] = c.path.neural_sites_reused;
      // Shares of the render's wall time: training (rank 0's, between passes),
      // and inference estimated as one per path vertex that did not reuse
      // its pixel's first site, at the measured cost, spread over the threads.
      const double wall = std::max(s.seconds, 1e-9);
      j["guide_neural_train_fraction"] = n.train_seconds / wall;
      j["guide_neural_inference_fraction"] =
          double(c.path.vertices - c.path.neural_sites_reused) * n.inference_seconds / (std::max(1, s.threads) * wall);
    }
    if (s.ranks > 1) {
      j["guide_sync"] = (s.guide_sync);
      j["guide_syncs"] = (uint64_t(s.guide_syncs));
      j["guide_sync_seconds"] = (s.guide_sync_seconds);
      j["guide_sync_bytes"] = (s.guide_sync_bytes);  // the largest single reduction
      j["guide_sync_seconds_per_reduction"] = s.guide_syncs > 0 ? s.guide_sync_seconds / s.guide_syncs : 0.0;
      j["guide_sync_fraction"] = (s.seconds > 0 ? s.guide_sync_seconds / s.seconds : 0.0);
    }
    j["guide_learn_spp"] = (uint64_t{s.guide_learn.all_spp});
    j["guide_learn_every"] = (uint64_t{s.guide_learn.every});
    j["guide_learn_taper"] = (s.guide_learn.taper ? "on" : "off");
    j["guide_roulette"] = (s.guide_roulette ? "guided" : "throughput");
    if (s.guide_roulette) j["guide_roulette_window"] = (s.guide_roulette_window);
    j["guide_max_ratio"] = s.guide_max_ratio;
    j["guided_roulette_fraction"] = (
          c.path.vertices > 0 ? double(c.path.guided_roulette) / double(c.path.vertices) : 0.0);
    j["guide_mix_learned_cells"] = (s.guide.mix_learned_cells);
    j["guide_mean_mix"] = (s.guide.mean_mix);
    j["guide_mix_samples_out_of_range"] = (s.guide.mix_out_of_range);
    j["guide_nee"] = (s.guide.learned_nee ? "learned" : "always");
    // --guide auto's trial: none | pending (not reached) | kept | switched-off
    static const char* trial_states[] = {"none", "pending", "kept", "switched-off"};
    j["guide_trial"] = (trial_states[static_cast<uint32_t>(s.guide_trial.state) & 3u]);
    const GuideTrial& t = s.guide_trial;
    if (t.state == GuideTrialState::Kept || t.state == GuideTrialState::SwitchedOff) {
      j["guide_trial_guided_inefficiency"] = (t.inefficiency[1]);
      j["guide_trial_unguided_inefficiency"] = (t.inefficiency[0]);
      j["guide_trial_dropped"] = t.dropped_method == 1 ? "guided" : t.dropped_method == 0 ? "unguided" : "none";
      j["guide_trial_dropped_spp"] = uint64_t{t.dropped_spp};
    }
    if (t.state != GuideTrialState::Off) {
      nlohmann::ordered_json windows = nlohmann::ordered_json::array();
      for (uint32_t k = 0; k < t.windows_done && k < kGuideTrialWindows; ++k) {
        const GuideTrialWindow& w = t.window[k];
        windows.push_back({{"start_spp", w.start_spp},
                           {"guided_rel_var", w.rel_var[1]},
                           {"unguided_rel_var", w.rel_var[0]},
                           {"guided_mean_rel_var", w.mean_rel_var[1]},
                           {"unguided_mean_rel_var", w.mean_rel_var[0]},
                           {"guided_cost", w.cost[1]},
                           {"unguided_cost", w.cost[0]},
                           {"guided_inefficiency", w.inefficiency[1]},
                           {"unguided_inefficiency", w.inefficiency[0]}});
      }
      j["guide_trial_windows"] = windows;
    }
    j["nee_skipped_fraction"] = (
          c.path.vertices > 0 ? double(c.path.nee_skipped) / double(c.path.vertices) : 0.0);
    j["guided_sample_fraction"] = (
          c.path.guidable_vertices > 0 ? double(c.path.guided_samples) / double(c.path.guidable_vertices) : 0.0);
    const uint64_t could_guide = c.path.guidable_vertices + c.path.guide_withheld_vertices;
    j["guide_withheld_fraction"] = could_guide > 0 ? double(c.path.guide_withheld_vertices) / double(could_guide) : 0.0;
  }
  // Per pass: how learning changes the paths.
  nlohmann::ordered_json passes = nlohmann::ordered_json::array();
  for (const PassStats& p : s.pass_stats) {
    const double n = p.samples > 0 ? double(p.samples) : 1.0;
    passes.push_back({{"spp", p.spp},
                      {"seconds", p.seconds},
                      {"zero_contribution_fraction", p.zero_radiance / n},
                      {"mean_path_length", p.vertices / n},
                      {"guided_sample_fraction",
                       p.guidable_vertices ? double(p.guided_samples) / double(p.guidable_vertices) : 0.0},
                      {"estimated_relmse", p.estimated_rel_mse},
                      {"guide_loss", p.guide_loss},
                      {"guide_seconds", p.guide_seconds},
                      // The network's inference, one per path vertex (but those
                      // that reused a site) at its last measured cost.
                      {"guide_inference_fraction",
                       s.guide_mode == "neural" && p.seconds > 0
                           ? double(p.vertices - p.neural_sites_reused) * s.neural_guide.inference_seconds /
                                 (std::max(1, s.threads) * p.seconds)
                           : 0.0}});
  }
  j["per_pass"] = passes;
  if (!snapshots.empty()) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const SnapshotRecord& r : snapshots)
      list.push_back({{"file", r.file},
                      {"spp", r.spp},
                      {"seconds", r.seconds},
                      {"render_seconds", r.render_seconds},
                      {"estimated_relmse", r.estimated_rel_mse}});
    j["snapshots"] = list;
  }
  // Invalid UTF-8 in a scene path is replaced, not thrown over.
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path);
}

}  // namespace tessera
