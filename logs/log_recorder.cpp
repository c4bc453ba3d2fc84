#include "logs/log_recorder.h"

#include <utility>

#include "core/clock.h"

namespace nadir::logs {

LogRecorder::LogRecorder(core::Bus& bus, const std::string& path, RecorderOptions options)
    : bus_(bus),
      filter_(options.channels),
      heartbeat_channel_(std::move(options.heartbeat_channel)),
      writer_(path) {
  for (const auto& [channel, rate_hz] : options.expected_rates_hz) {
    bus_.expectRate(channel, rate_hz);
  }
  subscription_ = bus_.subscribe(".*", [this](const core::RawMessage& message) {
    const std::string channel(message.channel);
    if (!filter_.keeps(channel)) return;
    const std::int64_t receive_utime =
        message.recv_utime > 0 ? message.recv_utime : core::wallClockUtime();
    writer_.write(receive_utime, channel, message.data, message.size);
    bytes_ += static_cast<std::int64_t>(message.size);
    // LCM's own self test is sent when a bus opens: no sign of data either.
    if (channel != heartbeat_channel_ && channel != "LCM_SELF_TEST") {
      last_receive_utime_ = receive_utime;
    }
  });
}

std::map<std::string, core::ChannelStats> LogRecorder::arrivals() const {
  std::map<std::string, core::ChannelStats> recorded;
  for (auto& [channel, stats] : bus_.stats()) {
    if (channel != heartbeat_channel_ && filter_.keeps(channel)) recorded.emplace(channel, stats);
  }
  return recorded;
}

}  // namespace nadir::logs
