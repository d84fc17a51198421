#include "scene/sampler_setup.h"

#include <algorithm>

namespace tessera {

std::optional<SamplerKind> sampler_kind_named(const std::string& name) {
  if (name == "zsobol") return SamplerKind::ZSobol;
  if (name == "paddedsobol" || name == "sobol") return SamplerKind::Sobol;
  if (name == "stratified") return SamplerKind::Stratified;
  if (name == "independent") return SamplerKind::Independent;
  if (name == "halton") return SamplerKind::Halton;
  return std::nullopt;
}

const char* sampler_name(SamplerKind kind) {
  switch (kind) {
    case SamplerKind::ZSobol: return "zsobol";
    case SamplerKind::Sobol: return "paddedsobol";
    case SamplerKind::Stratified: return "stratified";
    case SamplerKind::Independent: return "independent";
    case SamplerKind::Halton: return "halton";
  }
  return "?";
}

SamplerSetup sampler_setup(const SceneDesc& desc) {
  SamplerSetup s;
  s.kind = desc.sampler;
  s.seed = desc.seed;
  s.log2_spp = ceil_log2_spp(static_cast<uint64_t>(std::max(1, desc.sampler_spp)));
  s.jitter = desc.sampler_jitter;
  s.halton_randomize = desc.halton_randomize;
  s.strata_x = static_cast<uint32_t>(std::max(1, desc.strata_x));
  s.strata_y = static_cast<uint32_t>(std::max(1, desc.strata_y));
  s.halton = halton_layout(static_cast<uint32_t>(std::max(1, desc.film.xres)), static_cast<uint32_t>(std::max(1, desc.film.yres)));
  return s;
}

}  // namespace tessera
