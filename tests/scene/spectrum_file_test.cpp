// Spectra given as files (pbrt-v4's "spectrum eta" "spds/Au.eta.spd").
#include <gtest/gtest.h>

#include "scene/named_spectra.h"
#include "scene/spectrum_file.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_error;
using test::load_world;
using test::TempDir;

std::string parse_error(const std::string& text) {
  try {
    parse_spectrum_text(text, "s.spd");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(SpectrumFile, PairsWithCommentsAndAnyWhitespace) {
  std::vector<Float> v = parse_spectrum_text("# measured\n400 0.5  # blue\n\t500\t0.25\r\n600 1e-1\n", "s.spd");
  EXPECT_EQ(v, (std::vector<Float>{400.f, 0.5f, 500.f, 0.25f, 600.f, 0.1f}));
}

TEST(SpectrumFile, MalformedFilesAreErrors) {
  EXPECT_NE(parse_error("# nothing\n").find("no wavelength/value pairs"), std::string::npos);
  EXPECT_NE(parse_error("400 1 500\n").find("odd count"), std::string::npos);
  EXPECT_NE(parse_error("500 1 400 1\n").find("wavelengths must increase"), std::string::npos);
  EXPECT_NE(parse_error("400 1\n500 x\n").find("line 2: 'x' is not a finite number"), std::string::npos);
  EXPECT_NE(parse_error("400 nan\n").find("not a finite number"), std::string::npos);
  EXPECT_EQ(parse_error("400 1 500 1"), "");
  EXPECT_EQ(parse_error("400 1 500").rfind("cannot read spectrum file 's.spd': ", 0), 0u);
}

TEST(SpectrumFile, SceneParametersReadFilesBesideTheScene) {
  TempDir dir;
  // Flat spectra: a constant c reduces to RGB (c, c, c).
  dir.write("spds/eta.spd", "360 0.2\n830 0.2\n");
  dir.write("spds/k.spd", "# k\n360 3\n600 3\n830 3\n");
  SceneDesc s = load_world(std::string("Material \"conductor\" \"spectrum eta\" \"spds/eta.spd\" \"spectrum k\" \"spds/k.spd\"\n") +
                               kTriangle,
                           dir.path());
  const Material& m = s.materials.at(s.meshes.back().material);
  EXPECT_VEC3_NEAR(m.eta, Vec3(0.2f), 1e-3f);
  EXPECT_VEC3_NEAR(m.k, Vec3(3.f), 3e-3f);
  bool warned = false;
  for (const std::string& w : s.warnings)
    warned |= w.find("(files 'spds/eta.spd', 'spds/k.spd') used as spectra with --spectral on; reduced to RGB") !=
              std::string::npos;
  EXPECT_TRUE(warned);
  // The spectra themselves are kept, sampled every 5 nm, for spectral transport.
  ASSERT_GE(m.eta_spectrum, 0);
  ASSERT_GE(m.k_spectrum, 0);
  ASSERT_EQ(s.spectra.size(), 2u * kSpectralSamples);
  for (int i = 0; i < kSpectralSamples; ++i) {
    EXPECT_NEAR(s.spectra[m.eta_spectrum * kSpectralSamples + i], 0.2f, 1e-6f);
    EXPECT_NEAR(s.spectra[m.k_spectrum * kSpectralSamples + i], 3.f, 1e-6f);
  }
  // A sloped reflectance reduces to a colour that follows the slope.
  dir.write("red.spd", "400 0.1 700 0.9\n");
  SceneDesc red = load_world(std::string("Material \"diffuse\" \"spectrum reflectance\" \"red.spd\"\n") + kTriangle, dir.path());
  const Rgb r = red.materials.at(red.meshes.back().material).reflectance.value;
  EXPECT_GT(r.x, r.y);
  EXPECT_GT(r.y, r.z);
  // Named spectra are still names, not files.
  SceneDesc named = load_world(std::string("Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\"\n") + kTriangle, dir.path());
  EXPECT_VEC3_NEAR(named.materials.at(named.meshes.back().material).eta, *named_spectrum_rgb("metal-Ag-eta"), 1e-6f);
}

TEST(SpectrumFile, MissingOrBadFilesNameTheSceneLine) {
  TempDir dir;
  std::string e = load_error("WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"spds/none.spd\"\n", dir.path());
  EXPECT_NE(e.find("bad.pbrt:2: unknown named spectrum \"spds/none.spd\" (and no spectrum file"), std::string::npos) << e;
  std::filesystem::create_directories(dir.file("adir.spd"));
  e = load_error("WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"adir.spd\"\n", dir.path());
  EXPECT_NE(e.find("bad.pbrt:2:"), std::string::npos) << e;
  dir.write("odd.spd", "400 1 500\n");
  e = load_error("WorldBegin\n\nMaterial \"diffuse\" \"spectrum reflectance\" \"odd.spd\"\n", dir.path());
  EXPECT_NE(e.find("bad.pbrt:3: cannot read spectrum file"), std::string::npos) << e;
  EXPECT_NE(e.find("odd count"), std::string::npos) << e;
}

}  // namespace
}  // namespace tessera
