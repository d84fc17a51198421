// Materials, named materials, textures and the images they load.
#include <stb/stb_image_write.h>

#include <ImfRgbaFile.h>

#include "kernels/effects.h"
#include "kernels/material_eval.h"
#include "scene/displacement.h"
#include "scene/image_io.h"
#include "scene/pbrt_materials.h"
#include "scene/scene_effects.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::kTriangle;
using test::load_world;

const Material& material_of_last_mesh(const SceneDesc& s) { return s.materials.at(s.meshes.back().material); }

TEST(PbrtMaterials, DiffuseAndNamedMaterials) {
  SceneDesc s = load_world(std::string("MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0.6 0.1 0.1 ]\n") +
                           kTriangle + "NamedMaterial \"red\"\n" + kTriangle);
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].material, 0);
  const Material& m = material_of_last_mesh(s);
  EXPECT_EQ(m.type, MaterialType::Diffuse);
  EXPECT_VEC3_NEAR(m.reflectance.value, Vec3(0.6f, 0.1f, 0.1f), 1e-6f);
}

TEST(PbrtMaterials, ConductorNamedSpectraAndRoughnessRemap) {
  SceneDesc s = load_world(std::string("Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\""
                                       " \"float roughness\" 0.09\n") + kTriangle);
  const Material& m = material_of_last_mesh(s);
  EXPECT_EQ(m.type, MaterialType::Conductor);
  EXPECT_VEC3_NEAR(m.eta, Vec3(0.143f, 0.375f, 1.442f), 1e-3f);
  EXPECT_VEC3_NEAR(m.k, Vec3(3.983f, 2.386f, 1.603f), 1e-3f);
  EXPECT_NEAR(m.alpha_x, 0.3f, 1e-6f);
  EXPECT_NEAR(m.alpha_y, 0.3f, 1e-6f);
  s = load_world(std::string("Material \"conductor\" \"float uroughness\" 0.2 \"float vroughness\" 0.1 "
                             "\"bool remaproughness\" false\n") + kTriangle);
  EXPECT_FLOAT_EQ(material_of_last_mesh(s).alpha_x, 0.2f);
  EXPECT_FLOAT_EQ(material_of_last_mesh(s).alpha_y, 0.1f);
  EXPECT_VEC3_NEAR(material_of_last_mesh(s).eta, Vec3(0.2004f, 0.924f, 1.1022f), 1e-3f);  // metal-Cu default
  s = load_world(std::string("Material \"conductor\" \"rgb reflectance\" [ 0.9 0.8 0.7 ]\n") + kTriangle);
  EXPECT_TRUE(material_of_last_mesh(s).conductor_from_reflectance);
  EXPECT_VEC3_NEAR(material_of_last_mesh(s).reflectance.value, Vec3(0.9f, 0.8f, 0.7f), 1e-6f);
}

