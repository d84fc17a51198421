// The --stats JSON file: what a render did and how fast.
#pragma once

#include <string>

#include <vector>

#include "render/snapshots.h"

namespace tessera {

struct RenderStats;  // render/renderer.h

std::string stats_to_json(const RenderStats& stats, const std::string& scene, int32_t width, int32_t height,
                          uint64_t seed, const std::vector<SnapshotRecord>& snapshots = {});
void write_text_file(const std::string& path, const std::string& text);

}  // namespace tessera
