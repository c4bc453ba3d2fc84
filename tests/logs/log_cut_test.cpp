// cutLog: windows in time and sets of channels, re-read by nadir's reader and
// by LCM's own eventlog reader (what lcm-logplayer uses).

#include <lcm/eventlog.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/lcm_log.h"
#include "logs/log_cut.h"
#include "tests/logs/log_test_util.h"

namespace nadir::logs {
namespace {

using test::Event;

constexpr std::int64_t kT0 = 1'700'000'000'000'000;

// IMU every 0.1 s from 0 to 1.0 s (11 events, 24 bytes), CAM every 0.25 s
// from 0.1 s (0.10, 0.35, 0.60, 0.85: 4 events, 64 bytes), time order.
std::vector<Event> cutEvents() {
  std::vector<Event> events;
  for (int k = 0; k <= 10; ++k) {
    const std::int64_t dt = k * 100'000;
    events.push_back({kT0 + dt, "IMU", test::payload(24, dt)});
    if (k == 1 || k == 3 || k == 6 || k == 8) {
      const std::int64_t cam_dt = k == 1 ? 100'000 : k == 3 ? 350'000 : k == 6 ? 600'000 : 850'000;
      events.push_back({kT0 + cam_dt, "CAM", test::payload(64, cam_dt)});
    }
  }
  return events;
}

std::vector<core::LogEvent> readAll(const std::string& path) {
  core::LcmLogReader reader(path);
  std::vector<core::LogEvent> events;
  while (auto event = reader.next()) events.push_back(std::move(*event));
  EXPECT_EQ(reader.damageReport(), "");
  return events;
}

std::vector<std::int64_t> timesOf(const std::vector<core::LogEvent>& events) {
  std::vector<std::int64_t> times;
  for (const auto& e : events) times.push_back(e.timestamp_utime - kT0);
  return times;
}

// [0.3 s, 0.7 s): IMU 0.3..0.6 and CAM 0.35, 0.60; renumbered 0..5; bytes unchanged.
TEST(LogCut, TimeWindowIsHalfOpenAndRenumbered) {
  const std::string in = test::tempPath("cut_in.lcmlog");
  const std::string out = test::tempPath("cut_window.lcmlog");
  const std::vector<Event> events = cutEvents();
  test::writeLog(in, events);
  CutOptions options;
  options.start_s = 0.3;
  options.end_s = 0.7;
  const CutResult result = cutLog(in, out, options);
  EXPECT_EQ(result.events_read, 15);
  EXPECT_EQ(result.events_written, 6);
  EXPECT_EQ(result.first_written_utime, kT0 + 300'000);
  EXPECT_EQ(result.last_written_utime, kT0 + 600'000);
  EXPECT_EQ(result.written_per_channel.at("IMU"), 4);
  EXPECT_EQ(result.written_per_channel.at("CAM"), 2);
  EXPECT_EQ(result.bytes_written, 4 * (28 + 3 + 24) + 2 * (28 + 3 + 64));
  EXPECT_TRUE(result.damage.empty());

  const std::vector<core::LogEvent> cut = readAll(out);
  ASSERT_EQ(cut.size(), 6u);
  EXPECT_EQ(timesOf(cut),
            (std::vector<std::int64_t>{300'000, 350'000, 400'000, 500'000, 600'000, 600'000}));
  for (std::size_t i = 0; i < cut.size(); ++i) {
    EXPECT_EQ(cut[i].event_number, static_cast<std::int64_t>(i));
    EXPECT_EQ(cut[i].data,
              test::payload(cut[i].channel == "IMU" ? 24 : 64, cut[i].timestamp_utime - kT0));
  }
}

// Absolute bounds: from kT0 + 0.85 s to the end keeps CAM 0.85, IMU 0.9, 1.0.
TEST(LogCut, AbsoluteUtimeBounds) {
  const std::string in = test::tempPath("cut_in_abs.lcmlog");
  const std::string out = test::tempPath("cut_abs.lcmlog");
  test::writeLog(in, cutEvents());
  CutOptions options;
  options.start_s = 0.0;  // overridden by start_utime
  options.start_utime = kT0 + 850'000;
  const CutResult result = cutLog(in, out, options);
  EXPECT_EQ(result.events_written, 3);
  EXPECT_EQ(timesOf(readAll(out)), (std::vector<std::int64_t>{850'000, 900'000, 1'000'000}));
}

// Channel include and exclude regexes match whole names.
TEST(LogCut, ByChannel) {
  const std::string in = test::tempPath("cut_in_ch.lcmlog");
  const std::string out = test::tempPath("cut_ch.lcmlog");
  test::writeLog(in, cutEvents());

  CutOptions only_cam;
  only_cam.channels = "CA.*";
  EXPECT_EQ(cutLog(in, out, only_cam).events_written, 4);
  for (const auto& e : readAll(out)) EXPECT_EQ(e.channel, "CAM");

  CutOptions partial_name;
  partial_name.channels = "IM";  // a whole-name match: IMU is not IM
  EXPECT_EQ(cutLog(in, out, partial_name).events_written, 0);
  EXPECT_TRUE(readAll(out).empty());

  CutOptions both_but_imu;
  both_but_imu.channels = "IMU|CAM";
  both_but_imu.exclude = "IMU";
  both_but_imu.end_s = 0.5;
  const CutResult result = cutLog(in, out, both_but_imu);
  EXPECT_EQ(result.events_written, 2);  // CAM 0.10 and 0.35
  EXPECT_EQ(timesOf(readAll(out)), (std::vector<std::int64_t>{100'000, 350'000}));
}

// LCM's own reader reads a cut log event for event (lcm-logplayer can play it).
TEST(LogCut, LcmEventlogReadsTheCut) {
  const std::string in = test::tempPath("cut_in_lcm.lcmlog");
  const std::string out = test::tempPath("cut_lcm.lcmlog");
  test::writeLog(in, cutEvents());
  CutOptions options;
  options.start_s = 0.5;
  ASSERT_EQ(cutLog(in, out, options).events_written, 8);  // IMU 0.5..1.0, CAM 0.60, 0.85
  lcm_eventlog_t* log = lcm_eventlog_create(out.c_str(), "r");
  ASSERT_NE(log, nullptr);
  std::vector<std::int64_t> times;
  while (lcm_eventlog_event_t* event = lcm_eventlog_read_next_event(log)) {
    EXPECT_EQ(event->eventnum, static_cast<std::int64_t>(times.size()));
    times.push_back(event->timestamp - kT0);
    lcm_eventlog_free_event(event);
  }
  lcm_eventlog_destroy(log);
  EXPECT_EQ(times, (std::vector<std::int64_t>{500'000, 600'000, 600'000, 700'000, 800'000, 850'000,
                                              900'000, 1'000'000}));
}

// An empty window, a bad regex and cutting a log into itself are refused.
TEST(LogCut, BadRequestsAreRefused) {
  const std::string in = test::tempPath("cut_in_bad.lcmlog");
  test::writeLog(in, cutEvents());
  CutOptions empty;
  empty.start_s = 0.5;
  empty.end_s = 0.5;
  EXPECT_THROW(cutLog(in, test::tempPath("cut_bad.lcmlog"), empty), std::invalid_argument);
  CutOptions bad_regex;
  bad_regex.channels = "(";
  EXPECT_THROW(cutLog(in, test::tempPath("cut_bad.lcmlog"), bad_regex), std::invalid_argument);
  EXPECT_THROW(cutLog(in, in, CutOptions{}), std::invalid_argument);
  EXPECT_EQ(test::readBytes(in).size(),
            static_cast<std::size_t>(test::eventOffsets(cutEvents()).back()));
}

}  // namespace
}  // namespace nadir::logs
