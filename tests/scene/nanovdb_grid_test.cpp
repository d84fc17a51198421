// NanoVDB grids (pbrt-v4's "nanovdb" medium): read into our brick lattice,
// they give NanoVDB's own trilinear samples; bad files are refused with a
// message naming them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nanovdb/NanoVDB.h>
// This NanoVDB release's SampleFromVoxels.h names is_floating_point unqualified outside its namespace.
using nanovdb::is_floating_point;
#include <nanovdb/util/SampleFromVoxels.h>

#include "kernels/rng.h"
#include "kernels/sparse_grid.h"
#include "nanovdb_test_writer.h"
#include "scene/nanovdb_grid.h"
#include "scene/pbrt_loader.h"
#include "scene_test_helpers.h"

namespace tessera {
namespace {

using test::NvdbGridSpec;
using test::TempDir;

// A blob of smooth values around negative and positive index coordinates,
// plus a far-off cluster (another upper node).
NvdbGridSpec blob_spec() {
  NvdbGridSpec s;
  s.voxel_size = 0.25;
  s.origin = nanovdb::Vec3d(-1.0, 2.0, 0.5);
  s.voxels = nanovdb::CoordBBox(nanovdb::Coord(-13, -5, -20), nanovdb::Coord(21, 9, 3));
  s.value = [](int x, int y, int z) {
    const float r2 = 0.01f * (x * x + 2 * y * y + z * z);
    return r2 < 2.5f ? 2.f + std::sin(0.3f * x) * std::cos(0.2f * y + 0.1f * z) : 0.f;
  };
  return s;
}

TEST(NanoVdb, LatticeLookupsEqualNanoVdbsTrilinearSamples) {
  const NvdbGridSpec spec = blob_spec();
  auto handle = test::build_nvdb_grid(spec);
  const nanovdb::FloatGrid* grid = handle.grid<float>();
  ASSERT_NE(grid, nullptr);
  TempDir dir;
  const std::string path = dir.file("blob.nvdb");
  nanovdb::io::writeGrid(path, handle);
  const NanoVdbGrid g = read_nanovdb_grid(path, "density", true);
  ASSERT_TRUE(g.found);
  const SparseGridView v = sparse_grid_view(g.lattice);
  using Sampler = nanovdb::SampleFromVoxels<nanovdb::FloatGrid::TreeType, 1, false>;
  const Sampler sample(grid->tree());
  EXPECT_VEC3_NEAR(g.world_lo, Vec3(grid->worldBBox().min()[0], grid->worldBBox().min()[1], grid->worldBBox().min()[2]), 1e-6);
  Rng rng = Rng::for_sample(1, 2, 3);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p = g.world_lo - Vec3(0.5f) + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (g.world_hi - g.world_lo + Vec3(1.f));
    const float want = sample(grid->worldToIndexF(nanovdb::Vec3f(p.x, p.y, p.z)));
    ASSERT_NEAR(grid_value(v, p), want, 2e-5f * (1.f + want)) << i;
  }
}

// The fuzz seeds: density and temperature, zlib- and Blosc-compressed, as
// NanoVDB's writer makes them.
TEST(NanoVdb, ReadsZipAndBloscCompressedFiles) {
  for (const char* name : {"fire-zip.nvdb", "fire-blosc.nvdb"}) {
    const std::string path = std::string(TESSERA_SOURCE_DIR) + "/tests/fuzz/nvdb_corpus/" + name;
    const NanoVdbGrid d = read_nanovdb_grid(path, "density", true), t = read_nanovdb_grid(path, "temperature", false);
    ASSERT_TRUE(d.found && t.found) << name;
    EXPECT_FLOAT_EQ(d.lattice.max_value, 1.5f) << name;  // 1 + 0.1 x at x = 5, the blob's largest x
    EXPECT_FLOAT_EQ(t.lattice.max_value, 800.f + 50.f * 9.f) << name;
  }
}

TEST(NanoVdb, MissingGridsAreNotFoundAndBadFilesAreRefused) {
  TempDir dir;
  const std::string path = dir.file("blob.nvdb");
  NvdbGridSpec small = blob_spec();  // within one upper node: a file of about 300 kB
  small.voxels = nanovdb::CoordBBox(nanovdb::Coord(0, 0, 0), nanovdb::Coord(20, 9, 3));
  test::write_nvdb(path, {small});
  EXPECT_FALSE(read_nanovdb_grid(path, "temperature", false).found);
  auto message = [](const std::string& p, const std::string& name) -> std::string {
    try {
      read_nanovdb_grid(p, name, true);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message(dir.file("none.nvdb"), "density").find("none.nvdb"), std::string::npos);
  // Truncated: every length of a prefix is refused or finds nothing, never crashes.
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t len : {size_t{0}, size_t{10}, bytes.size() / 3, bytes.size() / 2, bytes.size() - 1}) {
    const std::string cut = dir.write("cut.nvdb", bytes.substr(0, len));
    try {
      EXPECT_FALSE(read_nanovdb_grid(cut, "density", true).found) << len;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("cut.nvdb"), std::string::npos) << e.what();
    }
  }
  // Single flipped bytes (every third of the headers, then a spread): refused
  // with the file's name, or read into a lattice of finite, non-negative values.
  int refused = 0, read = 0;
  for (size_t at = 0; at < bytes.size(); at += at < 1200 ? 3 : at < 4096 ? 16 : 7919) {
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(flipped[at] ^ 0x5a);
    const std::string bad = dir.write("flipped.nvdb", flipped);
    try {
      const NanoVdbGrid g = read_nanovdb_grid(bad, "density", true);
      ++read;
      for (Float v : g.lattice.values) ASSERT_TRUE(std::isfinite(v) && v >= 0.f) << at;
    } catch (const std::runtime_error& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("flipped.nvdb"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(read, 0);
  // Level sets are not media.
  NvdbGridSpec ls = blob_spec();
  ls.grid_class = nanovdb::GridClass::LevelSet;
  const std::string level_set = dir.file("ls.nvdb");
  test::write_nvdb(level_set, {ls});
  EXPECT_NE(message(level_set, "density").find("fog volume"), std::string::npos);
}

// Temperatures may be negative (Celsius) and have a background; densities may not.
TEST(NanoVdb, TemperaturesKeepTheirSignAndBackground) {
  TempDir dir;
  NvdbGridSpec t = blob_spec();
  t.value = [](int x, int, int) { return x < 0 ? -40.f : 0.f; };
  t.background = 20.f;
  const std::string path = dir.file("t.nvdb");
  test::write_nvdb(path, {t});
  const NanoVdbGrid g = read_nanovdb_grid(path, "density", false);
  ASSERT_TRUE(g.found);
  const SparseGridView v = sparse_grid_view(g.lattice);
  EXPECT_EQ(v.background, 20.f);
  EXPECT_EQ(grid_value(v, Vec3(1e4f)), 20.f);  // far outside: the background
  Float lowest = 0.f;
  for (Float x : g.lattice.values) lowest = std::min(lowest, x);
  EXPECT_EQ(lowest, -40.f);
  try {
    read_nanovdb_grid(path, "density", true);
    ADD_FAILURE() << "a density with a background or negative values was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("t.nvdb"), std::string::npos) << e.what();
  }
}

TEST(NanoVdb, MediumReadsDensityTemperatureAndParameters) {
  TempDir dir;
  NvdbGridSpec density = blob_spec();
  NvdbGridSpec temperature = blob_spec();
  temperature.name = "heat";
  temperature.value = [](int x, int, int) { return 1000.f + 10.f * x; };
  test::write_nvdb(dir.file("fire.nvdb"), {density, temperature});
  const std::string medium =
      "MakeNamedMedium \"fire\" \"string type\" \"nanovdb\" \"string filename\" \"fire.nvdb\" "
      "\"string temperaturename\" \"heat\" \"float Lescale\" 2 \"float temperaturecutoff\" 500 "
      "\"float temperaturescale\" 3 \"rgb sigma_a\" [ 1 2 3 ] \"float scale\" 0.5\n";
  SceneDesc d = load_pbrt_string("Camera \"perspective\"\nWorldBegin\n" + medium + "MediumInterface \"fire\" \"\"\n" +
                                     test::kTriangle, dir.file("scene.pbrt"), dir.path());
  ASSERT_EQ(d.grids.size(), 1u);
  ASSERT_EQ(d.media.size(), 1u);
  EXPECT_EQ(d.media[0].grid, 0);
  EXPECT_EQ(d.media[0].grid_emits, 1);
  EXPECT_EQ(d.media[0].sigma_a, Rgb(0.5f, 1.f, 1.5f));
  const GridDesc& g = d.grids[0];
  EXPECT_GT(g.temperature.nx, 0);
  EXPECT_EQ(g.temperature_offset, 500.f);  // "temperaturecutoff" is the older name of "temperatureoffset"
  EXPECT_EQ(g.temperature_scale, 3.f);
  EXPECT_EQ(g.blackbody_scale, 2.f);
  EXPECT_EQ(g.majorants.nx, 64);
  // No temperature grid by that name: not emissive.
  SceneDesc cold = load_pbrt_string("Camera \"perspective\"\nWorldBegin\nMakeNamedMedium \"m\" \"string type\" \"nanovdb\" "
                                    "\"string filename\" \"fire.nvdb\"\nMediumInterface \"m\" \"\"\n" + std::string(test::kTriangle),
                                    dir.file("scene.pbrt"), dir.path());
  EXPECT_EQ(cold.media[0].grid_emits, 0);
  EXPECT_EQ(cold.grids[0].temperature.nx, 0);
  // Errors name the scene file and line.
  const std::string e1 = test::load_error("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"nanovdb\"\n", dir.path());
  EXPECT_NE(e1.find("bad.pbrt:2"), std::string::npos) << e1;
  EXPECT_NE(e1.find("filename"), std::string::npos) << e1;
  const std::string e2 = test::load_error(
      "WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"fire.nvdb\" "
      "\"string gridname\" \"smoke\"\n", dir.path());
  EXPECT_NE(e2.find("bad.pbrt:2"), std::string::npos) << e2;
  EXPECT_NE(e2.find("smoke"), std::string::npos) << e2;
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

// A grid the file does not hold is named once with the directive's file:line
// (not "scene.pbrt:2: scene.pbrt:2: ...").
TEST(NanoVdb, AMissingGridIsOneLocatedError) {
  const std::string nvdb = std::string(TESSERA_SOURCE_DIR) + "/tests/fuzz/nvdb_corpus/fire-zip.nvdb";
  const std::string text = "WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"" + nvdb +
                           "\" \"string gridname\" \"nosuch\"\n";
  try {
    load_pbrt_string(text, "scene.pbrt", ".");
    ADD_FAILURE() << "a missing grid was accepted";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("scene.pbrt:2: ", 0), 0u) << what;
    EXPECT_EQ(what.find("scene.pbrt", 1), std::string::npos) << what;
    EXPECT_NE(what.find("no grid named \"nosuch\""), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace tessera
