#pragma once
// A ground vehicle's run over a course of gates and slalom boards (Liu et al.
// 2021): what it passed, missed and hit, how fast it went, and what the vision
// pipeline cost per frame. Plain data: nodes/control computes it from a run,
// logs/eval keeps it in metrics.json (schema in docs/evaluation.md).

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace nadir::logs {

// One gate or slalom board of the course, in course order.
struct BoardPassage {
  std::string kind;      // gate, slalom_left, slalom_right
  bool passed = false;   // gate: through its opening; slalom board: by the side it shows
  bool crossed = false;  // the board's line was crossed at all
  bool hit = false;      // a post touched
  double time_s = std::numeric_limits<double>::quiet_NaN();  // crossing, from the run's start
  // The body's centre along the board's line when crossing, from its centre,
  // m (+ right as the vehicle drives), and the heading off the board's axis, deg.
  double offset_m = std::numeric_limits<double>::quiet_NaN();
  double heading_error_deg = std::numeric_limits<double>::quiet_NaN();
};

// One stage of the vision pipeline per frame, beside Liu et al.'s table 2.
struct PipelineStage {
  std::string name;
  double instructions = std::numeric_limits<double>::quiet_NaN();  // emulated, mean per frame
  double chip_us = std::numeric_limits<double>::quiet_NaN();       // at the chip's rate
  double paper_us = std::numeric_limits<double>::quiet_NaN();      // the paper's table 2
};

struct CourseMetrics {
  int gates = 0;
  int gates_passed = 0;
  int gates_missed = 0;
  int gates_hit = 0;
  int slalom_boards = 0;
  int slalom_passed = 0;  // on the side the board shows
  int slalom_wrong_side = 0;
  int slalom_missed = 0;
  int slalom_hit = 0;
  int decoys_hit = 0;
  std::vector<BoardPassage> passages;
  // From the first motion to the last crossing (or the last motion), m and s.
  double distance_m = std::numeric_limits<double>::quiet_NaN();
  double duration_s = std::numeric_limits<double>::quiet_NaN();
  double average_speed_mps = std::numeric_limits<double>::quiet_NaN();
  double peak_speed_mps = std::numeric_limits<double>::quiet_NaN();
  // The pipeline: frames, its stages, and the camera-to-command latency.
  int frames = 0;
  std::vector<PipelineStage> stages;
  double chip_time_us = std::numeric_limits<double>::quiet_NaN();
  double emulated_fps = std::numeric_limits<double>::quiet_NaN();
  double latency_mean_us = std::numeric_limits<double>::quiet_NaN();
  double latency_max_us = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace nadir::logs
