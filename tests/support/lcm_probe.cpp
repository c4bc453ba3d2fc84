// Sends or receives numbered messages on a bus, for the tests across hosts:
//   lcm_probe send URL CHANNEL COUNT BYTES INTERVAL_MS
//   lcm_probe receive URL CHANNEL COUNT READY_FILE TIMEOUT_S
// send publishes COUNT messages of BYTES (the first 4 bytes the message's
// number, big-endian; the rest number-derived bytes), INTERVAL_MS apart. receive
// writes READY_FILE once subscribed, takes messages until it has COUNT or
// TIMEOUT_S pass, and prints "received K of COUNT, N corrupt, numbers: ...".

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/bus.h"

namespace {

std::uint8_t fill(std::uint32_t number, std::size_t i) {
  return static_cast<std::uint8_t>((number * 31u + i * 7u) & 0xffu);
}

int send(const std::string& url, const std::string& channel, int count, std::size_t bytes,
         int interval_ms) {
  auto bus = nadir::core::openBus(url);
  std::vector<std::uint8_t> data(std::max<std::size_t>(bytes, 4));
  for (int n = 0; n < count; ++n) {
    const auto number = static_cast<std::uint32_t>(n);
    for (int k = 0; k < 4; ++k) data[k] = static_cast<std::uint8_t>(number >> (24 - 8 * k));
    for (std::size_t i = 4; i < data.size(); ++i) data[i] = fill(number, i);
    bus->publish(channel, data.data(), data.size(), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(interval_ms));
  }
  return 0;
}

int receive(const std::string& url, const std::string& channel, int count,
            const std::string& ready_file, double timeout_s) {
  auto bus = nadir::core::openBus(url);
  std::set<std::uint32_t> numbers;
  int corrupt = 0;
  auto subscription = bus->subscribe(channel, [&](const nadir::core::RawMessage& m) {
    if (m.size < 4) {
      ++corrupt;
      return;
    }
    std::uint32_t number = 0;
    for (int k = 0; k < 4; ++k) number = (number << 8) | m.data[k];
    for (std::size_t i = 4; i < m.size; ++i) {
      if (m.data[i] != fill(number, i)) {
        ++corrupt;
        return;
      }
    }
    numbers.insert(number);
  });
  std::ofstream(ready_file) << "ready\n";
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (static_cast<int>(numbers.size()) < count && std::chrono::steady_clock::now() < end) {
    bus->handle(std::chrono::milliseconds(100));
  }
  std::printf("received %zu of %d, %d corrupt, numbers:", numbers.size(), count, corrupt);
  for (const std::uint32_t n : numbers) std::printf(" %u", n);
  std::printf("\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.size() == 6 && args[0] == "send") {
      return send(args[1], args[2], std::atoi(args[3].c_str()),
                  static_cast<std::size_t>(std::atol(args[4].c_str())), std::atoi(args[5].c_str()));
    }
    if (args.size() == 6 && args[0] == "receive") {
      return receive(args[1], args[2], std::atoi(args[3].c_str()), args[4],
                     std::atof(args[5].c_str()));
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "lcm_probe: %s\n", error.what());
    return 1;
  }
  std::fprintf(stderr,
               "usage: lcm_probe send URL CHANNEL COUNT BYTES INTERVAL_MS\n"
               "       lcm_probe receive URL CHANNEL COUNT READY_FILE TIMEOUT_S\n");
  return 2;
}
