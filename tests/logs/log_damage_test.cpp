// Damaged logs in all three tools: a log cut off mid-event, garbage inserted
// between events, an overwritten header and a corrupted length field. Each is
// read up to / around the damage, reported with its byte offset, and nothing
// before the damage is lost.

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "logs/log_cut.h"
#include "logs/log_index.h"
#include "logs/log_info.h"
#include "logs/log_player.h"
#include "tests/logs/log_test_util.h"

namespace nadir::logs {
namespace {

using test::Event;

constexpr std::int64_t kT0 = 1'000'000'000;

// Ten events 0.1 s apart on two channels, payloads of 40 + 3 * i bytes.
std::vector<Event> damageEvents() {
  std::vector<Event> events;
  for (int i = 0; i < 10; ++i) {
    events.push_back({kT0 + i * 100'000, i % 2 ? "IMU" : "CAM",
                      test::payload(static_cast<std::size_t>(40 + 3 * i), i * 100'000)});
  }
  return events;
}

std::vector<std::int64_t> indexedTimes(const LogIndex& index) {
  std::vector<std::int64_t> times;
  for (const IndexedEvent& e : index.events) times.push_back((e.timestamp_utime - kT0) / 100'000);
  return times;
}

// Records what a player sends, without any network.
class RecordingBus final : public core::Bus {
 public:
  std::vector<std::int64_t> times;
  std::string url() const override { return "recording://"; }
  void send(std::string_view, const void*, std::size_t, std::int64_t utime) override {
    times.push_back((utime - kT0) / 100'000);
  }
  bool handle(std::chrono::milliseconds) override { return false; }

 protected:
  void addSubscription(const Handler&) override {}
  void removeSubscription(int) override {}
};

// A log cut in half inside event 6's data: events 0..5 are read by index,
// info, cut and play, and each reports the truncation at event 6's offset.
TEST(LogDamage, TruncatedMidEventIsReadUpToTheCutInAllTools) {
  const std::string path = test::tempPath("damage_truncated.lcmlog");
  const std::vector<Event> events = damageEvents();
  test::writeLog(path, events);
  const std::vector<std::int64_t> offsets = test::eventOffsets(events);
  const std::int64_t cut_at = offsets[6] + 28 + 3 + 20;  // header, channel, 20 of 58 data bytes
  std::filesystem::resize_file(path, static_cast<std::uintmax_t>(cut_at));
  const std::string at_byte = "from byte " + std::to_string(offsets[6]);

  const LogIndex index = indexLog(path);
  EXPECT_EQ(indexedTimes(index), (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5}));
  ASSERT_EQ(index.damage.size(), 1u);
  EXPECT_EQ(index.damage[0].kind, core::LogDamage::Kind::kTruncated);
  EXPECT_EQ(index.damage[0].offset, offsets[6]);
  EXPECT_EQ(index.damage[0].bytes, cut_at - offsets[6]);
  EXPECT_NE(index.damage_report.find("truncated"), std::string::npos) << index.damage_report;
  EXPECT_NE(index.damage_report.find(at_byte), std::string::npos) << index.damage_report;
  EXPECT_NE(index.damage_report.find("after 6 whole events"), std::string::npos);

  const LogInfo info = logInfo(path);
  EXPECT_EQ(info.events, 6);
  EXPECT_EQ(info.end_utime, kT0 + 500'000);
  const std::string text = formatLogInfo(info);
  EXPECT_NE(text.find("truncated  " + std::to_string(cut_at - offsets[6]) + " bytes " + at_byte),
            std::string::npos)
      << text;

  const std::string out = test::tempPath("damage_truncated_cut.lcmlog");
  const CutResult cut = cutLog(path, out, CutOptions{});
  EXPECT_EQ(cut.events_read, 6);
  EXPECT_EQ(cut.events_written, 6);
  EXPECT_NE(cut.damage_report.find(at_byte), std::string::npos) << cut.damage_report;
  EXPECT_EQ(indexedTimes(indexLog(out)), (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(indexLog(out).damage_report, "");

  RecordingBus bus;
  std::int64_t now = 0;
  LogPlayer player(path, bus, {}, [&now] { return now; });
  EXPECT_NE(player.damageReport().find(at_byte), std::string::npos);
  now = 10'000'000;
  player.update();
  EXPECT_EQ(bus.times, (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(player.finished());
}

// 37 garbage bytes inserted between events 4 and 5: all ten events are read,
// and the garbage is reported at the byte where event 5 used to start.
TEST(LogDamage, GarbageBetweenEventsIsReadAround) {
  const std::string path = test::tempPath("damage_garbage.lcmlog");
  const std::vector<Event> events = damageEvents();
  test::writeLog(path, events);
  const std::vector<std::int64_t> offsets = test::eventOffsets(events);
  std::vector<std::uint8_t> bytes = test::readBytes(path);
  bytes.insert(bytes.begin() + offsets[5], 37, 0x55);
  test::writeBytes(path, bytes);

  const LogIndex index = indexLog(path);
  EXPECT_EQ(indexedTimes(index), (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  ASSERT_EQ(index.damage.size(), 1u);
  EXPECT_EQ(index.damage[0].kind, core::LogDamage::Kind::kSkipped);
  EXPECT_EQ(index.damage[0].offset, offsets[5]);
  EXPECT_EQ(index.damage[0].bytes, 37);
  EXPECT_EQ(index.events[5].offset, offsets[5] + 37);
  EXPECT_NE(index.damage_report.find("37 bytes from byte " + std::to_string(offsets[5])),
            std::string::npos)
      << index.damage_report;

  const std::string out = test::tempPath("damage_garbage_cut.lcmlog");
  const CutResult cut = cutLog(path, out, CutOptions{});
  EXPECT_EQ(cut.events_written, 10);
  EXPECT_EQ(cut.damage.size(), 1u);
  EXPECT_EQ(test::readBytes(out).size(), static_cast<std::size_t>(offsets.back()));

  // The player reads events after the damage by their indexed offsets.
  RecordingBus bus;
  std::int64_t now = 0;
  LogPlayer player(path, bus, {}, [&now] { return now; });
  player.seek(0.7);
  player.stepTo(kT0 + 900'000);
  EXPECT_EQ(bus.times, (std::vector<std::int64_t>{7, 8, 9}));
  player.seek(0.0);
  player.stepTo(kT0 + 900'000);
  EXPECT_EQ(bus.times.size(), 13u);
}

// Event 4's header overwritten with garbage: event 4 is lost, the rest kept.
TEST(LogDamage, OverwrittenHeaderLosesOnlyThatEvent) {
  const std::string path = test::tempPath("damage_header.lcmlog");
  const std::vector<Event> events = damageEvents();
  test::writeLog(path, events);
  const std::vector<std::int64_t> offsets = test::eventOffsets(events);
  std::vector<std::uint8_t> bytes = test::readBytes(path);
  std::fill(bytes.begin() + offsets[4], bytes.begin() + offsets[4] + 10, 0xAA);
  test::writeBytes(path, bytes);

  const LogInfo info = logInfo(path);
  EXPECT_EQ(info.events, 9);
  ASSERT_EQ(info.damage.size(), 1u);
  EXPECT_EQ(info.damage[0].offset, offsets[4]);
  EXPECT_EQ(info.damage[0].bytes, offsets[5] - offsets[4]);
  EXPECT_EQ(indexedTimes(indexLog(path)), (std::vector<std::int64_t>{0, 1, 2, 3, 5, 6, 7, 8, 9}));
}

// Event 4's data length grown by 8 bytes (still inside the file): event 5
// then starts inside event 4, so event 4 is the damage and event 5 survives.
TEST(LogDamage, CorruptedLengthDoesNotSwallowTheNextEvent) {
  const std::string path = test::tempPath("damage_length.lcmlog");
  const std::vector<Event> events = damageEvents();
  test::writeLog(path, events);
  const std::vector<std::int64_t> offsets = test::eventOffsets(events);
  std::vector<std::uint8_t> bytes = test::readBytes(path);
  bytes[static_cast<std::size_t>(offsets[4] + 27)] += 8;  // low byte of the data length
  test::writeBytes(path, bytes);

  const LogIndex index = indexLog(path);
  EXPECT_EQ(indexedTimes(index), (std::vector<std::int64_t>{0, 1, 2, 3, 5, 6, 7, 8, 9}));
  ASSERT_EQ(index.damage.size(), 1u);
  EXPECT_EQ(index.damage[0].offset, offsets[4]);
  EXPECT_EQ(index.damage[0].bytes, offsets[5] - offsets[4]);
}

// A couple of stray bytes after the last whole event are a truncated tail;
// every event is kept.
TEST(LogDamage, StrayTailBytesAfterTheLastEvent) {
  const std::string path = test::tempPath("damage_tail.lcmlog");
  const std::vector<Event> events = damageEvents();
  test::writeLog(path, events);
  const std::vector<std::int64_t> offsets = test::eventOffsets(events);
  std::vector<std::uint8_t> bytes = test::readBytes(path);
  bytes.push_back('x');
  bytes.push_back('y');
  test::writeBytes(path, bytes);

  const LogIndex index = indexLog(path);
  EXPECT_EQ(index.events.size(), 10u);
  ASSERT_EQ(index.damage.size(), 1u);
  EXPECT_EQ(index.damage[0].kind, core::LogDamage::Kind::kTruncated);
  EXPECT_EQ(index.damage[0].offset, offsets[10]);
  EXPECT_EQ(index.damage[0].bytes, 2);
}

// Re-reading damage after a seek does not count it twice; events carry their offsets.
TEST(LogDamage, SeekingBackDoesNotRecountDamage) {
  const std::string path = test::tempPath("damage_reread.lcmlog");
  const std::vector<Event> events = damageEvents();
  test::writeLog(path, events);
  const std::vector<std::int64_t> offsets = test::eventOffsets(events);
  std::vector<std::uint8_t> bytes = test::readBytes(path);
  bytes.insert(bytes.begin() + offsets[3], 5, 0x00);
  test::writeBytes(path, bytes);

  core::LcmLogReader reader(path);
  std::vector<std::int64_t> seen;
  while (const auto event = reader.next()) seen.push_back(event->offset);
  EXPECT_EQ(seen, (std::vector<std::int64_t>{offsets[0], offsets[1], offsets[2], offsets[3] + 5,
                                             offsets[4] + 5, offsets[5] + 5, offsets[6] + 5,
                                             offsets[7] + 5, offsets[8] + 5, offsets[9] + 5}));
  reader.seek(0);
  while (reader.next()) {
  }
  EXPECT_EQ(reader.skippedBytes(), 5);
  ASSERT_EQ(reader.damage().size(), 1u);
  EXPECT_EQ(reader.damage()[0].offset, offsets[3]);
  reader.seek(offsets[7] + 5);
  const auto event = reader.next();
  ASSERT_TRUE(event);
  EXPECT_EQ(event->timestamp_utime, kT0 + 700'000);
  EXPECT_THROW(reader.seek(static_cast<std::int64_t>(bytes.size()) + 1), core::LogError);
}

}  // namespace
}  // namespace nadir::logs
