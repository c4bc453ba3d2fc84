// LogRecorder: what arrives on a bus goes into an LCM log whole and in order,
// and what was lost on the way is counted per channel from the messages' times.

#include "logs/log_recorder.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/lcm_log.h"
#include "tests/logs/log_test_util.h"

namespace nadir::logs {
namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;

// CAMERA at 20 Hz with frames 5, 6 and 30 missing, RANGE at 40 Hz whole, and
// a heartbeat: each message in the log as sent; 3 frames lost in 2 gaps.
TEST(LogRecorder, RecordsWhatArrivesAndCountsWhatWasLost) {
  const std::string path = test::tempPath("recorded.lcmlog");
  auto bus = core::openBus("memq://");
  std::vector<test::Event> sent;
  {
    LogRecorder recorder(*bus, path, {.expected_rates_hz = {{"CAMERA", 20.0}}});
    const auto send = [&](const std::string& channel, std::size_t size, std::int64_t utime) {
      sent.push_back({0, channel, test::payload(size, utime)});
      bus->publish(channel, sent.back().data.data(), size, utime);
    };
    for (int k = 0; k < 40; ++k) {
      if (k != 5 && k != 6 && k != 30) send("CAMERA", 1000, kT0 + k * 50'000);
      send("RANGE", 40, kT0 + k * 50'000);
      send("RANGE", 40, kT0 + k * 50'000 + 25'000);
      if (k % 20 == 0) send("NADIR_HEARTBEAT", 30, kT0 + k * 50'000);
    }
    EXPECT_EQ(bus->handleAvailable(), static_cast<int>(sent.size()));
    EXPECT_EQ(recorder.eventsWritten(), static_cast<std::int64_t>(sent.size()));
    EXPECT_GT(recorder.lastReceiveUtime(), 0);

    const auto arrivals = recorder.arrivals();
    EXPECT_EQ(arrivals.count("NADIR_HEARTBEAT"), 0u);
    EXPECT_EQ(arrivals.at("CAMERA").messages, 37u);
    EXPECT_EQ(arrivals.at("CAMERA").missing, 3);
    EXPECT_EQ(arrivals.at("CAMERA").gaps, 2);
    EXPECT_EQ(arrivals.at("RANGE").messages, 80u);
    EXPECT_EQ(arrivals.at("RANGE").missing, 0);
    EXPECT_DOUBLE_EQ(arrivals.at("RANGE").rate_hz, 40.0);  // learnt: every 25 ms
    EXPECT_EQ(core::describeLosses(arrivals), "lost CAMERA 3 of 40 (2 gaps)");
  }
  core::LcmLogReader reader(path);
  std::size_t i = 0;
  while (const auto event = reader.next()) {
    ASSERT_LT(i, sent.size());
    EXPECT_EQ(event->channel, sent[i].channel);
    EXPECT_EQ(event->data, sent[i].data);
    ++i;
  }
  EXPECT_EQ(i, sent.size());
}

// Only the channels asked for are recorded; a log that cannot be made is named.
TEST(LogRecorder, RecordsTheChannelsAskedForAndNamesAPathItCannotWrite) {
  const std::string path = test::tempPath("recorded_some.lcmlog");
  auto bus = core::openBus("memq://");
  {
    LogRecorder recorder(*bus, path, {.channels = "POSE_.*"});
    const auto data = test::payload(24, kT0);
    for (const char* channel : {"POSE_TRUTH", "IMU", "POSE_VO"}) {
      bus->publish(channel, data.data(), data.size(), kT0);
    }
    bus->handleAvailable();
    EXPECT_EQ(recorder.eventsWritten(), 2);
    EXPECT_EQ(recorder.arrivals().count("IMU"), 0u);
  }
  core::LcmLogReader reader(path);
  EXPECT_EQ(reader.next()->channel, "POSE_TRUTH");
  EXPECT_EQ(reader.next()->channel, "POSE_VO");
  EXPECT_FALSE(reader.next().has_value());

  try {
    LogRecorder recorder(*bus, "/nonexistent-dir/x.lcmlog");
    ADD_FAILURE() << "made a log in a folder that does not exist";
  } catch (const core::LogError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent-dir/x.lcmlog"), std::string::npos);
  }
}

// Nothing lost: the line says on how many channels with a rate it looked.
TEST(LogRecorder, NothingLostSaysOnHowManyChannels) {
  std::map<std::string, core::ChannelStats> stats;
  stats["A"].rate_hz = 10.0;
  stats["B"].rate_hz = 0.0;  // irregular: not counted
  stats["C"].rate_hz = 5.0;
  EXPECT_EQ(core::describeLosses(stats), "nothing lost on 2 channels");
  EXPECT_EQ(core::describeLosses(stats, "C"), "nothing lost on 1 channel");
}

}  // namespace
}  // namespace nadir::logs
