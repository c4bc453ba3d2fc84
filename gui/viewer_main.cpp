// nadir-viewer: the 3D trajectory viewer. Log mode plays runs written by `nadir run`
// (or any LCM log holding POSE_TRUTH) over the first run's terrain; live mode
// shows what is on the bus now.
//
//   nadir-viewer [RUN_DIR|LOG ...] [--at SECONDS] [--screenshot FILE.png]
//   nadir-viewer --live [--url URL] [--scenario NAME|FILE] [RUN_DIR|LOG ...]

#include <CLI/CLI.hpp>

#include <QApplication>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/command_line.h"
#include "gui/live_feed.h"
#include "gui/run_data.h"
#include "gui/screenshot.h"
#include "gui/trajectory_view.h"
#include "gui/viewer_window.h"
#include "gui/vo_reset_sender.h"

int main(int argc, char** argv) {
  CLI::App app{"nadir-viewer: 3D view and playback of runs over the terrain, from logs or live"};
  std::vector<std::string> paths;
  app.add_option("RUN", paths, "run folders written by `nadir run`, or LCM logs");
  bool live = false;
  std::string url;
  std::string scenario;
  std::string camera_channel = nadir::gui::kDefaultCameraChannel;
  // Room for a few 1.2 MB images (the kernel caps it at net.core.rmem_max).
  std::int64_t recv_buf_bytes = std::int64_t{8} << 20;
  app.add_flag("--live", live, "show the truth, estimates and camera on the bus as they come");
  app.add_option("--url", url, "LCM URL for --live (default: $LCM_DEFAULT_URL, else LCM's)");
  app.add_option("--scenario", scenario,
                 "terrain of this scenario (a built-in name or a YAML file); default: the "
                 "first run's scenario.yaml");
  app.add_option("--recv-buf-size", recv_buf_bytes,
                 "UDP receive buffer for --live on udpm://, bytes (0: the system's)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--camera-channel", camera_channel,
                 "image_t channel shown beside the 3D view (live and logs)");
  std::string command_channel = "VO_COMMAND";
  app.add_option("--command-channel", command_channel,
                 "vo_command_t channel of the Reset VO button (--live)")
      ->capture_default_str();
  double at_s = 0.0;
  double wait_s = 0.5;
  std::string screenshot;
  app.add_option("--at", at_s, "start at this playback time, s");
  app.add_option("--screenshot", screenshot,
                 "save the window to this PNG after --wait, print what it shows and exit");
  app.add_option("--wait", wait_s, "seconds before --screenshot (live: of listening)")
      ->check(CLI::NonNegativeNumber);
  std::size_t until_truth_poses = 0;
  app.add_option("--until-truth-poses", until_truth_poses,
                 "with --live and --screenshot: take it once the live run holds this many truth "
                 "poses (--wait is then the most to wait)");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  if (!live && paths.empty()) {
    std::fprintf(stderr, "nadir-viewer: give a run folder or log, or --live (see --help)\n");
    return 2;
  }

  std::vector<nadir::gui::RunData> runs;
  std::optional<nadir::gui::ViewerTerrain> terrain;
  std::unique_ptr<nadir::core::Bus> bus;
  std::unique_ptr<nadir::gui::LiveFeed> feed;
  std::unique_ptr<nadir::gui::VoResetSender> reset_sender;
  try {
    for (const std::string& path : paths) {
      runs.push_back(nadir::gui::loadRun(path));
      if (!runs.back().damage.empty()) {
        std::fprintf(stderr, "nadir-viewer: warning: %s\n", runs.back().damage.c_str());
      }
    }
    if (scenario.empty() && !paths.empty()) {
      scenario = nadir::gui::scenarioOfRun(paths.front());
      if (scenario.empty()) {
        std::fprintf(stderr, "nadir-viewer: warning: no scenario.yaml beside %s: no terrain\n",
                     paths.front().c_str());
      }
    }
    if (!scenario.empty()) terrain = nadir::gui::terrainOfScenario(scenario);
    if (live) {
      nadir::core::BusParams bus_params;
      bus_params.url = url;
      bus_params.recv_buf_size_bytes = recv_buf_bytes;
      bus = nadir::core::openBus(bus_params);
      nadir::gui::LiveFeedParams params;
      params.background = true;
      params.camera_channel = camera_channel;
      feed = std::make_unique<nadir::gui::LiveFeed>(*bus, params);
      reset_sender = std::make_unique<nadir::gui::VoResetSender>(*bus, command_channel);
      // Scripts start sending once this is printed.
      std::printf("nadir-viewer: listening on %s\n", bus->url().c_str());
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nadir-viewer: %s\n", e.what());
    return 1;
  }

  nadir::gui::setViewerSurfaceFormat();
  QApplication qapp(argc, argv);
  nadir::gui::ViewerWindow window(std::move(runs), std::move(terrain));
  if (camera_channel != nadir::gui::kDefaultCameraChannel) window.setCameraChannel(camera_channel);
  if (feed) window.attachLive(*feed, QStringLiteral("live"));
  if (reset_sender) window.attachVoReset(*reset_sender);
  window.show();
  if (!live) window.seek(at_s);
  if (!screenshot.empty()) {
    // What was shown, for scripts: each run's poses, the time and the image.
    const auto report = [&window] {
      for (const nadir::gui::RunData& run : window.runs()) {
        std::printf("run %s: %zu truth poses", run.dir.c_str(), run.truth.size());
        for (const auto& [name, source] : run.sources) {
          std::printf(", %s %zu estimates", name.c_str(), source.size());
        }
        std::printf("\n");
      }
      std::printf("time %s\ncamera %s\n", window.timeText().toStdString().c_str(),
                  window.cameraCaption().toStdString().c_str());
    };
    if (live && until_truth_poses > 0) {
      const auto enough = [&window, until_truth_poses] {
        for (const nadir::gui::RunData& run : window.runs()) {
          if (run.dir == "live" && run.truth.size() >= until_truth_poses) return true;
        }
        return false;
      };
      nadir::gui::screenshotWhen(window, enough, wait_s, screenshot, "nadir-viewer", report);
    } else {
      nadir::gui::screenshotAfter(window, wait_s, screenshot, "nadir-viewer", report);
    }
  }
  return QApplication::exec();
}
