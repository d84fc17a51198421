// Materials and textures as plain tagged structs. A Material is what a scene
// file says; resolve_bsdf() (integrator side) turns it into BsdfParams at a hit.
#pragma once

#include "device.h"

namespace tessera {

// A material parameter: either a constant or a texture index.
struct TextureSlot {
  int32_t texture = -1;  // >= 0: index into the scene's textures; wins over value
  Rgb value{0.f};        // constant (float parameters use value.x)
};

enum class TextureType : uint32_t {
  Constant = 0, Image, Scale, Checkerboard, Mix, Bilerp, Dots, DirectionMix, FBm, Wrinkled, Windy, Marble
};

// Where a texture reads its coordinates (pbrt-v4's TextureMapping2D and
// TextureMapping3D). UV: st = (su * u + du, sv * v + dv). The others map the
// hit point p through texture_from_render (the inverse of the CTM at the
// Texture directive): Spherical and Cylindrical by its angles about the
// texture-space origin, Planar by st = (du + p . vs, dv + p . vt), Point3D
// (the 3D textures: fbm, wrinkled, windy, marble, 3D checkerboard) by p itself.
enum class TextureMapping : uint32_t { UV = 0, Spherical, Cylindrical, Planar, Point3D };

// Image textures' wrap modes and filters (pbrt-v4's WrapMode; "point" reads
// the nearest texel, every other filter bilinearly: without ray
// differentials pbrt-v4's trilinear and EWA filters read the finest level).
enum class ImageWrap : uint32_t { Repeat = 0, Black, Clamp, OctahedralSphere };
enum class ImageFilter : uint32_t { Bilinear = 0, Point };

struct Texture {
  TextureType type = TextureType::Constant;
  Rgb value{0.f};            // Constant
  int32_t image = -1;        // Image: index into the scene's images
  TextureMapping mapping = TextureMapping::UV;
  Float su = 1.f, sv = 1.f, du = 0.f, dv = 0.f;
  Mat4 texture_from_render{1.f};
  Vec3 vs{1.f, 0.f, 0.f}, vt{0.f, 1.f, 0.f};  // Planar
  Float scale = 1.f;         // Image: multiplier (pbrt "scale"); Marble: frequency
  bool invert = false;       // Image: 1 - value (pbrt "invert")
  ImageWrap wrap = ImageWrap::Repeat;        // Image
  ImageFilter filter = ImageFilter::Bilinear;  // Image
  TextureSlot a, b;          // Scale: a * b ("tex" * "scale"); Checkerboard, Mix, DirectionMix: tex1, tex2;
                             // Dots: inside, outside the dots
  TextureSlot amount;        // Mix: (1 - amount) tex1 + amount tex2
  Rgb corners[4] = {Rgb(0.f), Rgb(1.f), Rgb(0.f), Rgb(1.f)};  // Bilerp: v00, v01, v10, v11 at (s, t) corners
  int32_t octaves = 8;       // FBm, Wrinkled, Marble
  Float omega = 0.5f;        // FBm, Wrinkled, Marble: pbrt "roughness", each octave's weight relative to the last
  Float variation = 0.2f;    // Marble
  Vec3 dir{0.f, 1.f, 0.f};   // DirectionMix: unit, render space; amount |n . dir| of tex1
};

// Linear RGB texels, row 0 is the top row of the file.
struct ImageView {
  int32_t width = 0, height = 0;
  const Rgb* texels = nullptr;
};

enum class MaterialType : uint32_t {
  Diffuse = 0, Conductor, Dielectric, CoatedDiffuse, Interface, Mix, DiffuseTransmission, CoatedConductor, ThinDielectric,
  Hair, Subsurface
};

// Where a hair material's absorption comes from (pbrt-v4 HairMaterial, in
// this order of precedence): "sigma_a", "reflectance", the melanins.
enum class HairAbsorption : uint32_t { SigmaA = 0, Reflectance, Melanin };

struct Material {
  MaterialType type = MaterialType::Diffuse;
  TextureSlot reflectance{ -1, Rgb(0.5f) };  // diffuse/coateddiffuse/diffusetransmission albedo; conductor "reflectance"
  TextureSlot transmittance{ -1, Rgb(0.25f) };  // diffusetransmission
  Float scale = 1.f;                         // diffusetransmission: multiplies reflectance and transmittance
  bool conductor_from_reflectance = false;  // conductor given by "reflectance" instead of eta/k
  Rgb eta{0.2004f, 0.9240f, 1.1022f};       // conductor eta (pbrt default: metal-Cu)
  Rgb k{3.9129f, 2.4528f, 2.1422f};          // conductor k
  // Conductors given by measured spectra: indices into SceneView::spectra
  // (used in spectral mode; eta and k above are their RGB fit). -1: none.
  int32_t eta_spectrum = -1, k_spectrum = -1;
  Float ior = 1.5f;                          // dielectric eta / coateddiffuse coating eta
  // A dispersive index (named glass, eta spectrum): index into
  // SceneView::spectra, read at the path's first wavelength in spectral
  // mode (ior above is its value at 550 nm). -1: none.
  int32_t ior_spectrum = -1;
  Float alpha_x = 0.f, alpha_y = 0.f;        // GGX alpha, remapped from roughness by the loader (coated: the coat's)
  Float base_alpha_x = 0.f, base_alpha_y = 0.f;  // coatedconductor: the conductor's GGX alpha
  // Textured roughness (u, v): evaluated at the hit, then remapped
  // (alpha = sqrt(roughness), pbrt-v4) when remap_roughness. Unused when both are constant.
  TextureSlot roughness_u{-1, Rgb(0.f)}, roughness_v{-1, Rgb(0.f)};
  bool textured_roughness = false;
  // coatedconductor: the conductor's textured roughness, the same way.
  TextureSlot base_roughness_u{-1, Rgb(0.f)}, base_roughness_v{-1, Rgb(0.f)};
  bool textured_base_roughness = false;
  int32_t bump = -1;                         // "displacement" float texture (bump mapping), -1 = none
  int32_t normal_map = -1;                   // "normalmap" image (linear RGB), -1 = none; bump wins
  bool remap_roughness = true;
  Float thickness = 0.01f;                   // coated materials' layer (pbrt-v4 defaults)
  TextureSlot layer_albedo{-1, Rgb(0.f)};    // its scattering medium: albedo (black: clear) and
  TextureSlot layer_g{-1, Rgb(0.f)};         // Henyey-Greenstein g
  uint32_t layer_max_depth = 10, layer_samples = 1;
  // hair: the fibre's absorption (sigma_a, or reflectance above, or
  // eumelanin/pheomelanin concentrations), its longitudinal and azimuthal
  // roughness and its scales' tilt in degrees; its index is ior (1.55).
  HairAbsorption hair_absorption = HairAbsorption::Melanin;
  TextureSlot hair_sigma_a{-1, Rgb(0.f)};
  TextureSlot eumelanin{-1, Rgb(1.3f)}, pheomelanin{-1, Rgb(0.f)};
  TextureSlot beta_m{-1, Rgb(0.3f)}, beta_n{-1, Rgb(0.3f)}, hair_alpha{-1, Rgb(2.f)};
  // subsurface: the medium inside (SceneView::media; the loader puts it
  // inside the material's shapes) and the exit lobe's normalisation c
  // (scene/subsurface_params.h); the boundary is a dielectric of ior and alpha.
  int32_t subsurface_medium = -1;
  Float exit_norm = 1.f;
  int32_t mix[2] = {-1, -1};                 // Mix: material indices
  TextureSlot amount{ -1, Rgb(0.5f) };      // Mix: probability of choosing mix[1] (value.x)
};

}  // namespace tessera
