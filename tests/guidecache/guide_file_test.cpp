// A saved table guide is loaded only when it is what learning could have
// made: a checksum over its payload, every field range-checked (finite,
// non-negative, probabilities in [0, 1], counts and octrees that agree),
// one line saying what is wrong otherwise. Valid files round-trip exactly,
// version 4 (no checksum) included.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "../guide_file_bytes.h"
#include "guidecache/table/guide_field.h"
#include "guidecache/table/guiding.h"
#include "kernels/rng.h"

namespace tessera {
namespace {

using namespace testing;

constexpr uint64_t kScene = 77;

// A field with learned lights, one split (14 nodes, 13 cells) and values in
// every kind of entry, saved.
std::string learned_file() {
  GuideConfig cfg;
  cfg.split_updates = 50;
  GuideField f(cfg, Vec3(0.f), Vec3(1.f), 3, 1.f);
  GuideView g = f.view();
  Rng rng = Rng::for_sample(5, 1, 2);
  for (int i = 0; i < 2000; ++i) guide_record(g, 0, uint32_t(rng.next_u32() % g.stride), rng.uniform() * 5.f);
  f.fold();
  std::ostringstream out(std::ios::binary);
  f.save(out, kScene);
  return out.str();
}

GuideField load(const std::string& bytes) {
  std::istringstream in(bytes, std::ios::binary);
  return GuideField::load(in, kScene);
}

// The load fails with one line holding `expected`.
void expect_refused(const std::string& bytes, const std::string& expected) {
  try {
    load(bytes);
    ADD_FAILURE() << "loaded; expected an error with: " << expected;
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(expected), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(GuideFile, TheLayoutTheseTestsDamageIsTheSavedOne) {
  const std::string file = learned_file();
  EXPECT_EQ(guide_payload_get<uint32_t>(file, kGuideGridAt), 12u);
  EXPECT_EQ(guide_payload_get<float>(file, kGuideFloorAt), GuideConfig{}.floor);
  EXPECT_EQ(guide_payload_get<float>(file, kGuideProbAt), GuideConfig{}.guide_prob);
  EXPECT_EQ(guide_payload_get<uint64_t>(file, kGuideNodesAt), 14u);
  EXPECT_EQ(guide_payload_get<uint64_t>(file, guide_splits_at(file)), 1u);
  EXPECT_EQ(guide_resealed(file), file);
}

TEST(GuideFile, ValidFileRoundTripsByteForByte) {
  const std::string file = learned_file();
  GuideField back = load(file);
  std::ostringstream again(std::ios::binary);
  back.save(again, kScene);
  EXPECT_EQ(again.str(), file);
  EXPECT_TRUE(back == load(again.str()));
}

// Version 4 held the same fields without a size or checksum: read with the
// same range checks, it gives the same field.
TEST(GuideFile, VersionFourLoadsWithTheSameRangeChecks) {
  const std::string file = learned_file();
  EXPECT_TRUE(load(guide_as_version4(file)) == load(file));
  const std::string nan = guide_payload_set(file, guide_value_at(file, 3), std::numeric_limits<float>::quiet_NaN());
  expect_refused(guide_as_version4(nan), "corrupt guide cache (cell 0, entry 3: value nan)");
}

TEST(GuideFile, NaNIsRefused) {
  const std::string file = learned_file();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  expect_refused(guide_payload_set(file, guide_value_at(file, 3), nan), "corrupt guide cache (cell 0, entry 3: value nan)");
  expect_refused(guide_payload_set(file, kGuideFloorAt, nan), "corrupt guide cache (the floor is nan, not in [0, 1])");
}

TEST(GuideFile, InfIsRefused) {
  const std::string file = learned_file();
  const float inf = std::numeric_limits<float>::infinity();
  const size_t entry = 2 * 155 + 7;  // cell 2 (stride: 144 bins, 3 lights, 8 statistics)
  expect_refused(guide_payload_set(file, guide_value_at(file, entry), inf), "(cell 2, entry 7: value inf)");
  expect_refused(guide_payload_set(file, kGuideFixedScaleAt, inf), "fixed-point scale inf and largest target");
  // Finite values whose sum leaves a float's range.
  std::string huge = file;
  for (size_t e = 0; e < 144; ++e) huge = guide_payload_set(huge, guide_value_at(file, 155 + e), 3e38f);
  expect_refused(huge, "(cell 1: its values sum past a float's range)");
}

TEST(GuideFile, ProbabilitiesOutsideZeroOneAndNegativeValuesAreRefused) {
  const std::string file = learned_file();
  expect_refused(guide_payload_set(file, kGuideProbAt, -0.5f), "(the guide probability is -0.5, not in [0, 1])");
  expect_refused(guide_payload_set(file, kGuideFloorAt, 1.5f), "(the floor is 1.5, not in [0, 1])");
  expect_refused(guide_payload_set(file, kGuideNeeMinProbAt, -1e-3f), "least next-event probability is -0.001");
  expect_refused(guide_payload_set(file, guide_value_at(file, 10), -2.f), "(cell 0, entry 10: value -2)");
}

TEST(GuideFile, InconsistentCountsAreRefused) {
  const std::string file = learned_file();
  expect_refused(guide_payload_set(file, guide_splits_at(file), uint64_t{3}), "(3 splits counted for 1 made)");
  // Two leaves (roots 1 and 2) owning one cell.
  expect_refused(guide_payload_set(file, guide_node_at(2) + 4, int32_t{1}), "(leaf 2 and its cell 1)");
  // Root 0 split (its children are nodes 6 to 13): children that start at itself.
  ASSERT_EQ(guide_payload_get<int32_t>(file, guide_node_at(0)), 6);
  expect_refused(guide_payload_set(file, guide_node_at(0), int32_t{0}), "(inner node 0 and its children at 0)");
  // bins that do not fit the grid.
  expect_refused(guide_payload_set(file, kGuideGridAt, uint32_t{11}), "(144 direction bins for a grid of 11)");
}

// Any one damaged byte, wherever it is, is an error: in the payload the
// checksum finds it (the fingerprint too: it is no other scene's file).
TEST(GuideFile, AFlippedByteAnywhereIsRefused) {
  const std::string file = learned_file();
  for (size_t i = 0; i < file.size(); ++i)
    for (unsigned char mask : {0xffu, 0x01u, 0x80u}) {
      std::string damaged = file;
      damaged[i] = static_cast<char>(damaged[i] ^ mask);
      try {
        load(damaged);
        ADD_FAILURE() << "byte " << i << " ^ " << int(mask) << " loaded";
      } catch (const std::runtime_error& e) {
        if (i >= kGuidePayloadAt - 8) {
          EXPECT_NE(std::string(e.what()).find("checksum mismatch"), std::string::npos) << i << ": " << e.what();
        }
      }
    }
}

TEST(GuideFile, ATruncatedFileIsRefused) {
  const std::string file = learned_file();
  for (size_t n = 0; n < file.size(); ++n) EXPECT_THROW(load(file.substr(0, n)), std::runtime_error) << n;
  const size_t payload = file.size() - kGuidePayloadAt;
  expect_refused(file.substr(0, kGuidePayloadAt + 100),
                 "truncated guide cache (100 of its " + std::to_string(payload) + " payload bytes)");
  expect_refused(file.substr(0, file.size() - 1),
                 "truncated guide cache (" + std::to_string(payload - 1) + " of its " + std::to_string(payload) + " payload bytes)");
  expect_refused(file + "x", "corrupt guide cache (1 byte after its end)");
}

}  // namespace
}  // namespace tessera
