// A scene made ready for the GPU check on a machine that has only a GPU and
// nvcc's runtime: the packed scene (render/scene_pack.h), the settings its
// tiles render with, what a guide over it needs, and the image the host
// emulation of the device kernel gave for it. Written by
// make_gpu_fixtures.cpp, read by device_backend_on_device.cpp.
#pragma once

#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/film.h"
#include "render/render_tile.h"
#include "render/pod_io.h"
#include "render/scene_pack.h"

namespace tessera::cuda_check {

// Reads a decimal number in [1, max] at *p (digits only: no sign, no
// space) and moves *p past it; false if there is none or it is out of
// range. For the GPU check programs' arguments and settings.
inline bool read_count(const char** p, unsigned long max, unsigned long* value) {
  unsigned long v = 0;
  const char* q = *p;
  for (; *q >= '0' && *q <= '9'; ++q) {
    v = v * 10 + static_cast<unsigned long>(*q - '0');
    if (v > max) return false;
  }
  if (q == *p || v < 1) return false;
  *p = q;
  *value = v;
  return true;
}

struct GpuFixture {
  std::string name;
  TileSettings settings;  // unguided; no guide view
  int32_t width = 0, height = 0;
  uint32_t spp = 0;
  Vec3 lo{0.f}, hi{0.f};  // the scene's bounds, for a guide
  uint32_t lights = 0;
  Float max_emitted = 0.f;
  double host_seconds = 0.0;    // the emulated device's render on the machine that wrote it
  double embree_seconds = 0.0;  // the same pass with Embree there (its specialised integrator)
  int32_t host_threads = 0;
  std::vector<PixelAccum> reference;  // that render: samples [0, spp), one pass
};

constexpr char kFixtureMagic[8] = {'T', 'S', 'F', 'I', 'X', '0', '0', '2'};

inline void save_fixture(const std::string& path, const GpuFixture& f, const PackedScene& scene) {
  std::ofstream o(path, std::ios::binary);
  o.write(kFixtureMagic, sizeof(kFixtureMagic));
  const uint64_t name_size = f.name.size();
  write_pod(o, name_size);
  o.write(f.name.data(), static_cast<std::streamsize>(name_size));
  write_pod(o, f.settings);
  write_pod(o, f.width);
  write_pod(o, f.height);
  write_pod(o, f.spp);
  write_pod(o, f.lo);
  write_pod(o, f.hi);
  write_pod(o, f.lights);
  write_pod(o, f.max_emitted);
  write_pod(o, f.host_seconds);
  write_pod(o, f.embree_seconds);
  write_pod(o, f.host_threads);
  o.write(reinterpret_cast<const char*>(f.reference.data()),
          static_cast<std::streamsize>(f.reference.size() * sizeof(PixelAccum)));
  scene.save(o);
  if (!o) throw std::runtime_error("fixture: cannot write " + path);
}

inline PackedScene load_fixture(const std::string& path, GpuFixture* f) {
  std::ifstream i(path, std::ios::binary);
  char magic[sizeof(kFixtureMagic)];
  if (!i.read(magic, sizeof(magic)) || std::memcmp(magic, kFixtureMagic, sizeof(magic)) != 0)
    throw std::runtime_error("fixture: " + path + " is not a fixture of this version");
  uint64_t name_size = 0;
  read_pod(i, &name_size, "fixture");
  if (name_size > 4096) throw std::runtime_error("fixture: bad name");
  f->name.resize(name_size);
  i.read(f->name.data(), static_cast<std::streamsize>(name_size));
  read_pod(i, &f->settings, "fixture");
  read_pod(i, &f->width, "fixture");
  read_pod(i, &f->height, "fixture");
  read_pod(i, &f->spp, "fixture");
  read_pod(i, &f->lo, "fixture");
  read_pod(i, &f->hi, "fixture");
  read_pod(i, &f->lights, "fixture");
  read_pod(i, &f->max_emitted, "fixture");
  read_pod(i, &f->host_seconds, "fixture");
  read_pod(i, &f->embree_seconds, "fixture");
  read_pod(i, &f->host_threads, "fixture");
  if (f->width <= 0 || f->height <= 0 || f->width > 16384 || f->height > 16384) throw std::runtime_error("fixture: bad size");
  f->reference.resize(static_cast<size_t>(f->width) * f->height);
  if (!i.read(reinterpret_cast<char*>(f->reference.data()),
              static_cast<std::streamsize>(f->reference.size() * sizeof(PixelAccum))))
    throw std::runtime_error("fixture: truncated");
  return PackedScene::load(i);
}

}  // namespace tessera::cuda_check
