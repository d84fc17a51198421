// Scene pieces for the media tests: interface boxes, a head-on camera, slabs.
#pragma once

#include <string>

#include "render_helpers.h"

namespace tessera::testing {

// A closed box of the "interface" material (lo..hi), faces wound so that
// their normals point out of it: the inside of MediumInterface is the box.
inline std::string box(const Vec3& lo, const Vec3& hi) {
  auto v = [](double x, double y, double z) {
    return std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + " ";
  };
  // Eight corners; each face lists its corners counter-clockwise seen from outside.
  const std::string P = v(lo.x, lo.y, lo.z) + v(hi.x, lo.y, lo.z) + v(hi.x, hi.y, lo.z) + v(lo.x, hi.y, lo.z) +
                        v(lo.x, lo.y, hi.z) + v(hi.x, lo.y, hi.z) + v(hi.x, hi.y, hi.z) + v(lo.x, hi.y, hi.z);
  const char* faces[6] = {"0 3 2 0 2 1", "4 5 6 4 6 7", "0 1 5 0 5 4", "3 7 6 3 6 2", "0 4 7 0 7 3", "1 2 6 1 6 5"};
  std::string idx;
  for (const char* f : faces) idx += std::string(f) + " ";
  return "Shape \"trianglemesh\" \"point3 P\" [ " + P + "] \"integer indices\" [ " + idx + "]\n";
}

inline std::string header(int spp, int max_depth, double fov = 2.0) {
  return "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" [ " + std::to_string(fov) +
         " ]\nFilm \"rgb\" \"integer xresolution\" [ 16 ] \"integer yresolution\" [ 16 ]\n"
         "Sampler \"independent\" \"integer pixelsamples\" [ " + std::to_string(spp) + " ]\n"
         "Integrator \"volpath\" \"integer maxdepth\" [ " + std::to_string(max_depth) + " ]\n";
}

// A slab of medium between z = 2 and z = 5 (3 units thick), seen head-on.
inline std::string slab(const std::string& medium) {
  return medium + "AttributeBegin\nMaterial \"interface\"\nMediumInterface \"m\" \"\"\n" +
         box(Vec3(-50, -50, 2), Vec3(50, 50, 5)) + "AttributeEnd\n";
}

inline Rgb mean_rgb(const RenderResult& r) {
  const ImageRgb img = film_mean(r.film);
  Rgb m(0.f);
  for (size_t i = 0; i < img.rgb.size(); i += 3) m += Rgb(img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]);
  return m / static_cast<Float>(img.rgb.size() / 3);
}

}  // namespace tessera::testing
