// Read-only views of a built scene: flat arrays + sizes, valid on the side
// (CPU or GPU) whose memory they point into. Built by src/render/scene_data.h.
#pragma once

#include "camera_projection.h"
#include "distribution.h"
#include "light.h"
#include "light_bvh.h"
#include "material.h"
#include "grid_medium.h"
#include "instance.h"
#include "medium.h"
#include "spectral.h"

namespace tessera {

enum TriangleFlags : uint32_t {
  kTriFlipNormal = 1u << 0,   // negate cross(p0 - p2, p1 - p2)
  kTriHasNormals = 1u << 1,   // per-vertex shading normals present
  kTriHasUv = 1u << 2,        // per-vertex uv present (else pbrt's (0,0),(1,0),(1,1))
  // The second triangle (p00, p11, p01) of a quad (bilinear patch, PLY
  // quad) without uv: pbrt-v4's patch uv there is (0,0),(1,1),(0,1).
  kTriQuadSecondHalf = 1u << 3,
  // A face of a curve's tube: rays meeting it from inside (along the outward
  // face normal) pass through (MeshDesc::invisible_from_inside).
  kTriInvisibleFromInside = 1u << 4,
};

struct TriangleInfo {
  int32_t material = 0;
  int32_t light = -1;  // index into lights for emissive triangles
  uint32_t flags = 0;
};

struct CameraView {
  CameraProjection projection = CameraProjection::Perspective;
  Mat3 world_from_camera_linear{1.f};  // upper 3x3 of world_from_camera (may include scale/flip)
  Vec3 origin{0.f};                    // camera position in world space
  Vec2 screen_min{-1.f}, screen_max{1.f};  // screen window, pbrt-v4 convention
  Float tan_half_fov = 1.f;
  int32_t width = 0, height = 0;  // the full image
  // The film: the pixels rendered ("cropwindow"), from (film_x0, film_y0) of
  // the full image. Film pixel (x, y) is image pixel (film_x0 + x, film_y0 + y).
  int32_t film_x0 = 0, film_y0 = 0, film_width = 0, film_height = 0;
  Float lens_radius = 0.f;      // thin lens; 0 = pinhole (then no lens sample is drawn)
  Float focal_distance = 1e6f;
  // What the film records of a sample's radiance (pbrt-v4's pixel sensor:
  // exposure, white balance), then pbrt's per-sample "maxcomponentvalue".
  Mat3 pixel_from_radiance{1.f};
  Mat3 sensor_from_radiance{1.f}, pixel_from_sensor{1.f};  // the two halves, where the clamp sits between
  Float max_component_value = INFINITY;
  // Motion blur: the shutter and pbrt-v4's TransformTimes (moving shapes are
  // at their start transform at transform_start_time, their end one at transform_end_time).
  Float shutter_open = 0.f, shutter_close = 1.f;
  Float transform_start_time = 0.f, transform_end_time = 1.f;
  bool moves = false;  // a moving camera: its placement at the end of the transform interval
  Mat3 world_from_camera_linear_end{1.f};
  Vec3 origin_end{0.f};
};

// A separable pixel filter, sampled per axis in proportion to |f| (filter
// importance sampling). Each axis: its inverse cdf tabulated at n evenly
// spaced u in [0,1] and interpolated linearly (O(1) per sample), and, for
// filters with negative lobes (mitchell, sinc), the sample weight
// sign(f) * integral|f| / integral f per bin, so that the mean of weighted
// samples is the filtered image exactly. weight_* are null when every weight is 1.
struct FilterView {
  const Float* inverse_cdf_x = nullptr;  // offsets in [-radius_x, radius_x]
  const Float* inverse_cdf_y = nullptr;
  uint32_t n = 0;
  const Float* weight_x = nullptr;
  const Float* weight_y = nullptr;
  uint32_t bins = 0;
  Float radius_x = 0.5f, radius_y = 0.5f;
};

struct SceneView {
  // MIS at the coated BSDFs weighs by the balance heuristic (pbrt-v4's
  // volpath, its default integrator) or by the power heuristic (its "path"):
  // with their stochastic densities the choice shapes the picture (bsdf_mis_pdf).
  bool layered_mis_balance = true;
  const Vec3* positions = nullptr;
  const Vec3* normals = nullptr;
  // Motion blur: every vertex's position and normal at the end of the
  // transform interval (static ones repeated); null when nothing moves.
  const Vec3* positions_end = nullptr;
  const Vec3* normals_end = nullptr;
  const Vec2* uvs = nullptr;
  // Entries of positions (and positions_end), normals (and normals_end) and
  // uvs: 0 where an array is absent. Copies to a device need them.
  uint32_t num_vertices = 0, num_normals = 0, num_uvs = 0;
  const uint32_t* indices = nullptr;  // 3 per triangle
  const TriangleInfo* triangles = nullptr;
  // Unit geometric normal per triangle, normalize(cross(p0 - p2, p1 - p2)),
  // already negated for kTriFlipNormal (precomputed: every hit needs it).
  const Vec3* face_normals = nullptr;
  uint32_t num_triangles = 0;
  // Per triangle, its alpha (pbrt-v4 cutouts); null when no shape has one.
  const TextureSlot* triangle_alpha = nullptr;
  // Some triangle is kTriInvisibleFromInside: ray queries must filter hits
  // (hit_ignored in alpha.h), as for triangle_alpha.
  bool has_one_way_faces = false;
  // Instanced geometry (instance.h): triangles [0, num_world_triangles) are
  // in render space; the rest are the prototypes', each in its own space,
  // reached only through the instances.
  uint32_t num_world_triangles = 0;
  const ObjectPrototype* prototypes = nullptr;
  uint32_t num_prototypes = 0;
  const ObjectInstance* instances = nullptr;
  uint32_t num_instances = 0;
  bool instances_move = false;  // some instance moves: rays need a time, as for positions_end

