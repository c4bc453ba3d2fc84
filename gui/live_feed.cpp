#include "gui/live_feed.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "lcmtypes/codec.h"

namespace nadir::gui {

LiveFeed::LiveFeed(core::Bus& bus, LiveFeedParams params)
    : bus_(bus), params_(std::move(params)), collector_(params_.truth_channel) {
  if (!params_.camera_channel.empty()) {
    frames_ =
        std::make_unique<RecentCameraFrames>(params_.camera_channel, params_.image_budget_bytes);
  }
  subscriptions_.push_back(
      bus_.subscribe(".*", [this](const core::RawMessage& message) { take(message); }));
  if (params_.background) drainer_ = std::thread([this] { drain(); });
}

LiveFeed::~LiveFeed() {
  stop_ = true;
  if (drainer_.joinable()) drainer_.join();
}

void LiveFeed::drain() {
  try {
    while (!stop_) bus_.handle(std::chrono::milliseconds(50));
  } catch (...) {
    std::lock_guard lock(mutex_);
    failure_ = std::current_exception();
  }
}

void LiveFeed::take(const core::RawMessage& message) {
  std::lock_guard lock(mutex_);
  ++taken_;
  if (frames_ && message.channel == params_.camera_channel) {
    frames_->add(message.data, message.size);
    ++version_;
    return;
  }
  const bool truth = params_.truth_channel.empty()
                         ? msg::isType<msg::Pose>(message.data, message.size)
                         : message.channel == params_.truth_channel;
  if (truth) {
    if (const std::optional<std::int64_t> utime = core::peekUtime(message)) {
      const double t_s = core::stampFromUtime(*utime);
      if (t_s < newest_truth_s_ - kRestartJump_s) restart();
      newest_truth_s_ = std::max(newest_truth_s_, t_s);
    }
    keepNewestTruth(message);
  }
  if (collector_.add(std::string(message.channel), message.data, message.size)) ++version_;
}

void LiveFeed::keepNewestTruth(const core::RawMessage& message) {
  msg::Pose pose;
  try {
    pose = msg::decode<msg::Pose>(message.data, message.size);
  } catch (const std::exception&) {
    return;  // the collector counts it
  }
  if (newest_truth_ && pose.utime < newest_truth_->utime) return;
  newest_truth_ = pose;
  newest_truth_received_ = std::chrono::steady_clock::now();
}

void LiveFeed::restart() {
  collector_ = logs::TrajectoryCollector(params_.truth_channel);
  if (frames_) {
    frames_ =
        std::make_unique<RecentCameraFrames>(params_.camera_channel, params_.image_budget_bytes);
  }
  newest_truth_s_ = -1e300;
  newest_truth_.reset();
  ++restarts_;
}

int LiveFeed::poll() {
  if (!params_.background) bus_.handleAvailable();
  {
    std::lock_guard lock(mutex_);
    if (failure_) std::rethrow_exception(failure_);
  }
  return taken_.exchange(0);
}

int LiveFeed::restarts() const {
  std::lock_guard lock(mutex_);
  return restarts_;
}

std::optional<msg::Pose> LiveFeed::liveTruth(std::chrono::milliseconds max_age) const {
  std::lock_guard lock(mutex_);
  if (!newest_truth_ || std::chrono::steady_clock::now() - newest_truth_received_ > max_age) {
    return std::nullopt;
  }
  return newest_truth_;
}

std::optional<RunData> LiveFeed::run(const std::string& name) const {
  logs::LogTrajectories recorded;
  {
    std::lock_guard lock(mutex_);
    if (collector_.truthPoses() == 0) return std::nullopt;
    recorded = collector_.trajectories();
  }
  RunData run = runFromPoses(name, recorded);
  run.poses_from = "the bus";
  return run;
}

std::optional<CameraFrame> LiveFeed::LockedFrames::frameAt(double t_s) {
  std::lock_guard lock(feed_.mutex_);
  return feed_.frames_->frameAt(t_s);
}

std::size_t LiveFeed::LockedFrames::count() const {
  std::lock_guard lock(feed_.mutex_);
  return feed_.frames_->count();
}

std::string LiveFeed::LockedFrames::describe() const {
  std::lock_guard lock(feed_.mutex_);
  return feed_.frames_->describe();
}

}  // namespace nadir::gui
