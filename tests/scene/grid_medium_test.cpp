// Grid media: the brick lattice's lookups, the majorant grid's bounds and
// walk, and delta / ratio tracking through them.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kernels/grid_medium.h"
#include "kernels/rng.h"
#include "scene/pbrt_loader.h"
#include "scene/scene_desc.h"
#include "scene/sparse_grid_build.h"

namespace tessera {
namespace {

// Host storage and its kernel view together.
struct TestGrid {
  GridDesc desc;
  GridMediumView view;
  TestGrid(const std::vector<Float>& values, int32_t nx, int32_t ny, int32_t nz, Vec3 p0, Vec3 p1,
           int32_t majorant_res = 16) {
    desc.density = sparse_grid_from_dense(values, nx, ny, nz, p0, p1, Mat4(1.f));
    desc.majorants = build_majorant_grid(desc.density, Vec3(-0.5f), Vec3(nx, ny, nz) - 0.5f, majorant_res);
    view.density = sparse_grid_view(desc.density);
    view.majorants = majorant_grid_view(desc.majorants);
  }
};

// A medium on grid 0 with these coefficients per unit density.
Medium on_grid(const Rgb& sigma_a, const Rgb& sigma_s) {
  Medium m;
  m.sigma_a = sigma_a;
  m.sigma_s = sigma_s;
  m.grid = 0;
  return m;
}

// pbrt-v4's SampledGrid lookup on dense values, written out.
Float dense_lookup(const std::vector<Float>& v, int nx, int ny, int nz, Vec3 p0, Vec3 p1, Vec3 p) {
  const Vec3 u = (p - p0) / (p1 - p0);
  const double fx = u.x * nx - 0.5, fy = u.y * ny - 0.5, fz = u.z * nz - 0.5;
  const int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy)),
            iz = static_cast<int>(std::floor(fz));
  auto at = [&](int x, int y, int z) -> double {
    if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) return 0.0;
    return v[(static_cast<size_t>(z) * ny + y) * nx + x];
  };
  double sum = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    const double w = (dx ? fx - ix : 1 - (fx - ix)) * (dy ? fy - iy : 1 - (fy - iy)) * (dz ? fz - iz : 1 - (fz - iz));
    sum += w * at(ix + dx, iy + dy, iz + dz);
  }
  return static_cast<Float>(sum);
}

TEST(GridMedium, DensityIsTrilinearBetweenVoxelCentresAndZeroOutside) {
  // A 2 x 1 x 1 grid over [0,2] x [0,1] x [0,1]: values 0 and 1 at x = 0.5 and 1.5.
  const TestGrid t({0.f, 1.f}, 2, 1, 1, Vec3(0.f), Vec3(2.f, 1.f, 1.f));
  const GridMediumView& g = t.view;
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(0.5f, 0.5f, 0.5f)), 0.f);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.5f, 0.5f, 0.5f)), 1.f);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.0f, 0.5f, 0.5f)), 0.5f);
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.75f, 0.5f, 0.5f)), 0.75f);  // towards the zero beyond the last voxel
  EXPECT_FLOAT_EQ(grid_density(g, Vec3(1.5f, 0.25f, 0.5f)), 0.75f);
  EXPECT_EQ(grid_density(g, Vec3(2.5f, 0.5f, 0.5f)), 0.f);
  EXPECT_EQ(grid_density(g, Vec3(-1.f, 0.5f, 0.5f)), 0.f);
}

// A 37 x 21 x 45 grid, zero but for two blobs: only their bricks are stored,
// and every lookup equals the dense one.
struct TwoBlobs {
  static constexpr int nx = 37, ny = 21, nz = 45;
  std::vector<Float> v = std::vector<Float>(static_cast<size_t>(nx) * ny * nz, 0.f);
  Vec3 p0{-2.f, 0.f, 1.f}, p1{3.f, 2.f, 7.f};
  TwoBlobs() {
    Rng rng = Rng::for_sample(1, 2, 3);
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          const bool a = x < 5 && y < 6 && z < 4, b = x > 30 && y > 15 && z > 38;
          if (a || b) v[(static_cast<size_t>(z) * ny + y) * nx + x] = (b ? 20.f : 1.f) * rng.uniform();
        }
  }
};

