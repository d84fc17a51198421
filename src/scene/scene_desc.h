// What a scene file describes, in world space, before any acceleration
// structure is built. Produced by the pbrt-v4 loader (pbrt_loader.h) or by
// builtin_scenes.h; consumed by scene building (src/scene/scene.h).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/camera_projection.h"
#include "kernels/light.h"
#include "kernels/light_bvh.h"
#include "kernels/material.h"
#include "kernels/medium.h"
#include "kernels/sampler.h"
#include "scene/sparse_grid_build.h"

namespace tessera {

// Raised for malformed input. what() is one line: "file:line: problem".
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct MeshDesc {
  std::vector<Vec3> p;          // world-space positions
  std::vector<Vec3> n;          // optional world-space shading normals (empty or p.size())
  std::vector<Vec2> uv;         // optional (empty or p.size())
  std::vector<uint32_t> indices;  // three per triangle, all < p.size()
  int32_t material = 0;         // index into SceneDesc::materials
  // pbrt's ReverseOrientation XOR "transform swaps handedness". The geometric
  // normal is normalize(cross(p0 - p2, p1 - p2)), negated when this is set
  // (when shading normals exist, it is instead flipped to their side).
  bool flip_normals = false;
  int32_t area_light = -1;      // index into SceneDesc::area_lights, -1 = not emissive
  // pbrt-v4 "alpha": a float constant or float texture; hits where it is
  // below 1 are ignored with probability 1 - alpha. Constant 1 = opaque.
  TextureSlot alpha{-1, Rgb(1.f)};
  // Media inside and outside (indices into SceneDesc::media, -1: vacuum).
  MediumInterface media;
  // Motion blur: positions (and normals, when n is given) at the end of the
  // transform interval; empty for a shape that does not move.
  std::vector<Vec3> p_end, n_end;
  // The shapes pbrt-v4 would make of this mesh, each of which an area light's
  // "power" is given to whole: runs of this many triangles (1: a triangle
  // mesh, 2: bilinear patches), or 0: one shape, the whole mesh, of area
  // shape_area (a quadric: pbrt-v4's object-space Area()).
  uint32_t triangles_per_shape = 1;
  Float shape_area = 0.f;
  // A PLY of triangles and quads (pbrt-v4: a triangle mesh and bilinear
  // patches); loading only.
  bool mixed_faces = false;
  // A closed surface seen only from outside (curve tubes): hits from inside,
  // against the outward geometric normal, are ignored.
  bool invisible_from_inside = false;
  std::string where;            // "file:line" of the Shape directive, for messages
};

// An ObjectBegin / ObjectEnd definition used by more than one
// ObjectInstance: its shapes stored once, in render space as the definition
// placed them (never emissive: pbrt-v4 has no area lights in instances).
struct ObjectDesc {
  std::string name;
  std::vector<MeshDesc> meshes;
};

// One ObjectInstance of an ObjectDesc (SceneDesc::objects): the object's
// render space mapped into the scene's, at the start and at the end of the
// transform interval (equal unless the instance moves). An object instanced
// once, or an instance whose map is singular, is placed as ordinary meshes
// instead (scene/object_instances.h).
struct InstanceDesc {
  uint32_t object = 0;
  Mat4 render_from_object{1.f}, render_from_object_end{1.f};
  std::string where;  // "file:line" of the ObjectInstance
  // How many meshes preceded it in the file: flattened, it goes there, so
  // that a scene reads into the same triangle order with or without instancing.
  size_t meshes_before = 0;
};

struct AreaLightDesc {
  Rgb L{1.f};  // radiance with "scale" folded in; with an image, what multiplies its texels
  Float blackbody_kelvin = 0.f;  // "blackbody L": its temperature (spectral mode emits Planck's law)
  bool two_sided = false;
  int32_t image = -1;  // "filename": index into SceneDesc::images, read at (u, 1 - v), -1 = L alone
  // "power" (> 0): each shape emits this much, as pbrt-v4 scales each shape's
  // light (L / (pi area sides), over the image's mean luminance when it has one).
  Float power = 0.f;
};

struct ImageDesc {
  int32_t width = 0, height = 0;
  std::vector<Rgb> texels;  // linear RGB, row 0 = top of the file
  std::string path;
};

// A grid medium's lattices (Medium::grid indexes these).
struct GridDesc {
  SparseGridDesc density;
  MajorantGridDesc majorants;  // over the medium's box
  // Emission (GridMediumView): Le scaled per point, or a blackbody of the
  // temperature grid's value.
  SparseGridDesc le_scale;     // nx == 0: 1 everywhere
  SparseGridDesc temperature;  // nx == 0: Medium::Le is the emission
  Float temperature_offset = 0.f, temperature_scale = 1.f, blackbody_scale = 1.f;
  // pbrt-v4's "cloud" (density.lattice_from_world is then medium_from_world, density.nx 0).
  int32_t cloud = 0;
  Float cloud_density = 1.f, cloud_wispiness = 1.f, cloud_frequency = 5.f;
  // pbrt-v4's "rgbgrid": r, g, b lattices per quantity (nx 0: not given).
  int32_t rgb = 0;
  SparseGridDesc rgb_sigma_a[3], rgb_sigma_s[3], rgb_le[3];
  Float rgb_scale = 1.f, rgb_le_scale = 1.f;
};

// "World" in a SceneDesc is pbrt-v4's render space: the scene's world
// translated so that the camera is at the origin (render_origin).
struct CameraDesc {
  CameraProjection projection = CameraProjection::Perspective;  // the Camera directive's type (and spherical "mapping")
  // "screenwindow" (x0 x1 y0 y1, camera-plane units) when given, else
  // pbrt-v4's default from "frameaspectratio" (default: the film's).
  bool has_screen_window = false;
  Vec4 screen_window{-1.f, 1.f, -1.f, 1.f};
  Float frame_aspect_ratio = 0.f;  // 0: the film's xres / yres
  Mat4 world_from_camera{1.f};  // pbrt camera space: x right, y up, z forward (left-handed)
  Float fov_degrees = 90.f;     // pbrt-v4: angle spanned by the shorter image axis
  Float exposure_time = 1.f;    // shutterclose - shutteropen (scales the image, as in pbrt-v4)
  Float lens_radius = 0.f;      // thin lens (pbrt-v4 "lensradius"); 0 = pinhole
  Float focal_distance = 1e6f;  // distance of the plane in focus, along the view axis (camera space)
  Float shutter_open = 0.f, shutter_close = 1.f;
  Mat4 world_from_camera_end{1.f};  // == world_from_camera unless the camera moves (motion blur)
  Float transform_start_time = 0.f, transform_end_time = 1.f;  // pbrt-v4 TransformTimes
  std::string where;
};

// Largest image we accept: each pixel costs ~56 bytes of accumulators.
constexpr int64_t kMaxFilmDimension = 65536;
constexpr int64_t kMaxFilmPixels = int64_t(1) << 27;

struct FilmDesc {
  int32_t xres = 1280, yres = 720;
  std::string filename = "pbrt.exr";
  Float iso = 100.f;
  Float whitebalance = 0.f;      // kelvin; 0 = none
  Float max_component_value = INFINITY;  // pbrt-v4 scales a sample down to this largest channel
  std::string sensor = "cie1931";
  // Linear sRGB radiance -> sensor values (pbrt-v4: XYZ times the imaging
  // ratio; maxcomponentvalue clamps these) -> pixel values (white balance,
  // XYZ -> sRGB), and the product of the two. Set when loading ends
  // (pbrt_film.h); pixel_from_radiance is the identity for pbrt's defaults.
  Mat3 sensor_from_radiance{1.f}, pixel_from_sensor{1.f};
  Mat3 pixel_from_radiance{1.f};
  // The part of the image rendered ("cropwindow", or "pixelbounds" over the
  // resolution), as fractions of it: x0 x1 y0 y1, y down. Pixels are those
  // from ceil(res * low) to ceil(res * high), as pbrt-v4 computes them, so a
  // changed resolution (--res) keeps the same part of the picture.
  double crop[4] = {0.0, 1.0, 0.0, 1.0};
};

// The pixels of a film that are rendered: [x0, x1) x [y0, y1) of the full
// resolution (film_pixel_bounds in pbrt_film.h).
struct PixelBounds {
  int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int32_t width() const { return x1 - x0; }
  int32_t height() const { return y1 - y0; }
};

enum class FilterType : uint32_t { Gaussian = 0, Box, Triangle, Mitchell, LanczosSinc };
// pbrt-v4's pixel filters, all separable: f(x, y) = f1(x, radius) f1(y, radius_y).
struct FilterDesc {
  FilterType type = FilterType::Gaussian;
  Float radius = 1.5f;    // x radius. pbrt-v4 defaults: gaussian 1.5, box 0.5, triangle 2, mitchell 2, sinc 4
  Float radius_y = 1.5f;
  Float sigma = 0.5f;     // gaussian
  Float b = 1.f / 3.f, c = 1.f / 3.f;  // mitchell
  Float tau = 3.f;        // sinc
};

struct SceneDesc {
  CameraDesc camera;
  // Where render space's origin (the camera) is in the scene file's world:
  // every position in this SceneDesc is relative to it (pbrt-v4's
  // "cameraworld" rendering space), which keeps float precision near the
  // camera in scenes far from the world's origin.
  glm::dvec3 render_origin{0.0};
  FilmDesc film;
  FilterDesc filter;
  int32_t spp = 16;        // pbrt-v4 default pixelsamples
  int32_t max_depth = 5;   // pbrt-v4 default maxdepth
  // The Integrator's "lightsampler": how next-event estimation picks a
  // light (kernels/light_choice.h); pbrt-v4's default is "bvh".
  LightSamplerKind light_sampler = LightSamplerKind::Bvh;
  std::string integrator = "volpath";  // the Integrator directive's type (scene/light_paths.h reads it)
  uint64_t seed = 0;       // Sampler "integer seed"
  // Sampler type (kernels/sampler.h): zsobol (pbrt-v4's default), paddedsobol
  // (also drawn for pbrt's global "sobol"), stratified, independent, halton;
  // pmj02bn is drawn as zsobol (a warning says so).
  SamplerKind sampler = SamplerKind::ZSobol;
  int32_t strata_x = 4, strata_y = 4;  // stratified: "xsamples", "ysamples" (spp = their product)
  // The scene's own sample count (pixelsamples, or xsamples * ysamples), which
  // --spp does not change: zsobol's epoch is built from it, so a checkpoint
  // resumes with any --spp.
  int32_t sampler_spp = 16;
  bool sampler_jitter = true;          // stratified: "jitter"
  HaltonRandomize halton_randomize = HaltonRandomize::PermuteDigits;  // halton: "randomization"
  // Spectral transport (kernels/spectral.h): paths carry three sampled
  // wavelengths, as pbrt-v4's carry four; false: paths carry RGB.
  bool spectral = false;
  // Measured spectra (Material::eta_spectrum...), kSpectralSamples values
  // each at 360, 365, ..., 830 nm: see add_sampled_spectrum().
  std::vector<Float> spectra;
  std::vector<MeshDesc> meshes;
  std::vector<ObjectDesc> objects;      // instanced geometry (each used by two or more instances)
  std::vector<InstanceDesc> instances;
  std::vector<Material> materials;  // never empty after loading (index 0 = pbrt's default diffuse 0.5)
  std::vector<Texture> textures;
  std::vector<ImageDesc> images;
  std::vector<AreaLightDesc> area_lights;
  std::vector<Light> lights;        // point, spot, distant, infinite (area lights come from meshes)
  std::vector<Medium> media;        // MakeNamedMedium, in order of definition
  std::vector<GridDesc> grids;      // of the grid media (uniformgrid, rgbgrid, nanovdb, cloud)
  int32_t camera_medium = -1;       // the medium the camera sits in (pbrt-v4: the outside medium at Camera)
  std::vector<std::string> warnings;  // "file:line: message", in order of appearance
  // Every file the scene was read from (the scene file, Includes, meshes,
  // images, volumes, spectra): a render's outputs must not overwrite them.
  std::vector<std::string> files_read;
  std::string source;               // file name, or "<builtin:cornell-box>"
};

}  // namespace tessera
