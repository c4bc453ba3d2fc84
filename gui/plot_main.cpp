// nadir-plot: the plot viewer. Without --headless, a window on the runs under DIR
// (default: out if it exists, else the current folder); --headless renders a
// run's charts to PNG files and its error table to results.csv.
//
//   nadir-plot [DIR|LOG] [--live [--url URL]] [--truth NAME] [--run REL] [--figure NAME]
//              [--screenshot PNG [--wait S]]
//   nadir-plot --headless RUN_DIR|LOG --out DIR [--truth NAME]
//
// RUN_DIR may also be a tree of runs (a sweep): each run's files then go to
// DIR/<its path under RUN_DIR> (a loose log's without .lcmlog).

#include <CLI/CLI.hpp>

#include <QApplication>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/command_line.h"
#include "gui/live_feed.h"
#include "gui/plot_window.h"
#include "gui/plots.h"
#include "gui/run_data.h"
#include "gui/screenshot.h"

namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 1200;
constexpr int kHeight = 800;

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc);
  out << text;
  out.flush();
  if (!out) throw nadir::gui::RunDataError(path.string() + ": cannot write the file");
}

void renderRun(const std::string& run_dir, const fs::path& out_dir, const std::string& truth) {
  const nadir::gui::RunData run = nadir::gui::loadRun(run_dir, truth);
  if (!run.damage.empty()) {
    std::fprintf(stderr, "nadir-plot: %s: damaged, plotting what could be read: %s\n",
                 run.poses_from.c_str(), run.damage.c_str());
  }
  if (!run.truth_note.empty()) {
    std::fprintf(stderr, "nadir-plot: %s: %s\n", run_dir.c_str(), run.truth_note.c_str());
  }
  std::error_code error;
  fs::create_directories(out_dir, error);
  if (error) {
    throw nadir::gui::RunDataError(out_dir.string() +
                                   ": cannot create the directory: " + error.message());
  }
  for (nadir::gui::Figure& figure : nadir::gui::buildFigures(run)) {
    const fs::path path = out_dir / (figure.name + ".png");
    nadir::gui::renderFigurePng(std::move(figure), path.string(), kWidth, kHeight);
    std::printf("%s\n", path.c_str());
  }
  const fs::path csv = out_dir / "results.csv";
  writeText(csv, nadir::gui::resultsCsv(run.metrics));
  std::printf("%s\n", csv.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nadir-plot: plots of a run (truth and estimates) and its error table"};
  std::string run_dir;
  std::string out_dir;
  bool headless = false;
  app.add_option(
      "run_dir", run_dir,
      "a run directory (as `nadir run` writes it), an LCM log, or a tree of runs; without "
      "--headless, default out if it exists, else the current directory");
  app.add_flag("--headless", headless, "render PNG files and results.csv instead of a window");
  app.add_option("--out", out_dir, "where --headless writes its files");
  std::string truth;
  app.add_option("--truth", truth,
                 "the trajectory the others are compared with (default: the recorded truth, "
                 "POSE_TRUTH or truth.tum); the window takes it for every run that has it");
  bool live = false;
  std::string url;
  app.add_flag("--live", live, "also plot the run on the bus as it comes (window only)");
  app.add_option("--url", url, "LCM URL for --live (default: $LCM_DEFAULT_URL, else LCM's)");
  std::string select;
  std::string figure;
  std::string screenshot;
  app.add_option("--run", select, "the run shown first, by its path under DIR (window only)");
  app.add_option("--figure", figure,
                 "the figure shown first: position, attitude, error or top_view (window only)");
  app.add_option("--screenshot", screenshot,
                 "save the window to this PNG after --wait, and exit (window only)");
  double wait_s = 0.5;
  app.add_option("--wait", wait_s, "seconds before --screenshot (with --live: of listening)")
      ->check(CLI::NonNegativeNumber);
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;

  if (!headless) {
    if (!out_dir.empty()) {
      std::fprintf(stderr, "nadir-plot: --out is for --headless\n");
      return 1;
    }
    if (run_dir.empty()) run_dir = fs::is_directory("out") ? "out" : ".";
    if (!fs::exists(run_dir)) {
      std::fprintf(stderr, "nadir-plot: %s: no such folder or log\n", run_dir.c_str());
      return 1;
    }
    std::unique_ptr<nadir::core::Bus> bus;
    std::unique_ptr<nadir::gui::LiveFeed> feed;
    if (live) {
      try {
        bus = nadir::core::openBus(url);
        nadir::gui::LiveFeedParams params;
        params.background = true;
        params.camera_channel.clear();  // plots need no images
        feed = std::make_unique<nadir::gui::LiveFeed>(*bus, params);
      } catch (const std::exception& error) {
        std::fprintf(stderr, "nadir-plot: %s\n", error.what());
        return 1;
      }
    }
    QApplication application(argc, argv);
    nadir::gui::PlotWindow window(QString::fromStdString(run_dir), QString::fromStdString(truth));
    if (feed) window.attachLive(*feed);
    if (!select.empty() && !window.selectRun(QString::fromStdString(select))) {
      std::fprintf(stderr, "nadir-plot: %s\n", window.lastError().toStdString().c_str());
      return 1;
    }
    if (!figure.empty() && !window.showFigure(QString::fromStdString(figure))) {
      std::fprintf(stderr, "nadir-plot: no figure %s (position, attitude, error, top_view)\n",
                   figure.c_str());
      return 1;
    }
    window.show();
    // After the charts have laid themselves out in the shown window.
    if (!screenshot.empty()) nadir::gui::screenshotAfter(window, wait_s, screenshot, "nadir-plot");
    return QApplication::exec();
  }
  if (!select.empty() || !figure.empty() || !screenshot.empty()) {
    std::fprintf(stderr,
                 "nadir-plot: --run, --figure, --screenshot and --wait are for the window\n");
    return 1;
  }
  if (live) {
    std::fprintf(stderr, "nadir-plot: --live is for the window, not --headless\n");
    return 1;
  }
  if (run_dir.empty()) {
    std::fprintf(stderr, "nadir-plot: --headless needs RUN_DIR\n");
    return 1;
  }
  if (out_dir.empty()) {
    std::fprintf(stderr, "nadir-plot: --headless needs --out DIR\n");
    return 1;
  }

  // Headless needs no display: Qt's offscreen platform, unless one was chosen.
  if (std::getenv("QT_QPA_PLATFORM") == nullptr) setenv("QT_QPA_PLATFORM", "offscreen", 1);

  try {
    const std::vector<std::string> runs = nadir::gui::findRuns(run_dir);
    if (runs.empty()) {
      throw nadir::gui::RunDataError(
          run_dir +
          ": no run here (a run is a folder with run.lcmlog, metrics.json or TUM files, or an "
          "LCM log)");
    }
    QApplication application(argc, argv);
    for (const std::string& run : runs) {
      // A loose log's files go to a folder named after it, without .lcmlog.
      fs::path relative = fs::path(run).lexically_relative(run_dir);
      if (relative.extension() == ".lcmlog") relative.replace_extension();
      renderRun(run, relative == "." ? fs::path(out_dir) : fs::path(out_dir) / relative, truth);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "nadir-plot: %s\n", error.what());
    return 1;
  }
  return 0;
}
