// The numbers behind the random-walk "subsurface" material: the
// single-scattering albedo that gives a surface colour, and the
// normalisation of the lobe light leaves the medium by.
#pragma once

#include "kernels/device.h"

namespace tessera {

// The single-scattering albedo whose random walk in a semi-infinite medium
// reflects `reflectance` in total: Chiang, Kutz and Burley 2016's fit
// (exact at 0 and 1). pbrt-v4 instead inverts its photon-beam-diffusion
// profile; the two agree on the ends and differ by a few percent between.
Float random_walk_albedo(Float reflectance);

// c = 1 - 2 int_0^1 F(mu, eta) mu dmu, by quadrature: (1 - F(cos, eta)) /
// (c pi) is then a lobe of albedo exactly 1 (pbrt-v4's NormalizedFresnelBxDF
// uses a polynomial fit of the moment).
Float normalized_fresnel_norm(Float eta);

}  // namespace tessera
