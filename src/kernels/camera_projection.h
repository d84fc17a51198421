// pbrt-v4's camera types, shared by the scene description and the kernels'
// camera view ("realistic" lens systems are drawn as perspective).
#pragma once

#include <cstdint>

namespace tessera {

enum class CameraProjection : uint32_t { Perspective = 0, Orthographic, SphericalEqualArea, SphericalEquirectangular };

}  // namespace tessera
