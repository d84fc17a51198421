// pbrt-v4's "rgbgrid" voxels: an RGB per lattice point, stored as three
// scalar lattices (sparse_grid.h). Under RGB transport the three are read
// trilinearly; under spectral transport each of the eight surrounding
// voxels' RGB is turned into its spectrum at the path's wavelengths first
// and the spectra are interpolated, as pbrt-v4's SampledGrid does with
// RGBUnboundedSpectrum / RGBIlluminantSpectrum values.
#pragma once

#include "sparse_grid.h"
#include "spectral.h"

namespace tessera {

struct RgbGridView {
  SparseGridView channel[3];  // channel[0].nx == 0: no grid
};

TESSERA_HOST_DEVICE inline bool rgb_grid_present(const RgbGridView& v) { return grid_present(v.channel[0]); }

// The RGB grid at lattice point q; spectral (with wl) as an unbounded
// coefficient or, where `illuminant`, as emission.
TESSERA_HOST_DEVICE inline Rgb rgb_grid_value(const RgbGridView& v, const Vec3& q, const SpectralView* spectral,
                                              const Wavelengths* wl, bool illuminant) {
  if (!wl || !spectral)
    return Rgb(lattice_trilinear(v.channel[0], q), lattice_trilinear(v.channel[1], q),
               lattice_trilinear(v.channel[2], q));
  const SparseGridView& g = v.channel[0];
  if (!(q.x > -1.f && q.y > -1.f && q.z > -1.f && q.x < g.nx && q.y < g.ny && q.z < g.nz)) return Rgb(0.f);
  const int32_t ix = static_cast<int32_t>(glm::floor(q.x)), iy = static_cast<int32_t>(glm::floor(q.y)),
                iz = static_cast<int32_t>(glm::floor(q.z));
  const Float dx = q.x - ix, dy = q.y - iy, dz = q.z - iz;
  Rgb sum(0.f);
  for (int c = 0; c < 8; ++c) {
    const int32_t x = ix + (c & 1), y = iy + ((c >> 1) & 1), z = iz + (c >> 2);
    const Float w = ((c & 1) ? dx : 1.f - dx) * (((c >> 1) & 1) ? dy : 1.f - dy) * ((c >> 2) ? dz : 1.f - dz);
    if (!(w > 0.f)) continue;
    const Rgb rgb(lattice_value(v.channel[0], x, y, z), lattice_value(v.channel[1], x, y, z),
                  lattice_value(v.channel[2], x, y, z));
    if (is_black(rgb)) continue;
    sum += w * (illuminant ? spectral_illuminant(*spectral, wl, rgb) : spectral_unbounded(*spectral, wl, rgb));
  }
  return sum;
}

}  // namespace tessera
