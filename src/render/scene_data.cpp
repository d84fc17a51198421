#include "render/scene_data.h"

#include "scene/pbrt_film.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "kernels/effects.h"
#include "kernels/equal_area.h"
#include "kernels/fnv1a.h"
#include "kernels/vecmath.h"
#include "render/camera_limits.h"
#include "scene/scene_effects.h"
#include "scene/named_spectra.h"
#include "scene/rgb_spectrum_fit.h"
#include "scene/spectral_tables.h"

namespace tessera {

namespace {

GridMediumView grid_medium_view(const GridDesc& g, const std::vector<Float>& blackbody_rgb,
                                const SpectralView* spectral) {
  GridMediumView v;
  v.density = sparse_grid_view(g.density);
  v.majorants = majorant_grid_view(g.majorants);
  v.le_scale = sparse_grid_view(g.le_scale);
  v.temperature = sparse_grid_view(g.temperature);
  v.temperature_offset = g.temperature_offset;
  v.temperature_scale = g.temperature_scale;
  v.blackbody_scale = g.blackbody_scale;
  v.blackbody_rgb = blackbody_rgb.empty() ? nullptr : blackbody_rgb.data();
  v.cloud = g.cloud;
  v.cloud_density = g.cloud_density;
  v.cloud_wispiness = g.cloud_wispiness;
  v.cloud_frequency = g.cloud_frequency;
  v.rgb = g.rgb;
  for (int c = 0; c < 3; ++c) {
    v.rgb_sigma_a.channel[c] = sparse_grid_view(g.rgb_sigma_a[c]);
    v.rgb_sigma_s.channel[c] = sparse_grid_view(g.rgb_sigma_s[c]);
    v.rgb_le.channel[c] = sparse_grid_view(g.rgb_le[c]);
  }
  v.rgb_scale = g.rgb_scale;
  v.rgb_le_scale = g.rgb_le_scale;
  v.spectral = spectral;
  return v;
}

// For each triangle of m, the area of the pbrt-v4 shape it belongs to
// (MeshDesc::triangles_per_shape): what an area light's "power" is given to.
std::vector<double> shape_area_per_triangle(const MeshDesc& m) {
  const size_t n = m.indices.size() / 3;
  std::vector<double> area(n, static_cast<double>(m.shape_area));
  if (m.triangles_per_shape == 0) return area;
  for (size_t t = 0; t < n; ++t) {
    Vec3 normal;
    double a = 0.0;
    if (!triangle_normal(m.p[m.indices[3 * t]], m.p[m.indices[3 * t + 1]], m.p[m.indices[3 * t + 2]], &normal, &a)) a = 0.0;
    area[t] = a;
  }
  const size_t run = m.triangles_per_shape;
  for (size_t first = 0; first < n; first += run) {
    double sum = 0.0;
    for (size_t t = first; t < std::min(n, first + run); ++t) sum += area[t];
    for (size_t t = first; t < std::min(n, first + run); ++t) area[t] = sum;
  }
  return area;
}

// pbrt-v4's k_e for an image light: the mean luminance of its texels
// (negative ones read as 0, as every lookup reads them).
double mean_luminance(const ImageDesc& img) {
  double sum = 0.0;
  for (const Rgb& t : img.texels) sum += luminance(glm::max(t, Rgb(0.f)));
  return img.texels.empty() ? 0.0 : sum / static_cast<double>(img.texels.size());
}

}  // namespace

SceneData::SceneData(SceneDesc desc) : desc_(std::move(desc)) {
  effects_ = compute_effects(desc_);
  flatten_meshes();
  if (triangles_.empty() && desc_.lights.empty()) {
    throw SceneError(desc_.source + ": empty scene (no shapes and no lights)");
  }
  build_lights();
  build_camera();
  build_filter();
  build_view();
}

void SceneData::flatten_meshes() {
  // Every mesh, the world's and the instanced objects': stored once each.
  std::vector<MeshDesc*> all;
  for (MeshDesc& m : desc_.meshes) all.push_back(&m);
  for (ObjectDesc& o : desc_.objects)
    for (MeshDesc& m : o.meshes) all.push_back(&m);
  // Per-triangle alpha only for scenes with cutouts.
  for (const MeshDesc* m : all) {
    has_alpha_ |= m->alpha.texture >= 0 || m->alpha.value.x < 1.f;
    has_one_way_faces_ |= m->invisible_from_inside;
  }
  // Per-triangle media only for scenes that have any (the camera's included).
  has_media_ = (effects_ & kEffectMedia) != 0;
  MeshLayout layout;
  size_t vertices = 0, triangles = 0;
  for (const MeshDesc* m : all) {
    layout.moves |= !m->p_end.empty();
    layout.any_normals |= !m->n.empty();
    layout.any_uv |= !m->uv.empty();
    vertices += m->p.size();
    triangles += m->indices.size() / 3;
  }
  // Sized once: grown by doubling, the arrays would hold up to twice their
  // size, and three times while they move. Per-vertex normals and uv only
  // when some mesh has them (a triangle's flags say whether it reads them).
  positions_.reserve(vertices);
  if (layout.any_normals) normals_.reserve(vertices);
  if (layout.any_uv) uvs_.reserve(vertices);
  if (layout.moves) {
    positions_end_.reserve(vertices);
    if (layout.any_normals) normals_end_.reserve(vertices);
  }
  indices_.reserve(3 * triangles);
  face_normals_.reserve(triangles);
  triangles_.reserve(triangles);
  if (has_alpha_) triangle_alpha_.reserve(triangles);
  if (has_media_) triangle_media_.reserve(triangles);
  for (MeshDesc& m : desc_.meshes) append_mesh(m, layout, &bounds_);
  num_world_triangles_ = static_cast<uint32_t>(triangles_.size());
  std::vector<Bounds> object_bounds(desc_.objects.size());
  for (size_t i = 0; i < desc_.objects.size(); ++i) {
    ObjectPrototype proto;
    proto.first_triangle = static_cast<uint32_t>(triangles_.size());
    for (MeshDesc& m : desc_.objects[i].meshes) append_mesh(m, layout, &object_bounds[i]);
    proto.num_triangles = static_cast<uint32_t>(triangles_.size()) - proto.first_triangle;
    prototypes_.push_back(proto);
  }
  place_instances(object_bounds);
}

namespace {

Affine affine_of(const Mat4& m) { return Affine{Mat3(m), Vec3(m[3])}; }

}  // namespace

// Each instance's maps, and its box (the object's, placed at both ends of
// the transform interval: a vertex moves on a straight line between its two
// placements, which both boxes' union holds) in the scene's bounds.
void SceneData::place_instances(const std::vector<Bounds>& object_bounds) {
  instances_.reserve(desc_.instances.size());
  for (const InstanceDesc& desc : desc_.instances) {
    ObjectInstance inst;
    inst.prototype = desc.object;
    inst.render_from_object = affine_of(desc.render_from_object);
    inst.render_from_object_end = affine_of(desc.render_from_object_end);
    inst.object_from_render.linear = glm::inverse(inst.render_from_object.linear);
    inst.object_from_render.offset = -(inst.object_from_render.linear * inst.render_from_object.offset);
    inst.moves = desc.render_from_object_end != desc.render_from_object;
    instances_.push_back(inst);
    const Bounds& b = object_bounds[desc.object];
    if (!(b.lo.x <= b.hi.x)) continue;
    for (const Affine* a : {&inst.render_from_object, &inst.render_from_object_end})
      for (int c = 0; c < 8; ++c) {
        const Vec3 p = apply_point(*a, Vec3(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z));
        bounds_.lo = glm::min(bounds_.lo, p);
        bounds_.hi = glm::max(bounds_.hi, p);
      }
  }
}

void SceneData::append_mesh(MeshDesc& m, const MeshLayout& layout, Bounds* bounds) {
  const uint32_t base = static_cast<uint32_t>(positions_.size());
  const bool has_n = !m.n.empty(), has_uv = !m.uv.empty();
  for (size_t i = 0; i < m.p.size(); ++i) {
    positions_.push_back(m.p[i]);
    if (layout.any_normals) normals_.push_back(has_n ? m.n[i] : Vec3(0.f));
    if (layout.moves) {
      const bool moving = m.p_end.size() == m.p.size();
      positions_end_.push_back(moving ? m.p_end[i] : m.p[i]);
      if (layout.any_normals)
        normals_end_.push_back(has_n ? (moving && m.n_end.size() == m.n.size() ? m.n_end[i] : m.n[i]) : Vec3(0.f));
      if (moving) {
        bounds->lo = glm::min(bounds->lo, m.p_end[i]);
        bounds->hi = glm::max(bounds->hi, m.p_end[i]);
      }
    }
    if (layout.any_uv) uvs_.push_back(has_uv ? m.uv[i] : Vec2(0.f));
    bounds->lo = glm::min(bounds->lo, m.p[i]);
    bounds->hi = glm::max(bounds->hi, m.p[i]);
  }
  append_triangles(m, base);
  // The flat arrays now hold the mesh: its own are not kept for the render
  // (swapped with empty ones: assigning {} would keep their capacity).
  std::vector<Vec3>().swap(m.p);
  std::vector<Vec3>().swap(m.n);
  std::vector<Vec2>().swap(m.uv);
  std::vector<uint32_t>().swap(m.indices);
  std::vector<Vec3>().swap(m.p_end);
  std::vector<Vec3>().swap(m.n_end);
}

void SceneData::append_triangles(const MeshDesc& m, uint32_t base) {
  const bool has_n = !m.n.empty(), has_uv = !m.uv.empty();
  // An area light's "power": each shape's radiance scaled to emit it, as
  // pbrt-v4 does (L / (pi area sides), over an image's mean luminance).
  std::vector<double> power_area;
  double power_per_area = 0.0;
  if (m.area_light >= 0 && desc_.area_lights[m.area_light].power > 0.f) {
    const AreaLightDesc& al = desc_.area_lights[m.area_light];
    const double k_e = al.image >= 0 ? mean_luminance(desc_.images[al.image]) : 1.0;
    // A black image emits nothing however it is scaled.
    power_per_area = k_e > 0.0 ? al.power / (k_e * kPi * (al.two_sided ? 2.0 : 1.0)) : 0.0;
    power_area = shape_area_per_triangle(m);
  }
  TriangleInfo info;
  info.material = m.material;
  info.flags = (m.flip_normals ? kTriFlipNormal : 0u) | (has_n ? kTriHasNormals : 0u) | (has_uv ? kTriHasUv : 0u) |
               (m.invisible_from_inside ? kTriInvisibleFromInside : 0u);
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const Vec3 &a = m.p[m.indices[t]], &b = m.p[m.indices[t + 1]], &c = m.p[m.indices[t + 2]];
    // Degenerate triangles can never be hit or sampled; dropping them keeps
    // area-light pdfs finite.
    Vec3 n;
    double area = 0.0;
    if (!triangle_normal(a, b, c, &n, &area)) continue;
    face_normals_.push_back(m.flip_normals ? -n : n);
    for (int k = 0; k < 3; ++k) indices_.push_back(base + m.indices[t + k]);
    TriangleInfo ti = info;
    if (!has_uv && m.triangles_per_shape == 2 && (t / 3) % 2 == 1) ti.flags |= kTriQuadSecondHalf;
    if (m.area_light >= 0) {
      const AreaLightDesc& al = desc_.area_lights[m.area_light];
      if (!is_black(al.L)) {
        Light l;
        l.type = LightType::Area;
        l.L = al.L;
        l.image = al.image;
        if (!power_area.empty()) l.L *= static_cast<Float>(power_per_area / power_area[t / 3]);  // area > 0 here
        l.blackbody_kelvin = al.blackbody_kelvin;
        l.two_sided = al.two_sided;
        l.triangle = static_cast<uint32_t>(triangles_.size());
        l.area = static_cast<Float>(area);
        ti.light = static_cast<int32_t>(lights_.size());
        lights_.push_back(l);
      }
    }
    triangles_.push_back(ti);
    if (has_alpha_) triangle_alpha_.push_back(m.alpha);
    if (has_media_) triangle_media_.push_back(m.media);
  }
}

