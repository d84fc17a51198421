// Numerical extremes as a family: one small lit room generated with its
// radiance, its size, its distance from the origin, its light's size and its
// material and texture nesting pushed to extremes, each rendered without a
// guide and with both learning rules. Every render must be free of NaN, Inf
// and negative pixels with a finite variance; the three methods must agree
// within their confidence intervals; and where the extreme changes nothing
// but units (radiance x 1e30, size x 1e5, moved by 1e6) the image must agree
// with the plain room's, rescaled. (The albedo-1 furnace at depth 1000 is in
// furnace_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "guided_helpers.h"

namespace tessera {
namespace {

using testing::ChannelStats;
using testing::GuidedScene;
using testing::rule_name;

struct RoomVariant {
  const char* name;
  double radiance = 1.0;    // the light's radiance multiplier
  double size = 1.0;        // every length multiplied (camera included)
  double offset = 0.0;      // camera and world moved along x and z by this
  double light_size = 1.0;  // the light's side multiplied (its radiance divided by the square: same power)
  int texture_chain = 0;    // the floor's reflectance through this many nested "scale" textures
  int mix_depth = 0;        // the sphere's material through this many nested "mix" materials
  bool same_image = true;   // a change of units only: must agree with the plain room
};

std::string room(const RoomVariant& v) {
  auto num = [](double x) {
    char b[40];
    std::snprintf(b, sizeof b, "%.9g", x);
    return std::string(b);
  };
  auto p = [&](double x) { return num(x * v.size); };
  auto px = [&](double x) { return num(x * v.size + v.offset); };
  const double h = 0.25 * v.light_size;
  const double le = 8.0 * v.radiance / (v.light_size * v.light_size);
  std::string s = "LookAt " + px(0) + " " + p(1) + " " + px(-2.5) + "  " + px(0) + " " + p(0.8) + " " + px(0) +
                  "  0 1 0\n"
                  "Camera \"perspective\" \"float fov\" [ 55 ]\n"
                  "Film \"rgb\" \"integer xresolution\" [ 16 ] \"integer yresolution\" [ 16 ]\n"
                  "Sampler \"independent\" \"integer pixelsamples\" [ 64 ]\n"
                  "Integrator \"path\" \"integer maxdepth\" [ 8 ]\nWorldBegin\n"
                  "Translate " + num(v.offset) + " 0 " + num(v.offset) + "\nScale " + num(v.size) + " " + num(v.size) +
                  " " + num(v.size) + "\n";
  // The floor's texture: a chain of scale textures, each by 1.
  std::string floor_tex = "\"rgb reflectance\" [ 0.6 0.5 0.4 ]";
  if (v.texture_chain > 0) {
    s += "Texture \"t0\" \"spectrum\" \"constant\" \"rgb value\" [ 0.6 0.5 0.4 ]\n";
    for (int i = 1; i <= v.texture_chain; ++i)
      s += "Texture \"t" + std::to_string(i) + "\" \"spectrum\" \"scale\" \"texture tex\" \"t" + std::to_string(i - 1) +
           "\" \"float scale\" 1\n";
    floor_tex = "\"texture reflectance\" \"t" + std::to_string(v.texture_chain) + "\"";
  }
  // The sphere's material: nested mixes of two identical conductors.
  s += "MakeNamedMaterial \"m0\" \"string type\" \"conductor\" \"float roughness\" 0.2\n";
  for (int i = 1; i <= v.mix_depth; ++i)
    s += "MakeNamedMaterial \"m" + std::to_string(i) + "\" \"string type\" \"mix\" \"string materials\" [ \"m" +
         std::to_string(i - 1) + "\" \"m0\" ] \"float amount\" 0.5\n";
  s += "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ " + num(le) + " " + num(le) + " " + num(le) +
       " ]\nShape \"trianglemesh\" \"point3 P\" [ " + num(-h) + " 1.99 " + num(-h) + "  " + num(h) + " 1.99 " + num(-h) +
       "  " + num(h) + " 1.99 " + num(h) + "  " + num(-h) + " 1.99 " + num(h) +
       " ] \"integer indices\" [ 0 1 2 0 2 3 ]\nAttributeEnd\n"
       "Material \"diffuse\" " + floor_tex + "\n"
       "Shape \"trianglemesh\" \"point3 P\" [ -1 0 -1  1 0 -1  1 0 1  -1 0 1 ] \"integer indices\" [ 0 2 1 0 3 2 ]\n"
       "Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.7 0.7 ]\n"
       "Shape \"trianglemesh\" \"point3 P\" [ -1 2 -1  1 2 -1  1 2 1  -1 2 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
       "Shape \"trianglemesh\" \"point3 P\" [ -1 0 1  1 0 1  1 2 1  -1 2 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
       "Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.2 0.2 ]\n"
       "Shape \"trianglemesh\" \"point3 P\" [ -1 0 -1  -1 0 1  -1 2 1  -1 2 -1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
       "Material \"diffuse\" \"rgb reflectance\" [ 0.2 0.7 0.2 ]\n"
       "Shape \"trianglemesh\" \"point3 P\" [ 1 0 -1  1 2 -1  1 2 1  1 0 1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
       "AttributeBegin\nNamedMaterial \"m" + std::to_string(v.mix_depth) +
       "\"\nTranslate 0.3 0.35 0.2\nShape \"sphere\" \"float radius\" 0.35\nAttributeEnd\n";
  return s;
}

// No NaN, Inf or negative pixel; finite variances (the float variance layer
// saturates at the largest float instead of overflowing).
void expect_sane(const Film& film, const std::string& what) {
  const ImageRgb m = film_mean(film), v = film_variance_of_mean(film);
  for (size_t i = 0; i < m.rgb.size(); ++i) {
    ASSERT_TRUE(std::isfinite(m.rgb[i]) && m.rgb[i] >= 0.f) << what << ": pixel value " << m.rgb[i];
    ASSERT_TRUE(std::isfinite(v.rgb[i]) && v.rgb[i] >= 0.f) << what << ": variance " << v.rgb[i];
    ASSERT_TRUE(std::isfinite(pixel_estimate(film, i / 3, static_cast<int>(i % 3)).var_of_mean)) << what;
  }
}

ChannelStats scaled(ChannelStats s, double by) {
  for (int c = 0; c < 3; ++c) {
    s.mean[c] *= by;
    s.se[c] *= by;
  }
  return s;
}

TEST(Extremes, EveryVariantRendersSanelyAndAgreesAcrossGuideMethods) {
  const RoomVariant variants[] = {
      {"plain"},
      {"radiance 1e30", 1e30},
      {"radiance 1e-30", 1e-30},
      {"size 1e5", 1.0, 1e5},
      {"size 1e-5", 1.0, 1e-5},
      {"moved 1e6", 1.0, 1.0, 1e6},
      {"light 1e-3 across", 1.0, 1.0, 0.0, 1e-3, 0, 0, false},
      {"light 1e3 across (far past the room)", 1.0, 1.0, 0.0, 1e3, 0, 0, false},
      {"64 nested textures (the limit), 16 nested mixes", 1.0, 1.0, 0.0, 1.0, 63, 16},
  };
  ChannelStats plain;
  uint64_t seed = 7;  // every render its own seed: expect_agree compares independent estimates
  for (const RoomVariant& v : variants) {
    SCOPED_TRACE(v.name);
    const SceneDesc desc = load_pbrt_string(room(v), "<room>", ".");
    ASSERT_TRUE(desc.warnings.empty()) << desc.warnings[0];
    GuidedScene gs(desc);
    RenderOptions opt;
    opt.seed = seed++;
    const RenderResult unguided = gs.run(nullptr, opt);
    expect_sane(unguided.film, "unguided");
    const ChannelStats base = testing::channel_stats(unguided.film);
    testing::expect_precise(base, 0.05, "unguided");
    for (GuideTarget target : {GuideTarget::ExpectedSarsa, GuideTarget::QLearning}) {
      GuideField guide = gs.make_guide(testing::config_with(target));
      opt.seed = seed++;
      const RenderResult guided = gs.run(&guide, opt);
      expect_sane(guided.film, rule_name(target));
      testing::expect_agree(testing::channel_stats(guided.film), base, rule_name(target));
    }
    if (std::string(v.name) == "plain") plain = base;
    else if (v.same_image) testing::expect_agree(scaled(base, 1.0 / v.radiance), plain, "against the plain room");
  }
}

}  // namespace
}  // namespace tessera
