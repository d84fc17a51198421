// Grid media rendered: emission from Lescale and temperature grids as
// pbrt-v4 defines it (including the fade of its default 1x1x1 Lescale grid
// towards the box's faces), under RGB and spectral transport, and "nanovdb"
// media against their "uniformgrid" equivalents.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../scene/nanovdb_test_writer.h"
#include "../scene/scene_test_helpers.h"
#include "guided_helpers.h"
#include "media_helpers.h"
#include "scene/rgb_spectrum_fit.h"

namespace tessera {
namespace {

using testing::channel_stats;
using testing::ChannelStats;
using testing::header;
using testing::mean_rgb;
using testing::slab;

std::string repeat(const std::string& v, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += v + " ";
  return s;
}

// An absorbing 4^3 grid of density 1 over [-200, 200]^2 x [-10, 20]: the
// slab (z 2..5, seen head-on) lies where the density is constant.
std::string glowing_grid(const std::string& emission) {
  return "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"integer nx\" 4 \"integer ny\" 4 \"integer nz\" 4 "
         "\"float density\" [ " + repeat("1", 64) + "] \"point3 p0\" [ -200 -200 -10 ] \"point3 p1\" [ 200 200 20 ] "
         "\"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 0 0 0 ] " + emission + "\n";
}

// integral over the slab of sigma_a Le(t) exp(-sigma_a (t - 2)), Le(t) = le_factor(z), midpoint rule.
template <class F>
double slab_glow(F le_factor) {
  const int n = 30000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double z = 2.0 + 3.0 * (i + 0.5) / n;
    sum += 0.5 * le_factor(z) * std::exp(-0.5 * (z - 2.0));
  }
  return sum * 3.0 / n;
}

TEST(GridMedia, LeFadesTowardsTheBoxAsPbrtV4sDefaultLescaleGridDoes) {
  // The default Lescale is a 1x1x1 grid: 1 at the box's centre, trilinear
  // towards 0 half a box beyond it, so 1 - |u - 1/2| per axis (u in [0, 1]).
  const Rgb m = mean_rgb(testing::render_text(header(256, 5) + "WorldBegin\n" +
                                             slab(glowing_grid("\"rgb Le\" [ 1 2 4 ]"))));
  const double glow = slab_glow([](double z) { return 1.0 - std::abs((z + 10.0) / 30.0 - 0.5); });
  EXPECT_NEAR(m.x, 1.0 * glow, 0.01 * glow);
  EXPECT_NEAR(m.y, 2.0 * glow, 0.01 * 2.0 * glow);
  EXPECT_NEAR(m.z, 4.0 * glow, 0.01 * 4.0 * glow);
  // A full Lescale grid (nx * ny * nz values) is constant between its outer voxel centres.
  const Rgb g = mean_rgb(testing::render_text(header(256, 5) + "WorldBegin\n" +
                                             slab(glowing_grid("\"rgb Le\" [ 1 2 4 ] \"float Lescale\" [ " +
                                                               repeat("2", 64) + "]"))));
  const double flat = 2.0 * (1.0 - std::exp(-0.5 * 3.0));
  EXPECT_NEAR(g.x, 1.0 * flat, 0.01 * flat);
  EXPECT_NEAR(g.z, 4.0 * flat, 0.01 * 4.0 * flat);
}

// The film's RGB of B(lambda, T) / B(peak), written out.
Rgb blackbody_relative_rgb(double kelvin) {
  const double c2 = 1.4387769e7, peak = 2.8977721e6 / kelvin;
  const std::array<double, 3> rgb = emission_spectrum_rgb(
      [&](double l) { return std::pow(peak / l, 5) * std::expm1(c2 / (peak * kelvin)) / std::expm1(c2 / (l * kelvin)); });
  return Rgb(static_cast<Float>(std::max(0.0, rgb[0])), static_cast<Float>(std::max(0.0, rgb[1])),
             static_cast<Float>(std::max(0.0, rgb[2])));
}

TEST(GridMedia, TemperatureGridsGlowAsBlackbodiesUnderRgbAndSpectralTransport) {
  // 2000 in the grid, (2000 - 500) * 2 = 3000 K after offset and scale.
  const std::string scene =
      header(256, 5) + "WorldBegin\n" +
      slab(glowing_grid("\"float temperature\" [ " + repeat("2000", 64) + "] \"float temperatureoffset\" 500 "
                        "\"float temperaturescale\" 2 \"float Lescale\" [ " + repeat("1", 64) + "]"));
  const Rgb want = blackbody_relative_rgb(3000.0) * static_cast<Float>(1.0 - std::exp(-0.5 * 3.0));
  ASSERT_GT(want.x, want.z);  // orange
  for (bool spectral : {false, true}) {
    SCOPED_TRACE(spectral ? "spectral transport" : "RGB transport");
    SceneDesc d = load_pbrt_string(scene, "<t>", ".");
    d.spectral = spectral;
    RenderResult r = testing::render_desc(std::move(d), {});
    const ChannelStats s = channel_stats(r.film);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.mean[c], want[c], 0.01 * want[c] + 4.0 * s.se[c]) << "channel " << c;
  }
  // Below 100 K after offset and scale nothing glows.
  const Rgb cold = mean_rgb(testing::render_text(
      header(16, 5) + "WorldBegin\n" +
      slab(glowing_grid("\"float temperature\" [ " + repeat("550", 64) + "] \"float temperatureoffset\" 500"))));
  EXPECT_EQ(cold, Rgb(0.f));
}