void SceneData::build_lights() {
  for (const Light& l : desc_.lights) lights_.push_back(l);
  // Blackbody emitters: light_emission() turns luminance(L) into Planck's
  // law of that luminance. L is scale x blackbody_rgb(T), whose luminance is
  // 1 unless its RGB was clamped at 0 (very warm colours): divide by it, and
  // by the luminance of B / B(peak) as the spectral film integrates it.
  for (Light& l : lights_)
    if (l.blackbody_kelvin > 0.f) {
      const double y = spectrum_luminance([&](double lambda) { return blackbody_relative(Float(lambda), l.blackbody_kelvin); });
      const double rgb_y = luminance(blackbody_rgb(l.blackbody_kelvin));
      l.blackbody_norm = y > 0. && rgb_y > 0. ? static_cast<Float>(1.0 / (y * rgb_y)) : 0.f;
    }
  Float radius = triangles_.empty() ? 1.f : glm::max(1e-3f, 0.5f * glm::length(bounds_.hi - bounds_.lo));

  // Image lights' texel luminance (light selection, firefly bounds).
  std::vector<bool> emits(desc_.images.size(), false);
  for (const Light& l : lights_)
    if (l.image >= 0) emits[static_cast<size_t>(l.image)] = true;
  image_luminance_.resize(desc_.images.size());
  for (size_t i = 0; i < desc_.images.size(); ++i)
    if (emits[i]) {
      image_luminance_[i].mean = static_cast<Float>(mean_luminance(desc_.images[i]));
      for (const Rgb& t : desc_.images[i].texels) image_luminance_[i].max = std::max(image_luminance_[i].max, luminance(t));
    }
  image_views_.reserve(desc_.images.size());
  for (const ImageDesc& img : desc_.images) image_views_.push_back(ImageView{img.width, img.height, img.texels.data()});

  env_storage_.resize(lights_.size());
  std::vector<Float> power(lights_.size(), 0.f);
  for (size_t i = 0; i < lights_.size(); ++i) {
    const Light& l = lights_[i];
    switch (l.type) {
      case LightType::Area: {
        power[i] = luminance(l.L) * l.area * kPi * (l.two_sided ? 2.f : 1.f) *
                   (l.image >= 0 ? image_luminance_[l.image].mean : 1.f);
        break;
      }
      case LightType::Point: power[i] = 4.f * kPi * luminance(l.L); break;
      case LightType::Goniometric:
        power[i] = 4.f * kPi * luminance(l.L) * (l.image >= 0 ? image_luminance_[l.image].mean : 1.f);
        break;
      case LightType::Projection:  // the window's solid angle, about
        power[i] = luminance(l.L) * image_luminance_[l.image].mean * 4.f * l.screen_max.x * l.screen_max.y *
                   l.tan_half_fov * l.tan_half_fov;
        break;
      case LightType::Spot:
        power[i] = luminance(l.L) * 2.f * kPi * (1.f - 0.5f * (l.cos_falloff_start + l.cos_falloff_end));
        break;
      case LightType::Distant: power[i] = luminance(l.L) * kPi * radius * radius; break;
      case LightType::Infinite: {
        infinite_lights_.push_back(static_cast<int32_t>(i));
        lights_[i].world_from_light = glm::inverse(l.light_from_world);
        Float avg = luminance(l.L);
        if (l.image >= 0) {
          const ImageDesc& img = desc_.images[l.image];
          std::vector<Float> f(img.texels.size());
          double sum = 0.0;
          for (size_t p = 0; p < f.size(); ++p) {
            f[p] = luminance(img.texels[p]);
            sum += f[p];
          }
          env_storage_[i] = Distribution2D(f, img.width, img.height);
          avg *= static_cast<Float>(sum / std::max<size_t>(1, f.size()));
        }
        power[i] = 4.f * kPi * kPi * radius * radius * avg;
        break;
      }
    }
  }
  light_select_ = Distribution1D(power);
  if (desc_.light_sampler == LightSamplerKind::Bvh) build_light_tree();
  env_views_.resize(lights_.size());
  for (size_t i = 0; i < lights_.size(); ++i) env_views_[i] = env_storage_[i].view();
}