TEST(PbrtMaterials, DielectricCoatedInterfaceMix) {
  SceneDesc s = load_world(std::string("Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n") + kTriangle +
                           "Material \"dielectric\"\n" + kTriangle +
                           "Material \"coateddiffuse\" \"rgb reflectance\" [ 0.2 0.3 0.4 ] \"float roughness\" 0.25 "
                           "\"float thickness\" 0.02\n" + kTriangle + "Material \"interface\"\n" + kTriangle +
                           "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\nMakeNamedMaterial \"b\" \"string type\" \"conductor\"\n"
                           "Material \"mix\" \"string materials\" [ \"a\" \"b\" ] \"float amount\" 0.3\n" + kTriangle);
  ASSERT_EQ(s.meshes.size(), 5u);
  const Material& glass = s.materials[s.meshes[0].material];
  EXPECT_EQ(glass.type, MaterialType::Dielectric);
  EXPECT_NEAR(glass.ior, 1.5185f, 2e-4f);  // pbrt-v4's default BK7, at 550 nm
  EXPECT_FLOAT_EQ(s.materials[s.meshes[1].material].ior, 1.5f);
  const Material& coated = s.materials[s.meshes[2].material];
  EXPECT_EQ(coated.type, MaterialType::CoatedDiffuse);
  EXPECT_NEAR(coated.alpha_x, 0.5f, 1e-6f);
  EXPECT_FLOAT_EQ(coated.ior, 1.5f);
  EXPECT_EQ(s.materials[s.meshes[3].material].type, MaterialType::Interface);
  const Material& mix = s.materials[s.meshes[4].material];
  EXPECT_EQ(mix.type, MaterialType::Mix);
  EXPECT_EQ(s.materials[mix.mix[0]].type, MaterialType::Diffuse);
  EXPECT_EQ(s.materials[mix.mix[1]].type, MaterialType::Conductor);
  EXPECT_FLOAT_EQ(mix.amount.value.x, 0.3f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(PbrtMaterials, CoatedConductorKeepsItsCoatAndItsConductor) {
  SceneDesc s = load_world(std::string("Material \"coatedconductor\" \"spectrum conductor.eta\" \"metal-Ag-eta\" "
                                       "\"spectrum conductor.k\" \"metal-Ag-k\" \"float interface.roughness\" 0.04 "
                                       "\"float conductor.roughness\" 0.01 \"float interface.eta\" 1.7 "
                                       "\"float thickness\" 0.2\n") + kTriangle +
                           "Material \"coatedconductor\" \"rgb albedo\" [ 0.5 0.5 0.5 ]\n" + kTriangle);
  const Material& m = s.materials[s.meshes[0].material];
  EXPECT_EQ(m.type, MaterialType::CoatedConductor);
  EXPECT_VEC3_NEAR(m.eta, Vec3(0.155f, 0.117f, 0.138f), 1e-3f);
  EXPECT_FLOAT_EQ(m.alpha_x, 0.2f);        // the coat's, remapped
  EXPECT_FLOAT_EQ(m.base_alpha_x, 0.1f);   // the conductor's, remapped
  EXPECT_FLOAT_EQ(m.ior, 1.7f);
  EXPECT_FLOAT_EQ(m.thickness, 0.2f);
  // pbrt-v4's defaults: copper under a smooth coat of index 1.5.
  const Material& d = s.materials[s.meshes[1].material];
  EXPECT_EQ(d.type, MaterialType::CoatedConductor);
  EXPECT_FLOAT_EQ(d.ior, 1.5f);
  EXPECT_EQ(d.alpha_x, 0.f);
  EXPECT_EQ(d.base_alpha_x, 0.f);
  // Only the scattering layer (albedo) is approximated, and said so.
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("albedo"), std::string::npos) << s.warnings[0];
}

TEST(PbrtMaterials, CoatedConductorReadsATexturedConductorRoughness) {
  // pbrt-v4 evaluates both roughnesses at the hit: the conductor's from a
  // checkerboard (0.04 or 0.25, remapped to alpha 0.2 or 0.5), the coat's constant.
  SceneDesc s = load_world(std::string("Texture \"r\" \"float\" \"checkerboard\" \"float tex1\" 0.04 \"float tex2\" 0.25\n"
                                       "Material \"coatedconductor\" \"texture conductor.roughness\" \"r\" "
                                       "\"float interface.roughness\" 0.01\n") + kTriangle);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Material& m = material_of_last_mesh(s);
  ASSERT_TRUE(m.textured_base_roughness);
  EXPECT_FALSE(m.textured_roughness);
  SceneView view;
  view.materials = s.materials.data();
  view.num_materials = static_cast<uint32_t>(s.materials.size());
  view.textures = s.textures.data();
  SurfaceHit h{};
  h.ng = h.ns = Vec3(0.f, 0.f, 1.f);
  const auto alphas = [&](Vec2 uv) {
    h.uv = uv;
    BsdfParams b;
    EXPECT_TRUE(resolve_bsdf<kSpecAll>(view, s.meshes.back().material, h, Vec3(0.f, 0.f, 1.f), &b));
    EXPECT_FLOAT_EQ(b.alpha_x, 0.1f);  // the coat
    EXPECT_FLOAT_EQ(b.base_alpha_x, b.base_alpha_y);
    return b.base_alpha_x;
  };
  EXPECT_FLOAT_EQ(alphas(Vec2(0.25f, 0.25f)), 0.2f);
  EXPECT_FLOAT_EQ(alphas(Vec2(1.25f, 0.25f)), 0.5f);
}

TEST(PbrtMaterials, DiffuseTransmission) {
  SceneDesc s = load_world(std::string("Material \"diffusetransmission\" \"rgb transmittance\" [ 0.5 0.6 0.7 ] "
                                       "\"float scale\" 2\n") + kTriangle + "Material \"diffusetransmission\"\n" + kTriangle);
  const Material& m = s.materials[s.meshes[0].material];
  EXPECT_EQ(m.type, MaterialType::DiffuseTransmission);
  EXPECT_VEC3_NEAR(m.transmittance.value, Vec3(0.5f, 0.6f, 0.7f), 1e-6f);
  EXPECT_VEC3_NEAR(m.reflectance.value, Vec3(0.25f), 1e-6f);  // pbrt-v4's defaults: 0.25 and 0.25
  EXPECT_FLOAT_EQ(m.scale, 2.f);
  EXPECT_VEC3_NEAR(s.materials[s.meshes[1].material].transmittance.value, Vec3(0.25f), 1e-6f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(PbrtTextures, ConstantScaleCheckerboard) {
  SceneDesc s = load_world(
      "Texture \"c\" \"spectrum\" \"constant\" \"rgb value\" [ 0.1 0.2 0.3 ]\n"
      "Texture \"f\" \"float\" \"constant\" \"float value\" 0.5\n"
      "Texture \"s\" \"spectrum\" \"scale\" \"texture tex\" \"c\" \"texture scale\" \"f\"\n"
      "Texture \"k\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 4 \"texture tex1\" \"s\" "
      "\"rgb tex2\" [ 0 0 1 ]\n"
      "Material \"diffuse\" \"texture reflectance\" \"k\"\n" + std::string(kTriangle) +
      "Material \"conductor\" \"texture roughness\" \"f\"\n" + kTriangle);
  ASSERT_EQ(s.textures.size(), 4u);
  EXPECT_EQ(s.textures[0].type, TextureType::Constant);
  EXPECT_VEC3_NEAR(s.textures[0].value, Vec3(0.1f, 0.2f, 0.3f), 1e-6f);
  EXPECT_VEC3_NEAR(s.textures[1].value, Vec3(0.5f), 1e-6f);
  EXPECT_EQ(s.textures[2].type, TextureType::Scale);
  EXPECT_EQ(s.textures[2].a.texture, 0);
  EXPECT_EQ(s.textures[2].b.texture, 1);
  const Texture& k = s.textures[3];
  EXPECT_EQ(k.type, TextureType::Checkerboard);
  EXPECT_FLOAT_EQ(k.su, 8.f);
  EXPECT_FLOAT_EQ(k.sv, 4.f);
  EXPECT_EQ(k.a.texture, 2);
  EXPECT_EQ(k.b.texture, -1);
  EXPECT_VEC3_NEAR(k.b.value, Vec3(0, 0, 1), 1e-6f);
  EXPECT_EQ(s.materials[s.meshes[0].material].reflectance.texture, 3);
  // A constant float texture as roughness gives its value (remapped).
  EXPECT_NEAR(s.materials[s.meshes[1].material].alpha_x, std::sqrt(0.5f), 1e-6f);
}

TEST(PbrtTextures, MixAndBilerpEvaluateAsPbrtV4s) {
  SceneDesc s = load_world(
      "Texture \"amt\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 \"float v10\" 1 \"float v11\" 1\n"
      "Texture \"m\" \"float\" \"mix\" \"float tex1\" 2 \"float tex2\" 4 \"texture amount\" \"amt\"\n"
      "Texture \"d\" \"float\" \"mix\"\n" + std::string(kTriangle));
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_EQ(s.textures[0].type, TextureType::Bilerp);
  EXPECT_EQ(s.textures[1].type, TextureType::Mix);
  const HostTextures t(s);
  // The amount rises with s (v10 = v11 = 1): tex1 at s = 0, tex2 at s = 1.
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{0, Rgb(0.f)}, Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec2(0.25f, 0.7f)), 0.25f);
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{1, Rgb(0.f)}, Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec2(0.f, 0.3f)), 2.f);
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{1, Rgb(0.f)}, Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec2(0.75f, 0.3f)), 3.5f);
  // pbrt-v4's defaults: tex1 0, tex2 1, amount 0.5.
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{2, Rgb(0.f)}, Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec2(0.3f, 0.3f)), 0.5f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(PbrtTextures, UnsupportedClassWarnsConstantHalf) {
  SceneDesc s = load_world(std::string("Texture \"n\" \"float\" \"ptex\" \"string filename\" \"a.ptx\"\n") + kTriangle);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_VEC3_NEAR(s.textures[0].value, Vec3(0.5f), 1e-6f);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("test.pbrt:2"), std::string::npos);
}