TEST(GridMedium, SparseLatticeStoresOnlyOccupiedBricksAndMatchesDenseLookups) {
  const TwoBlobs b;
  const TestGrid t(b.v, b.nx, b.ny, b.nz, b.p0, b.p1);
  EXPECT_EQ(t.desc.density.values.size(), 5u * kBrickVoxels);  // blob a: 1 brick, blob b: 2 x 1 x 2
  Rng rng = Rng::for_sample(4, 5, 6);
  for (int i = 0; i < 100000; ++i) {
    const Vec3 u(rng.uniform(), rng.uniform(), rng.uniform());
    const Vec3 p = b.p0 - Vec3(0.3f) + u * (b.p1 - b.p0 + Vec3(0.6f));
    const Float want = dense_lookup(b.v, b.nx, b.ny, b.nz, b.p0, b.p1, p);
    ASSERT_NEAR(grid_density(t.view, p), want, 2e-4f) << i;  // float transforms: ~1e-6 voxel at 20 per voxel
  }
}

TEST(GridMedium, MajorantCellsBoundEveryLookupAndEmptyCellsAreZero) {
  const TwoBlobs b;
  const TestGrid t(b.v, b.nx, b.ny, b.nz, b.p0, b.p1, 16);
  const MajorantGridView& m = t.view.majorants;
  int zero_cells = 0;
  for (Float c : t.desc.majorants.max_density) zero_cells += c == 0.f;
  EXPECT_GT(zero_cells, 16 * 16 * 16 / 2);  // the space between the blobs is free
  Rng rng = Rng::for_sample(7, 8, 9);
  for (int i = 0; i < 200000; ++i) {
    const Vec3 q = m.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (m.hi - m.lo);
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = std::min(15, static_cast<int>((q[a] - m.lo[a]) / (m.hi[a] - m.lo[a]) * 16));
    const Float bound = m.max_density[(c[2] * 16 + c[1]) * 16 + c[0]];
    ASSERT_LE(lattice_trilinear(t.view.density, q), bound) << i;
  }
}

TEST(GridMedium, MajorantWalkVisitsTheCellsAlongTheRayInOrderWithoutGaps) {
  const TwoBlobs b;
  const TestGrid t(b.v, b.nx, b.ny, b.nz, b.p0, b.p1, 16);
  const MajorantGridView& m = t.view.majorants;
  Rng rng = Rng::for_sample(1, 1, 1);
  for (int i = 0; i < 3000; ++i) {
    Vec3 o = m.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (m.hi - m.lo);
    Vec3 d = Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f);
    if (i % 7 == 0) d.y = 0.f;   // axis-parallel planes too
    if (i % 11 == 0) d.x = -0.f;
    if (i % 13 == 0) o.z = m.lo.z + (m.hi.z - m.lo.z) * 5.f / 16.f;  // on a cell face
    Float t_max = 1e6f;
    if (i % 3 == 0) {  // from outside the box, unbounded
      o -= 100.f * d;
      t_max = kInfinity;
    }
    GridRay r;
    if (!grid_clip(t.view, glm::inverse(Mat3(t.desc.density.lattice_from_world)) *
                               (o - Vec3(t.desc.density.lattice_from_world[3])),
                   d, t_max, &r)) {
      ASSERT_EQ(i % 3, 0) << "a ray from inside the box missed it";
      continue;
    }
    MajorantWalk w = majorant_walk(m, r.o, r.d, r.t0, r.t1);
    Float ta, tb, bound, last = r.t0;
    int cells = 0;
    while (majorant_next(m, w, &ta, &tb, &bound)) {
      ASSERT_EQ(ta, last);
      ASSERT_GE(tb, ta);
      // The middle of the part lies in the cell whose bound was returned.
      const Vec3 q = r.o + 0.5f * (ta + tb) * r.d;
      int c[3];
      for (int a = 0; a < 3; ++a)
        c[a] = std::clamp(static_cast<int>(std::floor((q[a] - m.lo[a]) / (m.hi[a] - m.lo[a]) * 16)), 0, 15);
      if (tb - ta > 1e-3f * (r.t1 - r.t0)) {
        EXPECT_EQ(bound, m.max_density[(c[2] * 16 + c[1]) * 16 + c[0]]) << i;
      }
      last = tb;
      ++cells;
    }
    EXPECT_NEAR(last, r.t1, 1e-5f * (1.f + r.t1)) << i;  // up to rounding at the box's faces
    EXPECT_LE(cells, 3 * 16 + 3);
  }
}