void SceneData::build_light_tree() {
  LightGeometry g;
  g.positions = positions_.data();
  g.positions_end = positions_end_.empty() ? nullptr : positions_end_.data();
  g.normals = normals_.data();
  g.indices = indices_.data();
  g.triangles = triangles_.data();
  g.face_normals = face_normals_.data();
  std::vector<LightBounds> bounds;
  bounds.reserve(lights_.size());
  for (const Light& l : lights_)
    bounds.push_back(bounds_of_light(l, g, l.image >= 0 ? image_luminance_[static_cast<size_t>(l.image)].mean : 1.f));
  light_bvh_ = build_light_bvh(bounds);
}

void SceneData::build_camera() {
  const FilmDesc& film = desc_.film;
  camera_.width = film.xres;
  camera_.height = film.yres;
  const PixelBounds crop = film_pixel_bounds(film);
  camera_.film_x0 = crop.x0;
  camera_.film_y0 = crop.y0;
  camera_.film_width = crop.width();
  camera_.film_height = crop.height();
  camera_.world_from_camera_linear = Mat3(desc_.camera.world_from_camera);
  camera_.origin = Vec3(desc_.camera.world_from_camera * Vec4(0.f, 0.f, 0.f, 1.f));
  camera_.moves = desc_.camera.world_from_camera_end != desc_.camera.world_from_camera;
  camera_.world_from_camera_linear_end = Mat3(desc_.camera.world_from_camera_end);
  camera_.origin_end = Vec3(desc_.camera.world_from_camera_end * Vec4(0.f, 0.f, 0.f, 1.f));
  camera_.projection = desc_.camera.projection;
  // pbrt-v4's CameraBase: the screen window given, or [-a, a] x [-1, 1] for
  // a frame aspect a > 1, else [-1, 1] x [-1/a, 1/a].
  const Float aspect = desc_.camera.frame_aspect_ratio > 0.f
                           ? desc_.camera.frame_aspect_ratio
                           : static_cast<Float>(film.xres) / static_cast<Float>(film.yres);
  if (desc_.camera.has_screen_window) {
    const Vec4& w = desc_.camera.screen_window;
    camera_.screen_min = Vec2(w.x, w.z);
    camera_.screen_max = Vec2(w.y, w.w);
  } else if (aspect > 1.f) {
    camera_.screen_min = Vec2(-aspect, -1.f);
    camera_.screen_max = Vec2(aspect, 1.f);
  } else {
    camera_.screen_min = Vec2(-1.f, -1.f / aspect);
    camera_.screen_max = Vec2(1.f, 1.f / aspect);
  }
  camera_.tan_half_fov = std::tan(glm::radians(desc_.camera.fov_degrees) * 0.5f);
  camera_.pixel_from_radiance = desc_.film.pixel_from_radiance;
  camera_.sensor_from_radiance = desc_.film.sensor_from_radiance;
  camera_.pixel_from_sensor = desc_.film.pixel_from_sensor;
  camera_.lens_radius = desc_.camera.lens_radius;
  camera_.focal_distance = desc_.camera.focal_distance;
  camera_.max_component_value = desc_.film.max_component_value;
  camera_.shutter_open = desc_.camera.shutter_open;
  camera_.shutter_close = desc_.camera.shutter_close;
  camera_.transform_start_time = desc_.camera.transform_start_time;
  camera_.transform_end_time = desc_.camera.transform_end_time;
  check_camera_limits(camera_, desc_.camera.where.empty() ? desc_.source : desc_.camera.where, desc_.render_origin);
}

