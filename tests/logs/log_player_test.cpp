// LogPlayer driven by a fake clock: speed, pause, seek, loop, start offset,
// channel filter and remap, checked by what reaches the bus. Nothing sleeps.

#include <lcm/eventlog.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "core/log_bus.h"
#include "lcmtypes/codec.h"
#include "logs/log_player.h"
#include "tests/logs/log_test_util.h"

namespace nadir::logs {
namespace {

using test::Event;

constexpr std::int64_t kT0 = 1'700'000'000'000'000;
constexpr std::int64_t kSecond = 1'000'000;

// A at 0, 1, ..., 9 s and B at 0.5, 1.5, ..., 9.5 s: 20 events over 9.5 s.
std::string playerLog(const std::string& name) {
  std::vector<Event> events;
  for (int i = 0; i < 10; ++i) {
    events.push_back({kT0 + i * kSecond, "A", test::payload(20, i * kSecond)});
    events.push_back({kT0 + i * kSecond + kSecond / 2, "B", test::payload(30, i * kSecond)});
  }
  const std::string path = test::tempPath(name);
  test::writeLog(path, events);
  return path;
}

struct Sent {
  std::string channel;
  double t_s;  // event time after the log's start
  bool operator==(const Sent&) const = default;
};

std::ostream& operator<<(std::ostream& out, const Sent& s) {
  return out << s.channel << "@" << s.t_s;
}

// Records what a player publishes, without any network.
class RecordingBus final : public core::Bus {
 public:
  std::vector<Sent> sent;
  std::string url() const override { return "recording://"; }
  void send(std::string_view channel, const void*, std::size_t, std::int64_t utime) override {
    sent.push_back({std::string(channel), static_cast<double>(utime - kT0) / 1e6});
  }
  bool handle(std::chrono::milliseconds) override { return false; }

