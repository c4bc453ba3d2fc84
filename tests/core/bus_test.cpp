// The Bus: memq and log-file round trips, channel matching, decode errors,
// exceptions from handlers, URLs; and one UDP multicast round trip.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bus.h"
#include "core/log_bus.h"
#include "lcmtypes/bus_io.h"

namespace nadir::core {
namespace {

using std::chrono::milliseconds;

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "nadir_" + name; }

using msg::publish;
using msg::subscribe;

msg::Pose makePose(std::int64_t utime, double x) {
  msg::Pose pose;
  pose.utime = utime;
  pose.p_ned_m = Eigen::Vector3d(x, -2.5, -100.0);
  pose.v_ned_mps.z() = 0.125;
  return pose;
}

msg::Imu makeImu(std::int64_t utime) {
  msg::Imu imu;
  imu.utime = utime;
  imu.angular_velocity_rps.z() = 0.01;
  imu.linear_acceleration_mps2.z() = -9.81;
  return imu;
}

// A typed message published on memq:// arrives decoded with every field intact.
TEST(Bus, MemqRoundTrip) {
  auto bus = openBus("memq://");
  EXPECT_EQ(bus->url(), "memq://");
  std::vector<msg::Pose> received;
  auto subscription = subscribe<msg::Pose>(
      *bus, "POSE_TRUTH", [&](const msg::Pose& pose) { received.push_back(pose); });
  publish(*bus, "POSE_TRUTH", makePose(1000, 1.5));
  publish(*bus, "POSE_TRUTH", makePose(2000, 2.5));
  EXPECT_EQ(bus->handleAvailable(), 2);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received[0].utime, 1000);
  EXPECT_EQ(received[0].p_ned_m.x(), 1.5);
  EXPECT_EQ(received[1].utime, 2000);
  EXPECT_EQ(received[1].p_ned_m.x(), 2.5);
  EXPECT_EQ(received[1].p_ned_m.y(), -2.5);
  EXPECT_EQ(received[1].p_ned_m.z(), -100.0);
  EXPECT_EQ(received[1].v_ned_mps.z(), 0.125);
  EXPECT_EQ(received[1].q_world_body.w(), 1.0);
  EXPECT_FALSE(bus->handle(milliseconds(0)));
}

// LCM's channel names are 1 to 63 bytes: 63 are sent, 64 or none are refused
// on every transport with the name and the limit, and nothing is counted sent.
TEST(Bus, ChannelNamesOverLcmsLimitAreRefused) {
  for (const char* url : {"memq://", "udpm://239.255.76.67:7893?ttl=0"}) {
    auto bus = openBus(url);
    const std::string longest(63, 'C');
    publish(*bus, longest, makePose(1000, 1.5));
    const std::string too_long(64, 'C');
    try {
      publish(*bus, too_long, makePose(1000, 1.5));
      ADD_FAILURE() << url << ": a 64-byte channel name was sent";
    } catch (const BusError& error) {
      EXPECT_NE(std::string(error.what()).find("is 64 bytes: LCM's channel names are 1 to 63"),
                std::string::npos)
          << error.what();
    }
    EXPECT_THROW(publish(*bus, "", makePose(1000, 1.5)), BusError);
    EXPECT_EQ(bus->sent().count(too_long), 0u) << url;
    EXPECT_EQ(bus->sent().at(longest), 1) << url;
  }
}

// Channel patterns are regexes matched against the whole channel name, as in LCM.
TEST(Bus, ChannelRegexMatchesWholeNames) {
  auto bus = openBus("memq://");
  std::vector<std::string> pose_channels, exact;
  auto any_pose = bus->subscribe(
      "POSE_.*", [&](const RawMessage& m) { pose_channels.emplace_back(m.channel); });
  auto prefix_only =
      bus->subscribe("POSE", [&](const RawMessage& m) { exact.emplace_back(m.channel); });
  publish(*bus, "POSE_TRUTH", makePose(1, 0));
  publish(*bus, "IMU", makeImu(2));
  publish(*bus, "POSE_PPA", makePose(3, 0));
  bus->handleAvailable();
  EXPECT_EQ(pose_channels, (std::vector<std::string>{"POSE_TRUTH", "POSE_PPA"}));
  EXPECT_TRUE(exact.empty());
}

// Bytes that are not the subscribed type are dropped and counted, never handed over.
TEST(Bus, UndecodableMessageIsDroppedAndCounted) {
  auto bus = openBus("memq://");
  int calls = 0;
  auto subscription = subscribe<msg::Pose>(*bus, "POSE_TRUTH", [&](const msg::Pose&) { ++calls; });
  const std::vector<std::uint8_t> garbage = {1, 2, 3, 4, 5};
  bus->publish("POSE_TRUTH", garbage.data(), garbage.size(), 0);
  const msg::Bytes imu = msg::encode(makeImu(5));
  bus->publish("POSE_TRUTH", imu.data(), imu.size(), 5);  // right size class, wrong type
  publish(*bus, "POSE_TRUTH", makePose(7, 0));
  bus->handleAvailable();
  EXPECT_EQ(calls, 1);
  const auto stats = bus->stats();
  ASSERT_EQ(stats.count("POSE_TRUTH"), 1u);
  EXPECT_EQ(stats.at("POSE_TRUTH").messages, 3u);
  EXPECT_EQ(stats.at("POSE_TRUTH").decode_errors, 2u);
  // What a node's heartbeat and last line say of them.
  EXPECT_EQ(describeMalformed(stats), "dropped 2 malformed (POSE_TRUTH 2)");
  EXPECT_NE(describeArrivals(stats).find("POSE_TRUTH 3, 2 malformed"), std::string::npos)
      << describeArrivals(stats);
  EXPECT_EQ(describeMalformed({}), "");
}

// An exception thrown in a handler comes out of handle(), and the bus keeps working.
TEST(Bus, HandlerExceptionIsReraisedFromHandle) {
  auto bus = openBus("memq://");
  int calls = 0;
  auto subscription = bus->subscribe("CMD", [&](const RawMessage&) {
    if (++calls == 1) throw std::runtime_error("handler failed on purpose");
  });
  const std::uint8_t byte = 0;
  bus->publish("CMD", &byte, 1, 0);
  bus->publish("CMD", &byte, 1, 0);
  try {
    bus->handle(milliseconds(100));
    FAIL() << "the handler's exception was swallowed";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "handler failed on purpose");
  }
  EXPECT_TRUE(bus->handle(milliseconds(100)));
  EXPECT_EQ(calls, 2);
}

// Destroying a Subscription stops delivery; moving one keeps it.
TEST(Bus, SubscriptionLifetime) {
  auto bus = openBus("memq://");
  int calls = 0;
  Subscription kept;
  {
    Subscription temporary = bus->subscribe("A", [&](const RawMessage&) { ++calls; });
    kept = std::move(temporary);
  }
  const std::uint8_t byte = 0;
  bus->publish("A", &byte, 1, 0);
  bus->handleAvailable();
  EXPECT_EQ(calls, 1);
  kept.unsubscribe();
  bus->publish("A", &byte, 1, 0);
  bus->handleAvailable();
  EXPECT_EQ(calls, 1);
}

// peekUtime reads a nadir message's utime without decoding it.
TEST(Bus, PeekUtimeReadsTheFirstField) {
  const std::vector<std::uint8_t> bytes = msg::encode(makeImu(1'234'567'890'123LL));
  EXPECT_EQ(peekUtime(RawMessage{"IMU", bytes.data(), bytes.size(), 0}), 1'234'567'890'123LL);
  EXPECT_FALSE(peekUtime(RawMessage{"IMU", bytes.data(), 15, 0}));
}

