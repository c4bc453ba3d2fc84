// nadir-viewer: the 3D trajectory viewer of runs written by `nadir run` (log mode):
// the first run's terrain, every run's truth and estimates, played back together.
//
//   nadir-viewer RUN_DIR [RUN_DIR...] [--at SECONDS] [--screenshot FILE.png]

#include <CLI/CLI.hpp>

#include <QApplication>
#include <QTimer>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gui/run_data.h"
#include "gui/trajectory_view.h"
#include "gui/viewer_window.h"

int main(int argc, char** argv) {
  CLI::App app{"nadir-viewer: 3D view and playback of one or more runs over the terrain"};
  std::vector<std::string> dirs;
  app.add_option("RUN_DIR", dirs, "run folders written by `nadir run`")->required();
  double at_s = 0.0;
  std::string screenshot;
  app.add_option("--at", at_s, "start at this playback time, s");
  app.add_option("--screenshot", screenshot,
                 "save the window at --at to this PNG and exit (for docs and checks)");
  CLI11_PARSE(app, argc, argv);

  std::vector<nadir::gui::RunData> runs;
  std::optional<nadir::gui::ViewerTerrain> terrain;
  try {
    for (const std::string& dir : dirs) {
      runs.push_back(nadir::gui::loadRun(dir));
      if (!runs.back().damage.empty()) {
        std::fprintf(stderr, "nadir-viewer: warning: %s\n", runs.back().damage.c_str());
      }
    }
    const std::filesystem::path scenario = std::filesystem::path(dirs.front()) / "scenario.yaml";
    if (std::filesystem::exists(scenario)) {
      terrain = nadir::gui::terrainOfScenario(scenario.string());
    } else {
      std::fprintf(stderr, "nadir-viewer: warning: %s not found: no terrain\n",
                   scenario.string().c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nadir-viewer: %s\n", e.what());
    return 1;
  }

  nadir::gui::setViewerSurfaceFormat();
  QApplication qapp(argc, argv);
  nadir::gui::ViewerWindow window(std::move(runs), std::move(terrain));
  window.resize(1400, 900);
  window.show();
  window.seek(at_s);
  if (!screenshot.empty()) {
    // Once the window has been laid out and drawn.
    QTimer::singleShot(500, &window, [&window, &screenshot] {
      if (!window.grab().save(QString::fromStdString(screenshot))) {
        std::fprintf(stderr, "nadir-viewer: cannot write %s\n", screenshot.c_str());
        QApplication::exit(1);
        return;
      }
      QApplication::exit(0);
    });
  }
  return QApplication::exec();
}