// A smooth blob, zero on the outer voxels, as a uniformgrid over p0..p1 and
// as a NanoVDB grid with the same voxel centres: (i + 1/2) h from p0.
constexpr int kN = 12;
constexpr double kP0 = -1.5, kP1 = 1.5;
float blob(int x, int y, int z) {
  if (x <= 0 || y <= 0 || z <= 0 || x >= kN - 1 || y >= kN - 1 || z >= kN - 1) return 0.f;
  const double c = (kN - 1) / 2.0, r2 = ((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c)) / (c * c);
  return r2 < 1.0 ? static_cast<float>(3.0 * (1.0 - r2)) : 0.f;
}

std::string blob_uniformgrid() {
  std::string d;
  for (int z = 0; z < kN; ++z)
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) d += std::to_string(blob(x, y, z)) + " ";
  const std::string n = std::to_string(kN);
  return "\"string type\" \"uniformgrid\" \"integer nx\" " + n + " \"integer ny\" " + n + " \"integer nz\" " + n +
         " \"float density\" [ " + d + "] \"point3 p0\" [ -1.5 -1.5 -1.5 ] \"point3 p1\" [ 1.5 1.5 1.5 ]";
}

void write_blob_nvdb(const std::string& path) {
  test::NvdbGridSpec s;
  s.voxel_size = (kP1 - kP0) / kN;
  s.origin = nanovdb::Vec3d(kP0 + 0.5 * s.voxel_size);
  s.voxels = nanovdb::CoordBBox(nanovdb::Coord(0), nanovdb::Coord(kN - 1));
  s.value = blob;
  // pbrt-v4's nanovdb box is NanoVDB's worldBBox of the active voxels: with
  // the zeros active it is the uniformgrid's box, shifted by half a voxel.
  s.zeros_active = true;
  test::write_nvdb(path, {s});
}

// The blob, moved to z = 4 and lit by a distant light and a dim sky, inside an interface box.
std::string blob_scene(const std::string& medium_type_and_grid, const std::string& coefficients, int spp,
                       int max_depth = 50) {
  return header(spp, max_depth, 40.0) + "WorldBegin\n" +
         "LightSource \"distant\" \"point3 from\" [ 1 2 0 ] \"point3 to\" [ 0 0 4 ] \"rgb L\" [ 2 2 2 ]\n"
         "LightSource \"infinite\" \"rgb L\" [ 0.2 0.3 0.4 ]\n"
         "AttributeBegin\nTranslate 0 0 4\nMakeNamedMedium \"m\" " + medium_type_and_grid + " " + coefficients + "\n" +
         "Material \"interface\"\nMediumInterface \"m\" \"\"\n" +
         testing::box(Vec3(-1.6f), Vec3(1.6f)) + "AttributeEnd\n";
}

TEST(GridMedia, NanoVdbMediaRenderAsTheirUniformGridEquivalents) {
  test::TempDir dir;
  write_blob_nvdb(dir.file("blob.nvdb"));
  const std::string coefficients = "\"rgb sigma_a\" [ 0.2 0.4 0.8 ] \"rgb sigma_s\" [ 1.5 1 0.6 ] \"float g\" 0.3";
  const std::string nvdb = "\"string type\" \"nanovdb\" \"string filename\" \"blob.nvdb\"";
  auto run = [&](const std::string& grid) {
    SceneDesc d = load_pbrt_string(blob_scene(grid, coefficients, 256), dir.file("scene.pbrt"), dir.path());
    return channel_stats(testing::render_desc(std::move(d), {}).film);
  };
  const ChannelStats a = run(blob_uniformgrid()), b = run(nvdb);
  testing::expect_precise(a, 0.01, "uniformgrid blob");
  testing::expect_agree(a, b, "nanovdb against uniformgrid");
  // An albedo-1 furnace through the sparse grid (64^3 majorant cells, most
  // of them empty), strongly chromatic and deep (optical depth up to ~30 in
  // blue): 1 everywhere. (Weighting each collision by its own channel
  // mixture, as before the path-level hero MIS, gave 0.95 in blue here.)
  for (const std::string& grid : {blob_uniformgrid(), nvdb}) {
    std::string furnace = blob_scene(grid, "\"rgb sigma_a\" [ 0 0 0 ] \"rgb sigma_s\" [ 1 2 4 ] \"float g\" 0.5", 512,
                                       100000);
    furnace.replace(furnace.find("LightSource \"distant\""), furnace.find("LightSource \"infinite\"") -
                    furnace.find("LightSource \"distant\""), "");
    furnace.replace(furnace.find("[ 0.2 0.3 0.4 ]"), 15, "[ 1 1 1 ]");
    SceneDesc d = load_pbrt_string(furnace, dir.file("scene.pbrt"), dir.path());
    const ChannelStats f = channel_stats(testing::render_desc(std::move(d), {}).film);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.mean[c], 1.0, 0.01) << grid.substr(0, 30) << " channel " << c;
  }
}

