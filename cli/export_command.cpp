// nadir export: a run's camera stream as a EuRoC, TUM-mono (DSO) or TUM RGB-D dataset.
#include "cli/commands.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include <unistd.h>

#include "cli/frame_option.h"
#include "cli/progress_line.h"
#include "core/params.h"
#include "logs/export/export.h"
#include "nodes/sim/sim_params.h"

namespace nadir::cli {
namespace {

namespace fs = std::filesystem;

struct ExportCommandOptions {
  std::string run;
  std::string format;
  std::string out;
  std::string camera = "CAMERA_DOWN";
  std::string truth = "POSE_TRUTH";
  std::string imu = "IMU";
  core::Axes axes = core::Axes::kNed;
};

void runExport(const ExportCommandOptions& options) {
  dataset::ExportOptions export_options;
  export_options.format = dataset::parseFormat(options.format);
  // RUN_DIR is a run's folder (its run.lcmlog is read), or a log file itself.
  const fs::path run(options.run);
  const bool run_is_log = fs::is_regular_file(run);
  export_options.log_path = run_is_log ? run.string() : (run / "run.lcmlog").string();
  const fs::path run_dir = run_is_log ? run.parent_path() : run;
  export_options.out_dir =
      !options.out.empty()
          ? options.out
          : (run_dir / ("export_" + dataset::formatName(export_options.format))).string();
  export_options.camera_channel = options.camera;
  export_options.truth_channel = options.truth;
  export_options.imu_channel = options.imu;
  export_options.axes = options.axes;
  // The IMU's noise is the run's scenario's (a log does not carry it).
  if (const fs::path scenario = run_dir / "scenario.yaml"; fs::is_regular_file(scenario)) {
    sim::SimParams sim;
    core::applyYamlFileKeys(scenario.string(), {"sensors"},
                            [&sim](core::ParamVisitor& v) { sim.visit(v); });
    const sim::ImuParams& imu = sim.sensors.imu.model;
    export_options.imu_noise =
        dataset::ImuNoise{.gyroscope_noise_density = imu.gyro_noise_density_rps_rthz,
                          .gyroscope_random_walk = imu.gyro_bias_random_walk_rps_rts,
                          .accelerometer_noise_density = imu.accel_noise_density_mps2_rthz,
                          .accelerometer_random_walk = imu.accel_bias_random_walk_mps2_rts};
  }
  std::cout << "nadir export: " << options.camera << " of " << export_options.log_path << " as "
            << dataset::formatName(export_options.format) << std::endl;
  dataset::ExportSummary summary;
  {
    ProgressLine progress("nadir export");
    export_options.progress = [&progress](std::int64_t written, std::int64_t total) {
      progress.count(written, total, "images written");
    };
    summary = dataset::exportRun(export_options);
  }
  std::cout << "  wrote " << summary.images << " images, " << summary.poses
            << " ground-truth poses, " << summary.imu_samples << " IMU samples to "
            << summary.out_dir << "\n";
  for (const std::string& note : summary.notes) std::cout << "  note: " << note << "\n";
  if (!summary.damage.empty()) {
    std::cout << "  damaged log, exported what it holds: " << summary.damage << "\n";
  }
  std::cout << "  frames, units and file layout: " << summary.out_dir << "/README.md\n";
}

}  // namespace

void addExportCommand(CLI::App& app) {
  auto options = std::make_shared<ExportCommandOptions>();
  auto* command = app.add_subcommand(
      "export", "Write a run's camera images, IMU and ground truth as a EuRoC or TUM dataset");
  command->add_option("RUN_DIR", options->run, "run folder (holding run.lcmlog) or an LCM log")
      ->required();
  command->add_option("--format", options->format, "euroc, tum-mono (DSO) or tum (TUM RGB-D)")
      ->required()
      ->check(CLI::IsMember({"euroc", "tum-mono", "tum"}));
  command->add_option("--out", options->out,
                      "output folder, must not exist or be empty (default RUN_DIR/export_FORMAT)");
  command->add_option("--camera", options->camera, "image_t channel; intrinsics on CHANNEL_INFO")
      ->capture_default_str();
  command->add_option("--truth", options->truth, "pose_t truth channel")->capture_default_str();
  command->add_option("--imu", options->imu, "imu_t channel")->capture_default_str();
  addFrameOption(command, options->axes, "every pose, vector and extrinsic written");
  command->callback([options] { runExport(*options); });
}

}  // namespace nadir::cli
