// nadir launch: the scenario's nodes as live processes on UDP LCM (run/launch.h).
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "run/launch.h"

namespace nadir::cli {
namespace {

std::atomic<bool> g_stop_launch{false};

void onLaunchSignal(int) { g_stop_launch = true; }

}  // namespace

void addLaunchCommand(CLI::App& app) {
  auto options = std::make_shared<run::LaunchOptions>();
  auto* command = app.add_subcommand("launch",
                                     "Start the scenario's nodes as live processes on UDP LCM, "
                                     "recorded by `nadir log record`; print "
                                     "their health; stop them all at the end or on Ctrl-C");
  command->add_option("scenario", options->scenario, "built-in scenario name or YAML file")
      ->capture_default_str();
  command->add_option("--out", options->out_dir,
                      "folder for the node logs and the recording (default out/<scenario>-live)");
  command->add_option("--set", options->overrides, "override a parameter: key=value (repeatable)");
  command->add_flag("--force", options->force, "replace an earlier launch in the output folder");
  command
      ->add_option("--hosts", options->hosts_file,
                   "a hosts file: the hosts, the command prefix that reaches each, and the "
                   "node each runs (docs/running.md)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--bus-check-timeout", options->bus_check_timeout_s,
                   "with --hosts: how long the bus may take to join every host, s")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  command->add_option("--report-period", options->report_period_s, "seconds between reports")
      ->capture_default_str()
      ->check(CLI::Range(0.2, 600.0));
  auto restart = std::make_shared<bool>(false);
  auto max_restarts = std::make_shared<int>(3);
  command->add_flag("--restart", *restart,
                    "start a node that dies again (not nadir-sim or the logger: either dying "
                    "stops the launch); a VO node's num_resets counts its fresh start");
  command
      ->add_option("--max-restarts", *max_restarts,
                   "with --restart: how many times each node is started again at most")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  command->callback([options, restart, max_restarts] {
    options->max_restarts = *restart ? *max_restarts : 0;
    std::signal(SIGINT, onLaunchSignal);
    std::signal(SIGTERM, onLaunchSignal);
    const int status = run::launchScenario(*options, std::cout, g_stop_launch);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace nadir::cli
