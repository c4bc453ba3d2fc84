// The closed loop in sim time: the rover on the gate course, the slalom and the number 8,
// steered by the emulated SCAMP-5's disks through nadir-control, scored from
// the truth; the same run twice gives byte-identical logs; without the chip
// the rover never moves.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "run/run.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;

std::string tempDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("nadir_closed_loop_" + name);
  fs::remove_all(dir);
  return dir.string();
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

RunResult runCourse(const std::string& scenario, const std::string& dir,
                    std::vector<std::string> overrides = {}) {
  RunOptions options;
  options.scenario = scenario;
  options.out_dir = tempDir(dir);
  options.overrides = std::move(overrides);
  options.record_images = false;
  return runScenario(options);
}

// Eight gates among decoys at 2.4 m/s: every gate passed, no post touched, at
// 2.2 m/s or more on average (Liu et al. 2021: 2.20 m/s); twice, the same bytes.
TEST(ClosedLoop, TheGateCourseTwiceTheSame) {
  const RunResult a = runCourse("gates", "gates_a");
  ASSERT_TRUE(a.metrics.course.has_value());
  const logs::CourseMetrics& course = *a.metrics.course;
  EXPECT_EQ(course.gates, 8);
  EXPECT_EQ(course.gates_passed, 8);
  EXPECT_EQ(course.gates_hit, 0);
  EXPECT_EQ(course.decoys_hit, 0);
  EXPECT_GE(course.average_speed_mps, 2.2);
  for (const logs::BoardPassage& passage : course.passages) {
    EXPECT_LT(std::abs(passage.offset_m), 0.09);  // the body clear of both posts
  }
  EXPECT_GT(course.frames, 1000);
  EXPECT_GT(course.latency_mean_us, 25.0);  // at least the transfer and the PID
  // metrics.json has the course as the results saw it.
  const eval::RunMetrics written = eval::readMetricsJson(a.metrics_path);
  ASSERT_TRUE(written.course.has_value());
  EXPECT_EQ(written.course->gates_passed, 8);
  EXPECT_NE(a.table.find("course: 8 of 8 gates passed, 0 missed, 0 hit"), std::string::npos)
      << a.table;

  const RunResult b = runCourse("gates", "gates_b");
  const std::string log_a = readFile(a.log_path), log_b = readFile(b.log_path);
  EXPECT_GT(log_a.size(), 1000000u);
  EXPECT_TRUE(log_a == log_b) << "the logs differ";
}

// The fast slalom: every board passed on the side it shows, none touched, at
// 3.9 m/s at the peak (Liu et al. 2021: 3.88 m/s).
TEST(ClosedLoop, TheFastSlalom) {
  const RunResult result = runCourse("slalom", "slalom");
  ASSERT_TRUE(result.metrics.course.has_value());
  const logs::CourseMetrics& course = *result.metrics.course;
  EXPECT_EQ(course.slalom_boards, 6);
  EXPECT_EQ(course.slalom_passed, 6);
  EXPECT_EQ(course.slalom_hit, 0);
  EXPECT_GE(course.peak_speed_mps, 3.9);
}

// The number 8: each of the eight boards turned at its way (two 135 deg
// left, six 45 deg right), none touched, the lap flown at speed (Liu et al.
// 2021: 1.70 m/s on average).
TEST(ClosedLoop, TheNumberEight) {
  const RunResult result = runCourse("number8", "number8");
  ASSERT_TRUE(result.metrics.course.has_value());
  const logs::CourseMetrics& course = *result.metrics.course;
  EXPECT_EQ(course.slalom_boards, 8);
  EXPECT_EQ(course.slalom_passed, 8) << result.table;
  EXPECT_EQ(course.slalom_hit, 0);
  EXPECT_GE(course.average_speed_mps, 1.7);
}

// Without the chip's patterns the controller commands nothing and the rover
// stays where it started.
TEST(ClosedLoop, BlindTheRoverStays) {
  const RunResult result = runCourse("gates", "blind", {"ppa.enabled=false", "duration_s=1"});
  ASSERT_TRUE(result.metrics.course.has_value());
  EXPECT_EQ(result.metrics.course->gates_passed, 0);
  EXPECT_NEAR(result.metrics.truth_track_length_m, 0.0, 1e-9);
}

}  // namespace
}  // namespace nadir::run