// Transmittance along a line, by a fine midpoint rule.
double quadrature_optical_depth(const GridMediumView& g, Vec3 o, Vec3 d, Float t_max) {
  const int n = 20000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += grid_density(g, o + ((i + 0.5f) / n * t_max) * d);
  return sum * t_max / n;
}

// A ray from near one blob through the other, and its optical depth per unit extinction.
struct BlobRay {
  Vec3 o, d;
  Float len;
  double tau;
  explicit BlobRay(const TestGrid& t) {
    const Vec3 e(2.9f, 1.9f, 6.9f);
    o = Vec3(-2.2f, 0.1f, 1.1f);
    d = glm::normalize(e - o);
    len = glm::length(e - o);
    tau = quadrature_optical_depth(t.view, o, d, len);
  }
};

// Delta tracking through the two blobs (cells of every majorant, restarts
// at their faces): reaching the end, scattering and the emission along the
// way each match their integrals over the ray, per channel.
TEST(GridMedium, DeltaTrackingThroughSparseCellsMatchesQuadrature) {
  const TwoBlobs b;
  const TestGrid t(b.v, b.nx, b.ny, b.nz, b.p0, b.p1);
  Medium m = on_grid(Rgb(0.05f, 0.1f, 0.2f), Rgb(0.2f, 0.15f, 0.1f));
  m.Le = Rgb(1.f, 2.f, 3.f);
  const BlobRay ray(t);
  const double tau = ray.tau;
  const int n = 400000;
  glm::dvec3 reach(0.0), scatter(0.0), glow(0.0);  // (float sums of 400,000 weights drift)
  Rng rng = Rng::for_sample(5, 5, 5);
  for (int i = 0; i < n; ++i) {
    HeroChannels h;
    choose_hero(h, rng.uniform());
    const MediumSegment seg = sample_grid_segment(m, t.view, ray.o, ray.d, ray.len, rng.uniform(), nullptr, h);
    (seg.scattered ? scatter : reach) += glm::dvec3(seg.weight);
    glow += glm::dvec3(seg.emitted);
  }
  for (int k = 0; k < 3; ++k) {
    const double sigma_t = m.sigma_a[k] + m.sigma_s[k], T = std::exp(-sigma_t * tau);
    EXPECT_NEAR(reach[k] / n, T, 0.005) << k;
    EXPECT_NEAR(scatter[k] / n, m.sigma_s[k] / sigma_t * (1.0 - T), 0.005) << k;
    const double want = m.Le[k] * m.sigma_a[k] / sigma_t * (1.0 - T);
    EXPECT_NEAR(glow[k] / n, want, 0.02 * want) << k;
  }
}

