// Faults in the live system (docs/reliability.md), each over real UDP multicast
// with the node programs as nadir launch starts them: a VO node killed and
// restarted, the logger killed, a node stopped (SIGSTOP) and continued, and
// malformed and foreign datagrams on nadir's channels. Each test watches the
// bus itself, and compares what arrived with what was sent. Skipped where
// multicast does not reach this process (nadir doctor says how).

#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <regex>
#include <streambuf>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "lcmtypes/bus_io.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/messages.h"
#include "logs/eval/run_metrics.h"
#include "logs/run_log.h"
#include "nodes/scenario.h"
#include "run/launch.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const std::string kVoChannel = "POSE_VO_FEATURE";  // the feature VO's default

fs::path tempDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) /
                       ("nadir_launch_faults_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// What launch writes, readable from the test's thread while it runs.
class SharedText : public std::streambuf {
 public:
  std::string text() const {
    std::lock_guard lock(mutex_);
    return text_;
  }

 protected:
  int overflow(int c) override {
    if (c == traits_type::eof()) return traits_type::not_eof(c);
    std::lock_guard lock(mutex_);
    text_.push_back(static_cast<char>(c));
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    std::lock_guard lock(mutex_);
    text_.append(s, static_cast<std::size_t>(n));
    return n;
  }

 private:
  mutable std::mutex mutex_;
  std::string text_;
};

// A launch on a thread of its own, and a bus of the test's on the same URL.
class LiveLaunch {
 public:
  LiveLaunch(const std::string& name, int port, std::vector<std::string> overrides)
      : dir_(tempDir(name)), url_("udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0") {
    options_.scenario = "default";
    options_.out_dir = (dir_ / "out").string();
    options_.overrides = std::move(overrides);
    options_.overrides.push_back("bus.url=" + url_);
    options_.bin_dir = NADIR_BIN_DIR;
    options_.report_period_s = 1.0;
    const nodes::ScenarioParams scenario = nodes::loadScenario("default", options_.overrides);
    heartbeat_channel_ = scenario.bus.heartbeat_channel;
    truth_channel_ = scenario.sim.truth.channel;
    camera_channel_ = scenario.camera.channel;
    core::BusParams params;
    params.url = url_;
    bus_ = core::openBus(params);
    heartbeats_ = msg::subscribe<msg::Heartbeat>(*bus_, heartbeat_channel_,
                                                 [this](const msg::Heartbeat& beat) {
                                                   pid_[beat.node] = beat.pid;
                                                   sent_[beat.node] = beat.sent;
                                                 });
    estimates_ =
        msg::subscribe<msg::VoEstimate>(*bus_, kVoChannel, [this](const msg::VoEstimate& e) {
          if (e.status == msg::VoStatus::TRACKING) ++tracking_;
        });
    truths_ = bus_->subscribe(truth_channel_, [this](const core::RawMessage&) { ++truths_seen_; });
  }

  LaunchOptions& options() { return options_; }
  core::Bus& bus() { return *bus_; }
  const fs::path& dir() const { return dir_; }
  std::string recording() const { return (fs::path(options_.out_dir) / "launch.lcmlog").string(); }
  const std::string& truthChannel() const { return truth_channel_; }
  const std::string& cameraChannel() const { return camera_channel_; }
  const std::string& heartbeatChannel() const { return heartbeat_channel_; }
  std::string text() const { return text_.text(); }
  int trackingEstimates() const { return tracking_; }
  std::int64_t truthsSeen() const { return truths_seen_; }
  // What a node's last heartbeat says it sent on a channel.
  std::int64_t sentBy(const std::string& node, const std::string& channel) const {
    const auto it = sent_.find(node);
    if (it == sent_.end()) return 0;
    const auto count = it->second.find(channel);
    return count == it->second.end() ? 0 : count->second;
  }
  // The process of a node by its heartbeats; 0 before its first.
  int pidOf(const std::string& node) const {
    const auto it = pid_.find(node);
    return it == pid_.end() ? 0 : it->second;
  }

  void start() {
    status_ =
        std::async(std::launch::async, [this] { return launchScenario(options_, out_, stop_); });
  }
  bool running() const {
    return status_.wait_for(std::chrono::seconds(0)) != std::future_status::ready;
  }
  // Listens on the bus until done() or the launch ends; false if it ended first.
  // The deadline only ends a test that would hang: nothing is timed by it.
  bool listenUntil(const std::function<bool()>& done) {
    const auto deadline = Clock::now() + std::chrono::minutes(5);
    while (!done()) {
      if (!running() || Clock::now() > deadline) return false;
      bus_->handle(std::chrono::milliseconds(20));
    }
    return true;
  }
  int finish() {
    while (running()) bus_->handle(std::chrono::milliseconds(50));
    return status_.get();
  }

 private:
  fs::path dir_;
  std::string url_;
  LaunchOptions options_;
  SharedText text_;
  std::ostream out_{&text_};
  std::atomic<bool> stop_{false};
  std::future<int> status_;
  std::unique_ptr<core::Bus> bus_;
  std::string heartbeat_channel_;
  std::string truth_channel_;
  std::string camera_channel_;
  std::map<std::string, int> pid_;
  std::map<std::string, std::map<std::string, std::int64_t>> sent_;
  int tracking_ = 0;
  std::int64_t truths_seen_ = 0;
  core::Subscription heartbeats_;
  core::Subscription estimates_;
  core::Subscription truths_;
};

#define SKIP_WITHOUT_MULTICAST(launch)                                                    \
  if (!fs::exists((launch).recording()) || fs::file_size((launch).recording()) == 0) {    \
    GTEST_SKIP() << "UDP multicast does not reach this process here (see nadir doctor)\n" \
                 << (launch).text();                                                      \
  }

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The last line of text that starts with start; empty if none does.
std::string lastLineOf(const std::string& text, const std::string& start) {
  const std::size_t at = text.rfind("\n" + start);
  if (at == std::string::npos) return {};
  return text.substr(at + 1, text.find('\n', at + 1) - at - 1);
}

// The recording's events on one channel, decoded.
template <class T>
std::vector<T> recorded(const std::string& log_path, const std::string& channel) {
  std::vector<T> messages;
  core::LcmLogReader reader(log_path);
  while (auto event = reader.next()) {
    if (event->channel != channel) continue;
    try {
      messages.push_back(msg::decode<T>(event->data.data(), event->data.size()));
    } catch (const std::exception&) {
    }
  }
  return messages;
}

// The feature VO killed (SIGKILL) while it tracks: launch reports its exit status
// and starts it again; the new process takes its start pose from the truth,
// initialises and tracks again, and its estimates carry num_resets 1 so that a
// reader sees the estimate restart. The recording holds everything both
// processes said they sent, and the run's metrics show the reset and the gap.
TEST(LaunchFaults, AKilledVoNodeIsRestartedAndCountsAReset) {
  LiveLaunch launch("restart", 7881,
                    {"duration_s=14", "vo_direct.enabled=false", "nav.enabled=false"});
  launch.options().max_restarts = 2;
  launch.start();
  const bool tracking = launch.listenUntil(
      [&] { return launch.trackingEstimates() >= 20 && launch.pidOf("vo_feature") > 0; });
  SKIP_WITHOUT_MULTICAST(launch);
  ASSERT_TRUE(tracking) << "the feature VO never tracked\n" << launch.text();
  ASSERT_EQ(::kill(launch.pidOf("vo_feature"), SIGKILL), 0);
  EXPECT_EQ(launch.finish(), 0) << launch.text();
  const std::string text = launch.text();
  EXPECT_TRUE(contains(text, "nadir-vo-feature died (killed by signal 9)")) << text;
  EXPECT_TRUE(contains(text,
                       "restarted nadir-vo-feature (restart 1 of at most 2); its "
                       "num_resets goes on from 1"))
      << text;
  EXPECT_TRUE(contains(text, "the recording holds every message the nodes said they sent")) << text;
  EXPECT_TRUE(fs::exists(fs::path(launch.options().out_dir) / "vo_feature-restart1.log"));

  // Before the kill num_resets 0, after it 1, in time order; the new process
  // starts INITIALIZING and tracks again.
  const auto estimates = recorded<msg::VoEstimate>(launch.recording(), kVoChannel);
  ASSERT_FALSE(estimates.empty());
  const auto first_after = std::find_if(estimates.begin(), estimates.end(),
                                        [](const msg::VoEstimate& e) { return e.num_resets == 1; });
  ASSERT_NE(first_after, estimates.end()) << "no estimate of the restarted process";
  EXPECT_GT(std::count_if(estimates.begin(), first_after,
                          [](const msg::VoEstimate& e) { return e.num_resets == 0; }),
            20);
  EXPECT_TRUE(std::all_of(first_after, estimates.end(),
                          [](const msg::VoEstimate& e) { return e.num_resets == 1; }));
  EXPECT_GT(first_after->utime, (first_after - 1)->utime);
  EXPECT_EQ(first_after->status, msg::VoStatus::INITIALIZING);
  EXPECT_TRUE(std::any_of(first_after, estimates.end(), [](const msg::VoEstimate& e) {
    return e.status == msg::VoStatus::TRACKING;
  })) << "the restarted VO never tracked again";

  // The metrics: one reset, two tracking segments, and a gap of many frames (20
  // frames/s: a frame every 0.05 s; a new process takes its parameters, its
  // lens and the truth before its first estimate).
  const logs::LogTrajectories flight = logs::readRunLog(launch.recording());
  ASSERT_EQ(flight.sources.count("vo_feature"), 1u);
  const eval::SourceMetrics metrics =
      eval::evaluateSource(flight.truth, flight.sources.at("vo_feature"), eval::EvalOptions{});
  std::printf(
      "vo_feature killed and restarted: longest gap %.2f s, tracked %.1f %%, %zu segments\n",
      metrics.longest_gap_s, metrics.tracked_pct, metrics.tracking_segments);
  EXPECT_EQ(metrics.resets, 1u);
  EXPECT_GE(metrics.tracking_segments, 2u);
  EXPECT_GT(metrics.longest_gap_s, 4 * 0.05);
}

// The logger killed mid-flight: launch says so and stops every node, and the
// recording is readable to its last whole event, nothing skipped before it.
TEST(LaunchFaults, AKilledLoggerStopsTheLaunchAndItsRecordingReads) {
  LiveLaunch launch("logger", 7882,
                    {"duration_s=30", "camera.width=160", "camera.height=120",
                     "vo_feature.enabled=false", "vo_direct.enabled=false", "nav.enabled=false"});
  launch.start();
  // Two seconds of truth at 400 Hz on the bus: the simulator flies.
  const bool flying = launch.listenUntil([&] { return launch.truthsSeen() >= 800; });
  SKIP_WITHOUT_MULTICAST(launch);
  ASSERT_TRUE(flying) << launch.text();
  // `nadir log record` is the process writing this launch's recording.
  int logger_pid = 0;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    std::ifstream cmdline(entry.path() / "cmdline");
    std::string words((std::istreambuf_iterator<char>(cmdline)), std::istreambuf_iterator<char>());
    if (contains(words, std::string("log\0record", 10)) && contains(words, launch.recording())) {
      logger_pid = std::stoi(entry.path().filename().string());
    }
  }
  ASSERT_GT(logger_pid, 0) << "no logger writing " << launch.recording();
  ASSERT_EQ(::kill(logger_pid, SIGKILL), 0);
  EXPECT_EQ(launch.finish(), 1) << launch.text();
  const std::string text = launch.text();
  EXPECT_TRUE(contains(text, "logger died (killed by signal 9)")) << text;
  EXPECT_TRUE(contains(text, "the recording ends there; stopping every node")) << text;
  EXPECT_TRUE(contains(text, "nadir-sim: exit status 0 (stopped by launch)")) << text;
  EXPECT_TRUE(contains(text, "nadir-camera: exit status 0 (stopped by launch)")) << text;

  core::LcmLogReader reader(launch.recording());
  std::int64_t truths = 0;
  std::int64_t last_utime = -1;
  bool in_order = true;
  while (auto event = reader.next()) {
    if (event->channel != launch.truthChannel()) continue;
    const msg::Pose pose = msg::decode<msg::Pose>(event->data.data(), event->data.size());
    if (pose.utime <= last_utime && in_order) {
      ADD_FAILURE() << "truth at " << pose.utime << " after " << last_utime << " (event "
                    << reader.eventsRead() << ")";
    }
    in_order = in_order && pose.utime > last_utime;
    last_utime = pose.utime;
    ++truths;
  }
  EXPECT_EQ(reader.skippedBytes(), 0) << reader.damageReport();
  EXPECT_GT(truths, 0);
  EXPECT_TRUE(in_order);
}

