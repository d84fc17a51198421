#include "render/scene_pack.h"

#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "render/pod_io.h"

namespace tessera {
namespace {

// A new field in the views must be packed below (or shown not to need it):
// this fails the build until someone looks.
static_assert(sizeof(SceneView) == 792, "SceneView changed: pack its new arrays in scene_pack.cpp, then update this size");
static_assert(sizeof(BvhView) == 40, "BvhView changed: pack its new arrays in scene_pack.cpp, then update this size");

template <class S, class F>
size_t offset_in(const S& object, const F& field) {
  return static_cast<size_t>(reinterpret_cast<const unsigned char*>(&field) - reinterpret_cast<const unsigned char*>(&object));
}

}  // namespace

template <class T>
size_t PackedScene::append(const T* data, size_t count) {
  const size_t at = (bytes_.size() + 15) & ~size_t{15};
  bytes_.resize(at + ((count * sizeof(T) + 15) & ~size_t{15}), 0);
  std::memcpy(bytes_.data() + at, data, count * sizeof(T));
  return at;
}

template <class T>
void PackedScene::point_view(const T*& field, const T* data, size_t count) {
  if (data == nullptr || count == 0) {
    field = nullptr;
    return;
  }
  field = reinterpret_cast<const T*>(static_cast<uintptr_t>(append(data, count)));
  fixups_.push_back({true, offset_in(views_, field)});
}

template <class T>
void PackedScene::point_bytes(size_t field_at, const T* data, size_t count) {
  uintptr_t offset = 0;
  if (data != nullptr && count > 0) {
    offset = append(data, count);
    fixups_.push_back({false, field_at});
  }
  std::memcpy(bytes_.data() + field_at, &offset, sizeof(offset));
}

void PackedScene::pack_images(const SceneView& s) {
  if (s.images == nullptr || s.num_images == 0) {
    views_.scene.images = nullptr;
    return;
  }
  const size_t array_at = append(s.images, s.num_images);
  views_.scene.images = reinterpret_cast<const ImageView*>(static_cast<uintptr_t>(array_at));
  fixups_.push_back({true, offset_in(views_, views_.scene.images)});
  for (uint32_t i = 0; i < s.num_images; ++i) {
    const ImageView& img = s.images[i];
    const size_t at = array_at + i * sizeof(ImageView) + offset_in(img, img.texels);
    point_bytes(at, img.texels, static_cast<size_t>(img.width) * static_cast<size_t>(img.height));
  }
}

void PackedScene::pack_env_distributions(const SceneView& s) {
  if (s.env_distributions == nullptr || s.num_lights == 0) {
    views_.scene.env_distributions = nullptr;
    return;
  }
  const size_t array_at = append(s.env_distributions, s.num_lights);
  views_.scene.env_distributions = reinterpret_cast<const Distribution2DView*>(static_cast<uintptr_t>(array_at));
  fixups_.push_back({true, offset_in(views_, views_.scene.env_distributions)});
  for (uint32_t i = 0; i < s.num_lights; ++i) {
    const Distribution2DView& d = s.env_distributions[i];
    const size_t at = array_at + i * sizeof(Distribution2DView);
    const size_t w = d.width, h = d.height;
    point_bytes(at + offset_in(d, d.func), d.func, w * h);
    point_bytes(at + offset_in(d, d.cond_cdf), d.cond_cdf, h * (w + 1));
    point_bytes(at + offset_in(d, d.cond_integral), d.cond_integral, h);
    point_bytes(at + offset_in(d, d.marginal.func), d.marginal.func, d.marginal.n);
    point_bytes(at + offset_in(d, d.marginal.cdf), d.marginal.cdf, d.marginal.n + size_t{d.marginal.n > 0});
  }
}

PackedScene::PackedScene(const SceneView& s, const BvhView& bvh) {
  if (s.grids != nullptr)
    throw std::runtime_error("grid media cannot be packed for a device yet (render such scenes with --backend embree or bvh)");
  views_.scene = s;
  views_.bvh = bvh;
  SceneView& v = views_.scene;
  const size_t tris = s.num_triangles;
  point_view(v.positions, s.positions, s.num_vertices);
  point_view(v.normals, s.normals, s.num_normals);
  point_view(v.positions_end, s.positions_end, s.positions_end ? s.num_vertices : 0);
  point_view(v.normals_end, s.normals_end, s.normals_end ? s.num_normals : 0);
  point_view(v.uvs, s.uvs, s.num_uvs);
  point_view(v.indices, s.indices, 3 * tris);
  point_view(v.triangles, s.triangles, tris);
  point_view(v.face_normals, s.face_normals, tris);
  point_view(v.triangle_alpha, s.triangle_alpha, tris);
  point_view(v.prototypes, s.prototypes, s.num_prototypes);
  point_view(v.instances, s.instances, s.num_instances);
  point_view(v.materials, s.materials, s.num_materials);
  point_view(v.textures, s.textures, s.num_textures);
  pack_images(s);
  point_view(v.lights, s.lights, s.num_lights);
  const size_t light_bins = s.light_select.n;
  point_view(v.light_select.func, s.light_select.func, light_bins);
  point_view(v.light_select.cdf, s.light_select.cdf, light_bins + (light_bins > 0));
  point_view(v.infinite_lights, s.infinite_lights, s.num_infinite_lights);
  point_view(v.light_bvh.nodes, s.light_bvh.nodes, s.light_bvh.num_nodes);
  point_view(v.light_bvh.leaf_of_light, s.light_bvh.leaf_of_light, s.light_bvh.leaf_of_light ? s.num_lights : 0);
  point_view(v.light_bvh.unbounded, s.light_bvh.unbounded, s.light_bvh.num_unbounded);
  pack_env_distributions(s);
  point_view(v.media, s.media, s.num_media);
  point_view(v.triangle_media, s.triangle_media, s.triangle_media ? tris : 0);
  v.grids = nullptr;
  point_view(v.filter.inverse_cdf_x, s.filter.inverse_cdf_x, s.filter.n);
  point_view(v.filter.inverse_cdf_y, s.filter.inverse_cdf_y, s.filter.n);
  point_view(v.filter.weight_x, s.filter.weight_x, s.filter.bins);
  point_view(v.filter.weight_y, s.filter.weight_y, s.filter.bins);
  if (s.spectral.enabled) {
    const size_t res = static_cast<size_t>(s.spectral.res);
    point_view(v.spectral.cmf, s.spectral.cmf, 3 * kSpectralSamples);
    point_view(v.spectral.illuminant, s.spectral.illuminant, kSpectralSamples);
    point_view(v.spectral.table_scale, s.spectral.table_scale, res);
    point_view(v.spectral.table, s.spectral.table, 3 * res * res * res * 3);
  } else {
    v.spectral.cmf = v.spectral.illuminant = v.spectral.table_scale = v.spectral.table = nullptr;
  }
  point_view(v.spectra, s.spectra, static_cast<size_t>(s.num_spectra) * kSpectralSamples);
  point_view(views_.bvh.nodes, bvh.nodes, bvh.num_nodes);
  point_view(views_.bvh.triangles, bvh.triangles, bvh.num_triangles);
  point_view(views_.bvh.prototype_roots, bvh.prototype_roots, bvh.num_prototypes);
  if (bytes_.empty()) bytes_.resize(16, 0);
}

void PackedScene::patch(unsigned char* object, size_t at, uintptr_t base) {
  uintptr_t p = 0;
  std::memcpy(&p, object + at, sizeof(p));
  p += base;
  std::memcpy(object + at, &p, sizeof(p));
}

void PackedScene::write_for(uintptr_t base, unsigned char* out) const {
  std::memcpy(out, bytes_.data(), bytes_.size());
  for (const Fixup& f : fixups_)
    if (!f.in_views) patch(out, f.at, base);
}

SceneView PackedScene::view_at(uintptr_t base) const {
  Views v = views_;
  for (const Fixup& f : fixups_)
    if (f.in_views) patch(reinterpret_cast<unsigned char*>(&v), f.at, base);
  return v.scene;
}

BvhView PackedScene::bvh_at(uintptr_t base) const {
  Views v = views_;
  for (const Fixup& f : fixups_)
    if (f.in_views) patch(reinterpret_cast<unsigned char*>(&v), f.at, base);
  return v.bvh;
}

namespace {

constexpr char kPackMagic[8] = {'T', 'S', 'P', 'A', 'C', 'K', '0', '1'};

}  // namespace

void PackedScene::save(std::ostream& out) const {
  out.write(kPackMagic, sizeof(kPackMagic));
  write_pod(out, uint64_t{sizeof(Views)});
  write_pod(out, views_);
  write_pod(out, uint64_t{bytes_.size()});
  out.write(reinterpret_cast<const char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
  write_pod(out, uint64_t{fixups_.size()});
  for (const Fixup& f : fixups_) {
    write_pod(out, uint64_t{f.in_views});
    write_pod(out, uint64_t{f.at});
  }
  if (!out) throw std::runtime_error("packed scene: write failed");
}

PackedScene PackedScene::load(std::istream& in) {
  char magic[sizeof(kPackMagic)];
  if (!in.read(magic, sizeof(magic)) || std::memcmp(magic, kPackMagic, sizeof(magic)) != 0)
    throw std::runtime_error("packed scene: not a packed scene of this version");
  PackedScene p;
  uint64_t n = 0;
  read_pod(in, &n, "packed scene");
  if (n != sizeof(Views)) throw std::runtime_error("packed scene: written by a different build");
  read_pod(in, &p.views_, "packed scene");
  read_pod(in, &n, "packed scene");
  if (n % 16 != 0 || n > (uint64_t{1} << 40)) throw std::runtime_error("packed scene: bad size");
  p.bytes_.resize(n);
  if (!in.read(reinterpret_cast<char*>(p.bytes_.data()), static_cast<std::streamsize>(n)))
    throw std::runtime_error("packed scene: truncated");
  read_pod(in, &n, "packed scene");
  for (uint64_t i = 0; i < n; ++i) {
    uint64_t in_views = 0, at = 0;
    read_pod(in, &in_views, "packed scene");
    read_pod(in, &at, "packed scene");
    const size_t limit = in_views ? sizeof(Views) : p.bytes_.size();
    if (at + sizeof(uintptr_t) > limit) throw std::runtime_error("packed scene: bad pointer entry");
    p.fixups_.push_back({in_views != 0, static_cast<size_t>(at)});
  }
  return p;
}

}  // namespace tessera
