#include "scene/spectral_choice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>
#include <vector>

#include "kernels/rng.h"
#include "kernels/spectral.h"
#include "kernels/vecmath.h"
#include "scene/named_spectra.h"
#include "scene/spectral_tables.h"

namespace tessera {
namespace {

bool strongly_coloured(Rgb c) {
  const Float hi = max_component(c), lo = std::min({c.x, c.y, c.z});
  return hi > 0.f && lo < 0.5f * hi;
}

// --- rule (d): multi-bounce colour shift (see multibounce_colour_shift) ---

using Spectrum = std::array<double, kSpectralSamples>;  // at 360 + 5 i nm

// A reflectance's colours over its surface: (RGB, share of the surface).
using Colours = std::vector<std::pair<Rgb, double>>;

constexpr size_t kMaxTexels = 4096;
constexpr int kMaxTextureDepth = 8;

std::optional<Colours> slot_colours(const SceneDesc& s, const TextureSlot& slot, int depth);

std::optional<Colours> texture_colours(const SceneDesc& s, const Texture& t, int depth) {
  auto join = [](Colours a, const Colours& b, double wa, double wb) {
    for (auto& [c, w] : a) w *= wa;
    for (const auto& [c, w] : b) a.emplace_back(c, w * wb);
    return a;
  };
  switch (t.type) {
    case TextureType::Constant:
      return Colours{{t.value, 1.0}};
    case TextureType::Image: {
      if (t.image < 0 || static_cast<size_t>(t.image) >= s.images.size()) return std::nullopt;
      const std::vector<Rgb>& texels = s.images[static_cast<size_t>(t.image)].texels;
      if (texels.empty()) return std::nullopt;
      const size_t step = std::max<size_t>(1, texels.size() / kMaxTexels);
      Colours out;
      for (size_t i = 0; i < texels.size(); i += step) {
        const Rgb v = texels[i] * t.scale;
        out.emplace_back(t.invert ? glm::max(Rgb(0.f), Rgb(1.f) - v) : v, 1.0);
      }
      return out;
    }
    case TextureType::Scale: {  // a * b: one side must be constant
      const auto a = slot_colours(s, t.a, depth + 1), b = slot_colours(s, t.b, depth + 1);
      if (!a || !b) return std::nullopt;
      const Colours* var = a->size() == 1 ? &*b : &*a;
      const Colours* con = a->size() == 1 ? &*a : &*b;
      if (con->size() != 1) return std::nullopt;
      Colours out = *var;
      for (auto& [c, w] : out) c *= con->front().first;
      return out;
    }
    case TextureType::Mix: {
      const auto a = slot_colours(s, t.a, depth + 1), b = slot_colours(s, t.b, depth + 1);
      if (!a || !b || t.amount.texture >= 0) return std::nullopt;
      const double amt = std::clamp(static_cast<double>(t.amount.value.x), 0.0, 1.0);
      if (a->size() == 1 && b->size() == 1)  // one colour everywhere: the blend itself
        return Colours{{(1.f - t.amount.value.x) * a->front().first + t.amount.value.x * b->front().first, 1.0}};
      return join(*a, *b, 1.0 - amt, amt);
    }
    case TextureType::Checkerboard:
    case TextureType::Dots:
    case TextureType::DirectionMix: {  // about half the surface each
      const auto a = slot_colours(s, t.a, depth + 1), b = slot_colours(s, t.b, depth + 1);
      if (!a || !b) return std::nullopt;
      return join(*a, *b, 0.5, 0.5);
    }
    case TextureType::Bilerp:
      return Colours{{t.corners[0], 0.25}, {t.corners[1], 0.25}, {t.corners[2], 0.25}, {t.corners[3], 0.25}};
    default:  // noise textures: their colours are not known without evaluating them
      return std::nullopt;
  }
}

std::optional<Colours> slot_colours(const SceneDesc& s, const TextureSlot& slot, int depth) {
  if (slot.texture < 0) return Colours{{slot.value, 1.0}};
  if (depth > kMaxTextureDepth || static_cast<size_t>(slot.texture) >= s.textures.size()) return std::nullopt;
  return texture_colours(s, s.textures[static_cast<size_t>(slot.texture)], depth);
}

// The reflectance a diffuse-family material bounces light with, or nullopt
// for materials this model leaves out.
std::optional<Colours> material_colours(const SceneDesc& s, const Material& m) {
  switch (m.type) {
    case MaterialType::Diffuse:
    case MaterialType::CoatedDiffuse:
      return slot_colours(s, m.reflectance, 0);
    case MaterialType::DiffuseTransmission: {  // light leaves by either side: their sum
      const auto r = slot_colours(s, m.reflectance, 0), t = slot_colours(s, m.transmittance, 0);
      if (!r || !t || t->size() != 1) return std::nullopt;
      Colours out = *r;
      for (auto& [c, w] : out) c += t->front().first;
      return out;
    }
    default:
      return std::nullopt;
  }
}

glm::dvec3 corner(const MeshDesc& m, size_t tri, int v) { return glm::dvec3(m.p[m.indices[3 * tri + v]]); }

// Triangle tri's area, 0 where it is not finite.
double triangle_area(const MeshDesc& m, size_t tri) {
  const glm::dvec3 p0 = corner(m, tri, 0);
  const double a = 0.5 * glm::length(glm::cross(corner(m, tri, 1) - p0, corner(m, tri, 2) - p0));
  return std::isfinite(a) ? a : 0.0;
}

double mesh_area(const MeshDesc& m) {
  double a = 0.0;
  for (size_t t = 0; t < m.indices.size() / 3; ++t) a += triangle_area(m, t);
  return a;
}

// Each material's share of the scene's surface area (instances included,
// their area scaled by their transform's mean area scale).
std::vector<double> material_areas(const SceneDesc& s) {
  std::vector<double> area(s.materials.size(), 0.0);
  auto add = [&](const MeshDesc& m, double scale) {
    if (m.material >= 0 && static_cast<size_t>(m.material) < area.size())
      area[static_cast<size_t>(m.material)] += scale * mesh_area(m);
  };
  for (const MeshDesc& m : s.meshes) add(m, 1.0);
  for (const InstanceDesc& inst : s.instances) {
    if (inst.object >= s.objects.size()) continue;
    const double det = std::abs(glm::determinant(glm::dmat3(glm::dmat4(inst.render_from_object))));
    const double scale = std::isfinite(det) ? std::cbrt(det * det) : 0.0;
    for (const MeshDesc& m : s.objects[inst.object].meshes) add(m, scale);
  }
  return area;
}

Spectrum reflectance_spectrum(const SpectralView& v, Rgb rgb) {
  rgb = glm::clamp(rgb, Rgb(0.f), Rgb(1.f));
  Spectrum out{};
  if (!(rgb.x == rgb.x && rgb.y == rgb.y && rgb.z == rgb.z)) return out;
  const Vec3 c = rgb_sigmoid_coefficients(v, rgb);
  for (int i = 0; i < kSpectralSamples; ++i) {
    const double l = kLambdaMin + 5.0 * i;
    out[static_cast<size_t>(i)] = sigmoid(static_cast<Float>((c.x * l + c.y) * l + c.z));
  }
  return out;
}

// Linear sRGB of D65 light (luminance 1) reflected by spectrum r: what the
// film records of it.
glm::dvec3 rgb_under_d65(const SpectralTables& t, const Spectrum& r) {
  glm::dvec3 xyz(0.0);
  double y_white = 0.0;
  for (size_t i = 0; i < r.size(); ++i) {
    const double e = t.illuminant[i];
    xyz += e * r[i] * glm::dvec3(t.cmf[i * 3], t.cmf[i * 3 + 1], t.cmf[i * 3 + 2]);
    y_white += e * t.cmf[i * 3 + 1];
  }
  return glm::dmat3(t.rgb_from_xyz) * (xyz / y_white);
}

// Where light leaving a diffuse surface lands next: rays from points spread
// over the diffuse surfaces by area, cosine-distributed on the side that sees
// more of the scene (diffuse surfaces reflect on both sides), against every
// triangle of the scene's meshes (instanced geometry is not tested). A ray
// that leaves the scene lands nowhere, so an open scene (a floor under the
// sky) has few later bounces and a closed room many.
struct Landing {
  std::vector<double> share;  // per material: the share of rays landing on its diffuse surfaces
  double neutral = 0.0;       // share landing on other materials (glass, metal): colourless here
};

// splitmix64: a counter through the finaliser (kernels/rng.h), in [0, 1).
struct Splitmix {
  uint64_t x;
  double next() { return static_cast<double>(mix_bits(x += 0x9e3779b97f4a7c15ull) >> 11) * 0x1.0p-53; }
};

constexpr int kLandingPoints = 128, kLandingRaysPerSide = 4;

Landing landing_shares(const SceneDesc& s, const std::vector<char>& diffuse) {
  Landing out;
  out.share.assign(s.materials.size(), 0.0);
  auto is_diffuse = [&](int32_t m) { return m >= 0 && static_cast<size_t>(m) < diffuse.size() && diffuse[m]; };
  // Runs of up to kChunk consecutive triangles of one mesh (neighbours in
  // most meshes), each in a box: a ray tests a run's triangles only when it
  // enters the box. Nothing per triangle is stored (meshes can be huge).
  constexpr uint32_t kChunk = 32;
  struct Run {
    uint32_t mesh, first, count;  // triangles first..first+count-1 of s.meshes[mesh]
    glm::dvec3 lo, hi;
    double diffuse_area;  // cumulative over the runs, for picking start points
  };
  std::vector<Run> runs;
  double acc = 0.0;
  for (size_t mi = 0; mi < s.meshes.size(); ++mi) {
    const MeshDesc& m = s.meshes[mi];
    const size_t n = m.indices.size() / 3;
    for (size_t first = 0; first < n; first += kChunk) {
      Run r{static_cast<uint32_t>(mi), static_cast<uint32_t>(first),
            static_cast<uint32_t>(std::min<size_t>(kChunk, n - first)), glm::dvec3(INFINITY), glm::dvec3(-INFINITY), 0.0};
      for (size_t t = first; t < first + r.count; ++t) {
        const glm::dvec3 p0 = corner(m, t, 0), p1 = corner(m, t, 1), p2 = corner(m, t, 2);
        r.lo = glm::min(r.lo, glm::min(p0, glm::min(p1, p2)));
        r.hi = glm::max(r.hi, glm::max(p0, glm::max(p1, p2)));
        if (is_diffuse(m.material)) acc += triangle_area(m, t);
      }
      r.diffuse_area = acc;
      runs.push_back(r);
    }
  }
  if (!(acc > 0.0)) return out;
  struct Hit {
    uint32_t mesh = 0;
    size_t tri = 0;
    bool found = false;
  };
  // The nearest hit along o + t d, t > eps, other than triangle `self`.
  auto hit = [&](const glm::dvec3& o, const glm::dvec3& d, uint32_t self_mesh, size_t self_tri) {
    double best = INFINITY;
    Hit h;
    const glm::dvec3 inv_d = 1.0 / d;
    for (const Run& r : runs) {
      const glm::dvec3 t0 = (r.lo - o) * inv_d, t1 = (r.hi - o) * inv_d;
      const glm::dvec3 tn = glm::min(t0, t1), tf = glm::max(t0, t1);
      const double enter = std::max({tn.x, tn.y, tn.z}), leave = std::min({tf.x, tf.y, tf.z});
      // NaN (a flat box along an axis the ray runs in): test the run.
      if (enter > leave * (1.0 + 1e-9) + 1e-9 || leave < 0.0 || enter > best) continue;
      const MeshDesc& m = s.meshes[r.mesh];
      for (size_t t = r.first; t < r.first + r.count; ++t) {
        if (r.mesh == self_mesh && t == self_tri) continue;
        const glm::dvec3 p0 = corner(m, t, 0), e1 = corner(m, t, 1) - p0, e2 = corner(m, t, 2) - p0;
        const glm::dvec3 pv = glm::cross(d, e2);
        const double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-300) continue;
        const double inv = 1.0 / det;
        const glm::dvec3 tv = o - p0;
        const double u = glm::dot(tv, pv) * inv;
        if (u < 0.0 || u > 1.0) continue;
        const glm::dvec3 qv = glm::cross(tv, e1);
        const double v = glm::dot(d, qv) * inv;
        if (v < 0.0 || u + v > 1.0) continue;
        const double dist = glm::dot(e2, qv) * inv;
        if (dist > 1e-9 && dist < best) best = dist, h = Hit{r.mesh, t, true};
      }
    }
    return h;
  };
  Splitmix rng{0x5eed5eedull};
  double rays = 0.0;
  std::vector<Hit> side_hits[2];
  for (int p = 0; p < kLandingPoints; ++p) {
    // A start point: a run by its diffuse area, then a triangle in it by area.
    const double x = rng.next() * acc;
    const size_t ri = static_cast<size_t>(
        std::upper_bound(runs.begin(), runs.end(), x, [](double v, const Run& r) { return v < r.diffuse_area; }) -
        runs.begin());
    if (ri >= runs.size()) continue;
    const Run& r = runs[ri];
    const MeshDesc& m = s.meshes[r.mesh];
    double y = x - (ri > 0 ? runs[ri - 1].diffuse_area : 0.0);
    size_t tri = r.first;
    for (size_t t = r.first; t < r.first + r.count; ++t) {
      tri = t;
      if ((y -= triangle_area(m, t)) <= 0.0) break;
    }
    const glm::dvec3 p0 = corner(m, tri, 0), e1 = corner(m, tri, 1) - p0, e2 = corner(m, tri, 2) - p0;
    double b1 = rng.next(), b2 = rng.next();
    if (b1 + b2 > 1.0) b1 = 1.0 - b1, b2 = 1.0 - b2;
    const glm::dvec3 o = p0 + b1 * e1 + b2 * e2;
    const glm::dvec3 n = glm::normalize(glm::cross(e1, e2));
    if (!(n == n)) continue;
    const glm::dvec3 a = std::abs(n.x) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(a, n)), v = glm::cross(n, u);
    int counts[2] = {0, 0};
    for (int side = 0; side < 2; ++side) {
      side_hits[side].clear();
      for (int k = 0; k < kLandingRaysPerSide; ++k) {
        const double r1 = rng.next(), phi = 2.0 * M_PI * rng.next();
        const double sr = std::sqrt(r1), z = std::sqrt(std::max(0.0, 1.0 - r1));
        const glm::dvec3 d = sr * std::cos(phi) * u + sr * std::sin(phi) * v + (side ? -z : z) * n;
        side_hits[side].push_back(hit(o, d, r.mesh, tri));
        counts[side] += side_hits[side].back().found;
      }
    }
    for (const Hit& h : side_hits[counts[1] > counts[0] ? 1 : 0]) {
      rays += 1.0;
      if (!h.found) continue;
      const int32_t mat = s.meshes[h.mesh].material;
      if (is_diffuse(mat)) out.share[static_cast<size_t>(mat)] += 1.0;
      else out.neutral += 1.0;
    }
  }
  if (!(rays > 0.0)) return out;
  for (double& x : out.share) x /= rays;
  out.neutral /= rays;
  return out;
}

