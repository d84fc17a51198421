#include "comm/scene_wire.h"

#include "comm/wire.h"

namespace tessera {

template <class Archive>
void serialize(Archive& ar, MeshDesc& m) {
  ar(raw(m.p), raw(m.n), raw(m.uv), raw(m.indices), m.material, m.flip_normals, m.area_light, raw_value(m.alpha), raw_value(m.media),
     raw(m.p_end), raw(m.n_end), m.triangles_per_shape, m.shape_area, m.invisible_from_inside, m.where);
}
template <class Archive>
void serialize(Archive& ar, ObjectDesc& o) {
  ar(o.name, o.meshes);
}
template <class Archive>
void serialize(Archive& ar, InstanceDesc& i) {
  ar(i.object, raw_value(i.render_from_object), raw_value(i.render_from_object_end), i.where);
}
template <class Archive>
void serialize(Archive& ar, ImageDesc& i) {
  ar(i.width, i.height, raw(i.texels), i.path);
}
template <class Archive>
void serialize(Archive& ar, SparseGridDesc& g) {
  ar(raw_value(g.lattice_from_world), g.nx, g.ny, g.nz, g.bx, g.by, g.bz, raw(g.brick_of), raw(g.values), g.max_value,
     g.background);
}
template <class Archive>
void serialize(Archive& ar, MajorantGridDesc& m) {
  ar(raw_value(m.lo), raw_value(m.hi), m.nx, m.ny, m.nz, raw(m.max_density));
}
template <class Archive>
void serialize(Archive& ar, GridDesc& g) {
  ar(g.density, g.majorants, g.le_scale, g.temperature, g.temperature_offset, g.temperature_scale, g.blackbody_scale,
     g.cloud, g.cloud_density, g.cloud_wispiness, g.cloud_frequency, g.rgb, g.rgb_scale, g.rgb_le_scale);
  for (int c = 0; c < 3; ++c) ar(g.rgb_sigma_a[c], g.rgb_sigma_s[c], g.rgb_le[c]);
}
template <class Archive>
void serialize(Archive& ar, SceneDesc& d) {
  ar(raw_value(d.camera.world_from_camera), d.camera.fov_degrees, d.camera.lens_radius, d.camera.focal_distance,
     d.camera.where, d.camera.projection, d.camera.has_screen_window, raw_value(d.camera.screen_window),
     d.camera.frame_aspect_ratio);
  ar(d.film.xres, d.film.yres, d.film.crop[0], d.film.crop[1], d.film.crop[2], d.film.crop[3], d.film.filename, raw_value(d.filter), d.spp, d.max_depth, d.seed);
  ar(d.integrator, d.light_sampler, d.sampler, d.strata_x, d.strata_y, d.sampler_jitter, d.halton_randomize, d.sampler_spp, d.camera.exposure_time, d.film.iso, d.film.whitebalance, d.film.sensor, d.film.max_component_value,
     raw_value(d.film.pixel_from_radiance), raw_value(d.film.sensor_from_radiance), raw_value(d.film.pixel_from_sensor));
  ar(d.meshes, raw(d.materials), raw(d.textures), d.images, raw(d.area_lights), raw(d.lights), d.warnings, d.source);
  ar(raw(d.media), d.camera_medium, d.grids);
  ar(d.camera.shutter_open, d.camera.shutter_close, d.camera.transform_start_time, d.camera.transform_end_time,
     raw_value(d.camera.world_from_camera_end));
  ar(d.spectral, d.spectra);
  ar(d.objects, d.instances);
}

Bytes encode_scene(const SceneDesc& desc) { return encode(desc); }
SceneDesc decode_scene(const Bytes& bytes) { return decode<SceneDesc>(bytes); }

}  // namespace tessera
