// Every tracer refuses the rays Embree refuses (kernels/ray_guard.h): a
// miss for intersect, occluded for occluded, counted where it has a counter;
// the rays it takes are traced as before.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kernels/ray_guard.h"
#include "render/bvh_backend.h"
#include "render/embree_backend.h"
#include "render_helpers.h"

namespace tessera {
namespace {

// A quad at z = 0 across +-10, seen from z = -5.
SceneData quad_scene() {
  return SceneData(load_pbrt_string(
      "LookAt 0 0 -5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n"
      "Shape \"trianglemesh\" \"point3 P\" [ -10 -10 0  10 -10 0  10 10 0  -10 10 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]\n",
      "<test>", "."));
}

struct Refused {
  Vec3 o, d;
  Float tmax;
};

template <class Tracer>
void expect_guarded(Tracer tracer, const char* what) {
  uint64_t refused = 0;
  tracer.untraceable = &refused;
  // The render space puts the camera at the origin: the quad is at z = 5.
  TraceHit hit{};
  ASSERT_TRUE(tracer.intersect(Vec3(0.f), Vec3(0.f, 0.f, 1.f), kInfinity, &hit)) << what;
  EXPECT_NEAR(hit.t, 5.f, 1e-4f) << what;
  EXPECT_TRUE(tracer.occluded(Vec3(0.f), Vec3(0.f, 0.f, 1.f), 10.f)) << what;
  EXPECT_FALSE(tracer.occluded(Vec3(0.f), Vec3(0.f, 0.f, 1.f), 4.f)) << what;
  // A ray from the limit itself is taken (and misses the quad).
  EXPECT_FALSE(tracer.intersect(Vec3(kMaxRayComponent, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), kInfinity, &hit)) << what;
  EXPECT_EQ(refused, 0u) << what;
  const Float nan = std::numeric_limits<Float>::quiet_NaN();
  const Refused cases[] = {
      {Vec3(0.f, 0.f, -2e18f), Vec3(0.f, 0.f, 1.f), kInfinity},  // would hit the quad at 2e18
      {Vec3(0.f, 0.f, -std::numeric_limits<Float>::infinity()), Vec3(0.f, 0.f, 1.f), kInfinity},
      {Vec3(nan, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), kInfinity},
      {Vec3(0.f), Vec3(0.f, nan, 1.f), kInfinity},
      {Vec3(0.f), Vec3(0.f, 0.f, 2e18f), kInfinity},
      {Vec3(0.f), Vec3(0.f, 0.f, 1.f), nan},
  };
  uint64_t expected = 0;
  for (const Refused& r : cases) {
    hit.triangle = 12345;
    EXPECT_FALSE(tracer.intersect(r.o, r.d, r.tmax, &hit)) << what;
    EXPECT_EQ(hit.triangle, 12345u) << what;  // untouched
    EXPECT_TRUE(tracer.occluded(r.o, r.d, r.tmax)) << what;  // no light through it
    expected += 2;
    EXPECT_EQ(refused, expected) << what;
  }
  // Without a counter the answers are the same.
  tracer.untraceable = nullptr;
  EXPECT_TRUE(tracer.occluded(Vec3(0.f, 0.f, -2e18f), Vec3(0.f, 0.f, 1.f), kInfinity)) << what;
}

TEST(RayGuard, Predicate) {
  EXPECT_TRUE(ray_traceable(Vec3(kMaxRayComponent, -kMaxRayComponent, 0.f), Vec3(0.f, 0.f, 1.f), kInfinity));
  EXPECT_TRUE(ray_traceable(Vec3(0.f), Vec3(0.f), -1.f));  // Embree takes these (and finds nothing)
  EXPECT_FALSE(ray_traceable(Vec3(0.f, 1.9e18f, 0.f), Vec3(0.f, 0.f, 1.f), kInfinity));
  EXPECT_FALSE(ray_traceable(Vec3(0.f), Vec3(-1.9e18f, 0.f, 0.f), kInfinity));
  EXPECT_FALSE(ray_traceable(Vec3(0.f), Vec3(0.f, 0.f, 1.f), std::numeric_limits<Float>::quiet_NaN()));
}

TEST(RayGuard, EmbreeAndBvhTracersRefuseWhatEmbreeRefuses) {
  const SceneData scene = quad_scene();
  EmbreeBackend embree(scene);
  expect_guarded(embree.tracer(), "embree");
  BvhBackend bvh(scene);
  expect_guarded(bvh.tracer(), "bvh");
}

}  // namespace
}  // namespace tessera
