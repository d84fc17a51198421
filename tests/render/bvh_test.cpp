// The portable BVH (kernels/bvh.h, render/bvh_build.h) against Embree: the
// same closest hits (triangle and distance) and the same shadow-ray
// answers on random and camera rays of the shipped scenes, with cut-outs,
// one-way curve tubes and moving triangles; and a tree every triangle is in
// once, shallow enough for the traversal stack. Renders over it (the
// --backend bvh executor) agree with Embree's statistically, keep the
// furnace, and are bit-identical across thread counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kernels/bvh.h"
#include "kernels/rng.h"
#include "furnace_scene.h"
#include "guided_helpers.h"
#include "render_helpers.h"
#include "render/backends.h"
#include "render/bvh_build.h"
#include "render/embree_backend.h"

namespace tessera {
namespace {

struct Agreement {
  int rays = 0, hits = 0, mismatches = 0, occlusion_mismatches = 0, occluded = 0;
};

// Rays from random points of the scene's bounds in random directions, and
// from the camera through random pixels.
Agreement compare_with_embree(const SceneData& scene, int rays, uint64_t seed) {
  EmbreeScene embree(scene);
  const EmbreeTracer e = embree.tracer();
  const BvhBuild build = build_bvh(scene.view());
  const BvhTracer b{build.view(), &scene.view()};
  const SceneView& s = scene.view();
  Vec3 lo(kInfinity), hi(-kInfinity);
  for (uint32_t i = 0; i < 3 * s.num_triangles; ++i) {
    lo = glm::min(lo, s.positions[s.indices[i]]);
    hi = glm::max(hi, s.positions[s.indices[i]]);
  }
  Rng rng = Rng::for_sample(seed, 0, 0);
  Agreement a;
  for (int i = 0; i < rays; ++i) {
    Vec3 o, d;
    Float time = s.positions_end ? rng.uniform() : 0.f;
    if (i % 2 == 0) {
      o = lo + (hi - lo) * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
      d = sample_uniform_sphere(rng.uniform2());
    } else {
      const Vec2 p(rng.uniform() * s.camera.width, rng.uniform() * s.camera.height);
      const Ray r = generate_camera_ray(s.camera, p);
      o = r.o;
      d = r.d;
    }
    ++a.rays;
    TraceHit he{}, hb{};
    const bool fe = e.intersect(o, d, kInfinity, &he, time), fb = b.intersect(o, d, kInfinity, &hb, time);
    a.hits += fe;
    // A tie (a ray through an edge, coplanar faces) may pick either triangle at the same distance.
    const bool same = fe == fb && (!fe || he.triangle == hb.triangle ||
                                   std::fabs(he.t - hb.t) <= 1e-5f * std::max(1.f, he.t));
    const bool near = same && (!fe || std::fabs(he.t - hb.t) <= 1e-4f * std::max(1.f, he.t));
    a.mismatches += !near;
    // Shadow rays short of the closest hit (free, but for cut-outs) and past it (blocked).
    for (const Float tmax : {fe ? 0.5f * he.t : 10.f * glm::length(hi - lo), fe ? 2.f * he.t : 0.f}) {
      if (!(tmax > 0.f)) continue;
      const bool oe = e.occluded(o, d, tmax, time);
      a.occluded += oe;
      a.occlusion_mismatches += oe != b.occluded(o, d, tmax, time);
    }
  }
  return a;
}

void expect_agreement(const SceneData& scene, const char* name) {
  const Agreement a = compare_with_embree(scene, 20000, 7);
  std::printf("[bvh] %-14s %d rays, %d hits, %d differ, %d shadow answers differ\n", name, a.rays, a.hits, a.mismatches,
              a.occlusion_mismatches);
  EXPECT_GT(a.hits, a.rays / 10) << name;
  EXPECT_GE(a.occluded, a.hits / 2) << name;  // the shadow comparisons see blocked rays too
  // Rounding near edges may send a ray through a crack one side sees: a tiny counted fraction.
  EXPECT_LE(a.mismatches, a.rays / 2000) << name;
  EXPECT_LE(a.occlusion_mismatches, a.rays / 2000) << name;
}

SceneData load(const std::string& path) { return SceneData(load_pbrt_file(path)); }

TEST(Bvh, AgreesWithEmbreeOnTheShippedScenes) {
  for (const char* name : {"cornell-box", "door-ajar", "glossy", "pillars", "shelter"})
    expect_agreement(load(testing::source_dir() + "/scenes/" + name + ".pbrt"), name);
}

TEST(Bvh, AgreesWithEmbreeWithCutoutsTubesAndMotion) {
  const std::string scene = R"(
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
WorldBegin
LightSource "infinite"
Texture "checks" "float" "checkerboard" "float uscale" 8 "float vscale" 8 "float tex1" 0 "float tex2" 1
Shape "trianglemesh" "point3 P" [ -2 -2 -1  2 -2 -1  2 2 -1  -2 2 -1 ] "integer indices" [ 0 1 2 0 2 3 ]
  "point2 uv" [ 0 0 1 0 1 1 0 1 ] "texture alpha" "checks"
Shape "curve" "point3 P" [ -1 -1 0  -0.3 1 0.5  0.3 -1 -0.5  1 1 0 ] "float width" 0.4 "string type" "cylinder"
Shape "sphere" "float radius" 0.5
AttributeBegin
ActiveTransform EndTime
Translate 0.5 0 0
ActiveTransform All
Shape "trianglemesh" "point3 P" [ -1 -1 1  1 -1 1  0 1 1 ]
AttributeEnd
)";
  SceneData data(load_pbrt_string(scene, "bvh.pbrt", "."));
  ASSERT_TRUE(data.view().triangle_alpha);
  ASSERT_TRUE(data.view().has_one_way_faces);
  ASSERT_TRUE(data.view().positions_end);
  expect_agreement(data, "cutouts/tubes");
}

TEST(Bvh, HoldsEveryTriangleOnceInAShallowTree) {
  const SceneData scene = load(testing::source_dir() + "/scenes/pillars.pbrt");
  const BvhBuild b = build_bvh(scene.view());
  std::vector<int> seen(scene.view().num_triangles, 0);
  for (uint32_t t : b.triangles) ++seen[t];
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  EXPECT_LT(b.depth, kBvhStackSize - 1);
  for (const BvhNode& n : b.nodes) {
    if (n.count_axis & kBvhInner) {
      EXPECT_LT(n.offset, b.nodes.size());
    } else {
      EXPECT_GE(n.count_axis, 1u);
      EXPECT_LE(n.offset + n.count_axis, b.triangles.size());
    }
  }
  // Rays along the axes (zero direction components: infinite inverse) agree with Embree.
  EmbreeScene embree(scene);
  const BvhTracer t{b.view(), &scene.view()};
  for (const Vec3& d : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, -1), Vec3(0, -1, 0)}) {
    TraceHit hb{}, he{};
    const bool fb = t.intersect(Vec3(0.f, 0.5f, 0.f), d, kInfinity, &hb);
    ASSERT_EQ(fb, embree.tracer().intersect(Vec3(0.f, 0.5f, 0.f), d, kInfinity, &he));
    if (fb) {
      EXPECT_NEAR(hb.t, he.t, 1e-4f * std::max(1.f, he.t));
    }
  }
}