void SceneData::build_filter() {
  // Tabulate each axis of the separable filter; sampling |f| and weighting
  // each sample by sign(f) integral|f| / integral f is filter importance
  // sampling (pbrt-v4's FilterSampler, without its per-pixel weight sum).
  const FilterDesc& f = desc_.filter;
  constexpr int kBins = 256, kInverseSize = 1025;
  bool negative_lobes = false;
  auto build_axis = [&](Float radius, std::vector<Float>& inverse_cdf, std::vector<Float>& weight) {
    std::vector<Float> table(kBins);
    weight.resize(kBins);
    double sum_abs = 0, sum = 0;
    for (int i = 0; i < kBins; ++i) {
      Float x = ((i + 0.5f) / kBins * 2.f - 1.f) * radius;
      Float v = pixel_filter_1d(f, x, radius);
      table[i] = std::abs(v);
      weight[i] = v < 0.f ? -1.f : 1.f;  // the sign, scaled below
      sum_abs += std::abs(v);
      sum += v;
      negative_lobes |= v < 0.f;
    }
    if (!(sum > 0.0)) throw SceneError("pixel filter: its integral is not positive");
    for (Float& w : weight) w = static_cast<Float>(w * (sum_abs / sum));
    Distribution1D dist(table);
    inverse_cdf.resize(kInverseSize);
    for (int i = 0; i < kInverseSize; ++i) {
      Float u = std::min(static_cast<Float>(i) / (kInverseSize - 1), 0x1.fffffep-1f);
      Float x = dist.view().sample_continuous(u, nullptr, nullptr);
      inverse_cdf[i] = (2.f * x - 1.f) * radius;
    }
    inverse_cdf.back() = radius;
  };
  build_axis(f.radius, filter_inverse_cdf_x_, filter_weight_x_);
  build_axis(f.radius_y, filter_inverse_cdf_y_, filter_weight_y_);
  if (!negative_lobes) {
    filter_weight_x_.clear();
    filter_weight_y_.clear();
  }
}

