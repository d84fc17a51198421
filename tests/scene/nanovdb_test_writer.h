// Writes small .nvdb files for the tests with NanoVDB's own GridBuilder, so
// the reader is checked against the library's writer and sampler.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/IO.h>

namespace tessera::test {

struct NvdbGridSpec {
  std::string name = "density";
  double voxel_size = 1.0;
  nanovdb::Vec3d origin{0.0, 0.0, 0.0};   // world position of index (0, 0, 0)
  nanovdb::CoordBBox voxels;               // the voxels value() is asked for (inclusive)
  std::function<float(int, int, int)> value;
  nanovdb::GridClass grid_class = nanovdb::GridClass::FogVolume;
  bool zeros_active = false;  // zeros set too (active voxels): they widen the grid's bounding box
  float background = 0.f;
};

inline nanovdb::GridHandle<nanovdb::HostBuffer> build_nvdb_grid(const NvdbGridSpec& s) {
  nanovdb::GridBuilder<float> builder(s.background, s.grid_class);
  auto acc = builder.getAccessor();
  for (int z = s.voxels.min()[2]; z <= s.voxels.max()[2]; ++z)
    for (int y = s.voxels.min()[1]; y <= s.voxels.max()[1]; ++y)
      for (int x = s.voxels.min()[0]; x <= s.voxels.max()[0]; ++x) {
        const float v = s.value(x, y, z);
        if (v != 0.f || s.zeros_active) acc.setValue(nanovdb::Coord(x, y, z), v);
      }
  return builder.getHandle(s.voxel_size, s.origin, s.name);
}

inline void write_nvdb(const std::string& path, const std::vector<NvdbGridSpec>& grids) {
  std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
  for (const NvdbGridSpec& s : grids) handles.push_back(build_nvdb_grid(s));
  nanovdb::io::writeGrids<nanovdb::HostBuffer, std::vector>(path, handles);
}

}  // namespace tessera::test