 protected:
  void addSubscription(const Handler&) override {}
  void removeSubscription(int) override {}
};

std::vector<double> times(const std::vector<Sent>& sent) {
  std::vector<double> t;
  for (const Sent& s : sent) t.push_back(s.t_s);
  return t;
}

class LogPlayerTest : public ::testing::Test {
 protected:
  std::int64_t now_ = 123'456;  // the fake clock, microseconds
  RecordingBus bus_;
  LogPlayer::Clock clock() {
    return [this] { return now_; };
  }
};

// At speed 2, 2 s of clock play 4 s of log: A 0..4 and B 0.5..3.5, in time order.
TEST_F(LogPlayerTest, SpeedScalesPlayTime) {
  LogPlayer player(playerLog("play_speed.lcmlog"), bus_, {.speed = 2.0}, clock());
  EXPECT_EQ(player.update(), 1);  // A at 0 is due at once
  now_ += 2 * kSecond;
  EXPECT_EQ(player.update(), 8);
  EXPECT_EQ(times(bus_.sent), (std::vector<double>{0, 0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4}));
  EXPECT_DOUBLE_EQ(player.positionS(), 4.0);
  EXPECT_EQ(player.eventsSent(), 9);
}

// Changing speed keeps the position reached: 1 s at x1, then 1 s at x4 -> 5 s.
TEST_F(LogPlayerTest, SpeedChangeKeepsThePosition) {
  LogPlayer player(playerLog("play_speed_change.lcmlog"), bus_, {}, clock());
  now_ += kSecond;
  player.setSpeed(4.0);
  EXPECT_DOUBLE_EQ(player.positionS(), 1.0);
  now_ += kSecond;
  player.update();
  EXPECT_DOUBLE_EQ(player.positionS(), 5.0);
  EXPECT_EQ(bus_.sent.size(), 11u);  // A 0..5, B 0.5..4.5
  EXPECT_THROW(player.setSpeed(0.0), std::invalid_argument);
}

// While paused the clock runs but nothing is sent; play resumes where it stopped.
TEST_F(LogPlayerTest, PauseAndResume) {
  LogPlayer player(playerLog("play_pause.lcmlog"), bus_, {}, clock());
  now_ += kSecond;
  player.pause();  // sends A 0, B 0.5, A 1 first
  EXPECT_EQ(bus_.sent.size(), 3u);
  EXPECT_TRUE(player.paused());
  now_ += 10 * kSecond;
  EXPECT_EQ(player.update(), 0);
  EXPECT_FALSE(player.microsUntilNextEvent());
  EXPECT_DOUBLE_EQ(player.positionS(), 1.0);
  player.togglePause();
  EXPECT_EQ(player.microsUntilNextEvent(), kSecond / 2);  // B 1.5
  now_ += kSecond;
  player.update();
  EXPECT_EQ(times(bus_.sent), (std::vector<double>{0, 0.5, 1, 1.5, 2}));
}

// Seeking jumps without sending what it skips; an event at the seek time comes next.
TEST_F(LogPlayerTest, SeekForwardAndBack) {
  LogPlayer player(playerLog("play_seek.lcmlog"), bus_, {}, clock());
  player.update();  // A 0
  player.seek(5.0);
  EXPECT_EQ(player.microsUntilNextEvent(), 0);
  now_ += kSecond;
  player.update();
  EXPECT_EQ(times(bus_.sent), (std::vector<double>{0, 5, 5.5, 6}));
  player.seekBy(-3.25);  // to 2.75 s: B 2.5 is behind, A 3 is next
  EXPECT_DOUBLE_EQ(player.positionS(), 2.75);
  now_ += kSecond * 3 / 4;
  player.update();
  EXPECT_EQ(times(bus_.sent), (std::vector<double>{0, 5, 5.5, 6, 3, 3.5}));
  player.seek(100.0);  // clamped to the end: only the last event remains
  EXPECT_DOUBLE_EQ(player.positionS(), 9.5);
  player.update();
  EXPECT_EQ(bus_.sent.back(), (Sent{"B", 9.5}));
  EXPECT_TRUE(player.finished());
}

// Starting at 7 s with loop: 3 s of clock play 7..9.5 (2.5 s), wrap, then 7 and 7.5 again.
TEST_F(LogPlayerTest, StartOffsetAndLoop) {
  LogPlayer player(playerLog("play_loop.lcmlog"), bus_, {.start_s = 7.0, .loop = true}, clock());
  now_ += 3 * kSecond;
  player.update();
  EXPECT_EQ(times(bus_.sent), (std::vector<double>{7, 7.5, 8, 8.5, 9, 9.5, 7, 7.5}));
  EXPECT_EQ(player.loops(), 1);
  EXPECT_DOUBLE_EQ(player.positionS(), 7.5);
  EXPECT_FALSE(player.finished());
  // 5 more seconds: 7.5 -> 9.5 (2 s), wrap, 7 -> 10 would be 3 s but the loop is 2.5 s:
  // 7..9.5 again, wrap, then 0.5 s into the third pass.
  now_ += 5 * kSecond;
  player.update();
  EXPECT_EQ(player.loops(), 3);
  EXPECT_DOUBLE_EQ(player.positionS(), 7.5);
  EXPECT_EQ(bus_.sent.size(), 8u + 4u + 6u + 2u);
}

// Without loop the player finishes after the last event and sends nothing more.
TEST_F(LogPlayerTest, FinishesWithoutLoop) {
  LogPlayer player(playerLog("play_finish.lcmlog"), bus_, {}, clock());
  now_ += 20 * kSecond;
  EXPECT_EQ(player.update(), 20);
  EXPECT_TRUE(player.finished());
  EXPECT_FALSE(player.microsUntilNextEvent());
  now_ += 20 * kSecond;
  EXPECT_EQ(player.update(), 0);
  EXPECT_DOUBLE_EQ(player.positionS(), 9.5);
}

// The channel filter selects names in the log; remap renames them on the bus.
TEST_F(LogPlayerTest, ChannelFilterAndRemap) {
  PlayerOptions options;
  options.channels = "B";
  options.remap = {{"B", "BRAVO"}, {"A", "ALPHA"}};
  LogPlayer player(playerLog("play_remap.lcmlog"), bus_, options, clock());
  EXPECT_EQ(player.selectedEvents(), 10);
  player.stepTo(kT0 + 2 * kSecond);
  EXPECT_EQ(bus_.sent, (std::vector<Sent>{{"BRAVO", 0.5}, {"BRAVO", 1.5}}));
  EXPECT_EQ(parseRemap("CAMERA_DOWN=CAM2"),
            (std::pair<std::string, std::string>{"CAMERA_DOWN", "CAM2"}));
  EXPECT_THROW(parseRemap("CAMERA_DOWN"), std::invalid_argument);
  EXPECT_THROW(parseRemap("=X"), std::invalid_argument);
}

// The wait for the next event is in clock time: at x2, B 0.5 s is 0.25 s away.
TEST_F(LogPlayerTest, WaitForNextEventScalesWithSpeed) {
  LogPlayer player(playerLog("play_wait.lcmlog"), bus_, {.speed = 2.0}, clock());
  EXPECT_EQ(player.microsUntilNextEvent(), 0);
  player.update();
  EXPECT_EQ(player.microsUntilNextEvent(), kSecond / 4);
  now_ += kSecond / 4 - 1;
  EXPECT_EQ(player.update(), 0);
  now_ += 1;
  EXPECT_EQ(player.update(), 1);
}

// A start beyond the log's end is refused, naming the span.
TEST_F(LogPlayerTest, StartOutsideTheLogIsRefused) {
  EXPECT_THROW(LogPlayer(playerLog("play_bad_start.lcmlog"), bus_, {.start_s = 12.0}, clock()),
               std::invalid_argument);
}

// Through memq:// (LCM in this process): subscribers get the remapped channel.
TEST_F(LogPlayerTest, PlaysToMemq) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  std::vector<std::string> received;
  auto subscription = bus->subscribe(".*", [&](const core::RawMessage& message) {
    received.push_back(std::string(message.channel) + ":" + std::to_string(message.size));
  });
  LogPlayer player(playerLog("play_memq.lcmlog"), *bus, {.remap = {{"A", "ALPHA"}}}, clock());
  player.stepTo(kT0 + kSecond);
  bus->handleAvailable();
  EXPECT_EQ(received, (std::vector<std::string>{"ALPHA:20", "B:30", "ALPHA:20"}));
}

// Played into file://...?mode=w, the copy is a log LCM's own reader reads.
TEST_F(LogPlayerTest, PlaysIntoALogFileThatLcmReads) {
  const std::string out = test::tempPath("play_copy.lcmlog");
  {
    const std::unique_ptr<core::Bus> bus = core::openBus("file://" + out + "?mode=w");
    LogPlayer player(playerLog("play_file.lcmlog"), *bus, {.start_s = 8.0}, clock());
    now_ += 10 * kSecond;
    player.update();
  }
  lcm_eventlog_t* log = lcm_eventlog_create(out.c_str(), "r");
  ASSERT_NE(log, nullptr);
  std::vector<std::string> events;
  while (lcm_eventlog_event_t* event = lcm_eventlog_read_next_event(log)) {
    events.push_back(std::string(event->channel) + "@" +
                     std::to_string((event->timestamp - kT0) / 100'000));
    lcm_eventlog_free_event(event);
  }
  lcm_eventlog_destroy(log);
  EXPECT_EQ(events, (std::vector<std::string>{"A@80", "B@85", "A@90", "B@95"}));
}

// Images re-encoded on the way: a raw gray frame goes out as JPEG of the
// quality asked (decoding to within JPEG's error of the pixels) or as it was;
// other messages go out unchanged; the bytes sent are what the bus carried.
TEST_F(LogPlayerTest, ReencodesImagesAndCountsTheBytesSent) {
  cv::Mat pixels(48, 64, CV_8UC1);
  for (int y = 0; y < pixels.rows; ++y) {
    for (int x = 0; x < pixels.cols; ++x)
      pixels.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(2 * x + y);
  }
  const msg::Bytes raw = msg::encode(msg::Image{kT0, pixels, 0, {}});
  const std::string path = test::tempPath("play_images.lcmlog");
  test::writeLog(path, {{kT0, "CAMERA", raw}, {kT0, "A", test::payload(20, 0)}});

  for (const char* encoding : {"jpeg:75", "raw", "as-recorded"}) {
    SCOPED_TRACE(encoding);
    auto bus = core::openBus("memq://");
    std::map<std::string, std::int64_t> received_bytes;
    std::optional<msg::Image> image;
    bool jpeg = false;
    auto subscription = bus->subscribe(".*", [&](const core::RawMessage& message) {
      received_bytes[std::string(message.channel)] += static_cast<std::int64_t>(message.size);
      if (message.channel != "CAMERA") return;
      jpeg = msg::isJpegImage(message.data, message.size);
      image = msg::decode<msg::Image>(message.data, message.size);
    });
    LogPlayer player(path, *bus, {.image_encoding = ImageEncoding::parse(encoding)}, clock());
    player.stepTo(kT0);
    bus->handleAvailable();
    ASSERT_TRUE(image.has_value());
    EXPECT_EQ(jpeg, std::string(encoding) == "jpeg:75");
    EXPECT_EQ(player.imagesReencoded(), jpeg ? 1 : 0);
    EXPECT_EQ(image->utime, kT0);
    EXPECT_LE(cv::norm(image->pixels, pixels, cv::NORM_INF), jpeg ? 8.0 : 0.0);
    EXPECT_EQ(received_bytes.at("A"), 20);
    EXPECT_EQ(player.bytesSentByChannel(), received_bytes);
    EXPECT_EQ(player.bytesSent(), received_bytes.at("A") + received_bytes.at("CAMERA"));
    if (jpeg) {
      EXPECT_LT(received_bytes.at("CAMERA"), static_cast<std::int64_t>(raw.size()));
    } else {
      EXPECT_EQ(received_bytes.at("CAMERA"), static_cast<std::int64_t>(raw.size()));
    }
  }
}

// An encoding the player does not know, or a quality out of 1-100, is named.
TEST(ImageEncoding, ParsesWhatItKnowsAndNamesWhatItDoesNot) {
  EXPECT_EQ(ImageEncoding::parse("jpeg").jpeg_quality, 90);
  EXPECT_EQ(ImageEncoding::parse("jpeg:55").name(), "jpeg:55");
  EXPECT_EQ(ImageEncoding::parse("raw").kind, ImageEncoding::Kind::kRaw);
  for (const char* bad : {"png", "jpeg:0", "jpeg:101", "jpeg:9x", "jpeg:", ""}) {
    try {
      ImageEncoding::parse(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(bad), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace nadir::logs
