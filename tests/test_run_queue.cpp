#include <gtest/gtest.h>

#include "lowlevel/run_queue.h"

using ll::RunRing;

TEST(RunQueue, HoldsCapacityMinusOneRunsInOrder) {
    RunRing<8> q;
    q.clear();
    for (uint8_t i = 0; i < 7; ++i) {
        ASSERT_FALSE(q.full());
        q.push(ll::Run{1, 0, static_cast<uint8_t>(i + 1), 200});
    }
    EXPECT_TRUE(q.full());
    for (uint8_t i = 0; i < 7; ++i) {
        ASSERT_FALSE(q.empty());
        EXPECT_EQ(q.front().count, i + 1);
        q.pop();
    }
    EXPECT_TRUE(q.empty());
}

TEST(RunQueue, IndicesWrapAroundWithoutLosingRuns) {
    RunRing<4> q;
    q.clear();
    for (int round = 0; round < 10; ++round) {
        q.push(ll::Run{1, 0, static_cast<uint8_t>(round), 300});
        q.push(ll::Run{2, 1, static_cast<uint8_t>(round + 1), 301});
        ASSERT_EQ(q.used(), 2);
        EXPECT_EQ(q.front().count, round);
        q.pop();
        EXPECT_EQ(q.front().steps, 2);
        q.pop();
    }
    EXPECT_TRUE(q.empty());
}
