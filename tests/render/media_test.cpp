// Participating media (pbrt-v4's homogeneous media, MediumInterface and the
// volumetric path tracer): analytic answers for absorption along camera and
// shadow rays, medium emission, and a scattering furnace (chromatic, with a
// Henyey-Greenstein lobe, guided and unguided) whose radiance is 1 everywhere.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "guided_helpers.h"
#include "media_helpers.h"

namespace tessera {
namespace {

using testing::channel_stats;
using testing::ChannelStats;
using testing::GuidedScene;
using testing::box;
using testing::header;
using testing::mean_rgb;
using testing::slab;

constexpr const char* kAbsorber =
    "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.1 0.5 1 ] \"rgb sigma_s\" [ 0 0 0 ]\n";

TEST(Media, CameraRaysThroughAnAbsorberGetExpMinusSigmaD) {
  const std::string scene = header(4, 1) + "WorldBegin\n" + slab(kAbsorber) +
                            "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ]\n"
                            "Shape \"trianglemesh\" \"point3 P\" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "
                            "\"integer indices\" [ 0 2 1 0 3 2 ]\nAttributeEnd\n";
  RenderResult r = testing::render_text(scene);
  const Rgb m = mean_rgb(r);
  const double d = 3.0;
  EXPECT_NEAR(m.x, std::exp(-0.1 * d), 2e-4);
  EXPECT_NEAR(m.y, std::exp(-0.5 * d), 2e-4);
  EXPECT_NEAR(m.z, std::exp(-1.0 * d), 2e-4);
  EXPECT_EQ(r.stats.counters.path.medium_vertices, 0u);  // absorption alone is applied exactly
}

TEST(Media, ShadowRaysThroughAnAbsorberGetItsTransmittanceToo) {
  // A white diffuse wall at z = 10 lit head-on by a distant light through the
  // slab and seen through it: L = (1 / pi) E T^2.
  const std::string scene = header(4, 1) + "WorldBegin\n" +
                            "LightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0 1 ] \"rgb L\" [ 3 3 3 ]\n" +
                            slab(kAbsorber) +
                            "Material \"diffuse\" \"rgb reflectance\" [ 1 1 1 ]\n"
                            "Shape \"trianglemesh\" \"point3 P\" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "
                            "\"integer indices\" [ 0 2 1 0 3 2 ]\n";
  const Rgb m = mean_rgb(testing::render_text(scene));
  const double d = 3.0, E = 3.0;
  EXPECT_NEAR(m.x, E / M_PI * std::exp(-2 * 0.1 * d), 2e-4);
  EXPECT_NEAR(m.y, E / M_PI * std::exp(-2 * 0.5 * d), 2e-4);
  EXPECT_NEAR(m.z, E / M_PI * std::exp(-2 * 1.0 * d), 2e-4);
}

TEST(Media, AnEmissiveSlabGlowsLeTimesOneMinusTransmittance) {
  const std::string medium =
      "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 0 0 0 ] "
      "\"rgb Le\" [ 1 2 4 ] \"float Lescale\" 0.5\n";
  RenderResult r = testing::render_text(header(256, 5) + "WorldBegin\n" + slab(medium));
  const Rgb m = mean_rgb(r);
  const double glow = 0.5 * (1.0 - std::exp(-0.5 * 3.0));  // 65536 Bernoulli samples: 1 sigma ~ 0.2 %
  EXPECT_NEAR(m.x, 1.0 * glow, 0.01 * glow);
  EXPECT_NEAR(m.y, 2.0 * glow, 0.01 * 2.0 * glow);
  EXPECT_NEAR(m.z, 4.0 * glow, 0.01 * 4.0 * glow);
}

// A cube of scattering medium (no absorption, chromatic, forward-scattering)
// and a white two-sided diffuse card through it, under a uniform white sky:
// nothing absorbs, so every path ends in the sky and the radiance is 1
// everywhere, in every channel, for any number of bounces and any guide.
SceneDesc scattering_furnace(int spp) {
  const std::string scene = header(spp, 100000, 40.0) + "WorldBegin\n" +
                            "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n"
                            "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] "
                            "\"rgb sigma_s\" [ 0.3 0.5 0.8 ] \"float g\" 0.6\n"
                            "AttributeBegin\nMaterial \"interface\"\nMediumInterface \"m\" \"\"\n" +
                            box(Vec3(-1.5, -1.5, 3), Vec3(1.5, 1.5, 6)) + "AttributeEnd\n" +
                            "AttributeBegin\nMediumInterface \"m\"\nMaterial \"diffuse\" \"rgb reflectance\" [ 1 1 1 ]\n"
                            "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 4.5  1 -1 4.5  1 1 4  -1 1 4 ] "
                            "\"integer indices\" [ 0 1 2 0 2 3 ]\nAttributeEnd\n";
  return load_pbrt_string(scene, "<furnace>", ".");
}

// Unguided renders of a furnace with and without next-event estimation:
// 1 in every channel within 1 % (and, given precision, within it too).
void expect_unguided_furnace(const GuidedScene& s, double precision) {
  for (bool nee : {true, false}) {
    SCOPED_TRACE(nee ? "with next-event estimation" : "without");
    RenderOptions opt;
    opt.nee = nee;
    RenderResult r = s.run(nullptr, opt);
    const ChannelStats m = channel_stats(r.film);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.mean[c], 1.0, 0.01) << "channel " << c;
    if (precision > 0) testing::expect_precise(m, precision, "furnace");
    EXPECT_GT(r.stats.counters.path.medium_vertices, r.stats.counters.samples);
    EXPECT_EQ(r.stats.counters.rejected_nonfinite, 0u);
  }
}

TEST(Media, ScatteringFurnaceIsOneInEveryChannel) {
  expect_unguided_furnace(GuidedScene(scattering_furnace(1024)), 0.003);
}

// The same furnace dense and strongly chromatic (optical depths 9, 18 and
// 36 across the box): hundreds of collisions a path, still 1 in every
// channel (the hero MIS keeps each path's weight bounded).
TEST(Media, DeepChromaticFurnaceIsOneInEveryChannel) {
  std::string text = header(256, 100000, 40.0) + "WorldBegin\n" + "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n"
                     "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] "
                     "\"rgb sigma_s\" [ 3 6 12 ] \"float g\" 0.6\n"
                     "AttributeBegin\nMaterial \"interface\"\nMediumInterface \"m\" \"\"\n" +
                     box(Vec3(-1.5, -1.5, 3), Vec3(1.5, 1.5, 6)) + "AttributeEnd\n";
  expect_unguided_furnace(GuidedScene(load_pbrt_string(text, "<deep furnace>", ".")), 0.0);
}

// The furnace again, lit by the walls of a box of emitters (L = 1) around
// the camera, filled with a white medium: radiance 1 everywhere. Light
// samples from points in the medium take the large wall triangles by solid
// angle (kernels/spherical_triangle.h) near the walls and by area farther in;
// their pdfs must match the ones MIS gives to phase-sampled hits.
TEST(Media, AreaLitScatteringFurnaceIsOne) {
  const std::string scene =
      "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0 0 0 ] \"rgb sigma_s\" [ 0.6 0.9 1.5 ]\n"
      "MediumInterface \"m\"\n" + header(256, 100000, 60.0) + "WorldBegin\n"
      "AttributeBegin\nMediumInterface \"m\" \"\"\nAreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ] \"bool twosided\" true\n"
      "Material \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n" +
      box(Vec3(-1, -1, -1), Vec3(1, 1, 2)) + "AttributeEnd\n";
  expect_unguided_furnace(GuidedScene(load_pbrt_string(scene, "<area furnace>", ".")), 0.0);
}

TEST(Media, GuidedScatteringFurnaceIsOneInEveryChannel) {
  GuidedScene s(scattering_furnace(1024));
  // A fixed mixture: learned weights get out of the way in a furnace, where
  // the light arrives from everywhere.
  GuideField guide = s.make_guide(testing::config_with(GuideTarget::ExpectedSarsa, 0.5f));
  RenderResult r = s.run(&guide);
  const ChannelStats m = channel_stats(r.film);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.mean[c], 1.0, 0.01) << "channel " << c;
  testing::expect_precise(m, 0.003, "guided furnace");
  EXPECT_GT(r.stats.counters.path.guided_samples, 0u);
  EXPECT_GT(r.stats.guide.updates, 0u);
  EXPECT_EQ(r.stats.guide.rejected_nonfinite, 0u);
}

