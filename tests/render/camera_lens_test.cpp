// The thin-lens camera (pbrt-v4 "lensradius", "focaldistance"): a sharp
// edge at the focal distance stays sharp; out of focus it spreads exactly as
// the lens's circle of confusion predicts.
#include <gtest/gtest.h>

#include <cmath>

#include "render_helpers.h"

namespace tessera {
namespace {

constexpr int kW = 32, kH = 8;

// An emitter half-plane (world x < 0) at depth `edge_z`, seen through a lens
// focused at `focus`. Returns each column's mean.
std::vector<double> edge_columns(double lens_radius, double focus, double edge_z) {
  const std::string scene = R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 20 ] "float lensradius" [ )" + std::to_string(lens_radius) +
                            R"( ] "float focaldistance" [ )" + std::to_string(focus) + R"( ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 8 ]
Sampler "independent" "integer pixelsamples" [ 1024 ]
PixelFilter "box"
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ] "bool twosided" true
Shape "trianglemesh" "point3 P" [ -1000 -1000 )" + std::to_string(edge_z) + "  0 -1000 " + std::to_string(edge_z) +
                            "  0 1000 " + std::to_string(edge_z) + "  -1000 1000 " + std::to_string(edge_z) +
                            R"( ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  const ImageRgb img = film_mean(testing::render_text(scene).film);
  std::vector<double> cols(kW, 0.0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) cols[x] += img.rgb[3 * (y * kW + x)] / kH;
  return cols;
}

// P(X < t) for X the x coordinate of a uniform point on the unit disk.
double disk_x_cdf(double t) {
  if (t <= -1) return 0;
  if (t >= 1) return 1;
  return 0.5 + (t * std::sqrt(1 - t * t) + std::asin(t)) / M_PI;
}

// The expected lit share of each column, lit where camera-space x < 0:
// a ray through lens point x_l aimed at the focal plane crosses depth E at
// x_l (1 - E/f) + s E (s: the pinhole ray's slope), averaged over the box filter.
std::vector<double> expected_columns(double lens_radius, double focus, double edge_z) {
  std::vector<double> cols(kW, 0.0);
  const double tan_half = std::tan(10.0 * M_PI / 180.0), aspect = double(kW) / kH;
  const int steps = 400;
  for (int x = 0; x < kW; ++x) {
    for (int k = 0; k < steps; ++k) {
      const double raster = x + (k + 0.5) / steps;
      const double slope = (-aspect + 2 * aspect * raster / kW) * tan_half;
      const double k_lens = lens_radius * (1 - edge_z / focus), pinhole = slope * edge_z;
      double lit;
      if (std::abs(k_lens) < 1e-12) lit = pinhole < 0 ? 1 : 0;
      else if (k_lens > 0) lit = disk_x_cdf(-pinhole / k_lens);
      else lit = 1 - disk_x_cdf(-pinhole / k_lens);
      cols[x] += lit / steps;
    }
  }
  return cols;
}

double worst_difference(std::vector<double> got, std::vector<double> expected) {
  // The camera's handedness decides which side is lit; the profile is
  // mirror-antisymmetric, so compare against the matching orientation.
  if ((got[0] > 0.5) != (expected[0] > 0.5)) std::reverse(expected.begin(), expected.end());
  double worst = 0;
  for (int x = 0; x < kW; ++x) worst = std::max(worst, std::abs(got[x] - expected[x]));
  return worst;
}

TEST(CameraLens, InFocusEdgeStaysSharp) {
  const std::vector<double> pinhole = edge_columns(0, 1e6, 10), lens = edge_columns(0.3, 10, 10);
  EXPECT_LT(worst_difference(lens, expected_columns(0.3, 10, 10)), 0.02);
  EXPECT_LT(worst_difference(pinhole, expected_columns(0, 1e6, 10)), 0.02);
  for (int x = 0; x < kW; ++x) EXPECT_NEAR(lens[x], pinhole[x], 0.03) << x;
}

TEST(CameraLens, OutOfFocusEdgeSpreadsByTheCircleOfConfusion) {
  for (double focus : {5.0, 20.0}) {  // in front of and behind the edge
    SCOPED_TRACE(focus);
    const std::vector<double> got = edge_columns(2.0, focus, 10);
    EXPECT_LT(worst_difference(got, expected_columns(2.0, focus, 10)), 0.02);
    int blurred = 0;
    for (double v : got) blurred += v > 0.05 && v < 0.95;
    EXPECT_GE(blurred, 3);  // a pinhole's box-filtered edge touches one column
  }
}

}  // namespace
}  // namespace tessera