TEST(PbrtTextures, ImagemapPngIsSrgbDecodedAndDeduplicated) {
  test::TempDir dir;
  // 2x1 RGB: (255,128,0) (0,0,64).
  const unsigned char px[6] = {255, 128, 0, 0, 0, 64};
  ASSERT_NE(stbi_write_png(dir.file("tex.png").c_str(), 2, 1, 3, px, 6), 0);
  SceneDesc s = load_world(
      "Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"tex.png\" \"float scale\" 2 \"bool invert\" true"
      " \"float udelta\" 0.5\n"
      "Texture \"b\" \"spectrum\" \"imagemap\" \"string filename\" \"tex.png\"\n"
      "Texture \"c\" \"spectrum\" \"imagemap\" \"string filename\" \"tex.png\" \"string encoding\" \"linear\"\n"
      "Texture \"d\" \"spectrum\" \"imagemap\" \"string filename\" \"tex.png\" \"string encoding\" \"gamma 2\"\n"
      "Material \"diffuse\" \"texture reflectance\" \"a\"\n" + std::string(kTriangle),
      dir.path());
  ASSERT_EQ(s.images.size(), 3u);  // a and b share one image
  EXPECT_EQ(s.textures[0].image, s.textures[1].image);
  const ImageDesc& img = s.images[s.textures[0].image];
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 1);
  EXPECT_NEAR(img.texels[0].x, 1.f, 1e-6f);
  EXPECT_NEAR(img.texels[0].y, 0.2158605f, 1e-4f);  // sRGB 128/255
  EXPECT_NEAR(img.texels[1].z, 0.0512694f, 1e-4f);  // sRGB 64/255
  EXPECT_NEAR(s.images[s.textures[2].image].texels[0].y, 128.f / 255.f, 1e-6f);
  EXPECT_NEAR(s.images[s.textures[3].image].texels[0].y, std::pow(128.f / 255.f, 2.f), 1e-6f);
  EXPECT_FLOAT_EQ(s.textures[0].scale, 2.f);
  EXPECT_TRUE(s.textures[0].invert);
  EXPECT_FLOAT_EQ(s.textures[0].du, 0.5f);
}

