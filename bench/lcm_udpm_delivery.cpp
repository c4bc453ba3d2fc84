// Measures how many camera-sized LCM messages survive a UDP multicast hop on
// this machine: publishes N images of W x H gray at a rate, counts what a
// receiver thread gets. Prints one line of figures.
//
//   lcm_udpm_delivery [--frames N] [--width W] [--height H] [--rate HZ] [--url URL]
//
// rate 0 publishes back to back. The receive buffer is the system's
// net.core.rmem_default unless the URL has recv_buf_size=BYTES.

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>
#include <vector>

#include "core/bus.h"
#include "core/command_line.h"

namespace {

long readSysctl(const char* path) {
  std::ifstream in(path);
  long value = -1;
  in >> value;
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"LCM udpm delivery of camera-sized messages"};
  int frames = 100;
  int width = 1280;
  int height = 960;
  double rate_hz = 31.0;
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  app.add_option("--frames", frames)->check(CLI::PositiveNumber);
  app.add_option("--width", width)->check(CLI::PositiveNumber);
  app.add_option("--height", height)->check(CLI::PositiveNumber);
  app.add_option("--rate", rate_hz, "frames/s; 0 = back to back")->check(CLI::NonNegativeNumber);
  app.add_option("--url", url);
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;

  auto bus = nadir::core::openBus(url);
  std::atomic<int> received{0};
  auto subscription =
      bus->subscribe("BENCH_IMAGE", [&](const nadir::core::RawMessage&) { received.fetch_add(1); });
  std::atomic<bool> done{false};
  std::thread receiver([&] {
    while (!done) bus->handle(std::chrono::milliseconds(20));
  });

  const std::vector<std::uint8_t> image(static_cast<std::size_t>(width) * height, 128);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < frames; ++i) {
    bus->publish("BENCH_IMAGE", image.data(), image.size(), 0);
    if (rate_hz > 0) {
      std::this_thread::sleep_until(
          start + std::chrono::microseconds(static_cast<long>((i + 1) * 1e6 / rate_hz)));
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  done = true;
  receiver.join();
  std::printf(
      "url=%s rmem_max=%ld rmem_default=%ld frames=%d size=%dx%d rate_hz=%g delivered=%d "
      "(%.0f%%)\n",
      bus->url().c_str(), readSysctl("/proc/sys/net/core/rmem_max"),
      readSysctl("/proc/sys/net/core/rmem_default"), frames, width, height, rate_hz,
      received.load(), 100.0 * received.load() / frames);
  return 0;
}