// A tmpfs of a given size at a folder, unmounted when done (root only).
class SmallDisk {
 public:
  SmallDisk(const fs::path& at, const std::string& size) : at_(at) {
    fs::create_directories(at);
    mounted_ =
        ::geteuid() == 0 &&
        std::system(("mount -t tmpfs -o size=" + size + " tmpfs '" + at.string() + "'").c_str()) ==
            0;
  }
  ~SmallDisk() {
    if (mounted_) std::system(("umount -l '" + at_.string() + "'").c_str());
  }
  bool mounted() const { return mounted_; }

 private:
  fs::path at_;
  bool mounted_ = false;
};

// The disk fills while recording (the launch's folder on a 3 MB tmpfs: the
// camera's frames fill it in seconds): the logger stops at its first failed
// write; launch says why in its words and that the disk is full, stops every
// node cleanly, and the recording reads to its last whole event.
TEST(LaunchFaults, AFullDiskStopsTheLaunchAndItsRecordingReads) {
  LiveLaunch launch("fulldisk", 7885,
                    {"duration_s=60", "camera.width=160", "camera.height=120",
                     "vo_feature.enabled=false", "vo_direct.enabled=false", "nav.enabled=false"});
  const SmallDisk disk(launch.options().out_dir, "3m");
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  launch.start();
  const int status = launch.finish();
  SKIP_WITHOUT_MULTICAST(launch);
  EXPECT_EQ(status, 1) << launch.text();
  const std::string text = launch.text();
  const std::string words = lastLineOf(text, "launch: logger died");
  EXPECT_TRUE(
      contains(words, "logger died (exit status 1), its last words: \"nadir: error: cannot "))
      << text;
  EXPECT_TRUE(contains(words, launch.recording() + ": No space left on device\"")) << text;
  EXPECT_TRUE(contains(text, "launch: the disk holding " + launch.options().out_dir + " is full"))
      << text;
  EXPECT_TRUE(contains(text, "nadir-sim: exit status 0 (stopped by launch)")) << text;
  EXPECT_TRUE(contains(text, "nadir-camera: exit status 0 (stopped by launch)")) << text;
  core::LcmLogReader reader(launch.recording());
  std::int64_t truths = 0;
  while (auto event = reader.next()) {
    if (event->channel == launch.truthChannel()) {
      msg::decode<msg::Pose>(event->data.data(), event->data.size());
      ++truths;
    }
  }
  EXPECT_EQ(reader.skippedBytes(), 0) << reader.damageReport();
  EXPECT_GT(truths, 400);  // the first second at least, before the disk filled
}