TEST(PbrtTextures, ImagemapWrapAndFilterAsPbrtV4) {
  test::TempDir dir;
  const unsigned char px[6] = {255, 255, 255, 0, 0, 0};
  ASSERT_NE(stbi_write_png(dir.file("tex.png").c_str(), 2, 1, 3, px, 6), 0);
  const std::string image = "\"imagemap\" \"string filename\" \"tex.png\" ";
  SceneDesc s = load_world("Texture \"a\" \"float\" " + image + "\n" +
                               "Texture \"b\" \"float\" " + image + "\"string wrap\" \"black\" \"string filter\" \"point\"\n" +
                               "Texture \"c\" \"float\" " + image + "\"string wrap\" \"clamp\" \"string filter\" \"ewa\"\n" +
                               "Texture \"d\" \"float\" " + image + "\"string wrap\" \"octahedralsphere\"\n" + kTriangle,
                           dir.path());
  ASSERT_EQ(s.textures.size(), 4u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  EXPECT_EQ(s.textures[0].wrap, ImageWrap::Repeat);
  EXPECT_EQ(s.textures[0].filter, ImageFilter::Bilinear);
  EXPECT_EQ(s.textures[1].wrap, ImageWrap::Black);
  EXPECT_EQ(s.textures[1].filter, ImageFilter::Point);
  EXPECT_EQ(s.textures[2].wrap, ImageWrap::Clamp);
  EXPECT_EQ(s.textures[3].wrap, ImageWrap::OctahedralSphere);
  // Left of the image (s = -0.25): repeat reads the black right texel, clamp the white left one.
  HostTextures t(s);
  const Vec3 p(0.f), n(0.f, 0.f, 1.f);
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{0, Rgb(0.f)}, p, n, Vec2(-0.25f, 0.5f)), 0.f);
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{1, Rgb(0.f)}, p, n, Vec2(-0.25f, 0.5f)), 0.f);
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{2, Rgb(0.f)}, p, n, Vec2(-0.25f, 0.5f)), 1.f);
  EXPECT_FLOAT_EQ(t.eval(TextureSlot{1, Rgb(0.f)}, p, n, Vec2(0.3f, 0.5f)), 1.f);  // nearest: the white texel
  // pbrt-v4 refuses unknown names.
  EXPECT_NE(test::load_error("WorldBegin\nTexture \"e\" \"float\" " + image + "\"string wrap\" \"mirror\"\n", dir.path())
                .find("wrap mode \"mirror\" unknown"),
            std::string::npos);
  EXPECT_NE(test::load_error("WorldBegin\nTexture \"e\" \"float\" " + image + "\"string filter\" \"cubic\"\n", dir.path())
                .find("filter \"cubic\" unknown"),
            std::string::npos);
}