// The same media as density grids (pbrt-v4's "uniformgrid"): a 4^3 grid of
// density 2, constant where the scene is (between the outer voxel centres),
// with half the coefficients, gives the same images through delta and ratio
// tracking.
TEST(Media, GridMediaMatchTheirHomogeneousEquivalents) {
  std::string densities;
  for (int i = 0; i < 64; ++i) densities += "2 ";
  // Absorption through the slab (ratio tracking on camera and shadow rays).
  const std::string grid_absorber =
      "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 4 \"integer ny\" 4 \"integer nz\" 4 "
      "\"float density\" [ " + densities + "] \"point3 p0\" [ -200 -200 -10 ] \"point3 p1\" [ 200 200 20 ] "
      "\"rgb sigma_a\" [ 0.05 0.1 0.2 ] \"rgb sigma_s\" [ 0 0 0 ]\n";
  const std::string scene = header(1024, 1) + "WorldBegin\n" +
                            "LightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0 1 ] \"rgb L\" [ 3 3 3 ]\n" +
                            slab(grid_absorber) +
                            "Material \"diffuse\" \"rgb reflectance\" [ 1 1 1 ]\n"
                            "Shape \"trianglemesh\" \"point3 P\" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "
                            "\"integer indices\" [ 0 2 1 0 3 2 ]\n";
  const ChannelStats m = channel_stats(testing::render_text(scene).film);
  const double d = 3.0, E = 3.0;
  // Ratio tracking is a stochastic estimate (262144 camera and shadow
  // rays): within 4.5 of its standard errors, each below 0.8 % of the
  // expected value, so a bias of 3.6 % cannot hide.
  for (int c = 0; c < 3; ++c) {
    const double expected = E / M_PI * std::exp(-2 * 2 * (c == 0 ? 0.05 : c == 1 ? 0.1 : 0.2) * d);
    EXPECT_LT(m.se[c], 0.008 * expected) << "channel " << c;
    EXPECT_NEAR(m.mean[c], expected, 4.5 * m.se[c]) << "channel " << c << ", standard error " << m.se[c];
  }
  // The scattering furnace, chromatic, forward-scattering: still 1 everywhere.
  std::string furnace = header(1024, 100000, 40.0) + "WorldBegin\n" + "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n" +
                        "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 4 \"integer ny\" 4 "
                        "\"integer nz\" 4 \"float density\" [ " + densities + "] \"point3 p0\" [ -4 -4 0 ] "
                        "\"point3 p1\" [ 4 4 9 ] \"rgb sigma_a\" [ 0 0 0 ] \"rgb sigma_s\" [ 0.2 0.25 0.3 ] \"float g\" 0.6\n"
                        "AttributeBegin\nMaterial \"interface\"\nMediumInterface \"m\" \"\"\n" +
                        box(Vec3(-1.5, -1.5, 3), Vec3(1.5, 1.5, 6)) + "AttributeEnd\n";
  GuidedScene s(load_pbrt_string(furnace, "<grid furnace>", "."));
  RenderResult r = s.run(nullptr);
  const ChannelStats f = channel_stats(r.film);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.mean[c], 1.0, 0.01) << "channel " << c;
  testing::expect_precise(f, 0.003, "grid furnace");
  EXPECT_GT(r.stats.counters.path.medium_vertices, r.stats.counters.samples);
}

