#include "master/stats_json.h"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "scene/scene_effects.h"

namespace tessera {
namespace {

std::string quote(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o + "\"";
}

std::string number(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

// A flat JSON object written key by key, in insertion order.
struct JsonObject {
  std::string body;
  void add(const char* key, const std::string& json_value) {
    body += (body.empty() ? "  " : ",\n  ") + quote(key) + ": " + json_value;
  }
  void add(const char* key, double v) { add(key, number(v)); }
  void add(const char* key, uint64_t v) { add(key, std::to_string(v)); }
  void add_string(const char* key, const std::string& v) { add(key, quote(v)); }
  std::string str() const { return "{\n" + body + "\n}\n"; }
};

}  // namespace

std::string stats_to_json(const RenderStats& s, const std::string& scene, int32_t width, int32_t height, uint64_t seed,
                          const std::vector<SnapshotRecord>& snapshots) {
  const TileCounters& c = s.counters;
  const double paths = static_cast<double>(c.samples);
  const double rays = static_cast<double>(c.path.rays + c.path.shadow_rays);
  const double secs = s.seconds > 0 ? s.seconds : 1e-9;
  JsonObject j;
  j.add_string("tessera_version", TESSERA_VERSION);
  j.add_string("scene", scene);
  j.add("width", uint64_t(width));
  j.add("height", uint64_t(height));
  j.add("seed", seed);
  j.add("threads", uint64_t(s.threads));
  j.add("ranks", uint64_t(s.ranks));
  if (s.resumed_at_spp > 0) j.add("resumed_at_spp", uint64_t(s.resumed_at_spp));
  j.add("spp", uint64_t(s.spp));
  j.add("passes", uint64_t(s.passes));
  j.add("seconds", s.seconds);
  j.add_string("stop_reason", s.stop_reason);
  if (s.target_error > 0) j.add("target_error", s.target_error);
  // -1 when too few samples per pixel to estimate it.
  j.add("estimated_relmse", s.estimated_rel_mse);
  j.add("pass_end_seconds", s.pass_end_seconds);
  j.add("paths", c.samples);
  j.add("rays", c.path.rays + c.path.shadow_rays);
  j.add("camera_and_bounce_rays", c.path.rays);
  j.add("shadow_rays", c.path.shadow_rays);
  j.add("samples_per_second", paths / secs);
  j.add("rays_per_second", rays / secs);
  j.add("mean_path_length", paths > 0 ? c.path.vertices / paths : 0.0);
  j.add("medium_vertices", c.path.medium_vertices);  // scattering events in media (0 without media)
  // Light-traced caustics (0 unless --light-paths): paths traced, pixel
  // contributions made, and emitter hits the path tracer left to them.
  j.add("light_paths", c.path.light_paths);
  j.add("light_path_splats", c.path.light_splats);
  j.add("caustic_emission_left_to_light_paths", c.path.caustic_emission_skipped);
  j.add("zero_contribution_fraction", paths > 0 ? c.zero_radiance / paths : 0.0);
  j.add("nonfinite_samples_rejected", c.rejected_nonfinite);
  j.add("negative_samples_clamped", c.rejected_negative);
  j.add("interface_crossings", c.path.interface_skips);
  j.add_string("effects", describe_effects(s.effects));
  j.add_string("specialisation", describe_specialisation(s.specialisation));
  j.add_string("transport", s.spectral ? "spectral" : "rgb");
  j.add_string("guide", s.guide_mode);
  if (s.guide_mode != "none") {
    j.add("guide_cache_bytes", s.guide.bytes);
    j.add("guide_cells", s.guide.cells);
    j.add("guide_updates", s.guide.updates);
    j.add("guide_splits", s.guide.splits);
    j.add("guide_budget_reached", std::string(s.guide.budget_reached ? "true" : "false"));
    j.add("guide_targets_rejected_nonfinite", s.guide.rejected_nonfinite);
    j.add("guide_targets_rejected_large", s.guide.rejected_large);
    j.add("guide_fold_seconds", s.guide_fold_seconds);
    if (s.ranks > 1) {
      j.add_string("guide_sync", s.guide_sync);
      j.add("guide_syncs", uint64_t(s.guide_syncs));
      j.add("guide_sync_seconds", s.guide_sync_seconds);
      j.add("guide_sync_bytes", s.guide_sync_bytes);
      j.add("guide_sync_fraction", s.seconds > 0 ? s.guide_sync_seconds / s.seconds : 0.0);
    }
    j.add("guide_learn_spp", uint64_t{s.guide_learn.all_spp});
    j.add("guide_learn_every", uint64_t{s.guide_learn.every});
    j.add_string("guide_learn_taper", s.guide_learn.taper ? "on" : "off");
    j.add_string("guide_roulette", s.guide_roulette ? "guided" : "throughput");
    if (s.guide_roulette) j.add("guide_roulette_window", s.guide_roulette_window);
    j.add("guided_roulette_fraction",
          c.path.vertices > 0 ? double(c.path.guided_roulette) / double(c.path.vertices) : 0.0);
    j.add("guide_mix_learned_cells", s.guide.mix_learned_cells);
    j.add("guide_mean_mix", s.guide.mean_mix);
    j.add("guide_mix_samples_out_of_range", s.guide.mix_out_of_range);
    j.add_string("guide_nee", s.guide.learned_nee ? "learned" : "always");
    // --guide auto's trial: none | pending (not reached) | kept | switched-off
    static const char* trial_states[] = {"none", "pending", "kept", "switched-off"};
    j.add_string("guide_trial", trial_states[static_cast<uint32_t>(s.guide_trial.state) & 3u]);
    if (s.guide_trial.state == GuideTrialState::Kept || s.guide_trial.state == GuideTrialState::SwitchedOff) {
      j.add("guide_trial_guided_inefficiency", s.guide_trial.inefficiency[1]);
      j.add("guide_trial_unguided_inefficiency", s.guide_trial.inefficiency[0]);
    }
    j.add("nee_skipped_fraction",
          c.path.vertices > 0 ? double(c.path.nee_skipped) / double(c.path.vertices) : 0.0);
    j.add("guided_sample_fraction",
          c.path.guidable_vertices > 0 ? double(c.path.guided_samples) / double(c.path.guidable_vertices) : 0.0);
  }
  // Per pass: how learning changes the paths.
  std::string passes = "[";
  for (size_t i = 0; i < s.pass_stats.size(); ++i) {
    const PassStats& p = s.pass_stats[i];
    const double n = p.samples > 0 ? double(p.samples) : 1.0;
    passes += (i ? ",\n    " : "\n    ") + std::string("{\"spp\": ") + std::to_string(p.spp) +
              ", \"seconds\": " + number(p.seconds) + ", \"zero_contribution_fraction\": " +
              number(p.zero_radiance / n) + ", \"mean_path_length\": " + number(p.vertices / n) +
              ", \"guided_sample_fraction\": " +
              number(p.guidable_vertices ? double(p.guided_samples) / double(p.guidable_vertices) : 0.0) +
              ", \"estimated_relmse\": " + number(p.estimated_rel_mse) + "}";
  }
  j.add("per_pass", passes + "\n  ]");
  if (!snapshots.empty()) {
    std::string list = "[";
    for (size_t i = 0; i < snapshots.size(); ++i) {
      const SnapshotRecord& r = snapshots[i];
      list += (i ? ",\n    " : "\n    ") + std::string("{\"file\": ") + quote(r.file) + ", \"spp\": " +
              std::to_string(r.spp) + ", \"seconds\": " + number(r.seconds) + ", \"render_seconds\": " +
              number(r.render_seconds) + ", \"estimated_relmse\": " + number(r.estimated_rel_mse) + "}";
    }
    j.add("snapshots", list + "\n  ]");
  }
  return j.str();
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path);
}

}  // namespace tessera
