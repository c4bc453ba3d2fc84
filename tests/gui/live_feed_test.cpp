// nadir-viewer's data without a display: the live feed on an in-process bus (the
// truth, an estimate source and camera images as they come, damaged messages
// counted, the image budget) and the camera images of a log looked up by time.
#include "gui/live_feed.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/bus.h"
#include "core/frames.h"
#include "core/lcm_log.h"
#include "gui/camera_frames.h"
#include "gui_test_util.h"
#include "nadir/image_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/vo_estimate_t.hpp"
#include "tests/support/lcm_messages.h"

namespace nadir::gui {
namespace {

std::int64_t utimeOf(double t_s) { return static_cast<std::int64_t>(std::llround(t_s * 1e6)); }

nadir::pose_t truthMessage(double t_s) {
  return test::poseMessage(t_s, test::truthPosition(t_s), test::attitude());
}

nadir::vo_estimate_t estimateMessage(double t_s, int status) {
  nadir::vo_estimate_t m{};
  m.utime = utimeOf(t_s);
  m.source = "vo_feature";  // estimates are named by their source
  m.status = static_cast<std::int8_t>(status);
  m.pose = truthMessage(t_s);
  for (int i = 0; i < 3; ++i) m.pose.pos[i] += test::kOffset[i];
  return m;
}

// A width x height GRAY image whose every pixel is `value`.
nadir::image_t imageMessage(double t_s, int width, int height, std::uint8_t value) {
  nadir::image_t m{};
  m.utime = utimeOf(t_s);
  m.width = width;
  m.height = height;
  m.row_stride = width;
  m.pixelformat = nadir::image_t::PIXEL_FORMAT_GRAY;
  m.data.assign(static_cast<std::size_t>(width * height), value);
  m.size = static_cast<std::int32_t>(m.data.size());
  m.nmetadata = 0;
  return m;
}

// What the live feed gathers is the test run: 101 truth poses, the source's 19
// estimates 5 m off, and the images, whatever order channels interleave in.
TEST(GuiLiveFeed, GathersTheRunAsItComes) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  LiveFeed feed(*bus);
  EXPECT_FALSE(feed.run("live"));
  int j = 0;
  for (int k = 0; k < test::kTruthPoses; ++k) {
    const double t = test::truthStamp(k);
    ::nadir::test::publish(*bus, "POSE_TRUTH", truthMessage(t));
    if (j < test::kEstimates && test::estimateStamp(j) <= t + 1e-9) {
      ::nadir::test::publish(
          *bus, "POSE_VO_FEATURE",
          estimateMessage(test::estimateStamp(j), nadir::vo_estimate_t::STATUS_TRACKING));
      ++j;
    }
    if (k % 10 == 0) ::nadir::test::publish(*bus, "CAMERA_DOWN", imageMessage(t, 8, 6, k));
  }
  while (feed.poll() > 0) {
  }
  const std::optional<RunData> run = feed.run("live");
  ASSERT_TRUE(run);
  EXPECT_EQ(run->dir, "live");
  EXPECT_EQ(run->truth.size(), static_cast<std::size_t>(test::kTruthPoses));
  EXPECT_DOUBLE_EQ(run->t0_s, test::kT0);
  ASSERT_EQ(run->sources.count("vo_feature"), 1u);
  const SourceSeries& source = run->sources.at("vo_feature");
  ASSERT_EQ(source.size(), static_cast<std::size_t>(test::kEstimates));
  for (double error : source.position_error_m) EXPECT_NEAR(error, 5.0, 1e-6);
  EXPECT_TRUE(run->damage.empty()) << run->damage;

  ASSERT_NE(feed.frames(), nullptr);
  EXPECT_EQ(feed.frames()->count(), 11u);
  // At 104.55 s the newest image is the one of 104.5 s: k = 45 is not a multiple
  // of 10, so it is k = 40's (104.0 s), value 40.
  const std::optional<CameraFrame> frame = feed.frames()->frameAt(104.55);
  ASSERT_TRUE(frame);
  EXPECT_DOUBLE_EQ(frame->t_s, 104.0);
  EXPECT_EQ(frame->number, 4);
  ASSERT_EQ(frame->pixels.rows, 6);
  EXPECT_EQ(frame->pixels.at<std::uint8_t>(3, 3), 40);
  EXPECT_FALSE(feed.frames()->frameAt(99.0));
}

// A message that does not decode is counted in the run's damage, and the rest of
// the run is kept; a pose_t on another channel than the truth's named one
// changes nothing.
TEST(GuiLiveFeed, CountsDamagedMessagesAndIgnoresOthers) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  LiveFeedParams params;
  params.truth_channel = "POSE_TRUTH";
  LiveFeed feed(*bus, params);
  ::nadir::test::publish(*bus, "POSE_TRUTH", truthMessage(100.0));
  const std::uint8_t junk[5] = {1, 2, 3, 4, 5};
  bus->publish("POSE_TRUTH", junk, sizeof junk, 0);
  // An estimate cut short: its type is known, its body is not whole.
  std::vector<std::uint8_t> cut = ::nadir::test::encodeMessage(estimateMessage(100.0, 1));
  cut.resize(cut.size() - 3);
  bus->publish("POSE_VO_DIRECT", cut.data(), cut.size(), 0);
  nadir::pose_t not_a_rotation = truthMessage(100.1);
  not_a_rotation.orientation[0] = 0.0;
  not_a_rotation.orientation[1] = 0.0;
  not_a_rotation.orientation[2] = 0.0;
  not_a_rotation.orientation[3] = 0.0;
  ::nadir::test::publish(*bus, "POSE_TRUTH", not_a_rotation);
  ::nadir::test::publish(*bus, "POSE_TRUTH", truthMessage(100.2));
  while (feed.poll() > 0) {
  }
  const std::uint64_t version = feed.version();
  ::nadir::test::publish(*bus, "SOMETHING_ELSE", truthMessage(100.3));
  while (feed.poll() > 0) {
  }
  EXPECT_EQ(feed.version(), version);
  const std::optional<RunData> run = feed.run("live");
  ASSERT_TRUE(run);
  EXPECT_EQ(run->truth.size(), 2u);
  EXPECT_NE(run->damage.find("2 undecodable or invalid messages on POSE_TRUTH"), std::string::npos)
      << run->damage;
  EXPECT_NE(run->damage.find("1 undecodable or invalid message on POSE_VO_DIRECT"),
            std::string::npos)
      << run->damage;
}

