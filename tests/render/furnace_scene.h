// The analytic furnace: a closed emitting sphere (Le = 1) of albedo rho
// seen from inside. With pbrt's depth counting every pixel is exactly
// L = sum_{k=0..D} rho^k, while single paths still vary (NEE + MIS,
// Russian roulette): a scene with a known answer and real noise.
#pragma once

#include <cstdio>
#include <string>

namespace tessera::testing {

// res x res pixels; spp 0 leaves the Sampler out (the renderer's default or
// the test's options decide).
inline std::string furnace_scene(double rho, int max_depth, int res = 16, int spp = 256) {
  char sampler[96] = "";
  if (spp > 0) std::snprintf(sampler, sizeof sampler, "Sampler \"independent\" \"integer pixelsamples\" [ %d ]", spp);
  char buf[1024];
  std::snprintf(buf, sizeof buf, R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ %d ] "integer yresolution" [ %d ]
%s
Integrator "path" "integer maxdepth" [ %d ]
WorldBegin
AttributeBegin
  Material "diffuse" "rgb reflectance" [ %g %g %g ]
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
  Shape "sphere" "float radius" [ 10 ]
AttributeEnd
)", res, res, sampler, max_depth, rho, rho, rho);
  return buf;
}

inline double expected_furnace(double rho, int depth) {
  double s = 0, r = 1;
  for (int k = 0; k <= depth; ++k, r *= rho) s += r;
  return s;
}

}  // namespace tessera::testing
