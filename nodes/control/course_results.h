#pragma once
// A rover's run over a course of gates and slalom boards, scored from the
// truth: each board passed (a gate through its opening, a slalom board on the
// side it shows), missed or hit (the body's footprint touched a post), the
// speeds, and the vision pipeline's cost per frame beside Liu et al.'s (2021)
// table 2. No LCM: the registry entry reads the log into these structs.

#include <cstdint>
#include <string>
#include <vector>

#include "core/trajectory.h"
#include "logs/course_metrics.h"
#include "terrain/course.h"

namespace nadir::control {

// The body's footprint relative to the rear axle the truth pose refers to.
struct Footprint {
  double length_m = 0.43;
  double width_m = 0.18;
  double rear_overhang_m = 0.08;
};

// One frame of the PPA's pattern tracking: instructions per stage and chip time.
struct PatternFrame {
  std::int64_t utime = 0;
  std::int64_t threshold = 0, flood = 0, denoise = 0, coordinates = 0;
  double chip_time_s = 0.0;
};

// One command: the frame it came from, when it took effect, and its steering.
struct CommandTiming {
  std::int64_t frame_utime = 0;
  std::int64_t utime = 0;
  double steer_rad = 0.0;
};

struct CourseRunInput {
  core::Trajectory truth;  // the body (rear axle), time-sorted
  std::vector<terrain::CourseBoard> boards;
  Footprint footprint;
  std::vector<PatternFrame> frames;
  std::vector<CommandTiming> commands;
  // The chip's instruction rate, and the transfer and controller times the
  // controller counts into its latency, s.
  double chip_instruction_rate_hz = 10e6;
  double transfer_s = 24e-6;
  double compute_s = 1e-6;
};

// Throws std::invalid_argument for a truth of fewer than two poses.
logs::CourseMetrics courseResults(const CourseRunInput& input);

// The results table's section: the course line, each board, the speeds, and the
// pipeline beside the paper's table 2.
std::string formatCourse(const logs::CourseMetrics& metrics);

// Whether two rectangles on the floor overlap: centre, half length along
// heading_rad (from north towards east), half width across.
struct FloorRectangle {
  double north_m = 0.0, east_m = 0.0;
  double heading_rad = 0.0;
  double half_length_m = 0.0, half_width_m = 0.0;
};
bool overlap(const FloorRectangle& a, const FloorRectangle& b);

// The pictures of a course run, as Liu et al.'s (2021) figures 13 and 14: the
// path over the course (north to the right, coloured by speed, boards and
// posts drawn to scale), and the steering angle against the distance to each
// gate (or slalom board) as the rover approaches it. Throws std::runtime_error
// when a file cannot be written.
void writeCoursePlots(const CourseRunInput& input, const logs::CourseMetrics& metrics,
                      const std::string& path_png, const std::string& steering_png);

}  // namespace nadir::control