// The newest truth pose is the live truth while it is recent: an older one
// coming late does not replace it, a damaged one is not taken, and once the
// newest is older than the age asked for there is none.
TEST(GuiLiveFeed, KeepsTheNewestTruthWhileItIsLive) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  LiveFeed feed(*bus);
  const std::chrono::milliseconds long_age(60000);
  EXPECT_FALSE(feed.liveTruth(long_age));
  ::nadir::test::publish(*bus, "POSE_TRUTH", truthMessage(100.0));
  ::nadir::test::publish(*bus, "POSE_TRUTH", truthMessage(100.5));
  ::nadir::test::publish(*bus, "POSE_TRUTH", truthMessage(100.25));  // late
  nadir::pose_t not_a_rotation = truthMessage(100.75);
  for (double& w : not_a_rotation.orientation) w = 0.0;
  ::nadir::test::publish(*bus, "POSE_TRUTH", not_a_rotation);
  while (feed.poll() > 0) {
  }
  const std::optional<msg::Pose> truth = feed.liveTruth(long_age);
  ASSERT_TRUE(truth);
  EXPECT_EQ(truth->utime, utimeOf(100.5));
  EXPECT_LT((truth->p_ned_m - test::truthPosition(100.5)).norm(), 1e-9);

  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(feed.liveTruth(std::chrono::milliseconds(10)));
  EXPECT_TRUE(feed.liveTruth(long_age));
}

// The live images are kept up to the budget, oldest dropped first; an image that
// does not decode is kept with its reason.
TEST(GuiLiveFeed, KeepsTheNewestImagesWithinTheBudget) {
  RecentCameraFrames frames("CAMERA_DOWN", 3 * 100);  // three 10x10 gray images
  for (int i = 0; i < 5; ++i) {
    const std::vector<std::uint8_t> bytes =
        ::nadir::test::encodeMessage(imageMessage(10.0 + i, 10, 10, static_cast<std::uint8_t>(i)));
    frames.add(bytes.data(), bytes.size());
  }
  EXPECT_EQ(frames.count(), 3u);
  EXPECT_FALSE(frames.frameAt(11.5));  // image 1 was dropped; image 2 is at 12 s
  ASSERT_TRUE(frames.frameAt(12.0));
  EXPECT_EQ(frames.frameAt(12.0)->number, 2);
  nadir::image_t wrong = imageMessage(15.0, 10, 10, 0);
  wrong.pixelformat = 12345;
  const std::vector<std::uint8_t> bytes = ::nadir::test::encodeMessage(wrong);
  frames.add(bytes.data(), bytes.size());
  const std::optional<CameraFrame> last = frames.frameAt(20.0);
  ASSERT_TRUE(last);
  EXPECT_TRUE(last->pixels.empty());
  EXPECT_NE(last->error.find("unsupported pixel format 12345"), std::string::npos) << last->error;
}

// A log's images are found by time (the newest at or before it), read from the
// log when asked, whichever order they were written in; other channels are not
// images.
TEST(GuiLogCameraFrames, FindsTheImageOfATime) {
  const std::filesystem::path dir = test::freshDir("frames");
  const std::string log_path = (dir / "run.lcmlog").string();
  {
    core::LcmLogWriter writer(log_path);
    const auto write = [&writer](const std::string& channel, const auto& message) {
      const std::vector<std::uint8_t> bytes = ::nadir::test::encodeMessage(message);
      writer.write(message.utime, channel, bytes.data(), bytes.size());
    };
    write("POSE_TRUTH", truthMessage(100.0));
    write("CAMERA_DOWN", imageMessage(100.0, 4, 3, 10));
    write("CAMERA_DOWN", imageMessage(100.2, 4, 3, 30));  // written before 100.1
    write("CAMERA_DOWN", imageMessage(100.1, 4, 3, 20));
    write("CAMERA_FORWARD", imageMessage(100.15, 4, 3, 99));
  }
  LogCameraFrames frames(log_path);
  EXPECT_EQ(frames.count(), 3u);
  EXPECT_EQ(frames.describe(), "run.lcmlog CAMERA_DOWN");
  EXPECT_FALSE(frames.frameAt(99.9));
  for (const auto& [t, value] : std::vector<std::pair<double, int>>{
           {100.0, 10}, {100.05, 10}, {100.15, 20}, {100.2, 30}, {500.0, 30}, {100.1, 20}}) {
    const std::optional<CameraFrame> frame = frames.frameAt(t);
    ASSERT_TRUE(frame) << t;
    ASSERT_FALSE(frame->pixels.empty()) << t << ": " << frame->error;
    EXPECT_EQ(frame->pixels.at<std::uint8_t>(1, 2), value) << t;
  }
  EXPECT_EQ(frames.frameAt(100.1)->number, 2);  // the third image written
  EXPECT_THROW(LogCameraFrames((dir / "missing.lcmlog").string()), core::LogError);
}

}  // namespace
}  // namespace nadir::gui
