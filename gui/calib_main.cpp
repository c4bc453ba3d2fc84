// nadir-calib: checkerboard calibration of a camera in a window, from a folder
// of images, an LCM log, a live image_t channel or the virtual checkerboard.
//
//   nadir-calib (--images DIR | --log FILE [--channel CH] | --live CH [--bus URL] |
//                --virtual [SCENARIO] [--set KEY=VALUE]...)
//               [--board 9x6] [--square 0.025] [--model radtan|fisheye] [--out camera.yaml]
//               [--screenshot PNG [--frames N] [--timeout S]]
//
// --screenshot runs the images to their end with auto-capture (live: until
// --frames images or --timeout), calibrates, saves the window to PNG, prints
// one line (views, RMS, fx fy cx cy) and exits; 1 if no board was found.

#include <CLI/CLI.hpp>

#include <QApplication>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "core/command_line.h"
#include "gui/calib_sources.h"
#include "gui/calib_window.h"
#include "gui/camera_frames.h"
#include "gui/screenshot.h"

namespace {

constexpr char kProgram[] = "nadir-calib";

int fail(const std::string& message) {
  std::fprintf(stderr, "%s: %s\n", kProgram, message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "nadir-calib: checkerboard calibration of a camera, from a folder of images, an LCM log, a "
      "live image channel or the virtual checkerboard"};
  std::string images_dir;
  std::string log_path;
  std::string live_channel;
  std::string scenario;
  std::string channel = nadir::gui::kDefaultCameraChannel;
  app.add_option("--images", images_dir, "a folder of images of the board");
  app.add_option("--log", log_path, "an LCM log with image_t on --channel");
  app.add_option("--channel", channel, "the image_t channel of --log")->capture_default_str();
  app.add_option("--live", live_channel, "take the images of this image_t channel of the bus");
  CLI::Option* virtual_option =
      app.add_option("--virtual", scenario,
                     "the virtual checkerboard of a scenario (a built-in name or a YAML file; "
                     "default calibration); the board is the scenario's")
          ->expected(0, 1);
  std::vector<std::string> overrides;
  app.add_option("--set", overrides, "override a value of --virtual's scenario (key=value)");
  std::string bus_url;
  std::int64_t recv_buf_bytes = std::int64_t{8} << 20;
  app.add_option("--bus,--url", bus_url,
                 "LCM URL for --live (default: $LCM_DEFAULT_URL, else LCM's)");
  app.add_option("--recv-buf-size", recv_buf_bytes,
                 "UDP receive buffer for --live on udpm://, bytes (0: the system's)")
      ->check(CLI::NonNegativeNumber);
  std::string board_text = "9x6";
  double square_m = 0.025;
  std::string model_name = "radtan";
  std::string out_path;
  CLI::Option* board_option =
      app.add_option("--board", board_text, "inner corners, cols x rows")->capture_default_str();
  CLI::Option* square_option =
      app.add_option("--square", square_m, "the side of a square, m")->capture_default_str();
  app.add_option("--model", model_name, "lens model: radtan or fisheye")->capture_default_str();
  app.add_option("--out", out_path,
                 "where Save writes the calibration (OpenCV YAML; the report beside it as .txt); "
                 "with --screenshot written at the end");
  std::string screenshot;
  int live_frames = 0;
  double timeout_s = 30.0;
  app.add_option("--screenshot", screenshot,
                 "run the images to their end with auto-capture, calibrate, save the window to "
                 "this PNG, print a summary line and exit");
  CLI::Option* frames_option =
      app.add_option("--frames", live_frames,
                     "with --live and --screenshot: calibrate once this many images were offered")
          ->check(CLI::NonNegativeNumber);
  CLI::Option* timeout_option =
      app.add_option("--timeout", timeout_s,
                     "with --live and --screenshot: calibrate after this many seconds at the most")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;

  const bool is_virtual = virtual_option->count() > 0;
  if (is_virtual && scenario.empty()) scenario = "calibration";
  const int sources = int{!images_dir.empty()} + int{!log_path.empty()} +
                      int{!live_channel.empty()} + int{is_virtual};
  if (sources != 1) {
    return fail(sources == 0 ? "give the images: --images DIR, --log FILE, --live CHANNEL or "
                               "--virtual [SCENARIO] (see --help)"
                             : "give one of --images, --log, --live and --virtual, not several");
  }
  if (!overrides.empty() && !is_virtual) return fail("--set is for --virtual's scenario");
  if ((live_channel.empty() || screenshot.empty()) &&
      (frames_option->count() > 0 || timeout_option->count() > 0)) {
    return fail("--frames and --timeout are for --live with --screenshot");
  }

  if (!out_path.empty()) {
    // Said now, not after the images were run through.
    const std::filesystem::path folder = std::filesystem::absolute(out_path).parent_path();
    std::error_code error;
    if (!std::filesystem::is_directory(folder, error)) {
      return fail("--out " + out_path + ": no folder " + folder.string());
    }
  }

  nadir::gui::CalibWindowOptions options;
  std::unique_ptr<nadir::gui::FrameSource> source;
  try {
    const std::optional<nadir::calib::LensModel> model =
        nadir::calib::lensModelFromName(model_name);
    if (!model) return fail("--model " + model_name + ": unknown lens model (radtan or fisheye)");
    options.model = *model;
    options.board = nadir::calib::parseBoardSpec(board_text, square_m);
    options.out_path = out_path;
    if (!images_dir.empty()) {
      source = nadir::gui::openFolderSource(images_dir);
    } else if (!log_path.empty()) {
      source = nadir::gui::openLogSource(log_path, channel);
    } else if (!live_channel.empty()) {
      nadir::gui::LiveSourceParams params;
      params.channel = live_channel;
      params.bus_url = bus_url;
      params.recv_buf_bytes = recv_buf_bytes;
      source = nadir::gui::openLiveSource(params);
    } else {
      source = nadir::gui::openVirtualSource(scenario, overrides);
      const nadir::calib::BoardSpec board = *source->board();
      if (board_option->count() > 0 && (board.inner_cols != options.board.inner_cols ||
                                        board.inner_rows != options.board.inner_rows)) {
        return fail(
            "--board " + board_text + ": scenario " + scenario + " shows a " +
            std::to_string(board.inner_cols) + "x" + std::to_string(board.inner_rows) +
            " board; change it with --set world.checkerboard.inner_cols=" +
            std::to_string(options.board.inner_cols) +
            " --set world.checkerboard.inner_rows=" + std::to_string(options.board.inner_rows));
      }
      if (square_option->count() > 0 && square_m != board.square_m) {
        return fail(
            "--square " + std::to_string(square_m) + ": scenario " + scenario + " has squares of " +
            std::to_string(board.square_m) +
            " m; change them with --set world.checkerboard.square_m=" + std::to_string(square_m));
      }
      options.board = board;
    }
  } catch (const std::exception& error) {
    return fail(error.what());
  }
  if (source->live()) {
    std::printf("%s: listening to %s\n", kProgram, source->describe().c_str());
    std::fflush(stdout);
  }

  // A script's screenshot needs no display: Qt's offscreen platform, unless one was chosen.
  if (!screenshot.empty() && std::getenv("QT_QPA_PLATFORM") == nullptr &&
      std::getenv("DISPLAY") == nullptr && std::getenv("WAYLAND_DISPLAY") == nullptr) {
    setenv("QT_QPA_PLATFORM", "offscreen", 1);
  }
  QApplication qapp(argc, argv);
  options.play = screenshot.empty();
  nadir::gui::CalibWindow window(std::move(source), options);
  window.show();
  if (!screenshot.empty()) {
    const auto done = [&window, &screenshot, &out_path](const QString& error) {
      for (const QString& warning : window.warnings()) {
        std::fprintf(stderr, "%s: warning: %s\n", kProgram, warning.toStdString().c_str());
      }
      if (!error.isEmpty()) {
        std::fprintf(stderr, "%s: %s\n", kProgram, error.toStdString().c_str());
        QApplication::exit(1);
        return;
      }
      if (!out_path.empty() && !window.save(out_path)) {
        std::fprintf(stderr, "%s: %s\n", kProgram, window.lastError().toStdString().c_str());
        QApplication::exit(1);
        return;
      }
      // After the report and the chart have laid themselves out.
      nadir::gui::screenshotAfter(window, 0.3, screenshot, kProgram, [&window] {
        std::printf("%s: %s\n", kProgram, window.summary().c_str());
      });
    };
    window.runToEnd(done, live_frames,
                    std::chrono::milliseconds(static_cast<std::int64_t>(timeout_s * 1000)));
  }
  return QApplication::exec();
}
