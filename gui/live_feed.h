#pragma once
// The live mode of nadir-viewer and nadir-plot, without Qt: the truth, the
// estimates and the camera images taken off a bus as they come, and the run
// they make so far.
//
// The feed drains the bus on a thread of its own (background), so that a window
// busy drawing loses nothing to the bus's queue; or, without, poll() drains it
// (call it often: the windows do from a timer). Nothing here blocks.

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/bus.h"
#include "gui/camera_frames.h"
#include "gui/run_data.h"
#include "lcmtypes/messages.h"
#include "logs/run_log.h"

namespace nadir::gui {

struct LiveFeedParams {
  std::string camera_channel = kDefaultCameraChannel;  // empty: no images
  // The truth's pose_t channel; empty: the channel that carries pose_t. The
  // estimates are every vo_estimate_t, named by their source.
  std::string truth_channel;
  // Pixels of recent images kept for seeking back, bytes.
  std::size_t image_budget_bytes = std::size_t{256} << 20;
  // Drain the bus on the feed's own thread (the programs do).
  bool background = false;
};

class LiveFeed {
 public:
  static constexpr double kRestartJump_s = 1.0;

  // Subscribes on bus, which must outlive the feed.
  LiveFeed(core::Bus& bus, LiveFeedParams params = {});
  ~LiveFeed();
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  // Dispatches the messages waiting on the bus (without background), and
  // returns how many were taken since the last call. Throws what the bus threw
  // (core::BusError), from the feed's thread too.
  int poll();

  // Counts every truth, estimate or image message taken: it changes when run() would.
  // A truth stamped more than kRestartJump_s before the newest one starts a new
  // run: what was gathered is dropped (a simulation started again).
  std::uint64_t version() const { return version_; }
  // The run so far, named `name` (RunData::dir), without its metrics (they cost
  // more than the series: computeMetrics gives them); nothing before the first
  // truth pose.
  std::optional<RunData> run(const std::string& name) const;
  // The recent images (safe to use while the feed takes more); null without images.
  CameraFrames* frames() { return frames_ ? &locked_frames_ : nullptr; }
  // How many times a new run replaced the gathered one.
  int restarts() const;
  // The newest truth pose if it came at most max_age of wall time ago (the
  // truth is live); nothing otherwise.
  std::optional<msg::Pose> liveTruth(std::chrono::milliseconds max_age) const;

 private:
  // The images, each call under the feed's lock.
  class LockedFrames final : public CameraFrames {
   public:
    explicit LockedFrames(LiveFeed& feed) : feed_(feed) {}
    std::optional<CameraFrame> frameAt(double t_s) override;
    std::size_t count() const override;
    std::string describe() const override;

   private:
    LiveFeed& feed_;
  };

  void take(const core::RawMessage& message);
  void keepNewestTruth(const core::RawMessage& message);
  void restart();
  void drain();

  core::Bus& bus_;
  LiveFeedParams params_;
  mutable std::mutex mutex_;  // what the handlers fill, against the window's reads
  logs::TrajectoryCollector collector_;
  std::unique_ptr<RecentCameraFrames> frames_;
  LockedFrames locked_frames_{*this};
  std::atomic<std::uint64_t> version_{0};
  std::atomic<int> taken_{0};
  double newest_truth_s_ = -1e300;
  std::optional<msg::Pose> newest_truth_;
  std::chrono::steady_clock::time_point newest_truth_received_;
  int restarts_ = 0;
  std::vector<core::Subscription> subscriptions_;
  std::atomic<bool> stop_{false};
  std::exception_ptr failure_;
  std::thread drainer_;
};

}  // namespace nadir::gui
