#include "scene/sampler_setup.h"

#include <cmath>
#include <stdexcept>

namespace tessera {

SamplerKind sampler_kind_named(const std::string& name) {
  if (name == "zsobol") return SamplerKind::ZSobol;
  if (name == "paddedsobol" || name == "sobol") return SamplerKind::Sobol;
  if (name == "stratified") return SamplerKind::Stratified;
  if (name == "independent") return SamplerKind::Independent;
  throw std::invalid_argument("unknown sampler \"" + name + "\"");
}

const char* sampler_name(SamplerKind kind) {
  switch (kind) {
    case SamplerKind::ZSobol: return "zsobol";
    case SamplerKind::Sobol: return "paddedsobol";
    case SamplerKind::Stratified: return "stratified";
    case SamplerKind::Independent: return "independent";
  }
  return "?";
}

SamplerSetup sampler_setup(const SceneDesc& desc) {
  SamplerSetup s;
  s.kind = desc.sampler;
  s.seed = desc.seed;
  const uint64_t spp = static_cast<uint64_t>(std::max(1, desc.spp));
  s.log2_spp = ceil_log2_spp(spp);
  s.jitter = desc.sampler_jitter;
  if (static_cast<uint64_t>(desc.strata_x) * static_cast<uint64_t>(desc.strata_y) == spp) {
    s.strata_x = static_cast<uint32_t>(desc.strata_x);
    s.strata_y = static_cast<uint32_t>(desc.strata_y);
  } else {
    uint64_t div = static_cast<uint64_t>(std::sqrt(static_cast<double>(spp)));
    while (div > 1 && spp % div != 0) --div;
    s.strata_y = static_cast<uint32_t>(div);
    s.strata_x = static_cast<uint32_t>(spp / div);
  }
  return s;
}

}  // namespace tessera
