#include "render/embree_backend.h"

#include "kernels/hit_filter.h"
#include "render/render_tile_impl.h"
#include "scene/load_stop.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <string>

namespace tessera {
namespace {

// Exceptions must not cross Embree's C API: remember the first message and
// check after each call that can fail.
void embree_error(void* user, RTCError code, const char* message) {
  auto* first = static_cast<std::string*>(user);
  if (code != RTC_ERROR_NONE && first->empty()) *first = message ? message : "unknown error";
}

// Closest-hit and shadow rays alike: candidate hits on cut-out surfaces and
// on one-way faces from behind are rejected here, so Embree continues to the
// next candidate. Inside an instance Embree hands the filter the ray in the
// prototype's space, as hit_ignored wants it.
void hit_filter(const RTCFilterFunctionNArguments* args) {
  const auto* geometry = static_cast<const EmbreeScene::FilterData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                 RTCRayN_org_z(args->ray, args->N, i));
    const Vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                 RTCRayN_dir_z(args->ray, args->N, i));
    const unsigned inst = RTCHitN_instID(args->hit, args->N, i, 0);
    const int32_t instance = inst == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<int32_t>(inst) - 1;
    if (hit_ignored(*geometry->view, geometry->first_triangle + RTCHitN_primID(args->hit, args->N, i), instance,
                    RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i), o, d,
                    RTCRayN_time(args->ray, args->N, i)))
      args->valid[i] = 0;
  }
}

}  // namespace

EmbreeScene::EmbreeScene(const SceneData& data) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("embree: cannot create device");
  rtcSetDeviceErrorFunction(device_, embree_error, &error_);
  try {
    build(data);
  } catch (...) {
    // The destructor does not run for a constructor that throws: release
    // the handles here (calling ~EmbreeScene() would destroy the members,
    // and the unwinding destroys them again).
    release();
    throw;
  }
}

void EmbreeScene::release() {
  for (RTCScene prototype : prototypes_) rtcReleaseScene(prototype);
  prototypes_.clear();
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
  scene_ = nullptr;
  device_ = nullptr;
}

// Robust traversal: Embree's default triangle test lets a ray that meets an
// edge pass between two triangles on some ISAs (AVX2 without AVX-512): paths
// leave a closed albedo-1 sphere within 1000 bounces there
// (tests/render/furnace_test.cpp). A closed mesh that leaks light is a wrong
// picture; docs/backends.md gives robust mode's cost.
// A large scene's build takes seconds: Ctrl-C stops it as it stops loading.
static bool continue_build(void*, double) { return !load_stop_requested(); }

RTCScene EmbreeScene::new_scene() {
  RTCScene scene = rtcNewScene(device_);
  rtcSetSceneProgressMonitorFunction(scene, continue_build, nullptr);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  return scene;
}

void EmbreeScene::fail(const std::string& what) const {
  throw std::runtime_error("embree: " + what + (error_.empty() ? "" : ": " + error_));
}

// Triangles [first, first + count) as one geometry of `scene`, with the
// vertices they use (copied into new buffers, so that Embree owns the padding
// it needs past the end).
void EmbreeScene::attach_triangles(const SceneData& data, RTCScene scene, uint32_t first, uint32_t count, unsigned id) {
  if (count == 0) return;
  const std::vector<uint32_t>& indices = data.indices();
  const auto [lo, hi] = std::minmax_element(indices.begin() + 3 * size_t{first}, indices.begin() + 3 * (size_t{first} + count));
  const uint32_t v0 = *lo, nv = *hi - *lo + 1;
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  const Vec3* end = data.view().positions_end;
  // Motion blur: Embree interpolates each vertex between the two time steps by the ray's time.
  if (end) rtcSetGeometryTimeStepCount(geom, 2);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
  auto* ix = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), count));
  auto* v1 = end ? static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 1, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), nv))
                 : nullptr;
  if (!v || !ix || (end && !v1)) {
    rtcReleaseGeometry(geom);
    fail("cannot allocate geometry buffers");
  }
  std::memcpy(v, data.positions().data() + v0, size_t{nv} * 3 * sizeof(float));
  if (end) std::memcpy(v1, end + v0, size_t{nv} * 3 * sizeof(float));
  for (size_t i = 0; i < 3 * size_t{count}; ++i) ix[i] = indices[3 * size_t{first} + i] - v0;
  // Only scenes with cutouts or curve tubes pay for the filter.
  if (data.view().triangle_alpha || data.view().has_one_way_faces) {
    filters_.push_back(std::make_unique<FilterData>(FilterData{&data.view(), first}));
    rtcSetGeometryUserData(geom, filters_.back().get());
    rtcSetGeometryIntersectFilterFunction(geom, hit_filter);
    rtcSetGeometryOccludedFilterFunction(geom, hit_filter);
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
}

