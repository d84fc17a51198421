#include "master/stats_json.h"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "scene/scene_effects.h"

namespace tessera {
namespace {

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

}  // namespace

std::string stats_to_json(const RenderStats& s, const std::string& scene, int32_t width, int32_t height, uint64_t seed) {
  const TileCounters& c = s.counters;
  const double paths = static_cast<double>(c.samples);
  const double rays = static_cast<double>(c.path.rays + c.path.shadow_rays);
  const double secs = s.seconds > 0 ? s.seconds : 1e-9;
  char buf[4096];
  std::snprintf(buf, sizeof buf,
                "{\n"
                "  \"tessera_version\": \"%s\",\n"
                "  \"scene\": \"%s\",\n"
                "  \"width\": %d,\n  \"height\": %d,\n"
                "  \"seed\": %llu,\n"
                "  \"threads\": %d,\n"
                "  \"spp\": %u,\n  \"passes\": %u,\n"
                "  \"seconds\": %.6f,\n"
                "  \"stop_reason\": \"%s\",\n"
                "  \"paths\": %llu,\n"
                "  \"rays\": %.0f,\n  \"camera_and_bounce_rays\": %llu,\n  \"shadow_rays\": %llu,\n"
                "  \"samples_per_second\": %.3f,\n  \"rays_per_second\": %.3f,\n"
                "  \"mean_path_length\": %.6f,\n"
                "  \"zero_contribution_fraction\": %.6f,\n"
                "  \"nonfinite_samples_rejected\": %llu,\n"
                "  \"negative_samples_clamped\": %llu,\n"
                "  \"interface_crossings\": %llu,\n"
                "  \"effects\": \"%s\",\n"
                "  \"specialisation\": \"%s\"\n"
                "}\n",
                TESSERA_VERSION, escape(scene).c_str(), width, height, static_cast<unsigned long long>(seed), s.threads,
                s.spp, s.passes, s.seconds, s.stop_reason.c_str(), static_cast<unsigned long long>(c.samples), rays,
                static_cast<unsigned long long>(c.path.rays), static_cast<unsigned long long>(c.path.shadow_rays),
                paths / secs, rays / secs, paths > 0 ? c.path.vertices / paths : 0.0,
                paths > 0 ? c.zero_radiance / paths : 0.0, static_cast<unsigned long long>(c.rejected_nonfinite),
                static_cast<unsigned long long>(c.rejected_negative),
                static_cast<unsigned long long>(c.path.interface_skips), describe_effects(s.effects).c_str(),
                describe_specialisation(s.specialisation).c_str());
  return buf;
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path);
}

}  // namespace tessera
