#pragma once
// The live mode of nadir-viewer and nadir-plot, without Qt: the truth, the estimates and the camera
// images taken off a bus as they come, and the run they make so far.
//
// poll() dispatches what the bus holds; call it often (the window does from a
// timer). Nothing here blocks.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "gui/camera_frames.h"
#include "gui/run_data.h"
#include "logs/run_log.h"

namespace nadir::gui {

struct LiveFeedParams {
  std::string camera_channel = kDefaultCameraChannel;  // empty: no images
  // The truth's pose_t channel; empty: the channel that carries pose_t. The
  // estimates are every vo_estimate_t, named by their source.
  std::string truth_channel;
  // Pixels of recent images kept for seeking back, bytes.
  std::size_t image_budget_bytes = std::size_t{256} << 20;
};

class LiveFeed {
 public:
  static constexpr double kRestartJump_s = 1.0;

  // Subscribes on bus, which must outlive the feed.
  LiveFeed(core::Bus& bus, LiveFeedParams params = {});
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  // Dispatches the messages waiting on the bus; returns how many. Throws what
  // the bus throws (core::BusError).
  int poll();

  // Counts every truth, estimate or image message taken: it changes when run() would.
  // A truth stamped more than kRestartJump_s before the newest one starts a new
  // run: what was gathered is dropped (a simulation started again).
  std::uint64_t version() const { return version_; }
  // The run so far, named `name` (RunData::dir), without its metrics (they cost
  // more than the series: computeMetrics gives them); nothing before the first
  // truth pose.
  std::optional<RunData> run(const std::string& name) const;
  CameraFrames* frames() { return frames_.get(); }
  // How many times a new run replaced the gathered one.
  int restarts() const { return restarts_; }

 private:
  void take(const core::RawMessage& message);
  void restart();

  logs::TrajectoryCollector collector_;
  std::unique_ptr<RecentCameraFrames> frames_;
  core::Bus& bus_;
  std::vector<core::Subscription> subscriptions_;
  std::uint64_t version_ = 0;
  LiveFeedParams params_;
  double newest_truth_s_ = -1e300;
  int restarts_ = 0;
};

}  // namespace nadir::gui
