// The LCM log codec: compatibility with LCM's own eventlog (what lcm-logger
// writes and lcm-logplayer reads) and clear handling of damaged files.

#include <lcm/eventlog.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/lcm_log.h"

namespace nadir::core {
namespace {

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "nadir_" + name; }

struct Expected {
  std::int64_t timestamp_utime;
  std::string channel;
  std::vector<std::uint8_t> data;
};

std::vector<Expected> sampleEvents() {
  std::vector<Expected> events;
  for (int i = 0; i < 10; ++i) {
    std::vector<std::uint8_t> data(static_cast<std::size_t>(10 + 7 * i));
    for (std::size_t j = 0; j < data.size(); ++j) data[j] = static_cast<std::uint8_t>(i * 31 + j);
    events.push_back({1'700'000'000'000'000LL + i * 5'000, i % 2 ? "IMU" : "POSE_TRUTH", data});
  }
  events[3].data.clear();  // an empty payload is legal
  return events;
}

void writeWithNadir(const std::string& path, const std::vector<Expected>& events) {
  LcmLogWriter writer(path);
  for (const Expected& e : events)
    writer.write(e.timestamp_utime, e.channel, e.data.data(), e.data.size());
}

// Byte offset where each event starts: header 28 bytes, channel, data.
std::vector<std::int64_t> eventOffsets(const std::vector<Expected>& events) {
  std::vector<std::int64_t> offsets;
  std::int64_t at = 0;
  for (const Expected& e : events) {
    offsets.push_back(at);
    at += 28 + static_cast<std::int64_t>(e.channel.size() + e.data.size());
  }
  offsets.push_back(at);
  return offsets;
}

// A log written here is read by LCM's own reader, event for event.
TEST(LcmLog, LcmEventlogReadsWhatNadirWrites) {
  const std::string path = tempPath("written_by_nadir.lcmlog");
  const std::vector<Expected> events = sampleEvents();
  writeWithNadir(path, events);

  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "r");
  ASSERT_NE(log, nullptr);
  for (std::size_t i = 0; i < events.size(); ++i) {
    lcm_eventlog_event_t* event = lcm_eventlog_read_next_event(log);
    ASSERT_NE(event, nullptr) << "event " << i;
    EXPECT_EQ(event->eventnum, static_cast<std::int64_t>(i));
    EXPECT_EQ(event->timestamp, events[i].timestamp_utime);
    EXPECT_EQ(std::string(event->channel, static_cast<std::size_t>(event->channellen)),
              events[i].channel);
    ASSERT_EQ(event->datalen, static_cast<std::int32_t>(events[i].data.size()));
    const auto* bytes = static_cast<const std::uint8_t*>(event->data);
    EXPECT_EQ(std::vector<std::uint8_t>(bytes, bytes + event->datalen), events[i].data);
    lcm_eventlog_free_event(event);
  }
  EXPECT_EQ(lcm_eventlog_read_next_event(log), nullptr);
  lcm_eventlog_destroy(log);
}

// A log written by LCM's own writer is read here, event for event.
TEST(LcmLog, NadirReadsWhatLcmEventlogWrites) {
  const std::string path = tempPath("written_by_lcm.lcmlog");
  const std::vector<Expected> events = sampleEvents();
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "w");
  ASSERT_NE(log, nullptr);
  for (const Expected& e : events) {
    lcm_eventlog_event_t event{};
    event.timestamp = e.timestamp_utime;
    event.channellen = static_cast<std::int32_t>(e.channel.size());
    event.datalen = static_cast<std::int32_t>(e.data.size());
    event.channel = const_cast<char*>(e.channel.c_str());
    event.data = const_cast<std::uint8_t*>(e.data.data());
    ASSERT_EQ(lcm_eventlog_write_event(log, &event), 0);
  }
  lcm_eventlog_destroy(log);

  LcmLogReader reader(path);
  for (std::size_t i = 0; i < events.size(); ++i) {
    const std::optional<LogEvent> event = reader.next();
    ASSERT_TRUE(event) << "event " << i;
    EXPECT_EQ(event->event_number, static_cast<std::int64_t>(i));
    EXPECT_EQ(event->timestamp_utime, events[i].timestamp_utime);
    EXPECT_EQ(event->channel, events[i].channel);
    EXPECT_EQ(event->data, events[i].data);
  }
  EXPECT_FALSE(reader.next());
  EXPECT_EQ(reader.damageReport(), "");
}

// The first event's header bytes are the format's, worked out by hand.
// A reader told to report every 1000 bytes: 10 events of 28 + 3 + 200 = 231 bytes
// (2310 in all) report at the end of events 5 (1155 bytes, the first past 1000)
// and 10 (2310, past 2155), then once more at the end, with the file's size.
TEST(LcmLog, ProgressIsToldEveryStretchOfBytesAndAtTheEnd) {
  const std::string path = tempPath("progress.lcmlog");
  {
    LcmLogWriter writer(path);
    const std::vector<std::uint8_t> data(200, 7);
    for (int i = 0; i < 10; ++i) writer.write(i, "CHN", data.data(), data.size());
  }
  LcmLogReader reader(path);
  ASSERT_EQ(reader.fileSize(), 2310);
  std::vector<std::pair<std::int64_t, std::int64_t>> told;
  reader.onProgress([&](std::int64_t done, std::int64_t total) { told.emplace_back(done, total); },
                    1000);
  int events = 0;
  while (reader.next()) ++events;
  EXPECT_EQ(events, 10);
  const std::vector<std::pair<std::int64_t, std::int64_t>> expected = {
      {1155, 2310}, {2310, 2310}, {2310, 2310}};
  EXPECT_EQ(told, expected);
}