void SceneData::build_view() {
  SceneView& v = view_;
  v.layered_mis_balance = desc_.integrator != "path";
  v.positions = positions_.data();
  v.normals = normals_.data();
  if (!positions_end_.empty()) {
    v.positions_end = positions_end_.data();
    v.normals_end = normals_end_.data();
  }
  v.uvs = uvs_.data();
  v.num_vertices = static_cast<uint32_t>(positions_.size());
  v.num_normals = static_cast<uint32_t>(normals_.size());
  v.num_uvs = static_cast<uint32_t>(uvs_.size());
  v.indices = indices_.data();
  v.triangles = triangles_.data();
  v.face_normals = face_normals_.data();
  v.num_triangles = static_cast<uint32_t>(triangles_.size());
  v.triangle_alpha = has_alpha_ ? triangle_alpha_.data() : nullptr;
  v.has_one_way_faces = has_one_way_faces_;
  v.num_world_triangles = num_world_triangles_;
  v.prototypes = prototypes_.data();
  v.num_prototypes = static_cast<uint32_t>(prototypes_.size());
  v.instances = instances_.data();
  v.num_instances = static_cast<uint32_t>(instances_.size());
  for (const ObjectInstance& inst : instances_) v.instances_move |= inst.moves != 0;
  v.materials = desc_.materials.data();
  v.num_materials = static_cast<uint32_t>(desc_.materials.size());
  v.textures = desc_.textures.data();
  v.num_textures = static_cast<uint32_t>(desc_.textures.size());
  v.images = image_views_.data();
  v.num_images = static_cast<uint32_t>(image_views_.size());
  v.lights = lights_.data();
  v.num_lights = static_cast<uint32_t>(lights_.size());
  v.light_select = light_select_.view();
  v.light_sampler = desc_.light_sampler;
  v.light_bvh = light_bvh_.view();
  v.infinite_lights = infinite_lights_.data();
  v.num_infinite_lights = static_cast<uint32_t>(infinite_lights_.size());
  v.env_distributions = env_views_.data();
  v.camera = camera_;
  if (desc_.spectral) v.spectral = srgb_spectral_tables().view();
  v.spectra = desc_.spectra.empty() ? nullptr : desc_.spectra.data();
  v.num_spectra = static_cast<uint32_t>(desc_.spectra.size() / kSpectralSamples);
  for (const Material& m : desc_.materials) v.has_interfaces |= m.type == MaterialType::Interface;
  if (has_media_) {
    v.media = desc_.media.data();
    v.num_media = static_cast<uint32_t>(desc_.media.size());
    v.triangle_media = triangle_media_.data();
    v.camera_medium = desc_.camera_medium;
    for (const GridDesc& g : desc_.grids)
      if (g.temperature.nx > 0 && blackbody_rgb_table_.empty()) blackbody_rgb_table_ = build_blackbody_rgb_table();
    // (SceneData never moves: the views may point into view_.)
    for (const GridDesc& g : desc_.grids)
      grid_views_.push_back(grid_medium_view(g, blackbody_rgb_table_, desc_.spectral ? &v.spectral : nullptr));
    v.grids = grid_views_.data();
  }
  v.filter.inverse_cdf_x = filter_inverse_cdf_x_.data();
  v.filter.inverse_cdf_y = filter_inverse_cdf_y_.data();
  v.filter.n = static_cast<uint32_t>(filter_inverse_cdf_x_.size());
  v.filter.weight_x = filter_weight_x_.empty() ? nullptr : filter_weight_x_.data();
  v.filter.weight_y = filter_weight_y_.empty() ? nullptr : filter_weight_y_.data();
  v.filter.bins = static_cast<uint32_t>(filter_weight_x_.size());
  v.filter.radius_x = desc_.filter.radius;
  v.filter.radius_y = desc_.filter.radius_y;
}