// pbrt-v4's volpath lets shadow rays pass "interface" surfaces (also
// without media, and through a mix that resolves to one): a white wall lit
// head-on through such sheets keeps E / pi.
TEST(Media, ShadowRaysPassInterfaceSurfacesWithOrWithoutMedia) {
  auto wall_through = [](const std::string& sheet_material) {
    const std::string scene = header(4, 1) + "WorldBegin\n" +
                              "LightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 0 0 1 ] \"rgb L\" [ 3 3 3 ]\n" +
                              "MakeNamedMaterial \"black\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n"
                              "MakeNamedMaterial \"clear\" \"string type\" \"interface\"\n"
                              "AttributeBegin\n" + sheet_material + "\n" +
                              "Shape \"trianglemesh\" \"point3 P\" [ -100 -100 5  100 -100 5  100 100 5  -100 100 5 ] "
                              "\"integer indices\" [ 0 2 1 0 3 2 ]\nAttributeEnd\n"
                              "Material \"diffuse\" \"rgb reflectance\" [ 1 1 1 ]\n"
                              "Shape \"trianglemesh\" \"point3 P\" [ -100 -100 10  100 -100 10  100 100 10  -100 100 10 ] "
                              "\"integer indices\" [ 0 2 1 0 3 2 ]\n";
    SceneDesc d = load_pbrt_string(scene, "<sheet>", ".");
    return mean_rgb(testing::render_desc(std::move(d), RenderOptions{}));
  };
  EXPECT_NEAR(wall_through("NamedMaterial \"clear\"").x, 3.0 / M_PI, 1e-4);
  EXPECT_NEAR(wall_through("Material \"mix\" \"string materials\" [ \"black\" \"clear\" ] \"float amount\" 1").x,
              3.0 / M_PI, 1e-4);
  EXPECT_NEAR(wall_through("NamedMaterial \"black\"").x, 0.0, 1e-6);  // an opaque sheet blocks
}

TEST(Media, SameSeedGivesTheSameImageForAnyThreadCount) {
  GuidedScene s(scattering_furnace(4));
  RenderOptions one, three;
  one.threads = 1;
  three.threads = 3;
  EXPECT_TRUE(testing::films_identical(s.run(nullptr, one).film, s.run(nullptr, three).film));
}

TEST(Media, ScenesWithoutMediaDoNotRunTheVolumetricIntegrator) {
  SceneData plain(load_pbrt_string(header(1, 5) + "WorldBegin\n" + box(Vec3(-1), Vec3(1)), "<t>", "."));
  EXPECT_EQ(plain.effects() & kEffectMedia, 0u);
  EXPECT_EQ(specialisation_for(plain.effects()) & kSpecMedia, 0u);
  EXPECT_EQ(plain.view().triangle_media, nullptr);
  SceneData fog(scattering_furnace(1));
  EXPECT_NE(fog.effects() & kEffectMedia, 0u);
  EXPECT_NE(specialisation_for(fog.effects()) & kSpecMedia, 0u);
}

}  // namespace
}  // namespace tessera
