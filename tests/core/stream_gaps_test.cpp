// StreamGaps: messages lost on the way, counted from the messages' own times.
#include "core/stream_gaps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/bus.h"

namespace nadir::core {
namespace {

// 31 frames/s on a 400 Hz sim clock: frames at the first 2.5 ms step at or
// after k / 31 s, so intervals of 30 or 32.5 ms, never exactly 32.26.
std::int64_t frameUtime(int k) {
  const double t_us = static_cast<double>(k) * 1e6 / 31.0;
  const auto steps = static_cast<std::int64_t>(std::ceil(t_us / 2500.0 - 1e-9));
  return steps * 2500;
}

// Frames 0..99 at a given rate minus 10, 11, 12 and 50: 4 lost in 2 places.
TEST(StreamGaps, CountsLostFramesAtAGivenRate) {
  StreamGaps gaps(31.0);
  for (int k = 0; k < 100; ++k) {
    if (k == 10 || k == 11 || k == 12 || k == 50) continue;
    gaps.add(frameUtime(k));
  }
  EXPECT_EQ(gaps.received(), 96);
  EXPECT_EQ(gaps.missing(), 4);
  EXPECT_EQ(gaps.gaps(), 2);
  EXPECT_EQ(gaps.outOfOrder(), 0);
  EXPECT_DOUBLE_EQ(gaps.rateHz(), 31.0);
  EXPECT_FALSE(gaps.learnt());
}

// The same stream with no rate given: learnt from the first 16 intervals
// (one of them a gap, counted once the rate is known).
TEST(StreamGaps, LearnsTheRateAndCountsTheGapsItLearntFrom) {
  StreamGaps gaps;
  for (int k = 0; k < 100; ++k) {
    if (k == 3 || k == 60 || k == 61) continue;
    gaps.add(frameUtime(k));
  }
  EXPECT_TRUE(gaps.learnt());
  EXPECT_FALSE(gaps.irregular());
  // The median interval of 30 / 32.5 ms steps: one of the two.
  EXPECT_TRUE(gaps.rateHz() == 1e6 / 32500.0 || gaps.rateHz() == 1e6 / 30000.0) << gaps.rateHz();
  EXPECT_EQ(gaps.missing(), 3);
  EXPECT_EQ(gaps.gaps(), 2);
}

// Nothing is counted before the rate is known: 16 messages make 15 intervals.
TEST(StreamGaps, CountsNothingWhileLearning) {
  StreamGaps gaps;
  for (int k = 0; k < 16; ++k) gaps.add(k * 2 * 10000);  // every other one of 100 Hz
  EXPECT_DOUBLE_EQ(gaps.rateHz(), 0.0);
  EXPECT_EQ(gaps.missing(), 0);
}

// Intervals with no common beat (commands sent by hand) are not a stream.
TEST(StreamGaps, IrregularTimesAreNotCounted) {
  StreamGaps gaps;
  const std::vector<std::int64_t> times = {0,       130000,  170000,  510000,  530000,  990000,
                                           1400000, 1410000, 1777000, 2100000, 2333000, 2900000,
                                           3050000, 3120000, 3700000, 3790000, 4400000, 5000000};
  for (const std::int64_t t : times) gaps.add(t);
  EXPECT_TRUE(gaps.irregular());
  EXPECT_DOUBLE_EQ(gaps.rateHz(), 0.0);
  EXPECT_EQ(gaps.missing(), 0);
}

// A log played in a loop starts again from its beginning: a new start, not a
// loss; a message one period late is out of order and not counted twice.
TEST(StreamGaps, ALoopIsANewStartAndALateMessageIsOutOfOrder) {
  StreamGaps gaps(100.0);
  for (int loop = 0; loop < 2; ++loop) {
    for (int k = 0; k < 50; ++k) gaps.add(k * 10000);
  }
  EXPECT_EQ(gaps.missing(), 0);
  EXPECT_EQ(gaps.outOfOrder(), 1);
  // 0, 10, 30, 20, 40, 50 ms: 30 comes before 20, which the stream goes on
  // from: 30 is out of order, and the interval 20 -> 40 spans it (one lost: a
  // message out of order counts, once, never hidden).
  StreamGaps late(100.0);
  for (const std::int64_t t : {0, 10000, 30000, 20000, 40000, 50000}) late.add(t);
  EXPECT_EQ(late.outOfOrder(), 1);
  EXPECT_EQ(late.missing(), 1);
}

// A message whose time is any 64 bits (a foreign or corrupt one, found by the
// sanitizer build: the difference overflowed) is no loss. At 100 Hz: 0..40 ms,
// a time near the end of int64 (more than an hour ahead: out of order), 50 ms
// (a step back: out of order, a new start), 60 ms, a time near the start of
// int64 (back: out of order), 70 ms (more than an hour ahead: out of order),
// 80 ms. Nothing is missing.
TEST(StreamGaps, ATimeFromElsewhereIsNoLoss) {
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
  StreamGaps gaps(100.0);
  for (const std::int64_t t :
       {0L, 10000L, 20000L, 30000L, 40000L, kMax - 5, 50000L, 60000L, kMin + 5, 70000L, 80000L}) {
    gaps.add(t);
  }
  EXPECT_EQ(gaps.missing(), 0);
  EXPECT_EQ(gaps.gaps(), 0);
  EXPECT_EQ(gaps.outOfOrder(), 4);
  // While learning, a wild time is left out of the intervals the rate comes from.
  StreamGaps learnt;
  for (int k = 0; k <= StreamGaps::kLearnIntervals; ++k) learnt.add(k == 8 ? kMax : k * 10000);
  EXPECT_NEAR(learnt.rateHz(), 100.0, 1e-9);
}

// At 100 Hz, a message stamped 60 s ahead between 40 and 50 ms (another
// sender's, or a corrupt one) is out of order, not 5999 lost: the stream went
// on from before it. A real gap (60 and 70 ms lost) counts 2 once the stream
// goes on after it, and is not counted while only its first message has come.
TEST(StreamGaps, AJumpAheadCountsOnlyWhenTheStreamGoesOnAfterIt) {
  StreamGaps gaps(100.0);
  for (const std::int64_t t : {0L, 10000L, 20000L, 30000L, 40000L, 60'000'000L, 50000L, 80000L}) {
    gaps.add(t);
  }
  EXPECT_EQ(gaps.missing(), 0);  // 80 ms waits for the stream to go on
  EXPECT_EQ(gaps.outOfOrder(), 1);
  gaps.add(90000);
  EXPECT_EQ(gaps.missing(), 2);
  EXPECT_EQ(gaps.gaps(), 1);
  EXPECT_EQ(gaps.outOfOrder(), 1);
}

// The bus counts gaps per channel from every message it receives, at the
// rate it was told or a learnt one.
TEST(StreamGaps, TheBusCountsEachChannelsGaps) {
  auto bus = openBus("memq://");
  bus->expectRate("CAMERA", 31.0);
  const auto send = [&](const std::string& channel, std::int64_t utime) {
    std::vector<std::uint8_t> bytes(24, 0);
    for (int i = 0; i < 8; ++i) bytes[8 + i] = static_cast<std::uint8_t>(utime >> (56 - 8 * i));
    bus->publish(channel, bytes.data(), bytes.size(), utime);
  };
  for (int k = 0; k < 40; ++k) {
    if (k != 20) send("CAMERA", frameUtime(k));
    if (k != 30 && k != 31) send("RANGE", k * 20000);
  }
  bus->handleAvailable();
  const auto stats = bus->stats();
  EXPECT_EQ(stats.at("CAMERA").messages, 39u);
  EXPECT_EQ(stats.at("CAMERA").missing, 1);
  EXPECT_DOUBLE_EQ(stats.at("CAMERA").rate_hz, 31.0);
  EXPECT_EQ(stats.at("RANGE").missing, 2);
  EXPECT_EQ(stats.at("RANGE").gaps, 1);
  EXPECT_DOUBLE_EQ(stats.at("RANGE").rate_hz, 50.0);
}

}  // namespace
}  // namespace nadir::core
