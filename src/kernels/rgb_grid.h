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
  LatticeCell cell;
  if (!lattice_cell(v.channel[0], q, &cell)) return Rgb(0.f);
  Rgb sum(0.f);
  for (int k = 0; k < 8; ++k) {
    int32_t x, y, z;
    const Float w = lattice_corner(cell, k, &x, &y, &z);
    if (!(w > 0.f)) continue;
    const Rgb rgb(lattice_value(v.channel[0], x, y, z), lattice_value(v.channel[1], x, y, z),
                  lattice_value(v.channel[2], x, y, z));
    if (is_black(rgb)) continue;
    sum += w * (illuminant ? spectral_illuminant(*spectral, wl, rgb) : spectral_unbounded(*spectral, wl, rgb));
  }
  return sum;
}

}  // namespace tessera
