// A scene flattened into the arrays kernels read (kernels/scene_view.h):
// all meshes merged into one triangle list, one Light per emissive triangle,
// distributions for light selection, environment maps and the pixel filter.
// Owns the memory; view() stays valid while the SceneData lives and is not moved.
#pragma once

#include <memory>
#include <vector>

#include "kernels/scene_view.h"
#include "scene/scene_desc.h"
#include "render/distribution_build.h"
#include "render/light_bvh_build.h"

namespace tessera {

struct Bounds {
  Vec3 lo{3.4e38f}, hi{-3.4e38f};
};

class SceneData {
 public:
  // The film resolution and camera come from desc (apply command-line
  // overrides to desc first). Throws SceneError for an empty scene.
  explicit SceneData(SceneDesc desc);
  SceneData(const SceneData&) = delete;
  SceneData& operator=(const SceneData&) = delete;

  const SceneView& view() const { return view_; }
  const SceneDesc& desc() const { return desc_; }
  uint32_t effects() const { return effects_; }
  const Bounds& bounds() const { return bounds_; }
  size_t num_triangles() const { return triangles_.size(); }  // stored once each, instanced ones included
  const std::vector<Vec3>& positions() const { return positions_; }
  const std::vector<uint32_t>& indices() const { return indices_; }
  // A hash of geometry, materials and lights: ties a saved guide cache to its scene.
  uint64_t fingerprint() const;
  // What turns radiance into pixels (sensor, clamp, lens, filter): part of a
  // checkpoint's identity, not of a guide cache's. 0 for pbrt's defaults.
  uint64_t film_fingerprint() const;
  // The brightest radiance (or intensity, for point-like lights) any light
  // emits, in luminance: the scale of the guide's learning targets.
  Float max_emitted_radiance() const;

 private:
  struct MeshLayout {
    bool moves = false, any_normals = false, any_uv = false;  // which per-vertex arrays exist
  };
  void flatten_meshes();
  void append_mesh(MeshDesc& m, const MeshLayout& layout, Bounds* bounds);
  void append_triangles(const MeshDesc& m, uint32_t base);
  void place_instances(const std::vector<Bounds>& object_bounds);
  void build_lights();
  void build_light_tree();
  void build_camera();
  void build_filter();
  void build_view();

  SceneDesc desc_;
  uint32_t effects_ = 0;
  Bounds bounds_;
  std::vector<Vec3> positions_, normals_;
  std::vector<Vec2> uvs_;
  std::vector<uint32_t> indices_;
  std::vector<TriangleInfo> triangles_;
  std::vector<Vec3> face_normals_;
  uint32_t num_world_triangles_ = 0;  // the rest are the prototypes' (kernels/instance.h)
  std::vector<ObjectPrototype> prototypes_;
  std::vector<ObjectInstance> instances_;
  std::vector<ImageView> image_views_;
  std::vector<Light> lights_;
  std::vector<int32_t> infinite_lights_;
  Distribution1D light_select_;
  LightBvh light_bvh_;  // next-event estimation's light tree (empty unless the light sampler is bvh)
  // Per image: the mean and largest luminance of its texels (only for
  // images that lights emit).
  struct ImageLuminance {
    Float mean = 0.f, max = 0.f;
  };
  std::vector<ImageLuminance> image_luminance_;
  std::vector<Distribution2D> env_storage_;     // one per light (empty for non-image lights)
  std::vector<Distribution2DView> env_views_;
  std::vector<TextureSlot> triangle_alpha_;  // per triangle
  bool has_alpha_ = false;                   // any triangle not opaque
  bool has_one_way_faces_ = false;           // any triangle kTriInvisibleFromInside
  std::vector<MediumInterface> triangle_media_;  // per triangle, only for scenes with media
  std::vector<GridMediumView> grid_views_;
  std::vector<Float> blackbody_rgb_table_;     // for grids that glow by temperature (RGB transport)
  std::vector<Vec3> positions_end_, normals_end_;  // per vertex, only when some shape moves (motion blur)
  bool has_media_ = false;
  std::vector<Float> filter_inverse_cdf_x_, filter_inverse_cdf_y_;
  std::vector<Float> filter_weight_x_, filter_weight_y_;  // empty unless the filter has negative lobes
  CameraView camera_;
  SceneView view_;
};

}  // namespace tessera
