// nadir log info|cut|play|record: look into, cut, replay and record LCM logs (logs/).
#include "cli/commands.h"
#include "cli/progress_line.h"

#include <CLI/CLI.hpp>

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/clock.h"
#include "logs/log_cut.h"
#include "logs/log_info.h"
#include "logs/log_player.h"
#include "logs/log_recorder.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"

namespace nadir::cli {
namespace {

constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

struct LogInfoCommandOptions {
  std::string log;
};

struct LogCutCommandOptions {
  std::string log;
  std::string out;
  double start_s = kUnset;
  double end_s = kUnset;
  bool absolute = false;
  std::string channels;
  std::string exclude;
};

struct LogPlayCommandOptions {
  std::string log;
  std::string url;
  double speed = 1.0;
  double start_s = 0.0;
  bool loop = false;
  std::vector<std::string> remap;
  std::string channels;
  std::string image_encoding = "as-recorded";
};

struct LogRecordCommandOptions {
  std::string log;
  std::string url;
  std::string channels;
  std::vector<std::string> rates;
  std::string scenario;
  double idle_stop_s = 0.0;
  double duration_s = 0.0;
  bool force = false;
};

void runLogInfo(const LogInfoCommandOptions& options) {
  logs::LogInfo info;
  {
    ProgressLine progress("nadir log info: reading " + options.log);
    info = logs::logInfo(options.log, progress.reading());
  }
  std::cout << logs::formatLogInfo(info);
}

std::string seconds(double t_s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", t_s);
  return text;
}

void runLogCut(const LogCutCommandOptions& options) {
  logs::CutOptions cut;
  cut.channels = options.channels;
  cut.exclude = options.exclude;
  if (!std::isnan(options.start_s)) {
    if (options.absolute) {
      cut.start_utime = core::utimeFromSeconds(options.start_s);
    } else {
      cut.start_s = options.start_s;
    }
  }
  if (!std::isnan(options.end_s)) {
    if (options.absolute) {
      cut.end_utime = core::utimeFromSeconds(options.end_s);
    } else {
      cut.end_s = options.end_s;
    }
  }
  logs::CutResult result;
  {
    ProgressLine progress("nadir log cut: reading " + options.log);
    cut.progress = progress.reading();
    result = logs::cutLog(options.log, options.out, cut);
  }
  std::cout << "nadir log cut: wrote " << result.events_written << " of " << result.events_read
            << " events (" << result.bytes_written << " bytes) to " << options.out << "\n";
  if (result.events_written > 0) {
    std::cout << "  event time " << seconds(core::secondsFromUtime(result.first_written_utime))
              << " .. " << seconds(core::secondsFromUtime(result.last_written_utime)) << " s\n";
  }
  for (const auto& [channel, count] : result.written_per_channel) {
    std::cout << "  " << channel << ": " << count << "\n";
  }
  if (!result.damage_report.empty()) {
    std::cerr << "warning: the input is damaged; cut what could be read: " << result.damage_report
              << "\n";
  }
}

// ---- play: the terminal, signals and keys

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void onStopSignal(int signal_number) { g_stop_signal = signal_number; }

// Routes SIGINT, SIGTERM and SIGHUP to a flag the play loop checks, so the
// terminal is restored on the way out; the previous handlers come back after.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    struct sigaction action {};
    action.sa_handler = onStopSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;  // no SA_RESTART: a signal ends the wait at once
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &action, &saved_[i]);
  }
  ~StopSignals() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &saved_[i], nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  static constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> saved_{};
};

