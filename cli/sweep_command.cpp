// nadir sweep: a grid of runs in parallel, here or as Slurm jobs, and one
// table of results (run/sweep.h, run/slurm.h).
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>
#include <vector>

#include "cli/commands.h"
#include "run/slurm.h"
#include "run/sweep.h"

namespace nadir::cli {
namespace {

namespace fs = std::filesystem;

struct SweepOptions {
  std::string path;
  std::string out_dir;
  std::vector<std::string> overrides;
  bool tabulate = false;
  bool rerun = false;
  long cell = -1;
  bool slurm = false;
  bool submit = false;
  bool wait = false;
  bool status = false;
};

std::string selfProgram() { return fs::read_symlink("/proc/self/exe").string(); }

// The sweep file with the command line's --out and --set.
run::SweepSpec loadSpec(const SweepOptions& options) {
  run::SweepSpec spec = run::loadSweep(options.path);
  if (!options.out_dir.empty()) spec.out_dir = options.out_dir;
  spec.shared_overrides.insert(spec.shared_overrides.end(), options.overrides.begin(),
                               options.overrides.end());
  return spec;
}

// The words every Slurm job of this sweep runs: this program, the sweep file
// and the command line's --out and --set, all absolute.
std::vector<std::string> sweepCommand(const SweepOptions& options, const run::SweepSpec& spec) {
  std::vector<std::string> words = {selfProgram(), "sweep", fs::absolute(options.path).string(),
                                    "--out", fs::absolute(spec.out_dir).string()};
  for (const std::string& assignment : options.overrides) {
    words.push_back("--set");
    words.push_back(assignment);
  }
  return words;
}

// In a log, a line when the counts change; on a terminal, one line refreshed in place.
class ProgressLine {
 public:
  void show(const run::SweepProgress& progress) {
    const std::string line = "sweep: " + run::describeProgress(progress);
    if (!tty_ && progress.done == last_done_ && progress.running == last_running_) return;
    last_done_ = progress.done;
    last_running_ = progress.running;
    std::fprintf(stderr, "%s%s%s", tty_ ? "\r\033[K" : "", line.c_str(), tty_ ? "" : "\n");
    std::fflush(stderr);
  }
  void end() {
    if (tty_) std::fprintf(stderr, "\n");
  }

