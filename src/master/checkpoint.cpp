#include "master/checkpoint.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "comm/wire.h"
#include "kernels/fnv1a.h"
#include "render/output_file.h"

namespace tessera {
namespace {

constexpr char kMagic[] = "tessera-checkpoint";
// 2: per-pass error estimates; 3: next-event skip counter, guide cache v2; 4: medium
// vertex counter, --guide auto's trial; 5: guide cache v4; 6: light-path splats;
// 7: splats summed per light path, lights in their own medium; 8: counter of
// vertices the guide ratio left to the BSDF; 9: the guide's loss and learning time per pass;
// 12: --guide auto's trial windows and its unguided part of the film
constexpr uint32_t kVersion = 12;

// FNV-1a over the payload: any damaged byte is detected, not rendered.
uint64_t fnv1a(const std::string& s) { return tessera::fnv1a(s.data(), s.size()); }

struct CheckpointBody {
  Checkpoint* c;
  template <class Archive>
  void serialize(Archive& ar) {
    RenderResult& r = c->so_far;
    RenderStats& s = r.stats;
    ar(r.film.width, r.film.height, raw(r.film.pixels), raw(r.film.splats), r.film.light_paths);
    ar(s.spp, s.passes, s.seconds, raw_value(s.counters), raw(s.pass_stats), s.guide_fold_seconds, s.guide_sync_seconds,
       s.guide_syncs);
    ar(s.estimated_rel_mse, s.pass_end_seconds);
    ar(raw_value(s.guide_trial), raw(r.trial_unguided));
    ar(c->guide);
  }
};

}  // namespace

uint64_t render_options_fingerprint(const RenderOptions& o, int32_t width, int32_t height, const std::string& guide_mode) {
  std::ostringstream s;
  s << width << 'x' << height << ' ' << o.seed << ' ' << o.max_depth << ' ' << o.nee << ' ' << o.max_pass_spp << ' '
    << o.guide_learn.all_spp << ' ' << o.guide_learn.every << ' ' << o.guide_roulette << ' ' << guide_mode << ' '
    << o.force_full_specialisation;
  if (o.guide_trial) s << " trial";
  if (o.guide_roulette_window != kGuidedRouletteWindow) s << " window " << o.guide_roulette_window;
  if (o.guide_max_ratio != kMaxGuideRatio) s << " max-ratio " << o.guide_max_ratio;
  // Checkpoints from before the taper learned every K-th sample throughout.
  if (o.guide_learn.taper) s << " taper";
  if (o.sampler.kind == SamplerKind::Sobol) s << " sobol";
  if (o.sampler.kind == SamplerKind::ZSobol) s << " zsobol " << o.sampler.log2_spp;
  if (o.sampler.kind == SamplerKind::Stratified)
    s << " stratified " << o.sampler.strata_x << 'x' << o.sampler.strata_y << ' ' << o.sampler.jitter;
  if (o.sampler.kind == SamplerKind::Halton) s << " halton " << static_cast<uint32_t>(o.sampler.halton_randomize);
  if (o.light_paths) s << " light-paths";
  return fnv1a(s.str());
}

void write_checkpoint(const std::string& path, const RenderResult& so_far, const Guide* guide,
                      uint64_t scene_fingerprint, uint64_t options_fingerprint) {
  Checkpoint c{so_far, {}};
  if (guide) {
    std::ostringstream g(std::ios::binary);
    guide->save(g, scene_fingerprint);
    const std::string gs = g.str();
    c.guide.assign(gs.begin(), gs.end());
  }
  const Bytes body = encode(CheckpointBody{&c});
  const std::string payload(body.begin(), body.end());
  write_output(path, [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("--checkpoint: cannot write " + tmp);
    cereal::BinaryOutputArchive ar(f);
    f.write(kMagic, sizeof kMagic);
    ar(kVersion, scene_fingerprint, options_fingerprint, static_cast<uint64_t>(payload.size()), fnv1a(payload));
    f.write(payload.data(), static_cast<std::streamsize>(payload.size()));
    f.close();
    if (!f) throw std::runtime_error("--checkpoint: cannot write " + tmp);
  });
}

Checkpoint read_checkpoint(const std::string& path, uint64_t scene_fingerprint, uint64_t options_fingerprint) {
  auto fail = [&](const std::string& why) { return std::runtime_error("--resume " + path + ": " + why); };
  std::ifstream f(path, std::ios::binary);
  if (!f) throw fail("cannot open");
  char magic[sizeof kMagic] = {};
  if (!f.read(magic, sizeof magic) || std::string(magic, sizeof magic) != std::string(kMagic, sizeof kMagic))
    throw fail("not a Tessera checkpoint");
  uint32_t version = 0;
  uint64_t scene = 0, options = 0, size = 0, hash = 0;
  try {
    cereal::BinaryInputArchive ar(f);
    ar(version, scene, options, size, hash);
  } catch (const cereal::Exception&) {
    throw fail("truncated checkpoint header");
  }
  if (version != kVersion)
    throw fail("checkpoint version " + std::to_string(version) + ", this build reads version " + std::to_string(kVersion));
  if (scene != scene_fingerprint) throw fail("checkpoint of another scene");
  if (options != options_fingerprint)
    throw fail("checkpoint made with other render options (resolution, seed, depth or guiding differ)");
  // The payload must be exactly what is left of the file: a truncated file
  // is refused before its claimed size is allocated, trailing bytes are not
  // silently ignored.
  const std::streamoff header_end = f.tellg();
  f.seekg(0, std::ios::end);
  const std::streamoff file_end = f.tellg();
  f.seekg(header_end);
  if (header_end < 0 || file_end < header_end) throw fail("cannot read");
  const uint64_t left = static_cast<uint64_t>(file_end - header_end);
  if (size > left) throw fail("truncated checkpoint (" + std::to_string(left) + " of " + std::to_string(size) + " bytes)");
  if (size < left) throw fail("corrupt checkpoint (" + std::to_string(left - size) + " bytes after its end)");
  std::string payload(static_cast<size_t>(size), '\0');
  if (!f.read(payload.data(), static_cast<std::streamsize>(size))) throw fail("truncated checkpoint");
  if (fnv1a(payload) != hash) throw fail("corrupt checkpoint (checksum mismatch)");
  Checkpoint c;
  try {
    std::istringstream is(payload, std::ios::binary);
    cereal::BinaryInputArchive ar(is);
    CheckpointBody body{&c};
    ar(body);
  } catch (const std::exception& e) {
    throw fail(std::string("corrupt checkpoint (") + e.what() + ")");
  }
  const Film& film = c.so_far.film;
  if (film.width <= 0 || film.height <= 0 || film.pixels.size() != static_cast<size_t>(film.width) * film.height ||
      (!film.splats.empty() && film.splats.size() != film.pixels.size()) ||
      (!c.so_far.trial_unguided.empty() && c.so_far.trial_unguided.size() != film.pixels.size()))
    throw fail("corrupt checkpoint (film size)");
  return c;
}

}  // namespace tessera
