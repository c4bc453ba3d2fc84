// logInfo / formatLogInfo on a synthetic log whose counts, rates and gaps are
// worked out by hand.

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "logs/log_info.h"
#include "tests/logs/log_test_util.h"

namespace nadir::logs {
namespace {

using test::Event;

constexpr std::int64_t kT0 = 1'700'000'000'000'000;  // first event, UNIX time
constexpr std::int64_t kSim0 = 5'000'000;            // sim time of the first event

// IMU at 100 Hz over 1 s with samples 41..49 missing (a 0.1 s gap after 0.40 s),
// 40-byte payloads; POSE at 10 Hz from 0.05 s, 100 bytes; SHORT once at 0.5 s
// with 4 bytes (too short to carry a utime). Message utime = sim time.
std::vector<Event> infoEvents() {
  std::vector<Event> events;
  for (int k = 0; k <= 100; ++k) {
    if (k >= 41 && k <= 49) continue;
    const std::int64_t dt = k * 10'000;
    events.push_back({kT0 + dt, "IMU", test::payload(40, kSim0 + dt)});
  }
  for (int j = 0; j < 10; ++j) {
    const std::int64_t dt = 50'000 + j * 100'000;
    events.push_back({kT0 + dt, "POSE", test::payload(100, kSim0 + dt)});
  }
  events.push_back({kT0 + 500'000, "SHORT", test::payload(4, 0)});
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    return a.timestamp_utime < b.timestamp_utime;
  });
  return events;
}

const ChannelInfo& channel(const LogInfo& info, const std::string& name) {
  for (const ChannelInfo& c : info.channels)
    if (c.channel == name) return c;
  throw std::runtime_error("no channel " + name);
}

// Whole-log figures: 92 + 10 + 1 events over 1 s; size = 92*71 + 10*132 + 37 bytes.
TEST(LogInfo, WholeLogCountsSpanAndSize) {
  const std::string path = test::tempPath("info.lcmlog");
  test::writeLog(path, infoEvents());
  const LogInfo info = logInfo(path);
  EXPECT_EQ(info.events, 103);
  EXPECT_EQ(info.file_bytes, 92 * 71 + 10 * 132 + 37);
  EXPECT_EQ(info.start_utime, kT0);
  EXPECT_EQ(info.end_utime, kT0 + 1'000'000);
  EXPECT_DOUBLE_EQ(info.duration_s, 1.0);
  EXPECT_EQ(info.backward_steps, 0);
  EXPECT_EQ(info.messages_with_utime, 102);
  EXPECT_EQ(info.message_min_utime, kSim0);
  EXPECT_EQ(info.message_max_utime, kSim0 + 1'000'000);
  EXPECT_TRUE(info.damage.empty());
  EXPECT_EQ(info.damage_report, "");
  ASSERT_EQ(info.channels.size(), 3u);
  EXPECT_EQ(info.channels[0].channel, "IMU");  // sorted by name
  EXPECT_EQ(info.channels[1].channel, "POSE");
  EXPECT_EQ(info.channels[2].channel, "SHORT");
}

// IMU: 92 messages over 1 s is (92-1)/1 = 91 Hz; largest gap 0.40 -> 0.50 s.
TEST(LogInfo, ChannelRateAndLargestGap) {
  const std::string path = test::tempPath("info_rates.lcmlog");
  test::writeLog(path, infoEvents());
  const LogInfo info = logInfo(path);

  const ChannelInfo& imu = channel(info, "IMU");
  EXPECT_EQ(imu.messages, 92);
  EXPECT_EQ(imu.bytes, 92 * 40);
  EXPECT_EQ(imu.first_utime, kT0);
  EXPECT_EQ(imu.last_utime, kT0 + 1'000'000);
  EXPECT_NEAR(imu.rate_hz, 91.0, 1e-9);
  EXPECT_NEAR(imu.max_gap_s, 0.1, 1e-12);
  EXPECT_EQ(imu.max_gap_from_utime, kT0 + 400'000);
  EXPECT_EQ(imu.message_min_utime, kSim0);
  EXPECT_EQ(imu.message_max_utime, kSim0 + 1'000'000);

  // POSE: 10 messages from 0.05 to 0.95 s: 9 / 0.9 = 10 Hz, every gap 0.1 s, first one kept.
  const ChannelInfo& pose = channel(info, "POSE");
  EXPECT_EQ(pose.messages, 10);
  EXPECT_EQ(pose.bytes, 1000);
  EXPECT_NEAR(pose.rate_hz, 10.0, 1e-9);
  EXPECT_NEAR(pose.max_gap_s, 0.1, 1e-12);
  EXPECT_EQ(pose.max_gap_from_utime, kT0 + 50'000);

  // SHORT: one message has no rate, no gap and no utime.
  const ChannelInfo& one = channel(info, "SHORT");
  EXPECT_EQ(one.messages, 1);
  EXPECT_EQ(one.rate_hz, 0.0);
  EXPECT_EQ(one.max_gap_s, 0.0);
  EXPECT_EQ(one.messages_with_utime, 0);
}

// The table names every channel with its rate and says the log is clean.
TEST(LogInfo, FormattedTableShowsChannelsAndDamage) {
  const std::string path = test::tempPath("info_table.lcmlog");
  test::writeLog(path, infoEvents());
  const std::string text = formatLogInfo(logInfo(path));
  EXPECT_NE(text.find("103 events"), std::string::npos) << text;
  EXPECT_NE(text.find("IMU"), std::string::npos) << text;
  EXPECT_NE(text.find("91.00"), std::string::npos) << text;
  EXPECT_NE(text.find("10.00"), std::string::npos) << text;
  EXPECT_NE(text.find("0.400"), std::string::npos) << text;  // where IMU's gap starts
  EXPECT_NE(text.find("5.000000 .. 6.000000"), std::string::npos) << text;  // message time
  EXPECT_NE(text.find("damage: none"), std::string::npos) << text;
}

// Event times that step backwards are counted, not reordered.
TEST(LogInfo, BackwardStepsAreCounted) {
  const std::string path = test::tempPath("info_backwards.lcmlog");
  test::writeLog(path, {{100, "A", {}}, {300, "A", {}}, {200, "A", {}}, {400, "A", {}}});
  const LogInfo info = logInfo(path);
  EXPECT_EQ(info.backward_steps, 1);
  EXPECT_EQ(info.start_utime, 100);
  EXPECT_EQ(info.end_utime, 400);
  EXPECT_NE(formatLogInfo(info).find("backwards 1 times"), std::string::npos);
}

// An empty file is an empty, clean log.
TEST(LogInfo, EmptyLog) {
  const std::string path = test::tempPath("info_empty.lcmlog");
  test::writeLog(path, {});
  const LogInfo info = logInfo(path);
  EXPECT_EQ(info.events, 0);
  EXPECT_TRUE(info.channels.empty());
  EXPECT_NE(formatLogInfo(info).find("0 events"), std::string::npos);
}

}  // namespace
}  // namespace nadir::logs
