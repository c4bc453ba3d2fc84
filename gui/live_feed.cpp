#include "gui/live_feed.h"

#include <algorithm>
#include <utility>

#include "lcmtypes/codec.h"

namespace nadir::gui {

LiveFeed::LiveFeed(core::Bus& bus, LiveFeedParams params)
    : collector_(params.truth_channel), bus_(bus), params_(std::move(params)) {
  if (!params_.camera_channel.empty()) {
    frames_ =
        std::make_unique<RecentCameraFrames>(params_.camera_channel, params_.image_budget_bytes);
  }
  subscriptions_.push_back(bus_.subscribe(".*", [this](const core::RawMessage& message) {
    if (frames_ && message.channel == params_.camera_channel) {
      frames_->add(message.data, message.size);
      ++version_;
      return;
    }
    take(message);
  }));
}

void LiveFeed::take(const core::RawMessage& message) {
  const bool truth = params_.truth_channel.empty()
                         ? msg::isType<msg::Pose>(message.data, message.size)
                         : message.channel == params_.truth_channel;
  if (truth) {
    if (const std::optional<std::int64_t> utime = core::peekUtime(message)) {
      const double t_s = core::stampFromUtime(*utime);
      if (t_s < newest_truth_s_ - kRestartJump_s) restart();
      newest_truth_s_ = std::max(newest_truth_s_, t_s);
    }
  }
  if (collector_.add(std::string(message.channel), message.data, message.size)) ++version_;
}

void LiveFeed::restart() {
  collector_ = logs::TrajectoryCollector(params_.truth_channel);
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
