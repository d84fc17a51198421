// The master's ledger of a pass's tiles: each is done once, by the rank that
// held it; a silent rank's tiles go to the next one who asks, and its late
// results are refused.
#include <gtest/gtest.h>

#include "master/tile_ledger.h"

namespace tessera {
namespace {

TEST(TileLedger, TilesGoOutInOrderAndAreDoneOnceByTheirHolder) {
  TileLedger ledger(3);
  size_t a = 9, b = 9;
  ASSERT_TRUE(ledger.issue(1, &a));
  ASSERT_TRUE(ledger.issue(2, &b));
  EXPECT_EQ(a, 0u);
  EXPECT_EQ(b, 1u);
  EXPECT_FALSE(ledger.complete(2, 0)) << "rank 2 does not hold tile 0";
  EXPECT_TRUE(ledger.complete(1, 0));
  EXPECT_FALSE(ledger.complete(1, 0)) << "a tile is done once";
  EXPECT_FALSE(ledger.complete(1, 7)) << "no such tile";
  EXPECT_TRUE(ledger.any_waiting());
  EXPECT_FALSE(ledger.all_done());
}

TEST(TileLedger, ASilentRanksTilesGoFirstToTheNextAndItsLateResultIsRefused) {
  TileLedger ledger(4);
  size_t t = 0;
  ASSERT_TRUE(ledger.issue(2, &t));  // 0
  ASSERT_TRUE(ledger.issue(2, &t));  // 1
  ASSERT_TRUE(ledger.complete(2, 0));
  ASSERT_TRUE(ledger.issue(1, &t));  // 2
  EXPECT_EQ(ledger.take_back(2), 1u) << "only the tile it holds, not the one it finished";
  size_t next = 9;
  ASSERT_TRUE(ledger.issue(0, &next));
  EXPECT_EQ(next, 1u) << "the tile taken back goes out before the ones never issued";
  EXPECT_FALSE(ledger.complete(2, 1)) << "the late result of the silent rank";
  EXPECT_TRUE(ledger.complete(0, 1));
  EXPECT_EQ(ledger.done_by(2), std::vector<size_t>{0});
  EXPECT_EQ(ledger.done_by(0), std::vector<size_t>{1});
  ASSERT_TRUE(ledger.issue(1, &t));  // 3
  EXPECT_FALSE(ledger.issue(1, &t));
  EXPECT_TRUE(ledger.complete(1, 2));
  EXPECT_TRUE(ledger.complete(1, 3));
  EXPECT_TRUE(ledger.all_done());
  EXPECT_FALSE(ledger.any_waiting());
}

}  // namespace
}  // namespace tessera
