// --spectral auto: spectral transport only where it changes the picture.
#include <gtest/gtest.h>

#include "kernels/spectral.h"
#include "scene/spectral_choice.h"
#include "scene_test_helpers.h"

using namespace tessera;
using namespace tessera::test;

TEST(SpectralChoice, WhiteLightOnColouredSurfacesStaysRgb) {
  SceneDesc s = load_world(std::string("AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 17 17 17 ]\n") + kTriangle +
                           "AttributeEnd\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.8 0.1 0.1 ]\n" + kTriangle +
                           "LightSource \"point\" \"blackbody I\" [ 6500 ]\n");
  EXPECT_EQ(spectral_reason(s), "");
}

TEST(SpectralChoice, ColouredLightsAndMeasuredSpectraAreSpectral) {
  SceneDesc orange = load_world(std::string("AreaLightSource \"diffuse\" \"rgb L\" [ 108 76 24 ]\n") + kTriangle);
  EXPECT_EQ(spectral_reason(orange), "a strongly coloured area light");
  SceneDesc candle = load_world("LightSource \"point\" \"blackbody I\" [ 1800 ]\n" + std::string(kTriangle));
  EXPECT_EQ(spectral_reason(candle), "a strongly coloured light");
  TempDir dir;
  dir.write("eta.spd", "400 0.2 700 0.3\n");
  dir.write("k.spd", "400 3 700 4\n");
  SceneDesc gold = load_world(std::string("Material \"conductor\" \"spectrum eta\" \"eta.spd\" \"spectrum k\" \"k.spd\"\n") +
                                  kTriangle,
                              dir.path());
  EXPECT_EQ(spectral_reason(gold), "a conductor given by measured spectra");
  SceneDesc prism = load_world(std::string("Material \"dielectric\" \"spectrum eta\" \"glass-F11\"\n") + kTriangle);
  EXPECT_EQ(spectral_reason(prism), "a dispersive dielectric");
  SceneDesc plain = load_world(std::string("Material \"dielectric\" \"float eta\" 1.5\n") + kTriangle);
  EXPECT_EQ(spectral_reason(plain), "");
  SceneDesc fire = load_world(std::string("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" [ 1 ] "
                                          "\"float temperature\" [ 1500 ]\nMediumInterface \"m\" \"\"\n") +
                              kTriangle);
  EXPECT_EQ(spectral_reason(fire), "a medium glowing by temperature");
}

// pbrt-v4's named glasses disperse: Schott's Sellmeier formulas, sampled for
// spectral transport; RGB transport uses the index at 550 nm. pbrt-v4's
// "glass-F11" is the dense flint SF11 (n_d 1.78472).
TEST(SpectralChoice, NamedGlassesDisperse) {
  SceneDesc s = load_world(std::string("Material \"dielectric\" \"spectrum eta\" \"glass-F11\"\n") + kTriangle);
  const Material& m = s.materials.at(s.meshes.back().material);
  ASSERT_GE(m.ior_spectrum, 0);
  const Float* n = &s.spectra[m.ior_spectrum * kSpectralSamples];
  EXPECT_NEAR(m.ior, 1.7912f, 2e-4f);
  // n_d at 587.56 nm, between the 585 and 590 nm samples.
  const Float nd = n[45] + (n[46] - n[45]) * (587.56f - 585.f) / 5.f;
  EXPECT_NEAR(nd, 1.78472f, 2e-4f);
  for (int i = 1; i < kSpectralSamples; ++i) EXPECT_LT(n[i], n[i - 1]);  // normal dispersion
  const SceneDesc bk7 = load_world(std::string("Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n") + kTriangle);
  EXPECT_NEAR(bk7.materials.at(bk7.meshes.back().material).ior, 1.5185f, 2e-4f);
  // An eta given as samples disperses too (linear between them, constant beyond);
  // a flat one does not.
  const SceneDesc sampled =
      load_world(std::string("Material \"dielectric\" \"spectrum eta\" [ 400 1.6 700 1.5 ]\n") + kTriangle);
  const Material& ms = sampled.materials.at(sampled.meshes.back().material);
  ASSERT_GE(ms.ior_spectrum, 0);
  EXPECT_NEAR(sampled.spectra[ms.ior_spectrum * kSpectralSamples + 0], 1.6f, 1e-6f);   // 360 nm
  EXPECT_NEAR(sampled.spectra[ms.ior_spectrum * kSpectralSamples + 38], 1.55f, 1e-5f);  // 550 nm
  const SceneDesc flat =
      load_world(std::string("Material \"dielectric\" \"spectrum eta\" [ 400 1.5 700 1.5 ]\n") + kTriangle);
  EXPECT_EQ(flat.materials.at(flat.meshes.back().material).ior_spectrum, -1);
}
