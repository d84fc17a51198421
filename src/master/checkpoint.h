// Checkpoints: a render's state at a pass boundary (film accumulators,
// passes, counters, the guide cache), written atomically (temp file +
// rename) so a job killed at any moment leaves the previous checkpoint
// whole. `--resume` continues from one, with any number of ranks: pass
// boundaries line up, so the result is bit-identical to an uninterrupted
// render.
#pragma once

#include <cstdint>
#include <string>

#include "comm/transport.h"
#include "render/renderer.h"

namespace tessera {

// What must match for a checkpoint to continue a render: the scene, and the
// options that change the image's samples (resolution, seed, depth, guide
// mode and schedule, pass sizes). The spp target and time budget may change.
uint64_t render_options_fingerprint(const RenderOptions& options, int32_t width, int32_t height,
                                    const std::string& guide_mode);

struct Checkpoint {
  RenderResult so_far;
  Bytes guide;  // Guide::save bytes (either kind: load_guide); empty when the render is unguided
};

// Throws std::runtime_error naming the path on failure; never leaves a
// partial file at `path`.
void write_checkpoint(const std::string& path, const RenderResult& so_far, const Guide* guide,
                      uint64_t scene_fingerprint, uint64_t options_fingerprint);

// Throws std::runtime_error ("<path>: <problem>") for a missing, corrupt,
// truncated or foreign file, another version, scene or set of options.
Checkpoint read_checkpoint(const std::string& path, uint64_t scene_fingerprint, uint64_t options_fingerprint);

}  // namespace tessera