// shift_c over `bounces` bounces: the first off F (RGB f), the later ones off
// N (RGB n) (see multibounce_colour_shift).
Rgb bounce_shift(const SpectralTables& tables, const Spectrum& first, const glm::dvec3& first_rgb, const Spectrum& next,
                 const glm::dvec3& next_rgb, int bounces) {
  glm::dvec3 sum_rgb(0.0), sum_spectral(0.0), rgb_power = first_rgb;
  Spectrum power = first;
  for (int j = 1; j <= bounces; ++j) {
    sum_rgb += rgb_power;
    sum_spectral += rgb_under_d65(tables, power);
    rgb_power *= next_rgb;
    for (size_t k = 0; k < power.size(); ++k) power[k] *= next[k];
  }
  const double floor = 0.05 * std::max({sum_rgb.x, sum_rgb.y, sum_rgb.z});
  if (!(floor > 0.0)) return Rgb(0.f);
  return Rgb(glm::abs(sum_spectral - sum_rgb) / glm::max(sum_rgb, glm::dvec3(floor)));
}

}  // namespace

Rgb multibounce_colour_shift(const SceneDesc& s) {
  const SpectralTables& tables = srgb_spectral_tables();
  const SpectralView view = tables.view();
  const std::vector<double> area = material_areas(s);
  // Each diffuse-family material's mean reflectance spectrum and RGB.
  std::vector<Spectrum> spectrum(s.materials.size());
  std::vector<glm::dvec3> rgb(s.materials.size(), glm::dvec3(0.0));
  std::vector<char> diffuse(s.materials.size(), 0);
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const std::optional<Colours> colours = material_colours(s, s.materials[i]);
    double weights = 0.0;
    if (colours)
      for (const auto& [c, w] : *colours) weights += w;
    if (!(weights > 0.0)) continue;
    diffuse[i] = 1;
    spectrum[i].fill(0.0);
    for (const auto& [c, w] : *colours) {
      const Spectrum r = reflectance_spectrum(view, c);
      for (size_t k = 0; k < r.size(); ++k) spectrum[i][k] += w / weights * r[k];
      rgb[i] += w / weights * glm::dvec3(glm::clamp(c, Rgb(0.f), Rgb(1.f)));
    }
  }
  // The first bounce: a diffuse surface by its share of their area.
  Spectrum first{};
  glm::dvec3 first_rgb(0.0);
  double total = 0.0;
  for (size_t i = 0; i < s.materials.size(); ++i) {
    if (!diffuse[i] || !(area[i] > 0.0)) continue;
    for (size_t k = 0; k < first.size(); ++k) first[k] += area[i] * spectrum[i][k];
    first_rgb += area[i] * rgb[i];
    total += area[i];
  }
  if (!(total > 0.0)) return Rgb(0.f);
  for (double& x : first) x /= total;
  first_rgb /= total;
  // The later bounces: where light leaving a diffuse surface lands next.
  // Rays are cast only where a closed room of these surfaces, every bounce
  // landing by area, would shift by a quarter of the threshold: grey scenes,
  // however large, cost no rays.
  const int bounces = s.max_depth < 0 ? 100 : std::clamp(s.max_depth, 1, 100);
  const Rgb closed = bounce_shift(tables, first, first_rgb, first, first_rgb, bounces);
  if (max_component(closed) < 0.25f * kMultibounceShiftThreshold) return closed;
  const Landing landing = landing_shares(s, diffuse);
  Spectrum next{};
  glm::dvec3 next_rgb(landing.neutral);
  next.fill(landing.neutral);
  for (size_t i = 0; i < s.materials.size(); ++i) {
    if (!(landing.share[i] > 0.0)) continue;
    for (size_t k = 0; k < next.size(); ++k) next[k] += landing.share[i] * spectrum[i][k];
    next_rgb += landing.share[i] * rgb[i];
  }
  return bounce_shift(tables, first, first_rgb, next, next_rgb, bounces);
}

