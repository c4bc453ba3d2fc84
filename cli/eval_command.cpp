// nadir eval: the metrics of a recorded run (from its LCM log), or evo-style APE
// and RPE between two TUM files. Definitions: eval/run_metrics.h, docs/evaluation.md.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/frame_option.h"
#include "cli/progress_line.h"
#include "core/params.h"
#include "logs/eval/metrics.h"
#include "logs/eval/run_metrics.h"
#include "logs/eval/trajectory.h"
#include "nodes/sim/sim_params.h"

namespace nadir::cli {
namespace {

namespace fs = std::filesystem;

struct EvalCommandOptions {
  std::string path;  // RUN_DIR or LOG
  std::string truth_channel;
  std::string ref;
  std::string est;
  eval::EvalOptions eval;
};

// The truth's channel: as given, else the run's scenario.yaml's, else (empty) the
// channel of the log that carries pose_t.
std::string truthChannelOf(const EvalCommandOptions& options, const fs::path& dir) {
  if (!options.truth_channel.empty()) return options.truth_channel;
  const fs::path scenario = dir / "scenario.yaml";
  if (!fs::is_regular_file(scenario)) return {};
  sim::SimParams sim;
  core::applyYamlFileKeys(scenario.string(), {"truth"},
                          [&sim](core::ParamVisitor& v) { sim.visit(v); });
  return sim.truth.channel;
}

void evaluateRun(const EvalCommandOptions& options) {
  fs::path log = options.path;
  if (fs::is_directory(log)) log /= "run.lcmlog";
  if (!fs::exists(log)) throw eval::EvalError(log.string() + ": no such file or directory");
  const fs::path dir = log.has_parent_path() ? log.parent_path() : fs::path(".");

  eval::RunEvaluation run;
  {
    ProgressLine progress("nadir eval: reading " + log.string());
    run = eval::evaluateRunLog(log.string(), dir.string(), options.eval,
                               truthChannelOf(options, dir), progress.reading());
  }
  if (!run.recorded.damage.empty()) {
    std::cerr << "nadir eval: warning: " << log.string() << ": " << run.recorded.damage << "\n";
  }
  std::vector<std::string> written = {run.metrics_path};
  written.insert(written.end(), run.tum_paths.begin(), run.tum_paths.end());

  std::cout << eval::formatResultsTable(run.metrics) << "\n";
  for (std::size_t i = 0; i < written.size(); ++i) {
    std::cout << (i == 0 ? "wrote " : "      ") << written[i] << "\n";
  }
}

void evaluateTumPair(const EvalCommandOptions& options) {
  const core::Trajectory ref = core::readTum(options.ref);
  const core::Trajectory est = core::readTum(options.est);
  eval::TrajectoryEvaluation evaluation;
  try {
    evaluation = eval::evaluateTrajectories(ref, est, options.eval);
  } catch (const eval::EvalError& error) {
    throw eval::EvalError(options.est + " against " + options.ref + ": " + error.what());
  }
  std::cout << "reference " << options.ref << "\nestimate  " << options.est << "\n"
            << eval::formatTrajectoryReport(evaluation, options.eval);
}

}  // namespace

void addEvalCommand(CLI::App& app) {
  auto options = std::make_shared<EvalCommandOptions>();
  auto* command = app.add_subcommand(
      "eval",
      "Evaluate a run (RUN_DIR or its LOG: metrics.json, TUM files and a results table), or "
      "compare two TUM trajectories (--ref, --est) with evo's APE and RPE");
  command->add_option("path", options->path, "run folder (holding run.lcmlog) or LCM log");
  command->add_option("--truth-channel", options->truth_channel,
                      "the truth's pose_t channel (default: the run's scenario.yaml says, else "
                      "the log's channel of pose_t)");
  command->add_option("--ref", options->ref, "reference TUM trajectory (with --est)");
  command->add_option("--est", options->est, "estimated TUM trajectory (with --ref)");
  command
      ->add_option("--align", options->eval.align,
                   "align the estimate before APE and RPE: none, se3 or sim3 (Umeyama)")
      ->check(CLI::IsMember({"none", "se3", "sim3"}))
      ->capture_default_str();
  command->add_option("--delta", options->eval.rpe_delta, "RPE pair spacing")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--delta-unit", options->eval.rpe_delta_unit,
                   "unit of --delta: frames or meters")
      ->check(CLI::IsMember({"frames", "meters"}))
      ->capture_default_str();
  command
      ->add_option("--t-max-diff", options->eval.t_max_diff_s,
                   "TUM association: largest stamp difference of a pose pair, s")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  addFrameOption(command, options->eval.tum_axes, "the TUM files written");
  command->callback([options] {
    const bool pair = !options->ref.empty() || !options->est.empty();
    if (pair && !options->path.empty()) {
      throw eval::EvalError("give either RUN_DIR|LOG or --ref and --est, not both");
    }
    if (pair && (options->ref.empty() || options->est.empty())) {
      throw eval::EvalError(options->ref.empty() ? "--est needs --ref REF.tum"
                                                 : "--ref needs --est EST.tum");
    }
    if (!pair && options->path.empty()) {
      throw eval::EvalError(
          "nothing to evaluate: give RUN_DIR|LOG, or --ref REF.tum --est EST.tum");
    }
    eval::validateOptions(options->eval);
    if (pair) {
      evaluateTumPair(*options);
    } else {
      evaluateRun(*options);
    }
  });
}

}  // namespace nadir::cli