namespace {

// FNV-1a over raw bytes: stable across runs and machines of one endianness.
struct SceneHash : Fnv1a {
  template <class T>
  void add_vector(const std::vector<T>& v) {
    uint64_t n = v.size();
    add(&n, sizeof n);
    if (!v.empty()) add(v.data(), v.size() * sizeof(T));
  }
};

}  // namespace

uint64_t SceneData::fingerprint() const {
  SceneHash f;
  f.add_vector(positions_);
  f.add_vector(indices_);
  if (!positions_end_.empty()) f.add_vector(positions_end_);
  for (const TriangleInfo& t : triangles_) {
    f.add(&t.material, sizeof t.material);
    f.add(&t.light, sizeof t.light);
  }
  for (const Light& l : lights_) {
    f.add(&l.type, sizeof l.type);
    f.add(&l.L, sizeof l.L);
    f.add(&l.position, sizeof l.position);
    if (l.portal_area > 0.f) {  // only portals add bytes: other scenes keep their fingerprints
      const Vec3 portal[4] = {l.portal_p0, l.portal_s, l.portal_t, l.portal_n};
      f.add(portal, sizeof portal);
    }
  }
  uint64_t materials = desc_.materials.size();
  f.add(&materials, sizeof materials);
  if (!instances_.empty()) {  // only scenes with instances add bytes
    f.add_vector(prototypes_);
    f.add_vector(instances_);
  }
  // Cutouts change what the guide sees (only scenes with them add bytes).
  if (has_alpha_) f.add_vector(triangle_alpha_);
  if (has_media_) {
    f.add_vector(triangle_media_);
    f.add_vector(desc_.media);
    f.add(&desc_.camera_medium, sizeof desc_.camera_medium);
    for (const Light& l : lights_) f.add(&l.medium, sizeof l.medium);
    for (const GridDesc& g : desc_.grids) {
      for (const SparseGridDesc* s : {&g.density, &g.le_scale, &g.temperature, &g.rgb_sigma_a[0], &g.rgb_sigma_a[1],
                                      &g.rgb_sigma_a[2], &g.rgb_sigma_s[0], &g.rgb_sigma_s[1], &g.rgb_sigma_s[2],
                                      &g.rgb_le[0], &g.rgb_le[1], &g.rgb_le[2]}) {
        f.add_vector(s->brick_of);
        f.add_vector(s->values);
        f.add(&s->lattice_from_world, sizeof s->lattice_from_world);
        const int32_t dims[3] = {s->nx, s->ny, s->nz};
        f.add(dims, sizeof dims);
        f.add(&s->background, sizeof s->background);
      }
      f.add(&g.majorants.lo, sizeof g.majorants.lo);
      f.add(&g.majorants.hi, sizeof g.majorants.hi);
      const int32_t cells[3] = {g.majorants.nx, g.majorants.ny, g.majorants.nz};
      f.add(cells, sizeof cells);
      f.add_vector(g.majorants.max_density);
      const Float emission[3] = {g.temperature_offset, g.temperature_scale, g.blackbody_scale};
      f.add(emission, sizeof emission);
      const Float cloud[4] = {static_cast<Float>(g.cloud), g.cloud_density, g.cloud_wispiness, g.cloud_frequency};
      f.add(cloud, sizeof cloud);
      const Float rgb[3] = {static_cast<Float>(g.rgb), g.rgb_scale, g.rgb_le_scale};
      f.add(rgb, sizeof rgb);
    }
  }
  return f.h;
}