// A render over the BVH (the full integrator) or over Embree.
RenderResult render_with(SceneDesc desc, bool bvh, int threads, uint64_t seed = 3) {
  RenderOptions opt;
  opt.progress = false;
  opt.spp = static_cast<uint32_t>(desc.spp);
  opt.max_depth = desc.max_depth;
  opt.sampler = sampler_setup(desc);
  opt.seed = seed;
  opt.threads = threads;
  opt.force_full_specialisation = bvh;  // as --backend bvh sets it
  SceneData scene(std::move(desc));
  std::unique_ptr<TileBackend> backend = make_tile_backend(bvh ? "bvh" : "embree", scene);
  RenderResult r = render(scene, *backend, opt);
  EXPECT_EQ(r.stats.backend, bvh ? "bvh" : "embree");
  return r;
}

TEST(Bvh, RendersAgreeWithEmbree) {
  for (const char* name : {"cornell-box", "door-ajar", "glossy"}) {
    SceneDesc desc = load_pbrt_file(testing::source_dir() + "/scenes/" + name + ".pbrt");
    desc.film.xres = 32;
    desc.film.yres = 24;
    desc.spp = 64;
    const RenderResult e = render_with(desc, false, 2, 3), b = render_with(desc, true, 2, 4);
    for (const PixelAccum& p : b.film.pixels)
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p.sum[c])) << name;
    testing::expect_agree(testing::channel_stats(e.film), testing::channel_stats(b.film), name);
  }
}

TEST(Bvh, KeepsTheFurnaceAndIsBitIdenticalAcrossThreads) {
  const std::string scene = testing::furnace_scene(0.5, 20, 16, 64);
  const RenderResult one = render_with(load_pbrt_string(scene, "furnace.pbrt", "."), true, 1);
  const RenderResult two = render_with(load_pbrt_string(scene, "furnace.pbrt", "."), true, 2);
  EXPECT_TRUE(testing::films_identical(one.film, two.film));
  EXPECT_NEAR(testing::image_mean(film_mean(one.film)) / testing::expected_furnace(0.5, 20), 1.0, 0.01);
}

}  // namespace
}  // namespace tessera