TEST(PbrtTextures, ExrImageLoadsLinear) {
  test::TempDir dir;
  Imf::Rgba pixels[2 * 2];
  for (int i = 0; i < 4; ++i) pixels[i] = Imf::Rgba(0.25f * i, 2.f, 0.5f, 1.f);
  {
    Imf::RgbaOutputFile out(dir.file("env.exr").c_str(), 2, 2, Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels, 1, 2);
    out.writePixels(2);
  }
  ImageDesc img = load_image(dir.file("env.exr"));
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 2);
  EXPECT_FLOAT_EQ(img.texels[3].x, 0.75f);
  EXPECT_FLOAT_EQ(img.texels[1].y, 2.f);  // no clamping, no decoding
  EXPECT_THROW(load_image(dir.file("missing.exr")), SceneError);
}

// pbrt-v4's HairMaterial: absorption from sigma_a, else reflectance (or
// pbrt-v3's color), else melanin (eumelanin 1.3 when nothing is given);
// the ignored ones are named in warnings.
TEST(PbrtMaterials, HairAbsorptionPrecedenceAndDefaults) {
  SceneDesc s = load_world(std::string("Material \"hair\"\n") + kTriangle);
  const Material& plain = material_of_last_mesh(s);
  EXPECT_EQ(plain.type, MaterialType::Hair);
  EXPECT_EQ(plain.hair_absorption, HairAbsorption::Melanin);
  EXPECT_FLOAT_EQ(plain.eumelanin.value.x, 1.3f);
  EXPECT_FLOAT_EQ(plain.ior, 1.55f);
  EXPECT_FLOAT_EQ(plain.beta_m.value.x, 0.3f);
  EXPECT_FLOAT_EQ(plain.hair_alpha.value.x, 2.f);
  EXPECT_NE(compute_effects(s) & kEffectGlossy, 0u);

  s = load_world(std::string("Material \"hair\" \"float pheomelanin\" 0.5\n") + kTriangle);
  EXPECT_FLOAT_EQ(material_of_last_mesh(s).eumelanin.value.x, 0.f);  // a melanin given: no default eumelanin
  EXPECT_FLOAT_EQ(material_of_last_mesh(s).pheomelanin.value.x, 0.5f);

  s = load_world(std::string("Material \"hair\" \"rgb color\" [ 0.3 0.2 0.1 ] \"float eumelanin\" 2\n") + kTriangle);
  EXPECT_EQ(material_of_last_mesh(s).hair_absorption, HairAbsorption::Reflectance);
  EXPECT_VEC3_NEAR(material_of_last_mesh(s).reflectance.value, Vec3(0.3f, 0.2f, 0.1f), 1e-6f);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings[0].find("melanin concentrations are ignored"), std::string::npos);

  s = load_world(std::string("Material \"hair\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ] \"rgb reflectance\" [ 0.5 0.5 0.5 ] "
                             "\"float eta\" 1.4 \"float beta_m\" 0.2 \"float beta_n\" 0.6 \"float alpha\" 3\n") +
                 kTriangle);
  const Material& m = material_of_last_mesh(s);
  EXPECT_EQ(m.hair_absorption, HairAbsorption::SigmaA);
  EXPECT_VEC3_NEAR(m.hair_sigma_a.value, Vec3(0.1f, 0.2f, 0.3f), 1e-6f);
  EXPECT_FLOAT_EQ(m.ior, 1.4f);
  EXPECT_FLOAT_EQ(m.beta_m.value.x, 0.2f);
  EXPECT_FLOAT_EQ(m.beta_n.value.x, 0.6f);
  EXPECT_FLOAT_EQ(m.hair_alpha.value.x, 3.f);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings[0].find("\"reflectance\" is ignored"), std::string::npos);
}

