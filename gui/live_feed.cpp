#include "gui/live_feed.h"

#include <algorithm>
#include <utility>

namespace nadir::gui {

LiveFeed::LiveFeed(core::Bus& bus, LiveFeedParams params)
    : collector_(params.source_channels), bus_(bus), params_(std::move(params)) {
  if (!params_.camera_channel.empty()) {
    frames_ =
        std::make_unique<RecentCameraFrames>(params_.camera_channel, params_.image_budget_bytes);
  }
  subscriptions_.push_back(
      bus_.subscribe(eval::kTruthChannel, [this](const core::RawMessage& message) {
        const std::optional<std::int64_t> utime = core::peekUtime(message);
        if (utime) {
          const double t_s = static_cast<double>(*utime) / 1e6;
          if (t_s < newest_truth_s_ - kRestartJump_s) restart();
          newest_truth_s_ = std::max(newest_truth_s_, t_s);
        }
        take(message);
      }));
  for (const auto& [channel, name] : params_.source_channels) {
    subscriptions_.push_back(
        bus_.subscribe(channel, [this](const core::RawMessage& message) { take(message); }));
  }
  if (frames_) {
    subscriptions_.push_back(
        bus_.subscribe(params_.camera_channel, [this](const core::RawMessage& message) {
          frames_->add(message.data, message.size);
          ++version_;
        }));
  }
}

void LiveFeed::take(const core::RawMessage& message) {
  if (collector_.add(std::string(message.channel), message.data, message.size)) ++version_;
}

void LiveFeed::restart() {
  collector_ = eval::TrajectoryCollector(params_.source_channels);
  if (frames_) {
    frames_ =
        std::make_unique<RecentCameraFrames>(params_.camera_channel, params_.image_budget_bytes);
  }
  newest_truth_s_ = -1e300;
  ++restarts_;
}

int LiveFeed::poll() { return bus_.handleAvailable(); }

std::optional<RunData> LiveFeed::run(const std::string& name) const {
  if (collector_.truthPoses() == 0) return std::nullopt;
  RunData run = runFromPoses(name, collector_.trajectories());
  run.poses_from = "the bus";
  return run;
}

}  // namespace nadir::gui
