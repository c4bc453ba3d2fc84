#pragma once
// A Bus over an LCM log file. Reading dispatches the events in file order and
// advances a sim clock to each event's timestamp; writing records every
// published message with its own utime as the event timestamp.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/lcm_log.h"

namespace nadir::core {

struct LogBusOptions {
  enum class Mode { kRead, kWrite };
  std::string path;
  Mode mode = Mode::kRead;
  // Read only: 0 dispatches as fast as possible (sim time); S > 0 paces the
  // events at S times their recorded rate against the wall clock.
  double speed = 0.0;

  // Parses file://PATH[?mode=r|w][&speed=S]; throws BusError naming what is wrong.
  static LogBusOptions fromUrl(const std::string& url);
};

class LogBus final : public Bus {
 public:
  explicit LogBus(const LogBusOptions& options);
  ~LogBus() override;

  std::string url() const override;
  // Write mode only: appends an event stamped event_utime.
  void send(std::string_view channel, const void* data, std::size_t size,
            std::int64_t event_utime) override;
  // Read mode: dispatches the next event; false at the end of the log. Never
  // waits on the wall clock unless speed > 0. Write mode: always false.
  bool handle(std::chrono::milliseconds timeout) override;

  // Timestamp of the event dispatched last (the sim time), microseconds.
  std::int64_t nowUtime() const { return now_utime_; }
  // What damage the reader met (empty for a clean log or in write mode).
  std::string damageReport() const;
  std::int64_t eventsWritten() const;
  void flush();

 private:
  struct CompiledHandler;
  void addSubscription(const Handler& handler) override;
  void removeSubscription(int id) override;

  LogBusOptions options_;
  std::unique_ptr<LcmLogReader> reader_;
  std::unique_ptr<LcmLogWriter> writer_;
  std::vector<std::unique_ptr<CompiledHandler>> handlers_;
  std::int64_t now_utime_ = 0;
  std::optional<std::int64_t> first_event_utime_;
  std::chrono::steady_clock::time_point wall_start_;
  bool reported_damage_ = false;
  bool dispatching_ = false;
};

}  // namespace nadir::core