// The camera stopped (SIGSTOP) for a while, then continued: launch reports it
// silent (no heartbeat) and its channel quiet, at once and not at the next
// report, then heard and flowing again; the flight ends cleanly.
TEST(LaunchFaults, AStoppedNodeIsReportedSilentThenHeardAgain) {
  LiveLaunch launch("sigstop", 7883,
                    {"duration_s=8", "camera.width=160", "camera.height=120",
                     "vo_feature.enabled=false", "vo_direct.enabled=false", "nav.enabled=false"});
  launch.options().report_period_s = 60.0;  // what is said comes from the silence, not a report
  launch.start();
  const bool flying =
      launch.listenUntil([&] { return launch.truthsSeen() >= 800 && launch.pidOf("camera") > 0; });
  SKIP_WITHOUT_MULTICAST(launch);
  ASSERT_TRUE(flying) << launch.text();
  const int camera = launch.pidOf("camera");
  ASSERT_EQ(::kill(camera, SIGSTOP), 0);
  const auto stopped = Clock::now();
  const bool silent =
      launch.listenUntil([&] { return contains(launch.text(), "nadir-camera silent"); });
  const double silent_s = std::chrono::duration<double>(Clock::now() - stopped).count();
  const std::string quiet = launch.cameraChannel() + " (nadir-camera) quiet for";
  const bool reported = launch.listenUntil([&] { return contains(launch.text(), quiet); });
  const double quiet_s = std::chrono::duration<double>(Clock::now() - stopped).count();
  ASSERT_EQ(::kill(camera, SIGCONT), 0);
  ASSERT_TRUE(silent && reported) << launch.text();
  std::printf(
      "after SIGSTOP: nadir-camera reported silent at %.2f s, %s quiet at %.2f s (%.1f s "
      "without a heartbeat or a frame)\n",
      silent_s, launch.cameraChannel().c_str(), quiet_s, kSilentAfter_s);
  EXPECT_EQ(launch.finish(), 0) << launch.text();
  const std::string text = launch.text();
  EXPECT_TRUE(contains(text, "nadir-camera silent: no heartbeat for")) << text;
  EXPECT_TRUE(contains(text, "camera heard again after")) << text;
  EXPECT_TRUE(contains(text, launch.cameraChannel() + " flowing again after")) << text;
}

