#pragma once
// `nadir sweep`: a grid of parameter values (the thesis's experiment grid)
// flown cell by cell by `nadir run` child processes in parallel, then one
// table of position RMSE, rotation RMSE and robustness per cell and per VO,
// laid out like the thesis's tables 1 and 2 (Kim 2019).
//
// SWEEP.yaml:
//   scenario: thesis-oscillating
//   out: out/sweep                 # one folder per cell under it
//   jobs: 2                        # runs at once (default: the number of cores)
//   set: ["camera.fps=31"]         # overrides every cell shares
//   images: false                  # record camera images in the cells' logs
//   axes:                          # in order; the first splits the tables
//     vehicle.airspeed_mps: [10, 25]
//     vehicle.max_roll_rate_dps: [25, 45, 65]
//     vehicle.altitude_agl_m: [50, 100, 150, 200, 250, 300, 350, 400]
//     effect:                      # named variants: each value a list of overrides
//       ideal: []
//       noise: [camera.read_noise_counts=2, camera.shot_noise_electrons_per_count=10]
//   slurm:                         # what each cell asks of a Slurm cluster (run/slurm.h)
//     cpus_per_task: 2
//     mem: 8G
//     time: "01:00:00"
//     partition: batch             # optional, as are account and extra
//     account: vision
//     extra: [--qos=normal]
//
// A cell is done when its metrics.json reads and the command that made it
// (OUT/cell_.../sweep_cell.txt) is the one the sweep would run now: a sweep
// run again (after a failure, or with more axis values) runs only the rest.

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "logs/eval/run_metrics.h"

namespace nadir::run {

// A parameter and its values, or (variants non-empty) a label and named
// variants, each a list of overrides; values then holds the variants' names.
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
  std::vector<std::vector<std::string>> variants = {};

  // The overrides the axis's i-th value stands for.
  std::vector<std::string> overrides(std::size_t i) const;
};

// What each cell asks of a Slurm cluster: sbatch's --cpus-per-task, --mem,
// --time, --partition and --account, and any other sbatch options.
struct SlurmResources {
  int cpus_per_task = 2;
  std::string mem = "4G";
  std::string time = "02:00:00";
  std::string partition;
  std::string account;
  std::vector<std::string> extra;
};

struct SweepSpec {
  std::string scenario;
  std::string out_dir = "out/sweep";
  int jobs = 0;
  std::vector<std::string> shared_overrides;
  std::vector<SweepAxis> axes;
  // Record the camera images in each cell's run.lcmlog (off: the logs hold
  // everything else and the metrics are the same, at a fraction of the size).
  bool images = false;
  SlurmResources slurm;
};

// Throws core::ParamError naming the file, line and problem.
SweepSpec loadSweep(const std::string& path);

struct SweepCell {
  // One value per axis, in axis order.
  std::vector<std::string> values;
  std::string out_dir;
  int exit_status = -1;
  std::optional<eval::RunMetrics> metrics;
  // Why the cell has no metrics (the run failed: see its run.out).
  std::string error;
};

// Every combination of the axes' values, the last axis varying fastest.
std::vector<SweepCell> planSweep(const SweepSpec& spec);

// Where a sweep stands: cells done (before this run too: done_before of
// them), failed, running and waiting, and the time left at the pace of the
// cells that ran (0 while none has).
struct SweepProgress {
  std::size_t done = 0, done_before = 0, failed = 0, running = 0, pending = 0, total = 0;
  double elapsed_s = 0.0;
  double remaining_s = 0.0;
};

// "12/48 done (3 before), 1 failed, 2 running, 33 waiting, about 20 min to go".
std::string describeProgress(const SweepProgress& progress);

// The `nadir run` command of a cell (argv[0] = nadir_program).
std::vector<std::string> cellCommand(const SweepSpec& spec, const SweepCell& cell,
                                     const std::string& nadir_program);
// True when the cell's metrics.json reads (they are then in cell.metrics) and
// sweep_cell.txt holds command; a cell not done is left as it was.
bool cellDone(SweepCell& cell, const std::vector<std::string>& command);

// Runs one cell now, in this process's child (what a Slurm array task does):
// sweep_cell.txt written, an earlier metrics.json removed, output in
// OUT/run.out. Returns the run's exit status.
int runCell(const SweepSpec& spec, std::size_t index, const std::string& nadir_program);

// Runs `nadir_program run` for every cell not done (every cell with rerun),
// spec.jobs at a time, and reads each cell's metrics.json. A failed cell is
// kept with its error; the others go on.
std::vector<SweepCell> runSweep(const SweepSpec& spec, const std::string& nadir_program,
                                const std::function<void(const SweepProgress&)>& on_progress,
                                bool rerun = false);

// A finished cell's OUT/metrics.json into cell.metrics, or why not into cell.error.
void readCellMetrics(SweepCell& cell);
// The cells of a sweep that has run, from their metrics.json (after `nadir
// eval` has rewritten them, say), without running anything.
std::vector<SweepCell> readSweep(const SweepSpec& spec);

// The results: one CSV row per cell, and Markdown tables like the thesis's
// (one table per value of the first axis when there are three or more axes;
// rows the other axes; per source position RMSE, rotation RMSE, tracked % and
// resets, X where a source never initialised, the lowest error of a row in bold).
std::string sweepCsv(const SweepSpec& spec, const std::vector<SweepCell>& cells);
std::string sweepMarkdown(const SweepSpec& spec, const std::vector<SweepCell>& cells);

}  // namespace nadir::run