 private:
  bool tty_ = isatty(STDERR_FILENO) != 0;
  std::size_t last_done_ = static_cast<std::size_t>(-1);
  std::size_t last_running_ = static_cast<std::size_t>(-1);
};

// results.csv and results.md from the cells; exit status 1 if one has no metrics.
void writeResults(const run::SweepSpec& spec, const std::vector<run::SweepCell>& cells) {
  const fs::path out(spec.out_dir);
  fs::create_directories(out);
  std::ofstream(out / "results.csv") << run::sweepCsv(spec, cells);
  const std::string markdown = run::sweepMarkdown(spec, cells);
  std::ofstream(out / "results.md") << markdown;
  std::cout << markdown << "\nwrote " << (out / "results.csv").string() << " and "
            << (out / "results.md").string() << "\n";
  std::size_t failed = 0;
  for (const run::SweepCell& cell : cells) {
    if (!cell.metrics) {
      ++failed;
      std::cerr << "sweep: " << cell.out_dir << ": " << cell.error << "\n";
    }
  }
  if (failed > 0) throw CLI::RuntimeError(1);
}

// Follows submitted jobs until the merge has run; then the merged table.
void waitForSlurm(const run::SweepSpec& spec, const run::SlurmJobs& jobs) {
  ProgressLine line;
  // The merge is over when squeue has not listed it twice running (one
  // answer lost to a busy controller does not end the wait).
  for (int quiet = 0; quiet < 2;) {
    const run::SlurmStatus status = run::slurmStatus(spec, selfProgram(), jobs);
    line.show(status.progress);
    quiet = status.merge_active ? 0 : quiet + 1;
    if (quiet < 2) std::this_thread::sleep_for(std::chrono::seconds(2));
  }
  line.end();
  const fs::path results = fs::path(spec.out_dir) / "results.md";
  if (!fs::exists(results)) {
    std::cerr << "sweep: the merge job " << jobs.merge_job << " wrote no " << results.string()
              << "; see " << (fs::absolute(spec.out_dir) / "slurm" / "logs" / "merge.out").string()
              << "\n";
    throw CLI::RuntimeError(1);
  }
  writeResults(spec, run::readSweep(spec));
}

void runSweepCommand(const SweepOptions& options) {
  const run::SweepSpec spec = loadSpec(options);
  if (options.cell >= 0) {
    const int status = run::runCell(spec, static_cast<std::size_t>(options.cell), selfProgram());
    if (status != 0) throw CLI::RuntimeError(status);
    return;
  }
  if (options.status) {
    const run::SlurmJobs jobs = run::submittedJobs(spec);
    const run::SlurmStatus status = run::slurmStatus(spec, selfProgram(), jobs);
    std::cout << "sweep: " << run::describeProgress(status.progress);
    if (!jobs.merge_job.empty()) {
      std::cout << "; Slurm jobs " << (jobs.array_job.empty() ? "-" : jobs.array_job)
                << " (cells) and " << jobs.merge_job << " (merge, "
                << (status.merge_active ? "to come" : "over") << ")";
    }
    std::cout << "\n";
    if (!status.scheduler_note.empty()) std::cout << "sweep: " << status.scheduler_note << "\n";
    return;
  }
  if (options.slurm) {
    const run::SlurmPlan plan =
        run::writeSlurmScripts(spec, sweepCommand(options, spec), selfProgram(), options.rerun);
    const std::size_t total = run::planSweep(spec).size();
    std::cout << "sweep: " << plan.cells.size() << " of " << total << " cells to run"
              << (plan.cells.size() < total ? " (the others are done)" : "") << "; wrote "
              << (plan.array_script.empty() ? "" : plan.array_script + ", ") << plan.merge_script
              << " and " << plan.submit_script << "\n";
    if (!options.submit) {
      std::cout << "sweep: submit with " << plan.submit_script << " (or --submit)\n";
      return;
    }
    const run::SlurmJobs jobs = run::submitSlurm(plan);
    std::cout << "sweep: submitted: cells job "
              << (jobs.array_job.empty() ? "none" : jobs.array_job) << ", merge job "
              << jobs.merge_job << " after it; `nadir sweep " << options.path
              << " --status` says where it stands\n"
              << std::flush;
    if (options.wait) waitForSlurm(spec, jobs);
    return;
  }
  if (options.tabulate) {
    writeResults(spec, run::readSweep(spec));
    return;
  }
  ProgressLine line;
  const std::vector<run::SweepCell> cells = run::runSweep(
      spec, selfProgram(), [&line](const run::SweepProgress& p) { line.show(p); }, options.rerun);
  line.end();
  writeResults(spec, cells);
}

}  // namespace

void addSweepCommand(CLI::App& app) {
  auto options = std::make_shared<SweepOptions>();
  auto* command = app.add_subcommand(
      "sweep",
      "Run a grid of parameter values (SWEEP.yaml) as parallel runs, here or on Slurm; write "
      "one table. Cells already done are not run again");
  command->add_option("sweep", options->path, "the sweep file")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out_dir, "the sweep's folder (default: the file's out)");
  command->add_option("--set", options->overrides,
                      "an override every cell gets, after the file's set (repeatable)");
  command->add_flag("--rerun", options->rerun, "run every cell, done or not");
  auto* tabulate = command->add_flag(
      "--tabulate", options->tabulate,
      "run nothing: write the tables from the cells' metrics.json (after `nadir eval` of "
      "each cell, say)");
  auto* cell = command
                   ->add_option("--cell", options->cell,
                                "run this one cell (0-based; what a Slurm array task runs)")
                   ->check(CLI::NonNegativeNumber);
  auto* slurm = command->add_flag(
      "--slurm", options->slurm,
      "write Slurm scripts: a job array of the cells not done and a merge job after it "
      "(OUT/slurm/)");
  auto* submit =
      command->add_flag("--submit", options->submit, "with --slurm: submit them with sbatch");
  command
      ->add_flag("--wait", options->wait,
                 "with --submit: follow the jobs until the merge has run, then print the table")
      ->needs(submit);
  submit->needs(slurm);
  auto* status = command->add_flag(
      "--status", options->status,
      "say where the sweep stands: cells done, running, waiting, failed (squeue/sacct for "
      "submitted jobs) and the time left");
  tabulate->excludes(cell)->excludes(slurm)->excludes(status);
  cell->excludes(slurm)->excludes(status);
  slurm->excludes(status);
  command->callback([options] { runSweepCommand(*options); });
}

}  // namespace nadir::cli
