#include "scene/pbrt_media.h"

#include <algorithm>
#include <cmath>

#include "scene/nanovdb_grid.h"
#include "scene/pbrt_paths.h"

namespace tessera {
namespace {

struct MeasuredMedium {
  const char* name;
  Rgb sigma_prime_s, sigma_a;  // mm^-1
};

// Measured reduced scattering and absorption coefficients: Jensen, Marschner,
// Levoy and Hanrahan, "A Practical Model for Subsurface Light Transport"
// (SIGGRAPH 2001), and Narasimhan et al., "Acquiring Scattering Properties of
// Participating Media by Dilution" (SIGGRAPH 2006); the names pbrt-v4 uses.
const MeasuredMedium kPresets[] = {
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.00f, 0.00f, 0.00f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
    {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
    {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
    {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
    {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
    {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
    {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
    {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
    {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
    {"Coke", {8.9053e-05f, 8.372e-05f, 0.f}, {0.10014f, 0.16503f, 0.2468f}},
    {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0.f}, {0.091641f, 0.14158f, 0.20729f}},
    {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
    {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
    {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
    {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
    {"Merlot", {2.1129e-05f, 0.f, 0.f}, {0.11632f, 0.25191f, 0.29434f}},
    {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
    {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0.f}, {0.006164f, 0.013984f, 0.034983f}},
    {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
    {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
    {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
    {"Grape Juice", {5.382e-05f, 0.f, 0.f}, {0.10404f, 0.23958f, 0.29325f}},
    {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
    {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
    {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
    {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
    {"Head & Shoulders Shampoo", {0.023805f, 0.028804f, 0.034306f}, {0.084621f, 0.15688f, 0.20365f}},
    {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
    {"Orange Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
    {"Pink Lemonade Powder", {0.00012103f, 0.00013073f, 0.00012528f}, {0.001165f, 0.002366f, 0.003195f}},
    {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
    {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
    {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
    {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
    {"Pacific Ocean Surface Water", {0.0001764f, 0.00032095f, 0.00019617f}, {0.031845f, 0.031324f, 0.030147f}},
};


// The inverse of the CTM at MakeNamedMedium (pbrt-v4's medium space).
Mat4 medium_from_world_of(const Mat4& world_from_medium, const DirectiveContext& ctx) {
  if (glm::determinant(world_from_medium) == 0.f) ctx.fail("the medium's transform is singular");
  return glm::inverse(world_from_medium);
}

// "nx", "ny", "nz" (pbrt-v4's default 1 each), positive.
void read_dims(const ParamSet& params, const std::string& type, const DirectiveContext& ctx, int32_t* nx, int32_t* ny,
               int32_t* nz) {
  *nx = params.get_int("nx", 1);
  *ny = params.get_int("ny", 1);
  *nz = params.get_int("nz", 1);
  if (*nx < 1 || *ny < 1 || *nz < 1) ctx.fail(type + " \"nx\", \"ny\" and \"nz\" must be positive");
}

// A per-voxel array must have nx*ny*nz values.
void check_count(size_t count, uint64_t n, const std::string& type, const std::string& what,
                 const DirectiveContext& ctx) {
  if (count != n)
    ctx.fail(type + " has " + std::to_string(count) + " " + what + " values; nx*ny*nz = " + std::to_string(n));
}

// "p0" and "p1" (pbrt-v4's defaults 0 0 0 and 1 1 1), p0 below p1.
void read_box(const ParamSet& params, const std::string& type, const DirectiveContext& ctx, Vec3* p0, Vec3* p1) {
  *p0 = params.get_point3("p0").value_or(Vec3(0.f));
  *p1 = params.get_point3("p1").value_or(Vec3(1.f));
  if (!(p1->x > p0->x && p1->y > p0->y && p1->z > p0->z)) ctx.fail(type + " needs p0 < p1 on every axis");
}

// "temperatureoffset" (or its older name "temperaturecutoff") and "temperaturescale".
void read_temperature_mapping(const ParamSet& params, const std::string& type, GridDesc* g,
                              const DirectiveContext& ctx) {
  g->temperature_offset = params.get_float("temperatureoffset", params.get_float("temperaturecutoff", 0.f));
  g->temperature_scale = params.get_float("temperaturescale", 1.f);
  if (!std::isfinite(g->temperature_offset) || !std::isfinite(g->temperature_scale))
    ctx.fail(type + " \"temperatureoffset\" and \"temperaturescale\" must be finite");
}

// pbrt-v4's GridMedium emission: an "Lescale" grid (nx * ny * nz values, or
// one; pbrt-v4's default is a 1x1x1 grid of 1, which, read like any grid
// with zeros beyond its one voxel centre, fades Le to 1/2 at the box's faces
// and 1/8 at its corners) times Le, or a blackbody of the "temperature" grid.
void read_grid_emission(const ParamSet& params, const Mat4& medium_from_world, const Vec3& p0, const Vec3& p1,
                        int32_t nx, int32_t ny, int32_t nz, Medium* m, GridDesc* g, const DirectiveContext& ctx) {
  const std::vector<Float> temperature = params.get_floats("temperature");
  const uint64_t n = static_cast<uint64_t>(nx) * static_cast<uint64_t>(ny) * static_cast<uint64_t>(nz);
  if (!temperature.empty()) {
    if (params.find_any("Le")) ctx.fail("uniformgrid: \"Le\" and \"temperature\" cannot both be given (as in pbrt-v4)");
    check_count(temperature.size(), n, "uniformgrid", "temperature", ctx);
    for (Float t : temperature)
      if (!std::isfinite(t)) ctx.fail("uniformgrid temperatures must be finite");
    g->temperature = sparse_grid_from_dense(temperature, nx, ny, nz, p0, p1, medium_from_world);
    read_temperature_mapping(params, "uniformgrid", g, ctx);
    m->grid_emits = 1;
  }
  if (!m->grid_emits && is_black(m->Le)) {
    params.find_any("Lescale");
    return;
  }
  std::vector<Float> le_scale = params.get_floats("Lescale");
  int32_t sx = nx, sy = ny, sz = nz;
  if (le_scale.empty()) le_scale = {1.f};
  if (le_scale.size() == 1) {
    sx = sy = sz = 1;
  } else {
    check_count(le_scale.size(), n, "uniformgrid", "\"Lescale\"", ctx);
  }
  for (Float v : le_scale)
    if (!(v >= 0.f) || !std::isfinite(v)) ctx.fail("uniformgrid \"Lescale\" values must be finite and not negative");
  g->le_scale = sparse_grid_from_dense(le_scale, sx, sy, sz, p0, p1, medium_from_world);
  m->grid_emits = 1;
}

// pbrt-v4's GridMedium: "density" (nx * ny * nz floats, x fastest) over
// the box p0..p1 of the medium's space, with a 16^3 majorant grid as pbrt-v4 builds.
int32_t read_uniform_grid(const ParamSet& params, const Mat4& world_from_medium, Medium* m,
                          const DirectiveContext& ctx) {
  const std::vector<Float> density = params.get_floats("density");
  if (density.empty()) ctx.fail("uniformgrid medium needs \"float density\" values");
  int32_t nx, ny, nz;
  read_dims(params, "uniformgrid", ctx, &nx, &ny, &nz);
  const uint64_t n = static_cast<uint64_t>(nx) * static_cast<uint64_t>(ny) * static_cast<uint64_t>(nz);
  check_count(density.size(), n, "uniformgrid", "density", ctx);
  for (Float d : density)
    if (!(d >= 0.f) || !std::isfinite(d)) ctx.fail("uniformgrid densities must be finite and not negative");
  Vec3 p0, p1;
  read_box(params, "uniformgrid", ctx, &p0, &p1);
  const Mat4 medium_from_world = medium_from_world_of(world_from_medium, ctx);
  GridDesc g;
  g.density = sparse_grid_from_dense(density, nx, ny, nz, p0, p1, medium_from_world);
  // The box p0..p1 in lattice coordinates: voxel centres are the integers.
  const Vec3 n3(static_cast<Float>(nx), static_cast<Float>(ny), static_cast<Float>(nz));
  g.majorants = build_majorant_grid(g.density, Vec3(-0.5f), n3 - 0.5f, 16);
  read_grid_emission(params, medium_from_world, p0, p1, nx, ny, nz, m, &g, ctx);
  ctx.scene.grids.push_back(std::move(g));
  return static_cast<int32_t>(ctx.scene.grids.size() - 1);
}

// pbrt-v4's CloudMedium: a procedural density (kernels/grid_medium.h) over
// the box p0..p1 of the medium's space, bounded by 1 (one majorant cell).
int32_t read_cloud(const ParamSet& params, const Mat4& world_from_medium, const DirectiveContext& ctx) {
  GridDesc g;
  g.cloud = 1;
  g.cloud_density = params.get_float("density", 1.f);
  g.cloud_wispiness = params.get_float("wispiness", 1.f);
  g.cloud_frequency = params.get_float("frequency", 5.f);
  if (!(g.cloud_density >= 0.f) || !std::isfinite(g.cloud_density) || !std::isfinite(g.cloud_wispiness) ||
      !std::isfinite(g.cloud_frequency))
    ctx.fail("cloud \"density\" must be finite and not negative, \"wispiness\" and \"frequency\" finite");
  Vec3 p0, p1;
  read_box(params, "cloud", ctx, &p0, &p1);
  g.density.lattice_from_world = medium_from_world_of(world_from_medium, ctx);
  g.majorants.lo = p0;
  g.majorants.hi = p1;
  g.majorants.max_density = {1.f};
  ctx.scene.grids.push_back(std::move(g));
  return static_cast<int32_t>(ctx.scene.grids.size() - 1);
}

// pbrt-v4's RGBGridMedium: "sigma_a", "sigma_s" and "Le" as nx*ny*nz RGB
// values at the voxel centres of p0..p1 (as uniformgrid), sigma_a and
// sigma_s scaled by "scale" (either missing: 1), Le by "Lescale" (Le needs
// sigma_a, as in pbrt-v4). The majorant cells bound the extinction of any
// wavelength: an RGB's spectrum stays below twice its largest component.
int32_t read_rgb_grid(const ParamSet& params, const Mat4& world_from_medium, Medium* m, const DirectiveContext& ctx) {
  int32_t nx, ny, nz;
  read_dims(params, "rgbgrid", ctx, &nx, &ny, &nz);
  const uint64_t n = static_cast<uint64_t>(nx) * static_cast<uint64_t>(ny) * static_cast<uint64_t>(nz);
  const std::vector<Rgb> sigma_a = params.get_rgbs("sigma_a"), sigma_s = params.get_rgbs("sigma_s"),
                         le = params.get_rgbs("Le");
  if (sigma_a.empty() && sigma_s.empty()) ctx.fail("rgbgrid needs \"rgb sigma_a\" or \"rgb sigma_s\" values");
  if (!le.empty() && sigma_a.empty()) ctx.fail("rgbgrid needs \"sigma_a\" where \"Le\" is given (as in pbrt-v4)");
  const std::pair<const char*, const std::vector<Rgb>*> grids[3] = {{"sigma_a", &sigma_a}, {"sigma_s", &sigma_s}, {"Le", &le}};
  for (const auto& [name, values] : grids) {
    if (values->empty()) continue;
    check_count(values->size(), n, "rgbgrid", std::string("\"") + name + "\"", ctx);
    for (const Rgb& v : *values)
      if (!valid_coefficient(v)) ctx.fail(std::string("rgbgrid \"") + name + "\" values must be finite and not negative");
  }
  Vec3 p0, p1;
  read_box(params, "rgbgrid", ctx, &p0, &p1);
  const Float scale = params.get_float("scale", 1.f), le_scale = params.get_float("Lescale", 1.f);
  if (!(scale >= 0.f) || !std::isfinite(scale) || !(le_scale >= 0.f) || !std::isfinite(le_scale))
    ctx.fail("rgbgrid \"scale\" and \"Lescale\" must be finite and not negative");
  const Mat4 medium_from_world = medium_from_world_of(world_from_medium, ctx);
  GridDesc g;
  g.rgb = 1;
  g.rgb_scale = scale;
  g.rgb_le_scale = le_scale;
  SparseGridDesc* targets[3] = {g.rgb_sigma_a, g.rgb_sigma_s, g.rgb_le};
  std::vector<Float> channel(n), bound(n);
  MajorantGridDesc bounds[2];
  const Vec3 n3(static_cast<Float>(nx), static_cast<Float>(ny), static_cast<Float>(nz));
  for (int k = 0; k < 3; ++k) {
    const std::vector<Rgb>& values = *grids[k].second;
    if (values.empty()) continue;
    for (int c = 0; c < 3; ++c) {
      for (uint64_t i = 0; i < n; ++i) channel[i] = values[i][c];
      targets[k][c] = sparse_grid_from_dense(channel, nx, ny, nz, p0, p1, medium_from_world);
    }
    if (k == 2) break;
    for (uint64_t i = 0; i < n; ++i) bound[i] = 2.f * max_component(values[i]);
    bounds[k] = build_majorant_grid(sparse_grid_from_dense(bound, nx, ny, nz, p0, p1, medium_from_world),
                                    Vec3(-0.5f), n3 - 0.5f, 16);
  }
  // The lattice coordinates (voxel centres at the integers) without values.
  g.density.lattice_from_world = targets[sigma_a.empty() ? 1 : 0][0].lattice_from_world;
  g.majorants.lo = Vec3(-0.5f);
  g.majorants.hi = n3 - 0.5f;
  g.majorants.nx = g.majorants.ny = g.majorants.nz = 16;
  g.majorants.max_density.assign(16 * 16 * 16, 0.f);
  for (size_t i = 0; i < g.majorants.max_density.size(); ++i)
    g.majorants.max_density[i] = scale * ((sigma_a.empty() ? 1.f : bounds[0].max_density[i]) +
                                          (sigma_s.empty() ? 1.f : bounds[1].max_density[i]));
  // The medium's own coefficients only say whether it scatters and glows.
  Float max_a = sigma_a.empty() ? 1.f : 0.f, max_s = sigma_s.empty() ? 1.f : 0.f;
  for (const Rgb& v : sigma_a) max_a = std::max(max_a, max_component(v));
  for (const Rgb& v : sigma_s) max_s = std::max(max_s, max_component(v));
  m->sigma_a = Rgb(scale * max_a);
  m->sigma_s = Rgb(scale * max_s);
  m->Le = Rgb(0.f);
  m->grid_emits = !le.empty() && le_scale > 0.f;
  ctx.scene.grids.push_back(std::move(g));
  return static_cast<int32_t>(ctx.scene.grids.size() - 1);
}

// pbrt-v4's NanoVDBMedium: the float grids "density" (gridname) and,
// optionally, "temperature" (temperaturename) of a .nvdb file, whose world
// space is the medium's; the box is their worldBBox, with a 64^3 majorant grid.
int32_t read_nanovdb(const ParamSet& params, const Mat4& world_from_medium, Medium* m, const DirectiveContext& ctx) {
  const std::string filename = params.get_string("filename", "");
  if (filename.empty()) ctx.fail("nanovdb medium needs \"string filename\"");
  const std::string path = resolve_scene_path(filename, ctx.including_dir, ctx.search_dir);
  ctx.scene.files_read.push_back(path);
  const std::string density_name = params.get_string("gridname", "density");
  const std::string temperature_name = params.get_string("temperaturename", "temperature");
  const Mat4 medium_from_world = medium_from_world_of(world_from_medium, ctx);
  const Float le_scale = params.get_float("Lescale", 1.f);
  if (!(le_scale >= 0.f) || !std::isfinite(le_scale)) ctx.fail("nanovdb \"Lescale\" must be finite and not negative");
  NanoVdbGrid density, temperature;
  try {
    density = read_nanovdb_grid(path, density_name, true);
    if (!density.found) ctx.fail(path + ": no grid named \"" + density_name + "\"");
    // (As in pbrt-v4, a medium whose Lescale is 0 does not glow; its temperatures are not read.)
    if (le_scale > 0.f) temperature = read_nanovdb_grid(path, temperature_name, false);
  } catch (const SceneError&) {
    throw;  // located already (ctx.fail above): not a second "file:line: " prefix
  } catch (const std::runtime_error& e) {
    ctx.fail(e.what());
  } catch (const std::bad_alloc&) {
    ctx.fail(path + ": its grids do not fit in memory");
  }
  GridDesc g;
  Vec3 world_lo = density.world_lo, world_hi = density.world_hi;
  if (temperature.found) {
    world_lo = glm::min(world_lo, temperature.world_lo);
    world_hi = glm::max(world_hi, temperature.world_hi);
  }
  // The box in density lattice coordinates (its corners' bounds: the same box for axis-aligned grids).
  Vec3 lo(kInfinity), hi(-kInfinity);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? world_hi.x : world_lo.x, (c & 2) ? world_hi.y : world_lo.y,
                      (c & 4) ? world_hi.z : world_lo.z);
    const Vec3 q = Vec3(density.lattice.lattice_from_world * Vec4(corner, 1.f));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  g.density = std::move(density.lattice);
  g.density.lattice_from_world = g.density.lattice_from_world * medium_from_world;
  if (hi.x > lo.x && hi.y > lo.y && hi.z > lo.z) {
    g.majorants = build_majorant_grid(g.density, lo, hi, 64);
  } else {
    g.majorants.max_density = {0.f};  // an empty grid: no collision anywhere
  }
  read_temperature_mapping(params, "nanovdb", &g, ctx);
  if (temperature.found) {  // (read only where Lescale > 0)
    g.temperature = std::move(temperature.lattice);
    g.temperature.lattice_from_world = g.temperature.lattice_from_world * medium_from_world;
    g.blackbody_scale = le_scale;
    m->grid_emits = 1;
  }
  ctx.scene.grids.push_back(std::move(g));
  return static_cast<int32_t>(ctx.scene.grids.size() - 1);
}

}  // namespace

bool valid_coefficient(const Rgb& c) {
  for (int i = 0; i < 3; ++i)
    if (!(c[i] >= 0.f) || !std::isfinite(c[i])) return false;
  return true;
}

bool medium_preset(const std::string& name, Rgb* sigma_a, Rgb* sigma_s) {
  for (const MeasuredMedium& m : kPresets) {
    if (name == m.name) {
      *sigma_a = m.sigma_a;
      *sigma_s = m.sigma_prime_s;
      return true;
    }
  }
  return false;
}

Medium make_medium(const std::string& type, const ParamSet& params, const Mat4& world_from_medium,
                                  const DirectiveContext& ctx) {
  if (type != "homogeneous" && type != "uniformgrid" && type != "nanovdb" && type != "cloud" && type != "rgbgrid")
    ctx.fail("unknown medium type \"" + type + "\"");
  Medium m;
  m.g = params.get_float("g", 0.f);
  if (!std::isfinite(m.g)) ctx.fail("medium \"g\" must be finite");
  m.g = std::clamp(m.g, -0.99f, 0.99f);  // pbrt-v4 clamps too: |g| = 1 is a delta
  if (type == "rgbgrid") {
    m.grid = read_rgb_grid(params, world_from_medium, &m, ctx);
    return m;
  }
  Rgb sigma_a(1.f), sigma_s(1.f);  // pbrt-v4's defaults
  bool preset_found = false;
  // pbrt-v4 reads "preset" for homogeneous media only, "Le" for homogeneous
  // and uniformgrid, and has no "scale" for clouds: elsewhere they are
  // unused parameters (warned).
  const std::string preset = type == "homogeneous" ? params.get_string("preset", "") : "";
  if (!preset.empty()) {
    preset_found = medium_preset(preset, &sigma_a, &sigma_s);
    if (!preset_found) ctx.warn("medium preset \"" + preset + "\" not found (as in pbrt-v4, sigma_a/sigma_s are used)");
  }
  if (!preset_found) {
    sigma_a = params.get_rgb("sigma_a").value_or(Rgb(1.f));
    sigma_s = params.get_rgb("sigma_s").value_or(Rgb(1.f));
  } else {
    params.find_any("sigma_a");
    params.find_any("sigma_s");
  }
  const Float scale = type == "cloud" ? 1.f : params.get_float("scale", 1.f);
  if (!(scale >= 0.f) || !std::isfinite(scale)) ctx.fail("medium \"scale\" must be finite and not negative");
  m.sigma_a = sigma_a * scale;
  m.sigma_s = sigma_s * scale;
  if (!valid_coefficient(m.sigma_a) || !valid_coefficient(m.sigma_s))
    ctx.fail("medium sigma_a and sigma_s must be finite and not negative");
  // A homogeneous medium's one "Lescale" scales Le (uniformgrid reads its as a grid).
  if (type == "homogeneous" || type == "uniformgrid") m.Le = params.get_rgb("Le").value_or(Rgb(0.f));
  if (type == "homogeneous") m.Le *= params.get_float("Lescale", 1.f);
  if (!valid_coefficient(m.Le)) ctx.fail("medium \"Le\" must be finite and not negative");
  if (type == "uniformgrid") m.grid = read_uniform_grid(params, world_from_medium, &m, ctx);
  if (type == "nanovdb") m.grid = read_nanovdb(params, world_from_medium, &m, ctx);
  if (type == "cloud") m.grid = read_cloud(params, world_from_medium, ctx);
  return m;
}

}  // namespace tessera
