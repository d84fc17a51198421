// pbrt-v4's light samplers (kernels/light_choice.h, kernels/light_bvh.h):
// at any point the choice probabilities sum to one (the tree's, less what
// it loses in nodes whose children can both not reach the point, where
// pbrt-v4's tree chooses no light either), sampling draws lights
// with exactly those probabilities (chi-square), the probability sampling
// reports is the one MIS recomputes, and renders with bvh, power and
// uniform selection agree (every one unbiased).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "../kernels/chi2.h"
#include "kernels/light_choice.h"
#include "render_helpers.h"

namespace tessera {
namespace {

// Many lights of every bounded kind, spread over a room, facing every way,
// with powers over three decades; plus a sky and a sun (chosen apart from
// the tree). `extra` goes before WorldBegin.
std::string many_lights_scene(const std::string& integrator, int spp) {
  std::ostringstream s;
  s << "LookAt 0 1 -3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 60 ]\n"
    << "Film \"rgb\" \"integer xresolution\" [ 48 ] \"integer yresolution\" [ 32 ]\n"
    << "Sampler \"independent\" \"integer pixelsamples\" [ " << spp << " ]\n"
    << integrator << "\nWorldBegin\n"
    << "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n"
    << "Shape \"trianglemesh\" \"point3 P\" [ -4 0 -4  4 0 -4  4 0 4  -4 0 4 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n"
    << "Shape \"trianglemesh\" \"point3 P\" [ -4 0 4  4 0 4  4 4 4  -4 4 4 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 40; ++i) {
    const float x = -3.f + 6.f * u(rng), y = 0.3f + 3.f * u(rng), z = -2.f + 5.f * u(rng);
    const float power = std::pow(10.f, 3.f * u(rng) - 1.f);
    const float ax = 6.28f * u(rng), ay = 6.28f * u(rng);
    s << "AttributeBegin\n  Translate " << x << ' ' << y << ' ' << z << "\n  Rotate " << ax * 57.3f << " 1 0 0\n  Rotate "
      << ay * 57.3f << " 0 1 0\n";
    if (i % 8 == 6) {
      s << "  LightSource \"point\" \"rgb I\" [ " << power << ' ' << power << ' ' << power << " ]\n";
    } else if (i % 8 == 7) {
      s << "  LightSource \"spot\" \"rgb I\" [ " << power << " " << power << " " << power
        << " ] \"float coneangle\" [ 40 ] \"float conedelta\" [ 10 ]\n";
    } else {
      s << "  AreaLightSource \"diffuse\" \"rgb L\" [ " << power << ' ' << 0.5f * power << ' ' << power << " ]"
        << (i % 5 == 0 ? " \"bool twosided\" true" : "") << "\n"
        << "  Shape \"trianglemesh\" \"point3 P\" [ -0.1 0 -0.1  0.1 0 -0.1  0.1 0 0.1  -0.1 0 0.1 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n";
    }
    s << "AttributeEnd\n";
  }
  s << "LightSource \"infinite\" \"rgb L\" [ 0.05 0.05 0.05 ]\n"
    << "LightSource \"distant\" \"point3 from\" [ 1 3 -1 ] \"point3 to\" [ 0 0 0 ] \"rgb L\" [ 0.3 0.3 0.3 ]\n";
  return s.str();
}

SceneData many_lights(LightSamplerKind kind) {
  SceneDesc d = load_pbrt_string(many_lights_scene("Integrator \"path\"", 4), "<test>", ".");
  d.light_sampler = kind;
  return SceneData(std::move(d));
}

struct Query {
  LightQuery q;
  const char* what;
};

// Points on the floor, on the wall, in mid-air (a medium: no normal), one
// beside a lamp and one behind the wall.
std::vector<Query> queries() {
  return {{{Vec3(0.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f)}, "floor"},
          {{Vec3(1.f, 2.f, 4.f), Vec3(0.f, 0.f, -1.f)}, "wall"},
          {{Vec3(0.5f, 1.5f, 1.f), Vec3(0.f)}, "medium"},
          {{Vec3(-2.f, 3.5f, -1.5f), Vec3(0.f)}, "high in the air"},
          {{Vec3(0.f, 2.f, 6.f), Vec3(0.f, 0.f, 1.f)}, "behind the wall"}};
}

TEST(LightSampler, ProbabilitiesSumToOneAndMatchSampling) {
  for (LightSamplerKind kind : {LightSamplerKind::Bvh, LightSamplerKind::Power, LightSamplerKind::Uniform}) {
    const SceneData scene = many_lights(kind);
    const SceneView& s = scene.view();
    ASSERT_GE(s.num_lights, 60u);
    if (kind == LightSamplerKind::Bvh) {
      EXPECT_EQ(s.light_bvh.num_unbounded, 2u);
      EXPECT_EQ(s.light_bvh.num_nodes, 2 * (s.num_lights - 2) - 1);
    }
    for (const Query& at : queries()) {
      SCOPED_TRACE(std::string(at.what) + ", sampler " + std::to_string(static_cast<int>(kind)));
      std::vector<double> pmf(s.num_lights);
      double sum = 0.0;
      for (uint32_t li = 0; li < s.num_lights; ++li) {
        pmf[li] = light_choice_pmf(s, at.q, li);
        ASSERT_TRUE(pmf[li] >= 0.0 && std::isfinite(pmf[li]));
        sum += pmf[li];
      }
      if (kind == LightSamplerKind::Bvh) {
        EXPECT_LE(sum, 1.0 + 1e-4);
        EXPECT_GT(sum, 0.95);
      } else {
        EXPECT_NEAR(sum, 1.0, 1e-4);
      }
      // Stratified draws: the counts, against n x pmf; draws that choose no
      // light, against n x (1 - sum).
      constexpr int kDraws = 400000;
      std::vector<double> count(s.num_lights, 0.0);
      double none = 0.0;
      for (int k = 0; k < kDraws; ++k) {
        Float p = 0.f;
        const uint32_t li = choose_light(s, at.q, (static_cast<Float>(k) + 0.5f) / kDraws, &p);
        if (!(p > 0.f)) {
          none += 1.0;
          continue;
        }
        ASSERT_NEAR(p, pmf[li], 1e-5 + 1e-4 * pmf[li]) << "light " << li;
        count[li] += 1.0;
      }
      EXPECT_NEAR(none / kDraws, std::max(0.0, 1.0 - sum), 2e-3);
      double chsq = 0.0;
      int dof = -1;
      for (uint32_t li = 0; li < s.num_lights; ++li) {
        const double expect = kDraws * pmf[li];
        if (expect < 5.0) {
          EXPECT_LE(count[li], expect + 10.0) << "light " << li;
          continue;
        }
        chsq += (count[li] - expect) * (count[li] - expect) / expect;
        ++dof;
      }
      ASSERT_GT(dof, 0);
      EXPECT_GT(chi2::chi2_survival(chsq, dof), 1e-3) << "chi2 " << chsq << " dof " << dof;
    }
  }
}

// Where a light cannot reach the point (behind a one-sided lamp, outside a
// spot's cone) the tree never picks it; everywhere else it may.
TEST(LightSampler, TreeSkipsOnlyLightsThatCannotReachThePoint) {
  const SceneData scene = many_lights(LightSamplerKind::Bvh);
  const SceneView& s = scene.view();
  int skipped = 0;
  for (const Query& at : queries())
    for (uint32_t li = 0; li < s.num_lights; ++li) {
      if (light_choice_pmf(s, at.q, li) > 0.f) continue;
      ++skipped;
      const Light& l = s.lights[li];
      if (l.type == LightType::Spot) {
        const Vec3 w = glm::normalize(at.q.p - l.position);
        EXPECT_LE(glm::dot(w, l.direction), l.cos_falloff_end + 1e-3f) << at.what << ": spot " << li;
      } else {
        ASSERT_EQ(l.type, LightType::Area) << at.what << ": light " << li;
        EXPECT_FALSE(l.two_sided) << at.what << ": light " << li;
        // Every corner of the triangle is behind its face as seen from the point.
        const LightTriangle t = light_triangle(s, l.triangle);
        const Vec3 n = s.face_normals[l.triangle];
        for (const Vec3& v : {t.v0, t.v1, t.v2}) EXPECT_LE(glm::dot(at.q.p - v, n), 1e-4f) << at.what << ": light " << li;
      }
    }
  EXPECT_GT(skipped, 0);  // the test sees some
}

// The same scene with each light sampler: the same picture in expectation.
TEST(LightSampler, EverySamplerRendersTheSameMean) {
  // Uniform selection wastes most samples on dim lights: it gets 8x the
  // samples for about the noise of the others.
  const char* names[] = {"bvh", "power", "uniform"};
  const int spp[] = {256, 256, 2048};
  std::vector<ImageRgb> images;
  for (int k = 0; k < 3; ++k) {
    RenderOptions opt;
    opt.seed = 3;
    const std::string integrator =
        std::string("Integrator \"path\" \"integer maxdepth\" [ 3 ] \"string lightsampler\" \"") + names[k] + "\"";
    images.push_back(film_mean(testing::render_text(many_lights_scene(integrator, spp[k]), opt).film));
  }
  const double bvh = testing::image_mean(images[0]);
  ASSERT_GT(bvh, 0.0);
  for (size_t k = 1; k < images.size(); ++k) EXPECT_NEAR(testing::image_mean(images[k]) / bvh, 1.0, 0.02) << names[k];
  // 8x8 blocks too: a light picked wrongly somewhere shows there first.
  for (int by = 0; by < 4; ++by)
    for (int bx = 0; bx < 6; ++bx) {
      double m[3] = {0, 0, 0};
      for (size_t k = 0; k < 3; ++k)
        for (int y = 8 * by; y < 8 * by + 8; ++y)
          for (int x = 8 * bx; x < 8 * bx + 8; ++x)
            for (int c = 0; c < 3; ++c) m[k] += images[k].rgb[3 * (y * 48 + x) + c];
      EXPECT_NEAR(m[1] / m[0], 1.0, 0.1) << "block " << bx << ',' << by << " power";
      EXPECT_NEAR(m[2] / m[0], 1.0, 0.1) << "block " << bx << ',' << by << " uniform";
    }
}

TEST(LightSampler, SceneFileChoosesTheSampler) {
  auto kind = [](const std::string& integrator) {
    const std::string light = "LightSource \"point\" \"rgb I\" [ 1 1 1 ]\n";
    return load_pbrt_string("Integrator \"path\" " + integrator + "\nWorldBegin\n" + light, "<test>", ".").light_sampler;
  };
  EXPECT_EQ(kind(""), LightSamplerKind::Bvh);  // pbrt-v4's default
  EXPECT_EQ(kind("\"string lightsampler\" \"power\""), LightSamplerKind::Power);
  EXPECT_EQ(kind("\"string lightsampler\" \"uniform\""), LightSamplerKind::Uniform);
  EXPECT_EQ(kind("\"string lightsampler\" \"exhaustive\""), LightSamplerKind::Bvh);
  try {
    load_pbrt_string("Integrator \"path\" \"string lightsampler\" \"nearest\"\nWorldBegin\n"
                     "LightSource \"point\" \"rgb I\" [ 1 1 1 ]\n",
                     "scene.pbrt", ".");
    FAIL() << "an unknown light sampler must be refused";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.pbrt:1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nearest"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera
