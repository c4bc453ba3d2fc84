// The hosts fixture (tests/support/hosts.h): three network namespaces on one
// bridge, LCM between them over real UDP multicast. What host A sends with
// ttl=1 arrives whole on hosts B and C, every message, camera frames too
// with the buffers nadir doctor asks for; with ttl=0 nothing
// leaves A; the namespaces are gone once the fixture is, and those a killed
// test left are gone once the next fixture is made. Skipped with the reason
// where the fixture cannot run (not root, no ip).

#include "tests/support/hosts.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "tests/support/run_command.h"

namespace nadir::test {
namespace {

namespace fs = std::filesystem;

constexpr char kProbe[] = NADIR_LCM_PROBE;

// Starts receivers on hosts[1..], waits until each has subscribed, sends
// count messages of bytes from host 0, and returns each receiver's line.
std::vector<std::string> sendAcross(const TestHosts& hosts, int receivers, const std::string& url,
                                    int count, int bytes, int interval_ms, double timeout_s) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("nadir_hosts_" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::vector<fs::path> ready, out;
  for (int r = 1; r <= receivers; ++r) {
    ready.push_back(dir / ("ready" + std::to_string(r)));
    out.push_back(dir / ("out" + std::to_string(r)));
    fs::remove(ready.back());
    const std::string command = hosts.prefix(r) + kProbe + " receive '" + url + "' PROBE " +
                                std::to_string(count) + " " + ready.back().string() + " " +
                                std::to_string(timeout_s) + " > " + out.back().string() + " 2>&1 &";
    EXPECT_EQ(std::system(command.c_str()), 0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (const fs::path& file : ready) {
    while (!fs::exists(file) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_TRUE(fs::exists(file)) << "a receiver never subscribed";
  }
  const auto [status, output] =
      runCommand(hosts.prefix(0) + kProbe + " send '" + url + "' PROBE " + std::to_string(count) +
                 " " + std::to_string(bytes) + " " + std::to_string(interval_ms));
  EXPECT_EQ(status, 0) << output;
  std::vector<std::string> lines;
  for (const fs::path& file : out) {
    std::string line;
    const auto end =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s + 30);
    while (line.rfind("received", 0) != 0 && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::ifstream in(file);
      std::getline(in, line);
    }
    lines.push_back(line);
  }
  return lines;
}

std::string allNumbers(int count) {
  std::ostringstream text;
  text << "received " << count << " of " << count << ", 0 corrupt, numbers:";
  for (int n = 0; n < count; ++n) text << ' ' << n;
  return text.str();
}

// 200 messages of 20 kB, 2 ms apart, from A reach B and C, each one whole
// (within the kernel's default receive buffers of 208 kB).
TEST(Hosts, MessagesCrossFromHostToHost) {
  TestHosts hosts(3);
  if (!hosts.available()) GTEST_SKIP() << hosts.whyNot();
  const std::vector<std::string> lines =
      sendAcross(hosts, 2, "udpm://239.255.76.67:7667?ttl=1", 200, 20000, 2, 20.0);
  for (const std::string& line : lines) EXPECT_EQ(line, allNumbers(200));
}

// 31 camera frames of 1280 x 960 gray (1.2 MB, about 850 fragments each) at
// 31 frames/s from A reach B whole, with the receive buffers nadir doctor
// asks for (without them the kernel drops fragments: skipped, saying so).
TEST(Hosts, CameraFramesCrossWithRaisedBuffers) {
  long rmem_default = 0;
  std::ifstream("/proc/sys/net/core/rmem_default") >> rmem_default;
  if (rmem_default < 64L << 20) {
    GTEST_SKIP() << "net.core.rmem_default is " << rmem_default
                 << " bytes: camera frames need the buffers ./nadir doctor asks for";
  }
  TestHosts hosts(2);
  if (!hosts.available()) GTEST_SKIP() << hosts.whyNot();
  const std::vector<std::string> lines =
      sendAcross(hosts, 1, "udpm://239.255.76.67:7667?ttl=1", 31, 1280 * 960, 32, 20.0);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], allNumbers(31));
}

// With ttl=0 a message never leaves its host: B receives none of A's.
TEST(Hosts, TtlZeroStaysOnItsHost) {
  TestHosts hosts(2);
  if (!hosts.available()) GTEST_SKIP() << hosts.whyNot();
  const std::vector<std::string> lines =
      sendAcross(hosts, 1, "udpm://239.255.76.67:7667?ttl=0", 20, 1000, 2, 2.0);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "received 0 of 20, 0 corrupt, numbers:");
}

// Once the fixture is gone, so are its namespaces.
TEST(Hosts, RemovedWithTheFixture) {
  std::string name;
  {
    TestHosts hosts(2);
    if (!hosts.available()) GTEST_SKIP() << hosts.whyNot();
    name = hosts.name(1);
    EXPECT_NE(runCommand("ip netns list").second.find(name), std::string::npos);
  }
  EXPECT_EQ(runCommand("ip netns list").second.find(name), std::string::npos);
}

// A namespace left by a fixture whose process is gone (killed before its
// destructor ran) is removed by the next fixture.
TEST(Hosts, WhatAKilledTestLeftIsRemoved) {
  if (geteuid() != 0 || runCommand("ip -V").first != 0) GTEST_SKIP() << "needs root and ip";
  const std::string left = "nadirh999999999x0h0";  // no such pid
  ASSERT_EQ(runCommand("ip netns add " + left).first, 0);
  TestHosts hosts(1);
  EXPECT_EQ(runCommand("ip netns list").second.find(left), std::string::npos);
  runCommand("ip netns del " + left + " 2>/dev/null");
}

}  // namespace
}  // namespace nadir::test
