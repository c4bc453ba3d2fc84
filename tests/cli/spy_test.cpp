// nadir spy: nadir's Java types (nadir-lcmtypes.jar) decode what the C++ codec
// encodes, and lcm-spy started by `nadir spy` comes up on a virtual display
// (Xvfb) with every nadir type and stays up while nadir messages arrive.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "core/bus.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/messages.h"
#include "run/process.h"
#include "tests/support/run_command.h"

namespace nadir {
namespace {

namespace fs = std::filesystem;

std::string tempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("nadir_spy_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The jars a Java program needs to read nadir's types: lcm.jar and nadir's.
std::string typesClassPath() {
  std::string class_path;
  std::ifstream needed(std::string(NADIR_TYPES_JAR) + ".classpath");
  std::string line;
  while (std::getline(needed, line)) {
    if (!line.empty()) class_path += line + ":";
  }
  return class_path + NADIR_TYPES_JAR;
}

bool commandExists(const std::string& program) {
  return test::runCommand("command -v " + program).first == 0;
}

int lcmTypeCount() {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(NADIR_LCMTYPES_DIR)) {
    if (entry.path().extension() == ".lcm") ++count;
  }
  return count;
}

// A pose whose every value is exact in binary, encoded by the C++ codec, is
// read by a Java program through the jar with every field equal (the quaternion
// is not symmetric, so an order mistake shows).
TEST(SpyTypes, APoseEncodedInCppDecodesInJava) {
  if (!commandExists("java")) GTEST_SKIP() << "no java (package default-jdk-headless)";
  msg::Pose pose;
  pose.utime = 1'700'000'000'123'456;
  pose.p_ned_m = {12.5, -3.25, -120.0};
  pose.v_ned_mps = {1.5, 0.0, -0.25};
  pose.q_world_body = Eigen::Quaterniond(0.5, -0.5, 0.5, 0.5);
  pose.omega_body_rps = {0.125, -0.5, 2.0};
  pose.a_ned_mps2 = {0.0, 0.0, -9.75};
  const msg::Bytes bytes = msg::encode(pose);
  const std::string file = tempDir("pose") + "/pose.bin";
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  const auto [status, output] = test::runCommand("java -cp '" + typesClassPath() + "' '" +
                                                 NADIR_POSE_DECODE_SOURCE + "' '" + file + "'");
  ASSERT_EQ(status, 0) << output;
  EXPECT_EQ(output,
            "utime 1700000000123456\n"
            "pos 12.5 -3.25 -120.0\n"
            "vel 1.5 0.0 -0.25\n"
            "orientation 0.5 -0.5 0.5 0.5\n"
            "rotation_rate 0.125 -0.5 2.0\n"
            "accel 0.0 0.0 -9.75\n");
}

// A virtual display of its own (Xvfb picks a free number and says it).
class VirtualDisplay {
 public:
  explicit VirtualDisplay(const std::string& dir)
      : server_("Xvfb",
                {"Xvfb", "-displayfd", "1", "-screen", "0", "1024x768x24", "-nolisten", "tcp"},
                dir + "/xvfb.log") {
    server_.start();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline && server_.running()) {
      const std::string text = readFile(server_.logPath());
      const std::size_t newline = text.find('\n');
      if (newline != std::string::npos && newline > 0 &&
          text.find_first_not_of("0123456789") == newline) {
        display_ = ":";
        display_ += text.substr(0, newline);
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ~VirtualDisplay() { server_.stop(5.0); }
  const std::string& display() const { return display_; }  // empty if it never came up

 private:
  run::ChildProcess server_;
  std::string display_;
};

// `nadir spy` on a virtual display: lcm-spy's window appears, it finds every
// nadir type, and it is still running after nadir messages have come on its bus.
TEST(Spy, StartsOnAVirtualDisplayAndStaysUp) {
  if (!commandExists("java")) GTEST_SKIP() << "no java (package default-jdk-headless)";
  if (!commandExists("Xvfb") || !commandExists("xwininfo")) {
    GTEST_SKIP() << "no Xvfb or xwininfo (packages xvfb, x11-utils)";
  }
  const std::string dir = tempDir("window");
  const VirtualDisplay screen(dir);
  ASSERT_FALSE(screen.display().empty()) << readFile(dir + "/xvfb.log");
  ASSERT_EQ(setenv("DISPLAY", screen.display().c_str(), 1), 0);
  const std::string url = "udpm://239.255.76.67:7891?ttl=0";
  run::ChildProcess spy("nadir spy", {NADIR_BIN, "spy", "--url", url}, dir + "/spy.log");
  spy.start();
  // Java and Swing start in seconds; a minute means they never will.
  bool window = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!window && spy.running() && std::chrono::steady_clock::now() < deadline) {
    const auto [status, tree] =
        test::runCommand("xwininfo -display " + screen.display() + " -root -tree");
    window = status == 0 && tree.find("\"LCM Spy\"") != std::string::npos;
    if (!window) std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  ASSERT_TRUE(window) << readFile(spy.logPath());

  const std::unique_ptr<core::Bus> bus = core::openBus(url);
  for (int i = 0; i < 20; ++i) {
    msg::Pose pose;
    pose.utime = 1'000'000 + 10'000 * i;
    const msg::Bytes bytes = msg::encode(pose);
    bus->publish("POSE_TRUTH", bytes.data(), bytes.size(), pose.utime);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(spy.running()) << spy.describeExit() << "\n" << readFile(spy.logPath());
  spy.stop(5.0);
  const std::string log = readFile(spy.logPath());
  EXPECT_NE(log.find("Found " + std::to_string(lcmTypeCount()) + " LCM types"), std::string::npos)
      << log;
  EXPECT_EQ(log.find("Exception"), std::string::npos) << log;
}

}  // namespace
}  // namespace nadir
