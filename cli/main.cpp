// nadir: the command-line entry point. Each verb registers itself (cli/commands.h).
#include <CLI/CLI.hpp>

#include <iostream>

#include "cli/commands.h"
#include "core/command_line.h"

int main(int argc, char** argv) {
  CLI::App app{"nadir: a distributed testbed for GNSS-denied navigation"};
  app.set_version_flag("--version", std::string("nadir ") + NADIR_VERSION);
  app.require_subcommand(1);
  nadir::cli::addDoctorCommand(app);
  nadir::cli::addDemoCommand(app);
  nadir::cli::addSnapshotCommand(app);
  nadir::cli::addExportCommand(app);
  nadir::cli::addRunCommand(app);
  nadir::cli::addLaunchCommand(app);
  nadir::cli::addBusCommands(app);
  nadir::cli::addSweepCommand(app);
  nadir::cli::addLogCommands(app);
  nadir::cli::addEvalCommand(app);
  nadir::cli::addVoCommands(app);
  nadir::cli::addCalibCommand(app);
  nadir::cli::addSpyCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return nadir::core::exitAfter(app, error);
  } catch (const std::exception& error) {
    std::cerr << "nadir: error: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