TEST(LcmLog, HeaderBytesAreBigEndian) {
  const std::string path = tempPath("header.lcmlog");
  {
    LcmLogWriter writer(path);
    const std::uint8_t payload[2] = {0xAB, 0xCD};
    writer.write(0x0102030405060708LL, "CH", payload, 2);
  }
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
  const std::vector<std::uint8_t> expected = {
      0xED, 0xA1, 0xDA, 0x01,                          // magic
      0,    0,    0,    0,    0,    0,    0,    0,     // event number 0
      0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,  // timestamp
      0,    0,    0,    2,                             // channel length
      0,    0,    0,    2,                             // data length
      'C',  'H',  0xAB, 0xCD};
  EXPECT_EQ(bytes, expected);
}

// A log cut off inside its last event yields every whole event, then says it was truncated.
TEST(LcmLog, TruncatedTailKeepsWholeEventsAndIsReported) {
  const std::string path = tempPath("truncated.lcmlog");
  const std::vector<Expected> events = sampleEvents();
  writeWithNadir(path, events);
  const std::vector<std::int64_t> offsets = eventOffsets(events);
  std::filesystem::resize_file(path, static_cast<std::uintmax_t>(offsets.back() - 5));

  LcmLogReader reader(path);
  int count = 0;
  while (reader.next()) ++count;
  EXPECT_EQ(count, 9);
  EXPECT_EQ(reader.truncatedTailBytes(), offsets[10] - 5 - offsets[9]);
  EXPECT_EQ(reader.skippedBytes(), 0);
  EXPECT_NE(reader.damageReport().find("truncated"), std::string::npos) << reader.damageReport();
  EXPECT_NE(reader.damageReport().find(path), std::string::npos);
  EXPECT_NE(reader.damageReport().find("9 whole events"), std::string::npos);
}

// A log cut inside an event header (fewer than 28 bytes left) is also a truncated tail.
TEST(LcmLog, TruncatedInsideHeader) {
  const std::string path = tempPath("truncated_header.lcmlog");
  const std::vector<Expected> events = sampleEvents();
  writeWithNadir(path, events);
  const std::vector<std::int64_t> offsets = eventOffsets(events);
  std::filesystem::resize_file(path, static_cast<std::uintmax_t>(offsets[9] + 10));
  LcmLogReader reader(path);
  int count = 0;
  while (reader.next()) ++count;
  EXPECT_EQ(count, 9);
  EXPECT_EQ(reader.truncatedTailBytes(), 10);
}

// A damaged event in the middle is skipped; the events after it are still read.
TEST(LcmLog, DamagedEventInTheMiddleIsSkipped) {
  const std::string path = tempPath("damaged.lcmlog");
  const std::vector<Expected> events = sampleEvents();
  writeWithNadir(path, events);
  const std::vector<std::int64_t> offsets = eventOffsets(events);
  {
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(offsets[4]);
    file.write("\0\0\0\0", 4);  // break event 4's magic
  }
  LcmLogReader reader(path);
  std::vector<std::int64_t> numbers;
  while (const auto event = reader.next()) numbers.push_back(event->event_number);
  EXPECT_EQ(numbers, (std::vector<std::int64_t>{0, 1, 2, 3, 5, 6, 7, 8, 9}));
  EXPECT_EQ(reader.skippedBytes(), offsets[5] - offsets[4]);
  EXPECT_EQ(reader.truncatedTailBytes(), 0);
  EXPECT_NE(reader.damageReport().find("skipped"), std::string::npos);
}

// A file that is not a log is refused at open, naming the file.
TEST(LcmLog, NotALogIsRefusedNamingTheFile) {
  const std::string path = tempPath("not_a_log.txt");
  std::ofstream(path) << "waypoints:\n  - [0, 0, -100]\n";
  try {
    LcmLogReader reader(path);
    FAIL() << "no error for a text file";
  } catch (const LogError& error) {
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("not an LCM log"), std::string::npos);
  }
}

// A missing file is an error naming it.
TEST(LcmLog, MissingFileNamesThePath) {
  const std::string path = tempPath("does_not_exist.lcmlog");
  std::filesystem::remove(path);
  try {
    LcmLogReader reader(path);
    FAIL() << "no error for a missing file";
  } catch (const LogError& error) {
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
  }
}

// An empty file (lcm-logger's state before the first message) is an empty log.
TEST(LcmLog, EmptyFileIsAnEmptyLog) {
  const std::string path = tempPath("empty.lcmlog");
  std::ofstream(path).close();
  LcmLogReader reader(path);
  EXPECT_FALSE(reader.next());
  EXPECT_EQ(reader.damageReport(), "");
}

// A writer that cannot create its file says which.
TEST(LcmLog, UnwritablePathIsAnError) {
  EXPECT_THROW(LcmLogWriter("/nonexistent-dir/x.lcmlog"), LogError);
}

}  // namespace
}  // namespace nadir::core
