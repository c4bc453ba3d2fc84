// nadir sweep: a grid of runs in parallel and one table of results (run/sweep.h).
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <vector>

#include "cli/commands.h"
#include "run/sweep.h"

namespace nadir::cli {

void addSweepCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto tabulate = std::make_shared<bool>(false);
  auto* command = app.add_subcommand(
      "sweep", "Run a grid of parameter values (SWEEP.yaml) as parallel runs; write one table");
  command->add_option("sweep", *path, "the sweep file")->required()->check(CLI::ExistingFile);
  command->add_flag("--tabulate", *tabulate,
                    "run nothing: write the tables from the cells' metrics.json (after `nadir "
                    "eval` of each cell, say)");
  command->callback([path, tabulate] {
    const run::SweepSpec spec = run::loadSweep(*path);
    const bool tty = isatty(STDERR_FILENO) != 0;
    const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
    std::size_t last_done = static_cast<std::size_t>(-1);
    const auto progress = [tty, &last_done](const run::SweepProgress& p) {
      // In a log, a line when a cell finishes; on a terminal, one line refreshed in place.
      if (!tty && p.done == last_done) return;
      last_done = p.done;
      const double eta =
          p.done > 0 ? p.elapsed_s / static_cast<double>(p.done) * (p.total - p.done) : 0.0;
      std::fprintf(stderr, "%ssweep: %zu/%zu done (%zu failed), %zu running, %.0f s elapsed",
                   tty ? "\r" : "", p.done, p.total, p.failed, p.running, p.elapsed_s);
      if (p.done > 0 && p.done < p.total) std::fprintf(stderr, ", about %.0f s to go", eta);
      std::fprintf(stderr, tty ? "   " : "\n");
      std::fflush(stderr);
    };
    const std::vector<run::SweepCell> cells =
        *tabulate ? run::readSweep(spec) : run::runSweep(spec, self, progress);
    if (tty && !*tabulate) std::fprintf(stderr, "\n");
    const std::filesystem::path out(spec.out_dir);
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
  });
}

}  // namespace nadir::cli