// pbrt-v4's subsurface as a random walk: the medium's coefficients by
// pbrt-v4's precedence (name, sigma_a/sigma_s, reflectance with mfp, the
// whole-milk default), times scale, inside every shape of the material.
TEST(PbrtMaterials, SubsurfaceMakesAMediumInsideItsShapes) {
  SceneDesc s = load_world(std::string("Material \"subsurface\"\n") + kTriangle);
  const Material& m = material_of_last_mesh(s);
  EXPECT_EQ(m.type, MaterialType::Subsurface);
  EXPECT_FLOAT_EQ(m.ior, 1.33f);
  ASSERT_GE(m.subsurface_medium, 0);
  EXPECT_EQ(s.meshes.back().media.inside, m.subsurface_medium);
  EXPECT_EQ(s.meshes.back().media.outside, -1);
  EXPECT_VEC3_NEAR(s.media[m.subsurface_medium].sigma_s, Vec3(2.55f, 3.21f, 3.77f), 1e-6f);
  EXPECT_NEAR(m.exit_norm, 0.934f, 0.002f);  // 1 - 2 x Fresnel's first moment at eta 1.33
  EXPECT_TRUE(s.warnings.empty());

  s = load_world(std::string("Material \"subsurface\" \"string name\" \"Ketchup\" \"float scale\" 2 \"float g\" 0.5\n") + kTriangle);
  const Medium& ketchup = s.media[material_of_last_mesh(s).subsurface_medium];
  EXPECT_VEC3_NEAR(ketchup.sigma_s, 2.f * Vec3(0.18f, 0.07f, 0.03f), 1e-6f);
  EXPECT_VEC3_NEAR(ketchup.sigma_a, 2.f * Vec3(0.061f, 0.97f, 1.45f), 1e-6f);
  EXPECT_FLOAT_EQ(ketchup.g, 0.5f);

  s = load_world(std::string("Material \"subsurface\" \"rgb reflectance\" [ 0 0.5 1 ] \"float mfp\" 0.5\n") + kTriangle);
  const Medium& r = s.media[material_of_last_mesh(s).subsurface_medium];
  EXPECT_VEC3_NEAR(r.sigma_a + r.sigma_s, Vec3(2.f), 1e-5f);   // 1 / mfp
  EXPECT_NEAR(r.sigma_s.x, 0.f, 1e-4f);                         // black: albedo 0 (the fit, to 6e-6)
  EXPECT_NEAR(r.sigma_a.z, 0.f, 1e-5f);                         // white: albedo 1
  EXPECT_GT(r.sigma_s.y / 2.f, 0.5f);                           // a walk needs albedo > reflectance

  EXPECT_NE(test::load_error("WorldBegin\nMaterial \"subsurface\" \"string name\" \"Jam\"\n").find("\"Jam\" is not a known medium"),
            std::string::npos);
  EXPECT_NE(test::load_error("WorldBegin\nMaterial \"subsurface\" \"rgb reflectance\" [ 1 1 1 ] \"float mfp\" 0\n")
                .find("\"mfp\" times \"scale\" must be positive"),
            std::string::npos);
  EXPECT_NE(test::load_error("WorldBegin\nMaterial \"subsurface\" \"rgb sigma_a\" [ 1 1 1 ]\n").find("needs both"),
            std::string::npos);
  EXPECT_NE(test::load_error("WorldBegin\nMaterial \"subsurface\" \"float eta\" 0\n").find("\"eta\" must be positive"),
            std::string::npos);
  // pbrt-v4: the mean free path is scale x mfp.
  s = load_world(std::string("Material \"subsurface\" \"rgb reflectance\" [ 0.5 0.5 0.5 ] \"float mfp\" 0.5 \"float scale\" 4\n") +
                 kTriangle);
  const Medium& scaled = s.media[material_of_last_mesh(s).subsurface_medium];
  EXPECT_VEC3_NEAR(scaled.sigma_a + scaled.sigma_s, Vec3(0.5f), 1e-5f);
  EXPECT_EQ(scaled.subsurface, 1);
}

}  // namespace
}  // namespace tessera
