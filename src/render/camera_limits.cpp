#include "render/camera_limits.h"

#include "kernels/camera.h"
#include "scene/scene_desc.h"
#include "scene/scene_limits.h"

namespace tessera {

void check_camera_limits(const CameraView& c, const std::string& where, const glm::dvec3& origin) {
  // Origins and directions are monotone in the film position and the lens
  // point: the corners and the lens's edge bound them (the centre and the
  // lens's centre for the pinhole's rays).
  const Float w = static_cast<Float>(c.width), h = static_cast<Float>(c.height);
  const Vec2 film[] = {{0.f, 0.f}, {w, 0.f}, {0.f, h}, {w, h}, {0.5f * w, 0.5f * h}};
  const Float lens_u[] = {0.f, 0.5f, 1.f};
  for (const Float time : {0.f, 1.f}) {
    if (time > 0.f && !c.moves) break;
    for (const Vec2& p : film)
      for (const Float ux : lens_u)
        for (const Float uy : lens_u) {
          const Ray r = generate_camera_ray(c, p, Vec2(ux, uy), time);
          if (!representable(r.o))
            throw SceneError(where + ": the camera's rays start " + describe_far(r.o, origin) +
                             " (its \"lensradius\", orthographic \"screenwindow\" or transform's scale)");
          if (!(glm::length(r.d) > 0.5f))
            throw SceneError(where + ": the camera's ray directions overflow single precision (its \"screenwindow\", "
                                     "\"fov\" or \"focaldistance\" is too large)");
        }
  }
}

}  // namespace tessera
