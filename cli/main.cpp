// nadir: the command-line entry point. Each verb wires a library; no logic here.
#include <CLI/CLI.hpp>

#include <iostream>

#include "cli/demo.h"
#include "cli/doctor.h"
#include "cli/snapshot.h"

int main(int argc, char** argv) {
  CLI::App app{"nadir: a distributed testbed for GNSS-denied navigation"};
  app.set_version_flag("--version", std::string("nadir ") + NADIR_VERSION);
  app.require_subcommand(1);

  auto* doctor = app.add_subcommand(
      "doctor", "Check multicast, UDP buffers and headless OpenGL; print the fix for each");

  std::string demo_out = "out/demo";
  auto* demo = app.add_subcommand("demo", "Run what nadir has so far and say what ran");
  demo->add_option("--out", demo_out, "Output folder")->capture_default_str();

  std::string snapshot_config, snapshot_out = "snapshot.png";
  std::vector<std::string> snapshot_overrides;
  auto* snapshot = app.add_subcommand(
      "snapshot", "Render what a downward camera sees from one pose over a world, as a PNG");
  snapshot->add_option("--config", snapshot_config, "YAML parameter file")
      ->check(CLI::ExistingFile);
  snapshot->add_option("--set", snapshot_overrides, "override a parameter: key=value (repeatable)");
  snapshot->add_option("--out", snapshot_out, "PNG to write")->capture_default_str();

  CLI11_PARSE(app, argc, argv);
  try {
    if (*doctor) return nadir::cli::runDoctor();
    if (*demo) return nadir::cli::runDemo(demo_out);
    if (*snapshot)
      return nadir::cli::runSnapshot(snapshot_config, snapshot_overrides, snapshot_out);
  } catch (const std::exception& error) {
    std::cerr << "nadir: error: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