std::string spectral_reason(const SceneDesc& scene) {
  for (const Material& m : scene.materials) {
    if (m.ior_spectrum >= 0) return "a dispersive dielectric";
    if (m.eta_spectrum >= 0 || m.k_spectrum >= 0) return "a conductor given by measured spectra";
  }
  for (const AreaLightDesc& a : scene.area_lights) {
    if (a.image >= 0) continue;  // an image's texels: natural colours
    const Rgb c = a.blackbody_kelvin > 0.f ? blackbody_rgb(a.blackbody_kelvin) : a.L;
    if (strongly_coloured(c)) return "a strongly coloured area light";
  }
  for (const Light& l : scene.lights) {
    if (l.type == LightType::Infinite && l.image >= 0) continue;  // an image's texels: natural colours
    const Rgb c = l.blackbody_kelvin > 0.f ? blackbody_rgb(l.blackbody_kelvin) : l.L;
    if (strongly_coloured(c)) return "a strongly coloured light";
  }
  for (const Medium& m : scene.media) {
    if (strongly_coloured(m.Le)) return "a strongly coloured emitting medium";
    // Blackbodies below about 5000 K are strongly coloured; fire is far below.
    if (m.grid >= 0 && scene.grids[static_cast<size_t>(m.grid)].temperature.nx > 0) return "a medium glowing by temperature";
  }
  const Rgb shift = multibounce_colour_shift(scene);
  const Float worst = max_component(shift);
  if (worst > kMultibounceShiftThreshold) {
    const int c = shift.x == worst ? 0 : (shift.y == worst ? 1 : 2);
    char buf[160];
    std::snprintf(buf, sizeof buf, "saturated reflectances over several bounces (RGB an estimated %.1f %% off in %s)",
                  100.0 * worst, c == 0 ? "red" : (c == 1 ? "green" : "blue"));
    return buf;
  }
  return "";
}

}  // namespace tessera