// Tentative collisions (lookups) per ray through the two blobs: the
// majorant grid skips the free space between them.
double lookups_per_ray(const TestGrid& t, const Medium& m) {
  Rng rng = Rng::for_sample(2, 4, 6);
  uint64_t lookups = 0;
  const int rays = 20000;
  for (int i = 0; i < rays; ++i) {
    const Vec3 o(-2.f, rng.uniform() * 2.f, 1.f + rng.uniform() * 6.f);
    const Vec3 d = glm::normalize(Vec3(1.f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
    GridRay r;
    if (!grid_clip(t.view, o, d, 100.f, &r)) continue;
    TentativeCollisions c = tentative_collisions(t.view, r, max_component(medium_sigma_t(m)));
    Rng track = tracking_rng(0.5f, o, d);
    Vec3 q;
    while (next_tentative_collision(t.view, c, track, q)) ++lookups;
  }
  return static_cast<double>(lookups) / rays;
}

TEST(GridMedium, MajorantGridSkipsFreeSpace) {
  const TwoBlobs b;
  Medium m;
  m.sigma_s = Rgb(1.f);
  const double one_cell = lookups_per_ray(TestGrid(b.v, b.nx, b.ny, b.nz, b.p0, b.p1, 1), m);
  const double cells = lookups_per_ray(TestGrid(b.v, b.nx, b.ny, b.nz, b.p0, b.p1, 16), m);
  EXPECT_LT(cells, 0.25 * one_cell) << one_cell << " lookups per ray with one majorant, " << cells << " with 16^3";
}


TEST(GridMedium, RatioTrackingThroughASparseGridEstimatesTheTransmittance) {
  const TwoBlobs b;
  const TestGrid t(b.v, b.nx, b.ny, b.nz, b.p0, b.p1);
  Medium m = on_grid(Rgb(0.1f, 0.3f, 0.6f), Rgb(0.2f, 0.2f, 0.0f));
  const BlobRay ray(t);
  const double tau = ray.tau;
  ASSERT_GT(tau, 0.3);
  const int n = 100000;
  Rgb sum(0.f);
  for (int i = 0; i < n; ++i) sum += grid_transmittance(m, t.view, ray.o + Vec3(0.f, 0.f, 1e-7f * i), ray.d, ray.len, nullptr);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(sum[k] / n, std::exp(-(m.sigma_a[k] + m.sigma_s[k]) * tau), 0.006) << k;
}

// A 4^3 grid of ones over [-4, 4]^3: exactly 1 within [-3, 3]^3 (between
// the outer voxel centres).
struct ConstantGrid : TestGrid {
  ConstantGrid() : TestGrid(std::vector<Float>(64, 1.f), 4, 4, 4, Vec3(-4.f), Vec3(4.f)) {}
};

TEST(GridMedium, RatioTrackingEstimatesTheTransmittance) {
  const ConstantGrid c;
  Medium m = on_grid(Rgb(0.1f, 0.3f, 0.6f), Rgb(0.1f, 0.2f, 0.0f));
  const Float d = 2.5f;
  Rgb sum(0.f);
  const int n = 200000;
  Rng rng = Rng::for_sample(3, 4, 5);
  for (int i = 0; i < n; ++i) {
    const Vec3 o(rng.uniform() - 0.5f, rng.uniform() - 0.5f, -1.f);
    sum += grid_transmittance(m, c.view, o, Vec3(0.f, 0.f, 1.f), d, nullptr);
  }
  const Rgb mean = sum / static_cast<Float>(n);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mean[k], std::exp(-(m.sigma_a[k] + m.sigma_s[k]) * d), 0.004) << k;
}

TEST(GridMedium, DeltaTrackingEstimatesTransmittanceAndScatteringInEveryChannel) {
  const ConstantGrid c;
  Medium m = on_grid(Rgb(0.f, 0.2f, 0.5f), Rgb(0.f, 0.6f, 1.5f));
  const Float t_max = 1.3f;
  const int n = 400000;
  glm::dvec3 reach(0.0), scatter(0.0);
  Rng rng = Rng::for_sample(7, 8, 9);
  for (int i = 0; i < n; ++i) {
    const Vec3 o(rng.uniform() - 0.5f, rng.uniform() - 0.5f, -1.f);
    HeroChannels h;
    choose_hero(h, rng.uniform());
    const MediumSegment seg = sample_grid_segment(m, c.view, o, Vec3(0.f, 0.f, 1.f), t_max, rng.uniform(), nullptr, h);
    ASSERT_TRUE(std::isfinite(seg.weight.x) && std::isfinite(seg.weight.y) && std::isfinite(seg.weight.z));
    (seg.scattered ? scatter : reach) += glm::dvec3(seg.weight);
  }
  reach /= static_cast<double>(n);
  scatter /= static_cast<double>(n);
  for (int k = 0; k < 3; ++k) {
    const double sigma_t = m.sigma_a[k] + m.sigma_s[k];
    const double T = std::exp(-sigma_t * t_max);
    EXPECT_NEAR(reach[k], T, 0.006) << "channel " << k;
    const double albedo = sigma_t > 0 ? m.sigma_s[k] / sigma_t : 0.0;
    EXPECT_NEAR(scatter[k], albedo * (1.0 - T), 0.006) << "channel " << k;
  }
}

TEST(GridMedium, RaysMissingTheBoxSeeNoMedium) {
  const ConstantGrid c;
  Medium m;
  m.sigma_s = Rgb(1.f);
  m.grid = 0;
  EXPECT_EQ(grid_transmittance(m, c.view, Vec3(10.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), 100.f, nullptr), Rgb(1.f));
  HeroChannels h;
  choose_hero(h, 0.5f);
  const MediumSegment seg =
      sample_grid_segment(m, c.view, Vec3(10.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), kInfinity, 0.3f, nullptr, h);
  EXPECT_FALSE(seg.scattered);
  EXPECT_EQ(seg.weight, Rgb(1.f));
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

// pbrt-v4's cloud: solid below y = 0 (its base term), noise above, within
// [0, 1] everywhere; parameters as pbrt-v4 reads them.
TEST(CloudMedium, DensityIsSolidBelowAndNoisyAboveWithinOne) {
  SceneDesc d = load_pbrt_string(
      "Camera \"perspective\"\nWorldBegin\nAttributeBegin\nTranslate 0 10 0\n"
      "MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float density\" 2 \"float wispiness\" 0.5 \"float frequency\" 3 "
      "\"point3 p0\" [ -1 -1 -1 ] \"point3 p1\" [ 2 2 2 ] \"rgb sigma_s\" [ 3 3 3 ]\nAttributeEnd\n"
      "MediumInterface \"c\" \"\"\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 2 ]\n",
      "<t>", ".");
  ASSERT_EQ(d.grids.size(), 1u);
  const GridDesc& g = d.grids[0];
  EXPECT_EQ(g.cloud, 1);
  EXPECT_EQ(g.cloud_density, 2.f);
  EXPECT_EQ(g.cloud_wispiness, 0.5f);
  EXPECT_EQ(g.cloud_frequency, 3.f);
  EXPECT_EQ(g.majorants.lo, Vec3(-1.f));
  EXPECT_EQ(g.majorants.hi, Vec3(2.f));
  EXPECT_EQ(d.media[0].sigma_s, Rgb(3.f));
  GridMediumView v;
  v.density = sparse_grid_view(g.density);
  v.majorants = majorant_grid_view(g.majorants);
  v.cloud = g.cloud;
  v.cloud_density = g.cloud_density;
  v.cloud_wispiness = g.cloud_wispiness;
  v.cloud_frequency = g.cloud_frequency;
  Rng rng = Rng::for_sample(3, 3, 3);
  double between = 0.0;
  int inside = 0;
  const Vec3 origin = Vec3(0.f, 10.f, 0.f) - Vec3(d.render_origin);  // the medium's origin in render space
  for (int i = 0; i < 20000; ++i) {
    const Vec3 q(rng.uniform() * 3.f - 1.f, rng.uniform() * 3.f - 1.f, rng.uniform() * 3.f - 1.f);
    const Float rho = grid_density(v, origin + q);
    ASSERT_GE(rho, 0.f);
    ASSERT_LE(rho, 1.f);  // the majorant's bound
    if (q.y <= 0.f) {
      EXPECT_EQ(rho, 1.f) << q.y;
    }
    if (q.y > 0.55f && q.y < 0.95f) {
      between += rho;
      ++inside;
    }
  }
  EXPECT_GT(between / inside, 0.02);
  EXPECT_LT(between / inside, 0.9);
}

}  // namespace
}  // namespace tessera
