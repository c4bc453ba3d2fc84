#pragma once
// Time in nadir is int64 microseconds ("utime"). Live nodes stamp with the
// wall clock; batch runs and log replay use the time carried by the messages.

#include <chrono>
#include <cstdint>

namespace nadir::core {

inline std::int64_t wallClockUtime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

constexpr double secondsFromUtime(std::int64_t utime) { return static_cast<double>(utime) * 1e-6; }
constexpr std::int64_t utimeFromSeconds(double t_s) {
  return static_cast<std::int64_t>(t_s * 1e6 + (t_s >= 0 ? 0.5 : -0.5));
}

}  // namespace nadir::core
