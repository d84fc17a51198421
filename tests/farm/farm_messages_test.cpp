// The farm's messages byte for byte: a batch of jobs and a tile request
// encode to the bytes recorded when they began to name their pass (farm
// liveness: docs/farm.md, "A silent rank"; the counters inside a request
// last grew with PathCounters::untraceable_rays: 20 words), so ranks of
// one build agree on them and on the counters inside a request.
#include <gtest/gtest.h>

#include <cstring>

#include "comm/farm_protocol.h"
#include "comm/guide_wire.h"
#include "guidecache/table/guide_field.h"
#include "render/render_tile.h"

namespace tessera {
namespace {

// FNV-1a, 64 bits.
uint64_t fnv1a(const Bytes& bytes) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (uint8_t c : bytes) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

TileWork sample_work() {
  TileWork w;
  w.job = TileJob{1, 2, 3, 4, 7, 9, 4};
  w.pixels.resize(4);
  for (int i = 0; i < 4; ++i) {
    w.pixels[i].sum[0] = i + 0.5;
    w.pixels[i].sum_sq[2] = i * 3.25;
    w.pixels[i].n = 10 + i;
  }
  Splat sp;
  sp.pixel = 77;
  sp.value[1] = 2.5f;
  w.splats = {sp, sp};
  return w;
}

// Counters whose words are 1000, 1001, ... in declaration order.
TileCounters numbered_counters() {
  uint64_t words[sizeof(TileCounters) / sizeof(uint64_t)];
  for (size_t i = 0; i < std::size(words); ++i) words[i] = 1000 + i;
  TileCounters c;
  static_assert(sizeof(words) == sizeof(c));
  std::memcpy(&c, words, sizeof(c));
  return c;
}

TEST(FarmMessages, TileRequestBytesAreUnchanged) {
  TileRequest req;
  req.pass = 5;
  req.capacity = 3;
  req.results = {sample_work()};
  req.counters = WireCounters::to_wire(numbered_counters());
  req.interrupted = true;
  const Bytes b = encode(req);
  EXPECT_EQ(b.size(), 493u);
  EXPECT_EQ(fnv1a(b), 0xa5fe52f0d6dbe2f0ull);
}

TEST(FarmMessages, TileJobsBytesAreUnchanged) {
  const Bytes b = encode(TileJobs{5, {sample_work()}});
  EXPECT_EQ(b.size(), 328u);
  EXPECT_EQ(fnv1a(b), 0x7aa3966175ede4c6ull);
}

TEST(FarmMessages, CountersComeBackFieldByField) {
  TileRequest req;
  req.counters = WireCounters::to_wire(numbered_counters());
  const TileCounters c = decode<TileRequest>(encode(req)).counters.from_wire<TileCounters>();
  EXPECT_EQ(c.path.rays, 1000u);
  EXPECT_EQ(c.path.neural_sites_reused, 1014u);
  EXPECT_EQ(c.path.untraceable_rays, 1015u);
  EXPECT_EQ(c.samples, 1016u);
  EXPECT_EQ(c.rejected_negative, 1019u);
}

// Messages are read straight from their bytes, and a guide's reader seeks
// back after its magic: the master's guide, as it sends it to a worker that
// missed a fold, comes back the same.
TEST(FarmMessages, GuideSurvivesTheWire) {
  GuideField g(GuideConfig{}, Vec3(0.f), Vec3(1.f), 4, 10.f);
  const Bytes b = guide_to_bytes(g, 77);
  EXPECT_TRUE(guide_from_bytes(b, 77)->same_as(g));
  EXPECT_THROW(guide_from_bytes(b, 78), std::runtime_error) << "another scene's";
  EXPECT_THROW(guide_from_bytes(Bytes(b.begin(), b.begin() + b.size() / 2), 77), std::runtime_error);
  const GuideRound round = decode<GuideRound>(encode(GuideRound{3, 4, {1, 2, ~0ull}}));
  EXPECT_EQ(round.pass, 3u);
  EXPECT_EQ(round.round, 4u);
  EXPECT_EQ(round.words, (std::vector<uint64_t>{1, 2, ~0ull}));
}

}  // namespace
}  // namespace tessera