// Messages written to a log file come back in order, each with its own utime as sim time.
TEST(Bus, LogFileRoundTripInSimTime) {
  const std::string path = tempPath("bus_round_trip.lcmlog");
  {
    auto writer = openBus("file://" + path + "?mode=w");
    for (int i = 0; i < 5; ++i) {
      publish(*writer, "POSE_TRUTH", makePose(1'000'000 + 5000 * i, i));
      publish(*writer, "IMU", makeImu(1'000'000 + 5000 * i + 100));
    }
  }
  LogBus reader({.path = path});
  std::vector<std::int64_t> pose_times, imu_times, clock_at_pose;
  auto poses = subscribe<msg::Pose>(reader, "POSE_TRUTH", [&](const msg::Pose& pose) {
    pose_times.push_back(pose.utime);
    clock_at_pose.push_back(reader.nowUtime());
    EXPECT_EQ(pose.p_ned_m.x(), static_cast<double>(pose_times.size() - 1));
  });
  auto imus = subscribe<msg::Imu>(reader, "IMU", [&](const msg::Imu& imu) {
    imu_times.push_back(imu.utime);
    EXPECT_EQ(imu.linear_acceleration_mps2.z(), -9.81);
  });
  int dispatched = 0;
  while (reader.handle(milliseconds(0))) ++dispatched;
  EXPECT_EQ(dispatched, 10);
  EXPECT_EQ(pose_times, (std::vector<std::int64_t>{1000000, 1005000, 1010000, 1015000, 1020000}));
  EXPECT_EQ(clock_at_pose, pose_times);
  EXPECT_EQ(imu_times, (std::vector<std::int64_t>{1000100, 1005100, 1010100, 1015100, 1020100}));
  EXPECT_EQ(reader.nowUtime(), 1020100);
  EXPECT_EQ(reader.stats().at("IMU").messages, 5u);
}

// A handler's exception also comes out of a log bus's handle().
TEST(Bus, LogBusReraisesHandlerException) {
  const std::string path = tempPath("bus_throw.lcmlog");
  {
    LogBus writer({.path = path, .mode = LogBusOptions::Mode::kWrite});
    publish(writer, "IMU", makeImu(1));
  }
  LogBus reader({.path = path});
  auto subscription =
      reader.subscribe("IMU", [](const RawMessage&) { throw std::logic_error("bad input"); });
  EXPECT_THROW(reader.handle(milliseconds(0)), std::logic_error);
}

// A log opened for writing refuses subscriptions; one opened for reading refuses publishing.
TEST(Bus, LogBusModesRefuseTheWrongDirection) {
  const std::string path = tempPath("bus_modes.lcmlog");
  LogBus writer({.path = path, .mode = LogBusOptions::Mode::kWrite});
  EXPECT_THROW((void)writer.subscribe("X", [](const RawMessage&) {}), BusError);
  writer.flush();
  LogBus reader({.path = path});
  const std::uint8_t byte = 0;
  EXPECT_THROW(reader.publish("X", &byte, 1, 0), BusError);
}

// file:// URLs: options parsed, mistakes named.
TEST(Bus, LogUrlParsing) {
  const LogBusOptions options = LogBusOptions::fromUrl("file:///tmp/a.lcmlog?mode=r&speed=2.5");
  EXPECT_EQ(options.path, "/tmp/a.lcmlog");
  EXPECT_EQ(options.mode, LogBusOptions::Mode::kRead);
  EXPECT_EQ(options.speed, 2.5);
  EXPECT_EQ(LogBusOptions::fromUrl("file:///tmp/b.lcmlog?mode=w").mode,
            LogBusOptions::Mode::kWrite);
  for (const std::string bad : {"file://?mode=r", "file:///x?mode=q", "file:///x?speed=-1",
                                "file:///x?speed=fast", "file:///x?colour=red"}) {
    EXPECT_THROW(LogBusOptions::fromUrl(bad), BusError) << bad;
  }
  try {
    LogBusOptions::fromUrl("file:///x?colour=red");
  } catch (const BusError& error) {
    EXPECT_NE(std::string(error.what()).find("colour"), std::string::npos);
  }
}

