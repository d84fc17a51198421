#include "render/render_tile_impl.h"

#include <algorithm>

namespace tessera {

// Low discrepancy buys little for one splat per sample.
SamplerSetup light_path_sampler(const TileSettings& settings) {
  SamplerSetup setup;
  setup.kind = SamplerKind::Independent;
  setup.seed = mix_bits(settings.seed ^ 0x116847a7e5ull);
  return setup;
}

// A light path connects at every vertex after its specular chain and may
// reach a pixel more than once: its splats there become one, so that the
// film's second moments are per path (the variance layer needs them so).
void merge_splats_by_pixel(std::vector<Splat>& splats, size_t first) {
  if (splats.size() - first < 2) return;
  std::stable_sort(splats.begin() + static_cast<std::ptrdiff_t>(first), splats.end(),
                   [](const Splat& a, const Splat& b) { return a.pixel < b.pixel; });
  size_t out = first;
  for (size_t i = first + 1; i < splats.size(); ++i) {
    if (splats[i].pixel == splats[out].pixel) {
      for (int c = 0; c < 3; ++c) splats[out].value[c] += splats[i].value[c];
    } else {
      splats[++out] = splats[i];
    }
  }
  splats.resize(out + 1);
}

}  // namespace tessera
