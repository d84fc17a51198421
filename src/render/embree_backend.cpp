#include "render/embree_backend.h"

#include "kernels/hit_filter.h"
#include "render/render_tile_impl.h"

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
// next candidate.
void hit_filter(const RTCFilterFunctionNArguments* args) {
  const auto* view = static_cast<const SceneView*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                 RTCRayN_org_z(args->ray, args->N, i));
    const Vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                 RTCRayN_dir_z(args->ray, args->N, i));
    if (hit_ignored(*view, RTCHitN_primID(args->hit, args->N, i), RTCHitN_u(args->hit, args->N, i),
                          RTCHitN_v(args->hit, args->N, i), o, d, RTCRayN_time(args->ray, args->N, i)))
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
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
  scene_ = nullptr;
  device_ = nullptr;
}

void EmbreeScene::build(const SceneData& data) {
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  // Robust traversal: Embree's default triangle test lets a ray that meets
  // an edge pass between two triangles on some ISAs (AVX2 without AVX-512):
  // paths leave a closed albedo-1 sphere within 1000 bounces there
  // (tests/render/furnace_test.cpp). A closed mesh that leaks light is a
  // wrong picture; docs/backends.md gives robust mode's cost.
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  const size_t nv = data.positions().size(), nt = data.num_triangles();
  if (nt > 0) {
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    const Vec3* end = data.view().positions_end;
    // Motion blur: Embree interpolates each vertex between the two time steps by the ray's time.
    if (end) rtcSetGeometryTimeStepCount(geom, 2);
    // New buffers (not shared) so Embree owns the padding it needs past the end.
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* ix = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
    if (!v || !ix) {
      rtcReleaseGeometry(geom);
      throw std::runtime_error("embree: cannot allocate geometry buffers" + (error_.empty() ? "" : ": " + error_));
    }
    std::memcpy(v, data.positions().data(), nv * 3 * sizeof(float));
    std::memcpy(ix, data.indices().data(), nt * 3 * sizeof(uint32_t));
    if (end) {
      auto* v1 = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 1, RTC_FORMAT_FLOAT3,
                                                             3 * sizeof(float), nv));
      if (!v1) {
        rtcReleaseGeometry(geom);
        throw std::runtime_error("embree: cannot allocate motion buffers" + (error_.empty() ? "" : ": " + error_));
      }
      std::memcpy(v1, end, nv * 3 * sizeof(float));
    }
    // Only scenes with cutouts or curve tubes pay for the filter.
    if (data.view().triangle_alpha || data.view().has_one_way_faces) {
      rtcSetGeometryUserData(geom, const_cast<SceneView*>(&data.view()));
      rtcSetGeometryIntersectFilterFunction(geom, hit_filter);
      rtcSetGeometryOccludedFilterFunction(geom, hit_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(scene_);
  if (!error_.empty()) throw std::runtime_error("embree: " + error_);
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