// Instance i is geometry i + 1 of the top-level scene (the world's own
// triangles are geometry 0), so a hit's instID names it.
void EmbreeScene::attach_instance(const ObjectInstance& inst, unsigned id) {
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(geom, prototypes_[inst.prototype]);
  // A moving instance: Embree interpolates the two matrices linearly, as placement_at does.
  rtcSetGeometryTimeStepCount(geom, inst.moves ? 2 : 1);
  for (unsigned step = 0; step < (inst.moves ? 2u : 1u); ++step) {
    const Affine& a = step == 0 ? inst.render_from_object : inst.render_from_object_end;
    const float m[12] = {a.linear[0].x, a.linear[0].y, a.linear[0].z, a.linear[1].x, a.linear[1].y, a.linear[1].z,
                         a.linear[2].x, a.linear[2].y, a.linear[2].z, a.offset.x,    a.offset.y,    a.offset.z};
    rtcSetGeometryTransform(geom, step, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene_, geom, id);
  rtcReleaseGeometry(geom);
}

void EmbreeScene::build(const SceneData& data) {
  const SceneView& s = data.view();
  for (uint32_t i = 0; i < s.num_prototypes; ++i) {
    prototypes_.push_back(new_scene());
    attach_triangles(data, prototypes_.back(), s.prototypes[i].first_triangle, s.prototypes[i].num_triangles, 0);
    rtcCommitScene(prototypes_.back());
    check_load_stop();
  }
  scene_ = new_scene();
  attach_triangles(data, scene_, 0, s.num_world_triangles, 0);
  instance_first_.reserve(s.num_instances);
  for (uint32_t i = 0; i < s.num_instances; ++i) {
    attach_instance(s.instances[i], i + 1);
    instance_first_.push_back(s.prototypes[s.instances[i].prototype].first_triangle);
  }
  rtcCommitScene(scene_);
  check_load_stop();  // a cancelled build is an interrupted load, not an error
  if (!error_.empty()) fail("building the scene failed");
}

EmbreeScene::~EmbreeScene() { release(); }

namespace {

using TileFn = TileCounters (*)(const SceneView&, const EmbreeTracer&, const TileSettings&, const TileJob&, TilePixels,
                                std::vector<Splat>*);

template <size_t... I>
constexpr std::array<TileFn, sizeof...(I)> make_table(std::index_sequence<I...>) {
  return {&render_tile_spec<instantiated_spec(static_cast<uint32_t>(I)), EmbreeTracer, true>...};
}

// One instantiation per specialisation; chosen once per tile. The network's
// pixels share their first sites between samples (NeuralFirstSite); the bvh
// backend's do not, as the device's, which traces each sample alone.
constexpr auto kTileFns = make_table(std::make_index_sequence<kSpecIndexCount>{});

}  // namespace

TileCounters render_tile(const SceneView& scene, const EmbreeTracer& tracer, const TileSettings& settings,
                         const TileJob& job, TilePixels pixels, std::vector<Splat>* splats) {
  if (settings.path.light_traced_caustics && !splats)
    throw std::logic_error("render_tile: light-traced caustics need a splat list");
  return kTileFns[settings.specialisation & (kSpecIndexCount - 1)](scene, tracer, settings, job, pixels, splats);
}

}  // namespace tessera
