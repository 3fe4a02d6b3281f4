// The time left that the progress bar shows: the rate so far carried to the end, said only once enough
// of the work is done to judge the rate by.
#include <gtest/gtest.h>

#include "libcore/util/progress.h"

namespace hairgen {
namespace {

TEST(Progress, TimeLeftIsTheRateSoFarCarriedToTheEnd) {
  // 10 of 40 frames in 30 s: 3 s a frame, 30 frames left.
  ASSERT_TRUE(estimatedSecondsLeft(10, 40, 30.0));
  EXPECT_DOUBLE_EQ(*estimatedSecondsLeft(10, 40, 30.0), 90.0);
  EXPECT_DOUBLE_EQ(*estimatedSecondsLeft(1, 2, 5.0), 5.0);
  EXPECT_DOUBLE_EQ(*estimatedSecondsLeft(999, 1000, 999.0), 1.0);
}

TEST(Progress, NoTimeLeftBeforeEnoughIsDoneOrOnceAllIs) {
  EXPECT_FALSE(estimatedSecondsLeft(0, 100, 50.0));              // nothing done: no rate
  EXPECT_FALSE(estimatedSecondsLeft(4, 100, 1.0));               // 4 % in 1 s: too little to judge
  EXPECT_TRUE(estimatedSecondsLeft(5, 100, 1.0));                // 5 %
  EXPECT_TRUE(estimatedSecondsLeft(1, 1000, kEtaAfterSeconds));  // 0.1 %, but 2 s of it
  EXPECT_FALSE(estimatedSecondsLeft(100, 100, 9.0));             // done
  EXPECT_FALSE(estimatedSecondsLeft(120, 100, 9.0));
  EXPECT_FALSE(estimatedSecondsLeft(0, 0, 9.0));
}

TEST(Progress, DurationsReadAsSecondsMinutesHours) {
  EXPECT_EQ(formatDuration(0.4), "0 s");
  EXPECT_EQ(formatDuration(42.4), "42 s");
  EXPECT_EQ(formatDuration(59.6), "1 min 00 s");
  EXPECT_EQ(formatDuration(185.0), "3 min 05 s");
  EXPECT_EQ(formatDuration(7620.0), "2 h 07 min");
  EXPECT_EQ(formatDuration(-3.0), "0 s");
}

}  // namespace
}  // namespace hairgen
