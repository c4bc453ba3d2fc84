// nadir run: one scenario through the whole pipeline in one process (run/run.h).
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/frame_option.h"
#include "run/run.h"

namespace nadir::cli {
void printRunProgress(const run::RunProgress& progress) {
  // On a terminal one line refreshed in place; in a log a line every 10 s of wall time.
  static const bool tty = isatty(STDERR_FILENO) != 0;
  static double last_printed_s = -1e9;
  if (!tty && progress.wall_s - last_printed_s < 10.0) return;
  last_printed_s = progress.wall_s;
  const double speed = progress.wall_s > 0.0 ? progress.sim_s / progress.wall_s : 0.0;
  std::fprintf(stderr, "%srun: t %7.1f s", tty ? "\r" : "", progress.sim_s);
  if (progress.planned_s > 0.0) std::fprintf(stderr, " / %.0f s", progress.planned_s);
  std::fprintf(stderr, " | %llu frames | %llu messages | %.1fx real time%s",
               static_cast<unsigned long long>(progress.frames),
               static_cast<unsigned long long>(progress.messages), speed, tty ? "   " : "\n");
  std::fflush(stderr);
}

void endRunProgress() {
  if (isatty(STDERR_FILENO) != 0) std::fprintf(stderr, "\n");
}

void finishRun(const run::RunResult& result) {
  std::cout << "\n" << result.table << "\n";
  if (!result.stage_times.empty()) std::cout << result.stage_times << "\n";
  std::cout << "wrote " << result.log_path << " (replay: lcm-logplayer " << result.log_path
            << ")\n      " << result.metrics_path << "\n";
  for (const std::string& path : result.tum_paths) std::cout << "      " << path << "\n";
  for (const std::string& path : result.picture_paths) std::cout << "      " << path << "\n";
  std::cout << std::flush;
  const run::RunPlots plots = run::renderRunPlots(result.out_dir);
  for (const std::string& path : plots.png_paths) std::cout << "      " << path << "\n";
  if (!plots.problem.empty()) std::cerr << "nadir run: " << plots.problem << "\n";
}

void addRunCommand(CLI::App& app) {
  auto options = std::make_shared<run::RunOptions>();
  auto* command = app.add_subcommand(
      "run",
      "Fly a scenario through the whole pipeline in one process, in sim time; record, "
      "evaluate and print the results");
  command->add_option("scenario", options->scenario, "built-in scenario name or YAML file")
      ->capture_default_str();
  command->add_option("--out", options->out_dir, "output folder (default out/<scenario>)");
  command->add_option("--set", options->overrides, "override a parameter: key=value (repeatable)");
  command->add_flag("--force", options->force, "replace an earlier run in the output folder");
  command->add_flag("--no-images{false}", options->record_images,
                    "leave the camera images out of run.lcmlog (metrics are unchanged)");
  command->add_flag("--serial{false}", options->node_threads,
                    "run the VO nodes in the bus's dispatch, not on their own threads (their "
                    "estimates reach the others at once instead of with the next frame)");
  command->add_flag("--timing", options->stage_times,
                    "time the pipeline's stages and print where the wall time went (also "
                    "DIR/stage_times.txt)");
  addFrameOption(command, options->tum_axes, "the TUM files written");
  command->callback([options] {
    const run::RunResult result = run::runScenario(*options, printRunProgress);
    endRunProgress();
    finishRun(result);
  });
}

}  // namespace nadir::cli