uint64_t SceneData::film_fingerprint() const {
  bool shapes_move = !positions_end_.empty();
  for (const ObjectInstance& inst : instances_) shapes_move |= inst.moves != 0;
  // pbrt's defaults give 0, so checkpoints of such scenes keep their fingerprint.
  const FilterDesc default_filter;
  const bool defaults = camera_.pixel_from_radiance == Mat3(1.f) && !std::isfinite(camera_.max_component_value) &&
                        camera_.lens_radius == 0.f && std::memcmp(&desc_.filter, &default_filter, sizeof default_filter) == 0 &&
                        !shapes_move && !camera_.moves && !desc_.spectral && camera_.film_x0 == 0 &&
                        camera_.film_y0 == 0 && camera_.film_width == camera_.width && camera_.film_height == camera_.height &&
                        view_.layered_mis_balance && camera_.projection == CameraProjection::Perspective &&
                        !desc_.camera.has_screen_window && desc_.camera.frame_aspect_ratio == 0.f;
  if (defaults) return 0;
  SceneHash f;
  f.add(&camera_.pixel_from_radiance, sizeof camera_.pixel_from_radiance);
  f.add(&camera_.sensor_from_radiance, sizeof camera_.sensor_from_radiance);
  f.add(&camera_.max_component_value, sizeof camera_.max_component_value);
  f.add(&camera_.lens_radius, sizeof camera_.lens_radius);
  f.add(&camera_.focal_distance, sizeof camera_.focal_distance);
  f.add(&desc_.filter, sizeof desc_.filter);
  const int32_t crop[4] = {camera_.film_x0, camera_.film_y0, camera_.film_width, camera_.film_height};
  f.add(crop, sizeof crop);
  f.add(&camera_.projection, sizeof camera_.projection);
  f.add(&camera_.screen_min, sizeof camera_.screen_min);
  f.add(&camera_.screen_max, sizeof camera_.screen_max);
  if (!view_.layered_mis_balance) f.add("power-mis", 9);  // "path": the coated BSDFs' picture differs
  if (desc_.spectral) f.add("spectral", 8);  // only then: RGB checkpoints keep their fingerprints
  if (shapes_move || camera_.moves) {  // motion blur: the shutter, the transforms' times, the camera's end
    f.add(&camera_.world_from_camera_linear_end, sizeof camera_.world_from_camera_linear_end);
    f.add(&camera_.origin_end, sizeof camera_.origin_end);
    const Float times[4] = {camera_.shutter_open, camera_.shutter_close, camera_.transform_start_time,
                            camera_.transform_end_time};
    f.add(times, sizeof times);
  }
  return f.h;
}

Float SceneData::max_emitted_radiance() const {
  Float m = 0.f;
  for (const Light& l : lights_) m = std::max(m, luminance(l.L) * (l.image >= 0 ? image_luminance_[l.image].max : 1.f));
  return m;
}

}  // namespace tessera