// The blob as an rgbgrid whose voxels are the density times the
// coefficients (and an Le grid the density times Le) has, at every point,
// the coefficients and emission of the uniformgrid blob with a per-voxel
// Lescale grid of the density: both transports give the same image.
TEST(GridMedia, RgbGridsRenderAsTheirUniformGridEquivalents) {
  const Rgb sa(0.2f, 0.4f, 0.8f), ss(1.5f, 1.f, 0.6f), le(0.3f, 0.2f, 0.1f);
  std::string voxels_a, voxels_s, voxels_le, lescale;
  for (int z = 0; z < kN; ++z)
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) {
        const float b = blob(x, y, z);
        auto rgb = [&](const Rgb& c) {
          return std::to_string(b * c.x) + " " + std::to_string(b * c.y) + " " + std::to_string(b * c.z) + " ";
        };
        voxels_a += rgb(sa);
        voxels_s += rgb(ss);
        voxels_le += rgb(le);
        lescale += std::to_string(b) + " ";
      }
  const std::string n = std::to_string(kN);
  const std::string rgbgrid = "\"string type\" \"rgbgrid\" \"integer nx\" " + n + " \"integer ny\" " + n +
                              " \"integer nz\" " + n + " \"point3 p0\" [ -1.5 -1.5 -1.5 ] \"point3 p1\" [ 1.5 1.5 1.5 ] "
                              "\"rgb sigma_a\" [ " + voxels_a + "] \"rgb sigma_s\" [ " + voxels_s + "] \"rgb Le\" [ " +
                              voxels_le + "] \"float scale\" 0.5 \"float Lescale\" 2 \"float g\" 0.3";
  const std::string uniform = blob_uniformgrid() +
                              " \"rgb sigma_a\" [ 0.1 0.2 0.4 ] \"rgb sigma_s\" [ 0.75 0.5 0.3 ] \"rgb Le\" [ 0.6 0.4 0.2 ] "
                              "\"float Lescale\" [ " + lescale + "] \"float g\" 0.3";
  for (bool spectral : {false, true}) {
    SCOPED_TRACE(spectral ? "spectral transport" : "RGB transport");
    auto run = [&](const std::string& medium) {
      SceneDesc d = load_pbrt_string(blob_scene(medium, "", 256), "<t>", ".");
      d.spectral = spectral;
      return channel_stats(testing::render_desc(std::move(d), {}).film);
    };
    const ChannelStats u = run(uniform), r = run(rgbgrid);
    testing::expect_precise(u, 0.01, "uniformgrid blob");
    testing::expect_agree(u, r, "rgbgrid against uniformgrid");
  }
}

// pbrt-v4's cloud in an albedo-1 furnace: 1 everywhere (its density is
// bounded by 1, the one majorant cell).
TEST(GridMedia, CloudFurnaceIsOne) {
  const std::string scene = header(512, 100000, 40.0) + "WorldBegin\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n"
                            "AttributeBegin\nTranslate -0.5 -0.5 1.5\n"
                            "MakeNamedMedium \"m\" \"string type\" \"cloud\" \"rgb sigma_a\" [ 0 0 0 ] "
                            "\"rgb sigma_s\" [ 4 5 6 ] \"float g\" 0.4\n"
                            "Material \"interface\"\nMediumInterface \"m\" \"\"\n" +
                            testing::box(Vec3(0.f), Vec3(1.f)) + "AttributeEnd\n";
  RenderResult r = testing::render_text(scene);
  const ChannelStats f = channel_stats(r.film);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.mean[c], 1.0, 0.01) << "channel " << c;
  EXPECT_GT(r.stats.counters.path.medium_vertices, r.stats.counters.samples / 4);
}

}  // namespace
}  // namespace tessera
