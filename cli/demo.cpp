#include "cli/demo.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "run/run.h"

namespace nadir::cli {

// JPEG frames keep the demo's log a quarter of the raw one's size, at a small
// cost to the VOs (docs/benchmarks.md, "The log's frames: raw or JPEG").
constexpr const char* kDemoCameraOverride = "camera.jpeg_quality=90";

int runDemo(const std::string& out_dir) {
  std::cout << "nadir demo: the `default` scenario through the whole pipeline in one process,\n"
               "in sim time: the simulator, the downward camera rendering the procedural\n"
               "world, the VO nodes and the navigation filter on the feature VO (GPS denied\n"
               "after 20 s); recorded, evaluated and tabled. The camera sends JPEG frames\n"
               "(quality 90), as a radio link would: the log is about 0.26 GB instead of 0.98,\n"
               "and the VOs lose a little to the compression. This is `nadir run default\n"
               "--set "
            << kDemoCameraOverride << "`; without the --set the frames are raw.\n"
            << std::endl;
  run::RunOptions options;
  options.scenario = "default";
  options.overrides = {kDemoCameraOverride};
  options.out_dir = out_dir;
  options.force = true;
  const run::RunResult result = run::runScenario(options, printRunProgress);
  endRunProgress();
  finishRun(result);
  std::cout << "\nNext: `./nadir run SCENARIO` (./nadir sim --list shows them), `./nadir eval "
            << out_dir << "`,\n`./nadir export " << out_dir
            << " --format euroc`, and `./nadir doctor` before live `./nadir launch`.\n";
  return 0;
}

void addDemoCommand(CLI::App& app) {
  auto out_dir = std::make_shared<std::string>("out/demo");
  auto* demo = app.add_subcommand(
      "demo", "Fly the default scenario through the whole pipeline; print the results table");
  demo->add_option("--out", *out_dir, "Output folder (replaced)")->capture_default_str();
  demo->callback([out_dir] {
    if (const int status = runDemo(*out_dir); status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace nadir::cli