  const Material* materials = nullptr;
  uint32_t num_materials = 0;
  const Texture* textures = nullptr;
  uint32_t num_textures = 0;
  const ImageView* images = nullptr;
  uint32_t num_images = 0;

  const Light* lights = nullptr;
  uint32_t num_lights = 0;
  Distribution1DView light_select;     // power-proportional light selection (light tracing; "power")
  LightSamplerKind light_sampler = LightSamplerKind::Bvh;  // next-event estimation's choice (light_choice.h)
  LightBvhView light_bvh;              // its tree ("bvh")
  const int32_t* infinite_lights = nullptr;  // indices of Infinite lights
  uint32_t num_infinite_lights = 0;
  const Distribution2DView* env_distributions = nullptr;  // per light index, valid for image infinite lights

  // Participating media; null and 0 when the scene has none.
  const Medium* media = nullptr;
  uint32_t num_media = 0;
  const MediumInterface* triangle_media = nullptr;  // per triangle
  int32_t camera_medium = -1;                       // -1: vacuum
  const GridMediumView* grids = nullptr;             // of the grid media
  // Whether any material is "interface": only then can a shadow ray pass a
  // surface (else the first hit blocks it and one occlusion query decides).
  bool has_interfaces = false;

  CameraView camera;
  FilterView filter;
  // Spectral transport (spectral.h); disabled: paths carry RGB.
  SpectralView spectral;
  // Measured spectra (conductors' eta and k), kSpectralSamples values each.
  const Float* spectra = nullptr;
  uint32_t num_spectra = 0;
};

// What light l emits at the path's wavelengths, given its RGB emission rgb
// (L or an image texel, times any geometric factor): pbrt-v4's illuminant
// spectrum, or Planck's law for a blackbody. rgb itself in RGB mode.
TESSERA_HOST_DEVICE inline Rgb light_emission(const SceneView& s, const Wavelengths* wl, const Light& l, Rgb rgb) {
  if (!wl) return rgb;
  if (l.blackbody_kelvin > 0.f) {
    const Float k = luminance(rgb) * l.blackbody_norm;
    return Rgb(k * blackbody_relative(wl->lambda[0], l.blackbody_kelvin),
               k * blackbody_relative(wl->lambda[1], l.blackbody_kelvin),
               k * blackbody_relative(wl->lambda[2], l.blackbody_kelvin));
  }
  return spectral_illuminant(s.spectral, wl, rgb);
}

// The medium as the path sees it: its coefficients at the path's wavelengths
// in spectral mode (pbrt-v4's unbounded and illuminant spectra), else as given.
TESSERA_HOST_DEVICE inline Medium medium_at(const SceneView& s, int32_t medium, const Wavelengths* wl) {
  Medium m = s.media[medium];
  if (wl) {
    m.sigma_a = spectral_unbounded(s.spectral, wl, m.sigma_a);
    m.sigma_s = spectral_unbounded(s.spectral, wl, m.sigma_s);
    m.Le = spectral_illuminant(s.spectral, wl, m.Le);
  }
  return m;
}

}  // namespace tessera
