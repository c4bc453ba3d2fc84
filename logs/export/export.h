#pragma once
// Turns a run's camera stream into a dataset that external VO systems read:
// EuRoC (ORB-SLAM3, OpenVINS, Basalt, Kimera), the TUM monocular layout (DSO)
// and the TUM RGB-D layout (rgb.txt + groundtruth.txt, evo's "tum" format).
//
// Frames (docs/export.md): positions and orientations in nadir's world, local
// NED with the body FRD, or in REP-103's ENU with the body FLU. EuRoC's ground truth is the body
// (FRD, which is also the IMU frame) at the truth rate, with T_BS of cam0 = T_body_cam; the TUM
// forms' ground truth is the camera (OpenCV optical frame), T_world_cam, interpolated at the image
// times (linear position, SLERP orientation).

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/axes.h"

namespace nadir::dataset {

enum class Format {
  kEuroc,    // mav0/cam0, mav0/imu0, mav0/state_groundtruth_estimate0
  kTumMono,  // images/, times.txt, camera.txt (DSO), groundtruth.txt
  kTum,      // rgb/, rgb.txt, groundtruth.txt, calibration.txt
};

// "euroc", "tum-mono", "tum"; throws std::invalid_argument listing the names otherwise.
Format parseFormat(const std::string& name);
std::string formatName(Format format);

// An IMU's white noise and bias random walk, continuous time, as EuRoC's and
// Kalibr's sensor files give them.
struct ImuNoise {
  double gyroscope_noise_density = 0;      // rad/s/sqrt(Hz)
  double gyroscope_random_walk = 0;        // rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 0;  // m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 0;    // m/s^3/sqrt(Hz)
};

struct ExportOptions {
  std::string log_path;  // an LCM log, for example RUN_DIR/run.lcmlog
  std::string out_dir;   // created; must not exist or be empty
  Format format = Format::kEuroc;
  std::string camera_channel = "CAMERA_DOWN";
  std::string info_channel;  // camera_info_t; empty = camera_channel + "_INFO"
  std::string truth_channel = "POSE_TRUTH";
  std::string imu_channel = "IMU";
  // The axes of every pose, vector and extrinsic written: nadir's (world NED,
  // body FRD) or REP-103's (world ENU, body FLU; core/axes.h).
  core::Axes axes = core::Axes::kNed;
  // The IMU's noise as the run's scenario gave it (a log does not carry it):
  // written into EuRoC's imu0/sensor.yaml and the ORB-SLAM3 settings; without
  // it the settings are monocular only and a note says why.
  std::optional<ImuNoise> imu_noise;
  // Called after each image written, with the count so far and the number of
  // image_t on the camera channel; may be empty.
  std::function<void(std::int64_t written, std::int64_t total)> progress;
};

struct ExportSummary {
  std::int64_t images = 0;       // image files written
  std::int64_t poses = 0;        // ground-truth lines written
  std::int64_t imu_samples = 0;  // IMU lines written (EuRoC only; 0 for the TUM forms)
  std::string out_dir;
  // Empty for a clean log; otherwise what was damaged and where (the export
  // holds what the log held up to and around the damage).
  std::string damage;
  // Things the user should know: frames dropped (undecodable, out of order,
  // repeated times), calibration the format cannot express, missing truth.
  std::vector<std::string> notes;
};

class ExportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads the log twice (first the calibration, truth and IMU, then the images)
// and writes the dataset. Throws ExportError naming the file for: a missing or
// unreadable log, no image_t on the camera channel (listing the channels that
// carry image_t), no camera_info_t on the info channel, and an output folder
// that exists and is not empty (it is never overwritten). Nothing is written
// before those checks pass.
ExportSummary exportRun(const ExportOptions& options);

}  // namespace nadir::dataset
