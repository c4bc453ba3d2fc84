#include "core/log_bus.h"

#include <regex.h>

#include <algorithm>
#include <charconv>
#include <iostream>
#include <thread>

namespace nadir::core {

// Channel patterns match whole names with POSIX extended regexes, as LCM does.
struct LogBus::CompiledHandler {
  int id;
  std::string pattern;
  regex_t regex;
  RawHandler callback;
  bool removed = false;

  CompiledHandler(int handler_id, const std::string& channel_regex, RawHandler handler)
      : id(handler_id), pattern(channel_regex), callback(std::move(handler)) {
    const std::string anchored = "^(" + channel_regex + ")$";
    if (regcomp(&regex, anchored.c_str(), REG_EXTENDED | REG_NOSUB) != 0) {
      throw BusError("invalid channel regex '" + channel_regex + "'");
    }
  }
  ~CompiledHandler() { regfree(&regex); }
  CompiledHandler(const CompiledHandler&) = delete;
  CompiledHandler& operator=(const CompiledHandler&) = delete;

  bool matches(const std::string& channel) const {
    return regexec(&regex, channel.c_str(), 0, nullptr, 0) == 0;
  }
};

LogBusOptions LogBusOptions::fromUrl(const std::string& url) {
  constexpr std::string_view kScheme = "file://";
  if (!url.starts_with(kScheme)) throw BusError("not a file:// URL: '" + url + "'");
  LogBusOptions options;
  const std::string rest = url.substr(kScheme.size());
  const auto query_start = rest.find('?');
  options.path = rest.substr(0, query_start);
  if (options.path.empty()) throw BusError("file:// URL without a path: '" + url + "'");
  std::string query = query_start == std::string::npos ? "" : rest.substr(query_start + 1);
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string item = query.substr(0, amp);
    query = amp == std::string::npos ? "" : query.substr(amp + 1);
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "mode") {
      if (value == "r") {
        options.mode = Mode::kRead;
      } else if (value == "w") {
        options.mode = Mode::kWrite;
      } else {
        throw BusError("in '" + url + "': mode must be r or w, not '" + value + "'");
      }
    } else if (key == "speed") {
      const auto [end, ec] =
          std::from_chars(value.data(), value.data() + value.size(), options.speed);
      if (ec != std::errc() || end != value.data() + value.size() || options.speed < 0.0) {
        throw BusError("in '" + url + "': speed must be a number >= 0, not '" + value + "'");
      }
    } else {
      throw BusError("in '" + url + "': unknown option '" + key + "' (known: mode, speed)");
    }
  }
  return options;
}

LogBus::LogBus(const LogBusOptions& options) : options_(options) {
  if (options_.mode == LogBusOptions::Mode::kRead) {
    reader_ = std::make_unique<LcmLogReader>(options_.path);
  } else {
    writer_ = std::make_unique<LcmLogWriter>(options_.path);
  }
}

LogBus::~LogBus() = default;

std::string LogBus::url() const {
  std::string url = "file://" + options_.path;
  url += options_.mode == LogBusOptions::Mode::kRead ? "?mode=r" : "?mode=w";
  if (options_.mode == LogBusOptions::Mode::kRead && options_.speed > 0.0) {
    url += "&speed=" + std::to_string(options_.speed);
  }
  return url;
}

void LogBus::send(std::string_view channel, const void* data, std::size_t size,
                  std::int64_t event_utime) {
  if (!writer_) {
    throw BusError("cannot publish on '" + std::string(channel) + "': " + options_.path +
                   " is open for reading");
  }
  writer_->write(event_utime, std::string(channel), data, size);
  countMessage(channel, data, size);
}

bool LogBus::handle(std::chrono::milliseconds /*timeout*/) {
  if (!reader_) return false;
  std::optional<LogEvent> event = reader_->next();
  if (!event) {
    if (!reported_damage_ && !reader_->damageReport().empty()) {
      std::cerr << "warning: " << reader_->damageReport() << "\n";
    }
    reported_damage_ = true;
    return false;
  }
  if (options_.speed > 0.0) {
    if (!first_event_utime_) {
      first_event_utime_ = event->timestamp_utime;
      wall_start_ = std::chrono::steady_clock::now();
    }
    const auto offset_us = static_cast<double>(event->timestamp_utime - *first_event_utime_);
    std::this_thread::sleep_until(wall_start_ + std::chrono::microseconds(static_cast<std::int64_t>(
                                                    offset_us / options_.speed)));
  }
  now_utime_ = event->timestamp_utime;
  countMessage(event->channel, event->data.data(), event->data.size());
  const RawMessage raw{event->channel, event->data.data(), event->data.size(),
                       event->timestamp_utime};
  // Handlers may subscribe or unsubscribe from inside a callback: iterate by
  // index over the handlers present now and erase removed ones afterwards.
  dispatching_ = true;
  struct EndDispatch {
    LogBus* bus;
    ~EndDispatch() {
      bus->dispatching_ = false;
      std::erase_if(bus->handlers_, [](const auto& handler) { return handler->removed; });
    }
  } end_dispatch{this};
  const std::size_t count = handlers_.size();
  for (std::size_t i = 0; i < count; ++i) {
    CompiledHandler& handler = *handlers_[i];
    if (!handler.removed && handler.matches(event->channel)) handler.callback(raw);
  }
  return true;
}

std::string LogBus::damageReport() const { return reader_ ? reader_->damageReport() : ""; }

std::int64_t LogBus::eventsWritten() const { return writer_ ? writer_->eventsWritten() : 0; }

void LogBus::flush() {
  if (writer_) writer_->flush();
}

void LogBus::addSubscription(const Handler& handler) {
  if (!reader_) {
    throw BusError("cannot subscribe to '" + handler.channel_regex + "': " + options_.path +
                   " is open for writing");
  }
  handlers_.push_back(
      std::make_unique<CompiledHandler>(handler.id, handler.channel_regex, handler.callback));
}

void LogBus::removeSubscription(int id) {
  for (auto& handler : handlers_) {
    if (handler->id == id) handler->removed = true;
  }
  if (!dispatching_) std::erase_if(handlers_, [](const auto& handler) { return handler->removed; });
}

}  // namespace nadir::core
