#include "scene/subsurface_params.h"

#include <algorithm>
#include <cmath>

#include "kernels/fresnel.h"

namespace tessera {

Float random_walk_albedo(Float reflectance) {
  const double a = std::clamp(static_cast<double>(reflectance), 0.0, 1.0);
  const double s = 4.09712 + 4.20863 * a - std::sqrt(9.59217 + 41.6808 * a + 17.7126 * a * a);
  return static_cast<Float>(std::clamp(1.0 - s * s, 0.0, 1.0));
}

Float normalized_fresnel_norm(Float eta) {
  constexpr int kSteps = 4096;  // midpoint rule: F is smooth in mu
  double moment = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double mu = (i + 0.5) / kSteps;
    moment += fr_dielectric(static_cast<Float>(mu), eta) * mu / kSteps;
  }
  return static_cast<Float>(1.0 - 2.0 * moment);
}

}  // namespace tessera