// Datagrams on nadir's channels that are not what the channel carries: another
// type's message (a wrong fingerprint, with a plausible time), a truncated
// truth pose and random bytes. Every node drops them, counts them in its status
// and goes on; launch counts those on the heartbeat channel; the flight ends
// cleanly and the recording holds every message the nodes sent (and the
// malformed ones: a recording keeps what the bus carried).
TEST(LaunchFaults, MalformedDatagramsAreDroppedAndCounted) {
  LiveLaunch launch("malformed", 7884,
                    {"duration_s=6", "camera.width=160", "camera.height=120",
                     "vo_direct.enabled=false", "nav.enabled=false"});
  launch.start();
  const bool flying = launch.listenUntil([&] { return launch.truthsSeen() >= 800; });
  SKIP_WITHOUT_MULTICAST(launch);
  ASSERT_TRUE(flying) << launch.text();

  std::mt19937 random(22);
  const auto randomBytes = [&](std::size_t size) {
    std::vector<std::uint8_t> bytes(size);
    for (auto& byte : bytes) byte = static_cast<std::uint8_t>(random());
    return bytes;
  };
  msg::VoEstimate foreign;     // a pose on the wrong channel, stamped like the truth
  foreign.utime = 60'000'000;  // ahead of the flight: a gap, were it counted
  foreign.source = "elsewhere";
  const msg::Bytes foreign_bytes = msg::encode(foreign);
  msg::Pose pose;
  pose.utime = 2'000'000;
  msg::Bytes truncated = msg::encode(pose);
  truncated.resize(truncated.size() - 7);
  constexpr int kEach = 5;
  for (int i = 0; i < kEach; ++i) {
    core::Bus& bus = launch.bus();
    bus.publish(launch.truthChannel(), foreign_bytes.data(), foreign_bytes.size(), 0);
    bus.publish(launch.truthChannel(), truncated.data(), truncated.size(), 0);
    const auto noise = randomBytes(100 + 40 * static_cast<std::size_t>(i));
    bus.publish(launch.truthChannel(), noise.data(), noise.size(), 0);
    const auto image_noise = randomBytes(3000);
    bus.publish(launch.cameraChannel(), image_noise.data(), image_noise.size(), 0);
    const auto beat_noise = randomBytes(64);
    bus.publish(launch.heartbeatChannel(), beat_noise.data(), beat_noise.size(), 0);
    bus.handle(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(launch.finish(), 0) << launch.text();
  const std::string text = launch.text();
  // The camera reads the truth; the feature VO the images and the truth.
  const std::string each = std::to_string(kEach);
  const std::string truth_each = launch.truthChannel() + " " + std::to_string(3 * kEach);
  EXPECT_TRUE(contains(lastLineOf(text, "  nadir-camera: "),
                       "dropped " + std::to_string(3 * kEach) + " malformed (" + truth_each + ")"))
      << text;
  EXPECT_TRUE(contains(lastLineOf(text, "  nadir-vo-feature: "),
                       "dropped " + std::to_string(4 * kEach) + " malformed (" +
                           launch.cameraChannel() + " " + each + ", " + truth_each + ")"))
      << text;
  EXPECT_TRUE(contains(text, "launch: dropped " + std::to_string(kEach) + " malformed (" +
                                 launch.heartbeatChannel() + " " + std::to_string(kEach) + ")"))
      << text;
  // The truth lost nothing for its readers: the foreign times made no gap.
  EXPECT_FALSE(contains(text, "lost " + launch.truthChannel())) << text;
  EXPECT_TRUE(contains(text, "the recording holds every message the nodes said they sent")) << text;
}

// What a node's last line says it received on a channel and counted lost
// ("POSE_TRUTH 4001 at 400.0 Hz, 0 lost"); nothing if it does not say.
std::optional<std::pair<std::int64_t, std::int64_t>> receivedAndLost(const fs::path& node_log,
                                                                     const std::string& channel) {
  std::ifstream in(node_log);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string line = lastLineOf("\n" + text, "nadir-");
  const std::regex pattern("(^|[ ;])" + channel + " ([0-9]+) at [0-9.]+ Hz, ([0-9]+) lost");
  std::smatch match;
  if (!std::regex_search(line, match, pattern)) return std::nullopt;
  return std::pair{std::stoll(match[2].str()), std::stoll(match[3].str())};
}

// A node that floods the bus (the test: 60 kB datagrams on a channel of its own,
// 200 a second, ten times the camera's frames, for 5 s of a 10 s flight): what
// each node received of its inputs and what it counted lost add up to what was
// sent, channel by channel, so that nothing it lost is silent.
TEST(LaunchFaults, AFloodLeavesNoLossUncounted) {
  LiveLaunch launch("flood", 7886,
                    {"duration_s=10", "camera.width=320", "camera.height=240",
                     "vo_direct.enabled=false", "nav.enabled=false"});
  launch.start();
  const bool flying = launch.listenUntil([&] { return launch.truthsSeen() >= 800; });
  SKIP_WITHOUT_MULTICAST(launch);
  ASSERT_TRUE(flying) << launch.text();
  const std::vector<std::uint8_t> flood(60000, 0x5a);
  std::int64_t flooded = 0;
  for (const auto until = Clock::now() + std::chrono::seconds(5); Clock::now() < until;) {
    launch.bus().publish("FLOOD", flood.data(), flood.size(), 0);
    ++flooded;
    launch.bus().handleAvailable();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(launch.finish(), 0) << launch.text();
  std::printf("flooded %lld datagrams of 60 kB\n", static_cast<long long>(flooded));
  const fs::path out(launch.options().out_dir);
  struct Input {
    std::string node_log;
    std::string channel;
    std::string sender;
  };
  for (const Input& input : {Input{"camera.log", launch.truthChannel(), "sim"},
                             Input{"vo_feature.log", launch.truthChannel(), "sim"},
                             Input{"vo_feature.log", launch.cameraChannel(), "camera"}}) {
    SCOPED_TRACE(input.node_log + " " + input.channel);
    const auto counts = receivedAndLost(out / input.node_log, input.channel);
    ASSERT_TRUE(counts) << "no count of " << input.channel << " in " << input.node_log;
    const std::int64_t sent = launch.sentBy(input.sender, input.channel);
    std::printf("%s: %s %lld received, %lld counted lost, of %lld sent\n", input.node_log.c_str(),
                input.channel.c_str(), static_cast<long long>(counts->first),
                static_cast<long long>(counts->second), static_cast<long long>(sent));
    EXPECT_GT(sent, 0);
    EXPECT_EQ(counts->first + counts->second, sent);
  }
}

}  // namespace
}  // namespace nadir::run
