#include "scene/scene_limits.h"

#include <cstdio>

namespace tessera {

std::string describe_far(const Vec3& p, const glm::dvec3& origin) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "at (%g, %g, %g): beyond +-%g (or not finite), where single-precision ray tracing cannot go",
                double(p.x) + origin.x + 0.0, double(p.y) + origin.y + 0.0, double(p.z) + origin.z + 0.0,
                double(kMaxSceneCoordinate));  // + 0: no "-0"
  return buf;
}

}  // namespace tessera
