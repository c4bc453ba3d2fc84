#pragma once
// `nadir run`: one scenario flown by the whole pipeline in one process, in sim
// time, deterministically: the simulator drives an in-process bus on which
// the same node classes the live programs run (cameras, VO nodes) receive and
// publish; everything published is recorded to DIR/run.lcmlog, then
// evaluated into DIR/metrics.json, TUM files and a results table.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/axes.h"
#include "logs/eval/run_metrics.h"

namespace nadir::nodes {
struct ScenarioParams;
}

namespace nadir::run {

struct RunOptions {
  // Built-in scenario name or YAML path.
  std::string scenario = "default";
  std::vector<std::string> overrides;
  // Output folder; empty: out/<scenario name>.
  std::string out_dir;
  // Replace the files of an earlier run in out_dir (otherwise refused).
  bool force = false;
  // Leave the camera images out of run.lcmlog (everything else is recorded):
  // for sweeps, where a 1280x960 stream would write 38 MB per second of flight.
  bool record_images = true;
  // The axes of the TUM files written (core/axes.h); the log and metrics are
  // nadir's whatever they are.
  core::Axes tum_axes = core::Axes::kNed;
  // Nodes that take camera frames (the VO nodes) work on their own threads
  // while the camera renders the next frame; their outputs reach the others
  // with the next frame (core/worker_bus.h). false: all in the bus's dispatch
  // on one thread, their outputs at once. Deterministic either way.
  bool node_threads = true;
  // Time the pipeline's stages (core/stage_times.h) and report where the wall
  // time went, in RunResult::stage_times and DIR/stage_times.txt.
  bool stage_times = false;
};

struct RunProgress {
  double sim_s = 0.0;
  // Expected length of the flight, s, when known (duration_s or a recorded flight); else 0.
  double planned_s = 0.0;
  double wall_s = 0.0;
  std::uint64_t frames = 0;
  std::uint64_t messages = 0;
};

struct RunResult {
  std::string out_dir;
  std::string log_path;
  std::string metrics_path;
  std::vector<std::string> tum_paths;
  // tracks.png (top view) and last_frame.png (the main camera's last image).
  std::vector<std::string> picture_paths;
  eval::RunMetrics metrics;
  RunProgress totals;
  // The metrics table, then what the nodes add (the PPA's target passes).
  std::string table;
  // With RunOptions::stage_times: the table of where the wall time went.
  std::string stage_times;
};

// Flies the scenario and evaluates it. on_progress is called about every
// half second of wall time. Throws core::ParamError for a bad scenario or
// override, std::runtime_error naming the folder if out_dir holds an earlier
// run and force is not set.
RunResult runScenario(const RunOptions& options,
                      const std::function<void(const RunProgress&)>& on_progress = {});

// Writes dir/scenario.yaml: the scenario as it ran, under "# <command>: the
// effective scenario" (nadir run and nadir launch; the viewers take its terrain).
void writeEffectiveScenario(const std::string& dir, const std::string& command,
                            nodes::ScenarioParams& scenario);

struct RunPlots {
  std::vector<std::string> png_paths;  // what nadir-plot wrote into the plots folder
  std::string problem;                 // why there are none; empty when it worked
};
// A run's charts: nadir-plot --headless on run (a run folder or an LCM log) into
// plots_dir (default: run_dir/plots), its output in plots_dir/nadir-plot.log.
// nadir-plot is the program in bin_dir (default: beside this one; Qt stays in
// gui/). A missing or failing nadir-plot is reported in `problem`, not thrown:
// the run itself is done.
RunPlots renderRunPlots(const std::string& run, const std::string& plots_dir = {},
                        const std::string& bin_dir = {});

}  // namespace nadir::run