// BusParams: an empty url takes LCM_DEFAULT_URL; recv_buf_size is added to udpm URLs only.
TEST(Bus, BusParamsResolveTheUrl) {
  ::setenv("LCM_DEFAULT_URL", "udpm://239.255.76.99:7699?ttl=1", 1);
  BusParams params;
  EXPECT_EQ(params.resolvedUrl(), "udpm://239.255.76.99:7699?ttl=1");
  params.recv_buf_size_bytes = 33554432;
  EXPECT_EQ(params.resolvedUrl(), "udpm://239.255.76.99:7699?ttl=1&recv_buf_size=33554432");
  ::unsetenv("LCM_DEFAULT_URL");
  EXPECT_EQ(BusParams{}.resolvedUrl(), "udpm://239.255.76.67:7667?ttl=0");
  params.url = "memq://";
  EXPECT_EQ(params.resolvedUrl(), "memq://");
}

// A URL LCM cannot open is an error that names it.
TEST(Bus, BadUrlIsNamed) {
  try {
    openBus("nosuchprovider://x");
    FAIL() << "no error";
  } catch (const BusError& error) {
    EXPECT_NE(std::string(error.what()).find("nosuchprovider://x"), std::string::npos);
  }
}

// Over real UDP multicast on this host (ttl=0): a message reaches a subscriber
// on a second bus instance, and a handler's exception still comes out of handle().
TEST(BusNetwork, UdpmRoundTripOnThisHost) {
  const std::string url = "udpm://239.255.76.67:7667?ttl=0";
  std::unique_ptr<Bus> sender, receiver;
  try {
    sender = openBus(url);
    receiver = openBus(url);
  } catch (const BusError& error) {
    GTEST_SKIP() << "no multicast route here (" << error.what() << "); nadir doctor shows the fix";
  }
  const std::string channel = "NADIR_TEST_" + std::to_string(::getpid());
  std::vector<msg::Pose> received;
  auto subscription = subscribe<msg::Pose>(
      *receiver, channel, [&](const msg::Pose& pose) { received.push_back(pose); });
  publish(*sender, channel, makePose(42, 3.25));
  for (int i = 0; i < 50 && received.empty(); ++i) receiver->handle(milliseconds(100));
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].utime, 42);
  EXPECT_EQ(received[0].p_ned_m.x(), 3.25);

  auto thrower = receiver->subscribe(channel + "_THROW", [](const RawMessage&) {
    throw std::runtime_error("from a udpm handler");
  });
  publish(*sender, channel + "_THROW", makePose(43, 0));
  bool thrown = false;
  for (int i = 0; i < 50 && !thrown; ++i) {
    try {
      receiver->handle(milliseconds(100));
    } catch (const std::runtime_error& error) {
      thrown = std::string(error.what()) == "from a udpm handler";
    }
  }
  EXPECT_TRUE(thrown);
}

// A udpm URL's ttl: as given, 0 when none is (LCM's default), nothing for
// another transport or a ttl that is no number.
TEST(Bus, UdpmTtlIsReadFromTheUrl) {
  EXPECT_EQ(udpmTtl("udpm://239.255.76.67:7667?ttl=1"), 1);
  EXPECT_EQ(udpmTtl("udpm://239.255.76.67:7667?recv_buf_size=8&ttl=0"), 0);
  EXPECT_EQ(udpmTtl("udpm://239.255.76.67:7667?recv_buf_size=8"), 0);
  EXPECT_EQ(udpmTtl("udpm://239.255.76.67:7667"), 0);
  EXPECT_EQ(udpmTtl("udpm://239.255.76.67:7667?ttl=255"), 255);
  EXPECT_FALSE(udpmTtl("udpm://239.255.76.67:7667?ttl=x").has_value());
  EXPECT_FALSE(udpmTtl("memq://").has_value());
  EXPECT_FALSE(udpmTtl("file:///tmp/a.lcmlog?mode=w").has_value());
}

}  // namespace
}  // namespace nadir::core