// Keys arrive one by one without echo while this lives (stdin a terminal);
// Ctrl-C still raises SIGINT. The settings are restored when it goes.
class RawTerminal {
 public:
  RawTerminal() {
    if (isatty(STDIN_FILENO) == 0 || tcgetattr(STDIN_FILENO, &saved_) != 0) return;
    termios raw = saved_;
    raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
  }
  ~RawTerminal() {
    if (active_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;
  bool active() const { return active_; }

 private:
  termios saved_{};
  bool active_ = false;
};

enum class Key { kNone, kPause, kSeekBack, kSeekForward, kFaster, kSlower, kQuit };

// Reads what was typed: space, q, and the arrows (ESC [ A..D or ESC O A..D).
std::vector<Key> readKeys() {
  char bytes[64];
  const ssize_t count = read(STDIN_FILENO, bytes, sizeof(bytes));
  std::vector<Key> keys;
  for (ssize_t i = 0; i < count; ++i) {
    const char c = bytes[i];
    if (c == ' ') {
      keys.push_back(Key::kPause);
    } else if (c == 'q' || c == 'Q') {
      keys.push_back(Key::kQuit);
    } else if (c == '\x1b' && i + 2 < count && (bytes[i + 1] == '[' || bytes[i + 1] == 'O')) {
      switch (bytes[i + 2]) {
        case 'A':
          keys.push_back(Key::kFaster);
          break;
        case 'B':
          keys.push_back(Key::kSlower);
          break;
        case 'C':
          keys.push_back(Key::kSeekForward);
          break;
        case 'D':
          keys.push_back(Key::kSeekBack);
          break;
        default:
          break;
      }
      i += 2;
    }
  }
  return keys;
}

// Waits up to wait_us for a key on stdin (if keys is set) or a signal.
void waitFor(std::int64_t wait_us, bool keys) {
  timespec timeout{};
  timeout.tv_sec = static_cast<std::time_t>(wait_us / 1'000'000);
  timeout.tv_nsec = static_cast<long>(wait_us % 1'000'000) * 1000;
  pollfd input{STDIN_FILENO, POLLIN, 0};
  ppoll(keys ? &input : nullptr, keys ? 1 : 0, &timeout, nullptr);
}

void runLogPlay(const LogPlayCommandOptions& options) {
  logs::PlayerOptions player_options;
  player_options.speed = options.speed;
  player_options.start_s = options.start_s;
  player_options.loop = options.loop;
  player_options.channels = options.channels;
  player_options.image_encoding = logs::ImageEncoding::parse(options.image_encoding);
  for (const std::string& text : options.remap) player_options.remap.insert(logs::parseRemap(text));

  const std::string url = options.url.empty() ? core::defaultBusUrl() : options.url;
  const std::unique_ptr<core::Bus> bus = core::openBus(url);
  logs::LogPlayer player(options.log, *bus, player_options);

  std::cout << "nadir log play: " << options.log << " (" << player.events() << " events, "
            << seconds(player.durationS()) << " s";
  if (player.selectedEvents() != player.events()) {
    std::cout << ", " << player.selectedEvents() << " on the selected channels";
  }
  std::cout << ") to " << bus->url() << "\n";
  for (const auto& [from, to] : player_options.remap) {
    std::cout << "  " << from << " is sent as " << to << "\n";
  }
  if (player_options.image_encoding.kind != logs::ImageEncoding::Kind::kAsRecorded) {
    std::cout << "  images are sent " << player_options.image_encoding.name() << "\n";
  }
  if (!player.damageReport().empty()) {
    std::cerr << "warning: the log is damaged; playing what could be read: "
              << player.damageReport() << "\n";
  }

  const StopSignals stop_signals;
  const RawTerminal terminal;
  const bool show_status = isatty(STDERR_FILENO) != 0;
  if (terminal.active()) {
    std::cout << "  keys: space pause/resume, left/right seek -/+5 s, up/down speed x2 / /2, "
                 "q quit\n";
  }
  std::cout << std::flush;

  constexpr std::int64_t kMaxWaitUs = 100'000;  // status refresh and signal checks
  constexpr std::int64_t kStatusPeriodUs = 100'000;
  std::int64_t last_status = std::numeric_limits<std::int64_t>::min() / 2;
  const auto showStatus = [&](bool force) {
    if (!show_status) return;
    const std::int64_t now = logs::LogPlayer::steadyClockUtime();
    if (!force && now - last_status < kStatusPeriodUs) return;
    last_status = now;
    std::cerr << "\r\033[K" << player.statusLine() << std::flush;
  };

  bool quit = false;
  while (!quit && g_stop_signal == 0) {
    player.update();
    if (player.finished()) break;
    showStatus(false);
    const std::int64_t wait_us =
        std::clamp<std::int64_t>(player.microsUntilNextEvent().value_or(kMaxWaitUs), 0, kMaxWaitUs);
    waitFor(wait_us, terminal.active());
    if (!terminal.active()) continue;
    pollfd input{STDIN_FILENO, POLLIN, 0};
    if (poll(&input, 1, 0) <= 0) continue;
    for (const Key key : readKeys()) {
      switch (key) {
        case Key::kPause:
          player.togglePause();
          break;
        case Key::kSeekBack:
          player.seekBy(-5.0);
          break;
        case Key::kSeekForward:
          player.seekBy(5.0);
          break;
        case Key::kFaster:
          player.setSpeed(std::min(player.speed() * 2.0, 1024.0));
          break;
        case Key::kSlower:
          player.setSpeed(std::max(player.speed() / 2.0, 1.0 / 1024.0));
          break;
        case Key::kQuit:
          quit = true;
          break;
        case Key::kNone:
          break;
      }
    }
    showStatus(true);
  }
  showStatus(true);
  if (show_status) std::cerr << "\n";
  std::cout << "nadir log play: sent " << player.eventsSent() << " messages, " << player.bytesSent()
            << " bytes";
  if (player.imagesReencoded() > 0) {
    std::cout << " (" << player.imagesReencoded() << " images re-encoded "
              << player_options.image_encoding.name() << ")";
  }
  if (player.finished()) {
    std::cout << "; the log ended\n";
  } else {
    std::cout << "; stopped at " << seconds(player.positionS()) << " s\n";
  }
  for (const auto& [channel, bytes] : player.bytesSentByChannel()) {
    std::cout << "  " << channel << ": " << bytes << " bytes\n";
  }
  if (g_stop_signal != 0) throw CLI::RuntimeError(128 + g_stop_signal);
}

// "CHANNEL=HZ" -> {CHANNEL, HZ}; throws std::invalid_argument.
std::pair<std::string, double> parseRate(const std::string& text) {
  const auto eq = text.find('=');
  double rate_hz = 0.0;
  std::size_t used = 0;
  if (eq != std::string::npos && eq > 0) {
    try {
      rate_hz = std::stod(text.substr(eq + 1), &used);
    } catch (const std::exception&) {
      used = 0;
    }
  }
  if (eq == std::string::npos || eq == 0 || used == 0 || used != text.size() - eq - 1 ||
      !(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    throw std::invalid_argument("a rate is CHANNEL=HZ with HZ > 0, not '" + text + "'");
  }
  return {text.substr(0, eq), rate_hz};
}

void printArrivals(const std::map<std::string, core::ChannelStats>& arrivals) {
  for (const auto& [channel, stats] : arrivals) {
    std::cout << "  " << channel << ": " << stats.messages << " messages, " << stats.bytes
              << " bytes";
    if (stats.rate_hz > 0.0) {
      char rate[96];
      std::snprintf(rate, sizeof(rate), ", %.2f Hz, %lld lost in %lld gaps", stats.rate_hz,
                    static_cast<long long>(stats.missing), static_cast<long long>(stats.gaps));
      std::cout << rate;
    } else {
      std::cout << ", no steady rate (losses not counted)";
    }
    if (stats.out_of_order > 0) std::cout << ", " << stats.out_of_order << " out of order";
    std::cout << "\n";
  }
}

void runLogRecord(const LogRecordCommandOptions& options) {
  if (!options.force && std::filesystem::exists(options.log)) {
    throw std::runtime_error(options.log + " already exists; pass --force to replace it");
  }
  logs::RecorderOptions recorder_options;
  recorder_options.channels = options.channels;
  if (!options.scenario.empty()) {
    recorder_options.expected_rates_hz =
        nodes::expectedRates(nodes::loadScenario(options.scenario));
  }
  for (const std::string& text : options.rates) {
    const auto [channel, rate_hz] = parseRate(text);
    recorder_options.expected_rates_hz[channel] = rate_hz;
  }
  const std::string url = options.url.empty() ? core::defaultBusUrl() : options.url;
  const std::unique_ptr<core::Bus> bus = core::openBus(url);
  logs::LogRecorder recorder(*bus, options.log, recorder_options);
  std::cout << "nadir log record: " << bus->url() << " to " << options.log;
  if (!options.channels.empty()) std::cout << " (channels matching " << options.channels << ")";
  std::cout << "; Ctrl-C stops" << std::endl;

  const StopSignals stop_signals;
  const bool show_status = isatty(STDERR_FILENO) != 0;
  const std::int64_t started = logs::LogPlayer::steadyClockUtime();
  std::int64_t last_status = started;
  const char* ended = "stopped";
  while (g_stop_signal == 0) {
    bus->handle(std::chrono::milliseconds(100));
    const std::int64_t now = logs::LogPlayer::steadyClockUtime();
    if (now - last_status >= 1'000'000) {
      last_status = now;
      recorder.flush();
      if (show_status) {
        std::cerr << "\r\033[K" << seconds(core::secondsFromUtime(now - started)) << " s  "
                  << recorder.eventsWritten() << " messages  " << recorder.bytesWritten()
                  << " bytes  " << core::describeLosses(recorder.arrivals()) << std::flush;
      }
    }
    if (options.duration_s > 0.0 && core::secondsFromUtime(now - started) >= options.duration_s) {
      ended = "its duration is over";
      break;
    }
    if (options.idle_stop_s > 0.0 && recorder.lastReceiveUtime() > 0 &&
        core::secondsFromUtime(core::wallClockUtime() - recorder.lastReceiveUtime()) >=
            options.idle_stop_s) {
      ended = "the bus went quiet";
      break;
    }
  }
  recorder.flush();
  if (show_status) std::cerr << "\n";
  const auto arrivals = recorder.arrivals();
  std::cout << "nadir log record: " << ended << "; " << recorder.eventsWritten() << " messages, "
            << recorder.bytesWritten() << " bytes in " << options.log << "; "
            << core::describeLosses(arrivals) << "\n";
  printArrivals(arrivals);
}

}  // namespace

void addLogCommands(CLI::App& app) {
  CLI::App* log = app.add_subcommand("log", "Look into, cut and replay LCM logs");
  log->require_subcommand(1);

  auto info_options = std::make_shared<LogInfoCommandOptions>();
  CLI::App* info = log->add_subcommand(
      "info", "Channels, counts, rates, gaps, time spans and damage of a log, as a table");
  info->add_option("LOG", info_options->log, "The LCM log")->required();
  info->callback([info_options] { runLogInfo(*info_options); });

  auto cut_options = std::make_shared<LogCutCommandOptions>();
  CLI::App* cut =
      log->add_subcommand("cut", "Write a time window and a set of channels of a log to a new log");
  cut->add_option("LOG", cut_options->log, "The LCM log to read")->required();
  cut->add_option("OUT", cut_options->out, "The LCM log to write (replaced)")->required();
  cut->add_option("--start", cut_options->start_s,
                  "Keep events from this time, s after the log's first event");
  cut->add_option("--end", cut_options->end_s,
                  "Keep events before this time, s after the log's first event");
  cut->add_flag("--absolute", cut_options->absolute,
                "--start and --end are absolute event times, s (UNIX or sim time)");
  cut->add_option("--channels", cut_options->channels,
                  "Keep only channels whose whole name matches this regex");
  cut->add_option("--exclude", cut_options->exclude,
                  "Drop channels whose whole name matches this regex");
  cut->callback([cut_options] { runLogCut(*cut_options); });

  auto play_options = std::make_shared<LogPlayCommandOptions>();
  CLI::App* play = log->add_subcommand(
      "play",
      "Replay a log onto a bus in real time: pause, seek, speed, loop and channel remapping");
  play->add_option("LOG", play_options->log, "The LCM log to play")->required();
  play->add_option("--url", play_options->url,
                   "Bus to publish on (udpm://, memq://, file://PATH?mode=w); default "
                   "$LCM_DEFAULT_URL or LCM's");
  play->add_option("--speed", play_options->speed, "Times real time")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  play->add_option("--start", play_options->start_s, "Start this far into the log, s")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  play->add_flag("--loop", play_options->loop, "Go back to --start after the last event");
  play->add_option("--remap", play_options->remap, "Send channel FROM as TO (FROM=TO, repeatable)");
  play->add_option("--channels", play_options->channels,
                   "Play only channels whose whole name (in the log) matches this regex");
  play->add_option("--image-encoding", play_options->image_encoding,
                   "Send images as-recorded, raw, or jpeg[:QUALITY] (re-encoded on the way; "
                   "default quality 90)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            try {
              logs::ImageEncoding::parse(text);
            } catch (const std::invalid_argument& error) {
              return error.what();
            }
            return {};
          },
          "ENCODING"));
  play->callback([play_options] { runLogPlay(*play_options); });

  auto record_options = std::make_shared<LogRecordCommandOptions>();
  CLI::App* record = log->add_subcommand(
      "record",
      "Record a bus into an LCM log (as lcm-logger), counting per channel what was lost on the "
      "way");
  record->add_option("LOG", record_options->log, "The LCM log to write")->required();
  record->add_option("--url", record_options->url,
                     "Bus to record (udpm://, memq://); default $LCM_DEFAULT_URL or LCM's");
  record->add_option("--channels", record_options->channels,
                     "Record only channels whose whole name matches this regex");
  record
      ->add_option("--rate", record_options->rates,
                   "A channel's rate, CHANNEL=HZ of message time, to count its losses against "
                   "(repeatable; other channels have theirs learnt)")
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            try {
              parseRate(text);
            } catch (const std::invalid_argument& error) {
              return error.what();
            }
            return {};
          },
          "CHANNEL=HZ"));
  record->add_option("--scenario", record_options->scenario,
                     "Take the rates of the streams this scenario's nodes publish");
  record
      ->add_option("--idle-stop", record_options->idle_stop_s,
                   "Stop once nothing has arrived for this long, s (after the first message)")
      ->check(CLI::PositiveNumber);
  record->add_option("--duration", record_options->duration_s, "Stop after this long, s")
      ->check(CLI::PositiveNumber);
  record->add_flag("--force", record_options->force, "Replace LOG if it exists");
  record->callback([record_options] { runLogRecord(*record_options); });
}

}  // namespace nadir::cli
