#include "cli/doctor.h"

#include "cli/commands.h"

#include <CLI/CLI.hpp>

#include <lcm/lcm.h>

#include <GeographicLib/Config.h>
#include <Eigen/Core>

#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "cli/doctor_checks.h"
#include "core/bus.h"
#include "core/lcm_bus.h"
#include "render/egl_context.h"

namespace nadir::cli {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::int64_t readInteger(const std::string& path) {
  try {
    return std::stoll(readFile(path));
  } catch (const std::exception&) {
    return -1;
  }
}

bool loopbackHasMulticastFlag() {
  constexpr unsigned kIffMulticast = 0x1000;
  try {
    return (std::stoul(readFile("/sys/class/net/lo/flags"), nullptr, 16) & kIffMulticast) != 0;
  } catch (const std::exception&) {
    return false;
  }
}

// The multicast group of a udpm:// URL, or nothing for other transports.
std::optional<std::uint32_t> udpmGroup(const std::string& url) {
  constexpr std::string_view kScheme = "udpm://";
  if (!url.starts_with(kScheme)) return std::nullopt;
  const std::string rest = url.substr(kScheme.size());
  try {
    return parseIpv4(rest.substr(0, rest.find_first_of(":?")));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// Publishes a few small and camera-sized messages to ourselves over the bus.
CheckResult checkUdpmSelfTest(const std::string& url) {
  CheckResult result;
  result.name = "LCM self-test";
  constexpr int kSmall = 5;
  constexpr int kLarge = 10;
  constexpr std::size_t kLargeBytes = 1280 * 960;
  try {
    core::LcmBus bus(url);
    const std::string channel = "NADIR_DOCTOR_" + std::to_string(::getpid());
    int small_received = 0;
    int large_received = 0;
    auto subscription = bus.subscribe(channel, [&](const core::RawMessage& message) {
      (message.size == kLargeBytes ? large_received : small_received) += 1;
    });
    std::atomic<bool> done{false};
    std::thread receiver([&] {
      while (!done) bus.handle(std::chrono::milliseconds(20));
    });
    const std::vector<std::uint8_t> small(64, 1);
    const std::vector<std::uint8_t> large(kLargeBytes, 2);
    for (int i = 0; i < kSmall; ++i) bus.publish(channel, small.data(), small.size(), 0);
    // Camera rate: 31 frames/s, as the thesis's simulator streamed.
    for (int i = 0; i < kLarge; ++i) {
      bus.publish(channel, large.data(), large.size(), 0);
      std::this_thread::sleep_for(std::chrono::milliseconds(32));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    done = true;
    receiver.join();
    result.detail = url + " delivered " + std::to_string(small_received) + "/" +
                    std::to_string(kSmall) + " small and " + std::to_string(large_received) + "/" +
                    std::to_string(kLarge) + " camera-size (1280x960 gray) messages";
    if (small_received < kSmall) {
      result.status = CheckStatus::kFail;
      result.fix = {"sudo ip link set lo multicast on", "sudo ip route add 224.0.0.0/4 dev lo"};
    } else if (large_received < kLarge) {
      result.status = CheckStatus::kFail;
      result.detail += ": the UDP receive buffers are too small for camera images";
      result.fix = receiveBufferFix();
    } else {
      result.status = CheckStatus::kOk;
    }
  } catch (const std::exception& error) {
    result.status = CheckStatus::kFail;
    result.detail = error.what();
    result.fix = {"sudo ip link set lo multicast on", "sudo ip route add 224.0.0.0/4 dev lo"};
  }
  return result;
}

CheckResult checkHeadlessGl() {
  CheckResult result;
  result.name = "headless OpenGL";
  try {
    render::HeadlessGlContext context(4, 5);
    const render::GlContextInfo& info = context.info();
    result.status = info.core_profile ? CheckStatus::kOk : CheckStatus::kFail;
    result.detail = info.gl_renderer + ", OpenGL " + info.gl_version + ", EGL " + info.egl_version +
                    " (" + info.egl_vendor + "), surfaceless Mesa platform";
  } catch (const std::exception& error) {
    result.status = CheckStatus::kFail;
    result.detail = error.what();
    result.fix = {"sudo apt-get install libegl1 libgl1-mesa-dri"};
  }
  return result;
}

CheckResult versions() {
  CheckResult result;
  result.name = "versions";
  std::ostringstream text;
  text << "LCM " << LCM_MAJOR_VERSION << "." << LCM_MINOR_VERSION << "." << LCM_MICRO_VERSION
       << ", OpenCV " << NADIR_OPENCV_VERSION << ", Qt " << NADIR_QT_VERSION << ", GDAL "
       << NADIR_GDAL_VERSION << ", GeographicLib "
       << GEOGRAPHICLIB_VERSION_STRING << ", Eigen " << EIGEN_WORLD_VERSION << "."
       << EIGEN_MAJOR_VERSION << "." << EIGEN_MINOR_VERSION;
  result.detail = text.str();
  return result;
}

void print(const CheckResult& result) {
  const char* tag = "[INFO]";
  switch (result.status) {
    case CheckStatus::kOk:
      tag = "[ OK ]";
      break;
    case CheckStatus::kWarn:
      tag = "[WARN]";
      break;
    case CheckStatus::kFail:
      tag = "[FAIL]";
      break;
    case CheckStatus::kInfo:
      break;
  }
  std::cout << "  " << tag << " " << result.name << ": " << result.detail << "\n";
  for (const std::string& line : result.fix) std::cout << "         fix: " << line << "\n";
}

}  // namespace

int runDoctor() {
  std::cout << "nadir doctor: what live LCM and headless rendering need\n";
  const std::string url = core::defaultBusUrl();
  std::vector<CheckResult> results;
  if (const auto group = udpmGroup(url)) {
    results.push_back(checkMulticastRoute(parseProcNetRoute(readFile("/proc/net/route")), *group,
                                          loopbackHasMulticastFlag()));
  } else {
    results.push_back({CheckStatus::kInfo,
                       "multicast route",
                       "LCM_DEFAULT_URL is " + url + ", not udpm://: no route needed",
                       {}});
  }
  results.push_back(checkReceiveBuffers(readInteger("/proc/sys/net/core/rmem_max"),
                                        readInteger("/proc/sys/net/core/rmem_default")));
  results.push_back(checkExposure(url));
  results.push_back(checkUdpmSelfTest(url));
  results.push_back(checkHeadlessGl());
  results.push_back(versions());
  int failures = 0;
  for (const CheckResult& result : results) {
    print(result);
    if (result.status == CheckStatus::kFail) ++failures;
  }
  std::cout << (failures == 0
                    ? "all checks passed\n"
                    : std::to_string(failures) + " check(s) failed: run the fix lines above\n");
  return failures == 0 ? 0 : 1;
}

void addDoctorCommand(CLI::App& app) {
  app.add_subcommand("doctor",
                     "Check multicast, UDP buffers and headless OpenGL; print the fix for each")
      ->callback([] {
        if (const int status = runDoctor(); status != 0) throw CLI::RuntimeError(status);
      });
}

}  // namespace nadir::cli
