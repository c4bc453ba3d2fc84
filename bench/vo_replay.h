#pragma once
// What the VO benchmarks share: a recorded run's folder (run.lcmlog with the
// camera's images, scenario.yaml), its messages fed through an in-process bus
// to a VO node as fast as it takes them, the node's estimates and the truth
// recorded to OUT/run.lcmlog for `nadir eval`, and one debug image saved as
// PNG. Header-only: the benchmark programs are its only users.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "lcmtypes/bus_io.h"

namespace nadir::bench {

struct RunFolder {
  std::filesystem::path log;       // run.lcmlog
  std::filesystem::path scenario;  // scenario.yaml
  std::filesystem::path out;       // where the bench writes
};

// Throws std::runtime_error naming what is missing.
inline RunFolder openRunFolder(const std::string& run_dir, const std::string& out_dir) {
  const std::filesystem::path run(run_dir);
  RunFolder folder{run / "run.lcmlog", run / "scenario.yaml",
                   out_dir.empty() ? run / "bench" : std::filesystem::path(out_dir)};
  if (!std::filesystem::exists(folder.log) || !std::filesystem::exists(folder.scenario))
    throw std::runtime_error(run_dir + " is not a nadir run folder (run.lcmlog and scenario.yaml)");
  std::filesystem::create_directories(folder.out);
  return folder;
}

// Records the truth and the estimates, saves the first debug image at or
// after debug_at_s from the first camera image, and replays the log.
class VoReplay {
 public:
  VoReplay(const RunFolder& folder, const std::string& truth_channel,
           const std::string& pose_channel, const std::string& image_channel,
           const std::string& debug_channel, std::string debug_png, double debug_at_s)
      : folder_(folder),
        image_channel_(image_channel),
        pose_channel_(pose_channel),
        debug_channel_(debug_channel),
        debug_png_(std::move(debug_png)),
        debug_at_s_(debug_at_s),
        writer_((folder.out / "run.lcmlog").string()) {
    core::BusParams bus_params;
    bus_params.url = "memq://";
    bus_ = core::openBus(bus_params);
    recorder_ =
        bus_->subscribe(truth_channel + "|" + pose_channel, [this](const core::RawMessage& raw) {
          writer_.write(core::peekUtime(raw).value_or(0), std::string(raw.channel), raw.data,
                        raw.size);
        });
    debug_ = msg::subscribe<msg::Image>(*bus_, debug_channel, [this](const msg::Image& image) {
      if (debug_png_.empty() || debug_written_ || !first_image_utime_) return;
      if (image.utime < *first_image_utime_ + static_cast<std::int64_t>(debug_at_s_ * 1e6)) return;
      cv::Mat bgr;
      cv::cvtColor(image.pixels, bgr, cv::COLOR_RGB2BGR);
      cv::imwrite(debug_png_, bgr);
      debug_written_ = true;
    });
  }

  core::Bus& bus() { return *bus_; }

  // Feeds every message until done() says stop; returns the wall-clock
  // seconds. Throws std::runtime_error if the log holds no camera images.
  double replay(const std::function<bool()>& done) {
    core::LcmLogReader reader(folder_.log.string());
    bool saw_images = false;
    const auto start = std::chrono::steady_clock::now();
    while (auto event = reader.next()) {
      // What the run's own VO published: the replay makes its own.
      if (event->channel == pose_channel_ || event->channel == debug_channel_) continue;
      if (event->channel == image_channel_) {
        saw_images = true;
        if (!first_image_utime_) {
          // The image's own (sim) time, what the debug image is compared with.
          const core::RawMessage raw{event->channel, event->data.data(), event->data.size(), 0};
          first_image_utime_ = core::peekUtime(raw).value_or(event->timestamp_utime);
        }
      }
      bus_->publish(event->channel, event->data.data(), event->data.size(), event->timestamp_utime);
      bus_->handleAvailable();
      if (done()) break;
    }
    writer_.flush();
    if (!saw_images)
      throw std::runtime_error(folder_.log.string() + " holds no " + image_channel_ +
                               " images (recorded with --no-images?)");
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  std::string estimatesLog() const { return (folder_.out / "run.lcmlog").string(); }
  bool debugWritten() const { return debug_written_; }

 private:
  RunFolder folder_;
  std::string image_channel_;
  std::string pose_channel_;
  std::string debug_channel_;
  std::string debug_png_;
  double debug_at_s_;
  core::LcmLogWriter writer_;
  std::unique_ptr<core::Bus> bus_;
  core::Subscription recorder_;
  core::Subscription debug_;
  std::optional<std::int64_t> first_image_utime_;
  bool debug_written_ = false;
};

inline double msPerFrame(double seconds, std::int64_t frames) {
  return frames > 0 ? 1e3 * seconds / static_cast<double>(frames) : 0.0;
}

}  // namespace nadir::bench
