#include "gui/run_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "gui_test_util.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;
using logs::SourceEstimate;
using test::kEstimates;
using test::kLostEstimate;
using test::kTruthPoses;
using test::writeLogRun;

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::trunc) << text;
}

TEST(GuiRunData, FindsRunsInATree) {
  const fs::path root = test::freshDir("tree");
  fs::create_directories(root / "a" / "run1" / "sub");
  fs::create_directories(root / "b" / "c" / "run2");
  fs::create_directories(root / "empty");
  writeText(root / "a" / "run1" / "truth.tum", "");
  writeText(root / "a" / "run1" / "sub" / "truth.tum", "");  // inside a run: not a run
  writeText(root / "b" / "c" / "run2" / "metrics.json", "{}");
  writeText(root / "empty" / "notes.txt", "");

  const std::vector<std::string> runs = findRuns(root.string());
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(fs::path(runs[0]), root / "a" / "run1");
  EXPECT_EQ(fs::path(runs[1]), root / "b" / "c" / "run2");
  EXPECT_TRUE(isRunDir((root / "b" / "c" / "run2").string()));
  EXPECT_FALSE(isRunDir((root / "empty").string()));
  // A run given directly is the only run.
  EXPECT_EQ(findRuns((root / "a" / "run1").string()).size(), 1u);
  EXPECT_THROW(findRuns((root / "missing").string()), RunDataError);
}

TEST(GuiRunData, LoadsTumFilesAndComputesMetrics) {
  const fs::path dir = test::writeTumRun("tum_run");
  const RunData run = loadRun(dir.string());
  EXPECT_EQ(fs::path(run.poses_from), dir / "truth.tum");
  EXPECT_TRUE(run.metrics_from.empty());
  EXPECT_DOUBLE_EQ(run.t0_s, test::kT0);

  ASSERT_EQ(run.truth.size(), static_cast<std::size_t>(kTruthPoses));
  const FigureColumns truth = figureColumns(run.truth);
  EXPECT_NEAR(truth.x_m.back(), 100.0, 1e-9);  // 10 m/s for 10 s
  EXPECT_NEAR(truth.y_m.back(), 50.0, 1e-9);
  EXPECT_NEAR(truth.z_m.back(), -100.0, 1e-9);
  EXPECT_NEAR(truth.roll_deg[7], test::kRollDeg, 1e-9);
  EXPECT_NEAR(truth.pitch_deg[7], test::kPitchDeg, 1e-9);
  EXPECT_NEAR(truth.yaw_deg[7], test::kYawDeg, 1e-9);

  ASSERT_EQ(run.sources.size(), 1u);
  const SourceSeries& source = run.sources.at("vo_test");
  const FigureColumns pose = figureColumns(source);
  ASSERT_EQ(pose.size(), static_cast<std::size_t>(kEstimates));
  ASSERT_EQ(source.position_error_m.size(), static_cast<std::size_t>(kEstimates));
  for (int j = 0; j < kEstimates; ++j) {
    const auto i = static_cast<std::size_t>(j);
    EXPECT_EQ(source.estimates[i].status, SourceEstimate::kTracking);
    EXPECT_NEAR(source.position_error_m[i], 5.0, 1e-9) << j;  // |(3, 4, 0)|
    EXPECT_NEAR(pose.yaw_deg[i], test::kYawDeg, 1e-9);
  }
  // At t = 100.5 s the truth is at (5, 2.5, -100); the estimate 3 m north, 4 m east.
  EXPECT_NEAR(pose.x_m.front(), 8.0, 1e-9);
  EXPECT_NEAR(pose.y_m.front(), 6.5, 1e-9);
  ASSERT_EQ(source.tracked.size(), 1u);
  EXPECT_EQ(source.tracked.front().size(), static_cast<std::size_t>(kEstimates));

  const eval::SourceMetrics& m = run.metrics.sources.at("vo_test");
  EXPECT_NEAR(m.position_rmse_m, 5.0, 1e-9);
  EXPECT_NEAR(m.rotation_rmse_deg, 0.0, 1e-6);
  // Tracked from the first estimate (0.5 s) until the last one's period ends (10 s).
  EXPECT_NEAR(m.tracked_pct, 95.0, 1e-9);
}

TEST(GuiRunData, LoadsTheLogWithStatuses) {
  const fs::path dir = writeLogRun("log_run");
  // A truth.tum that disagrees shows which file the poses came from.
  writeText(dir / "truth.tum", "0 1 2 3 0 0 0 1\n");
  const RunData run = loadRun(dir.string());
  EXPECT_EQ(fs::path(run.poses_from), dir / "run.lcmlog");
  EXPECT_TRUE(run.damage.empty()) << run.damage;
  ASSERT_EQ(run.truth.size(), static_cast<std::size_t>(kTruthPoses));
  const SourceSeries& source = run.sources.at("vo_feature");
  const FigureColumns pose = figureColumns(source);
  ASSERT_EQ(source.estimates.size(), static_cast<std::size_t>(kEstimates));
  for (int j = 0; j < kEstimates; ++j) {
    const auto i = static_cast<std::size_t>(j);
    if (j == kLostEstimate) {
      EXPECT_EQ(source.estimates[i].status, SourceEstimate::kLost);
      EXPECT_TRUE(std::isnan(source.position_error_m[i]));
      EXPECT_TRUE(std::isnan(pose.x_m[i]));
      EXPECT_TRUE(std::isnan(pose.roll_deg[i]));
    } else {
      EXPECT_EQ(source.estimates[i].status, SourceEstimate::kTracking);
      EXPECT_NEAR(source.position_error_m[i], 5.0, 1e-6) << j;  // utime rounds to 1 us
    }
  }
  // The LOST estimate splits the tracking into two stretches.
  ASSERT_EQ(source.tracked.size(), 2u);
  EXPECT_EQ(source.tracked[0].size(), static_cast<std::size_t>(kLostEstimate));
  EXPECT_NEAR(run.metrics.sources.at("vo_feature").position_rmse_m, 5.0, 1e-6);
}

// A log file is a run of its own: its poses, and metrics computed from them unless
// it is a run folder's run.lcmlog, whose metrics.json is its run's.
TEST(GuiRunData, LoadsALogFile) {
  const fs::path dir = writeLogRun("log_file");
  fs::copy_file(dir / "run.lcmlog", dir / "flight.lcmlog");
  eval::RunMetrics metrics;
  eval::SourceMetrics m;
  m.position_rmse_m = 7.5;  // not what the poses give
  metrics.sources["vo_feature"] = m;
  eval::writeMetricsJson((dir / "metrics.json").string(), metrics, eval::EvalOptions{});

  const RunData loose = loadRun((dir / "flight.lcmlog").string());
  EXPECT_EQ(loose.dir, (dir / "flight.lcmlog").string());
  EXPECT_EQ(fs::path(loose.poses_from), dir / "flight.lcmlog");
  EXPECT_TRUE(loose.metrics_from.empty());
  EXPECT_EQ(loose.truth.size(), static_cast<std::size_t>(kTruthPoses));
  EXPECT_NEAR(loose.metrics.sources.at("vo_feature").position_rmse_m, 5.0, 1e-6);

  const RunData own = loadRun((dir / "run.lcmlog").string());
  EXPECT_EQ(fs::path(own.metrics_from), dir / "metrics.json");
  EXPECT_DOUBLE_EQ(own.metrics.sources.at("vo_feature").position_rmse_m, 7.5);
}

// Loose logs in a tree are runs; a run folder's run.lcmlog is not listed beside
// its folder, and a log given as the root is the only run.
TEST(GuiRunData, FindsLooseLogs) {
  const fs::path root = test::freshDir("loose");
  fs::create_directories(root / "flights");
  const fs::path run = writeLogRun("loose_run");
  fs::copy(run, root / "run1");
  fs::copy_file(run / "run.lcmlog", root / "flights" / "a.lcmlog");
  writeText(root / "flights" / "notes.txt", "");
  const std::vector<std::string> runs = findRuns(root.string());
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(fs::path(runs[0]), root / "flights" / "a.lcmlog");
  EXPECT_EQ(fs::path(runs[1]), root / "run1");
  EXPECT_EQ(findRuns((root / "flights" / "a.lcmlog").string()),
            std::vector<std::string>{(root / "flights" / "a.lcmlog").string()});
  EXPECT_THROW(findRuns((root / "flights" / "notes.txt").string()), RunDataError);
}

TEST(GuiRunData, MetricsComeFromMetricsJson) {
  const fs::path dir = test::writeTumRun("json_run");
  eval::RunMetrics metrics;
  metrics.truth_poses = 101;
  eval::SourceMetrics m;
  m.position_rmse_m = 7.5;  // not what the poses give: the file wins
  m.rotation_rmse_deg = 0.25;
  m.tracked_pct = 87.5;
  m.ape_translation_m.rmse = 6.125;
  metrics.sources["vo_test"] = m;
  eval::EvalOptions options;
  options.truth_max_gap_s = 0.75;
  eval::writeMetricsJson((dir / "metrics.json").string(), metrics, options);

  const RunData run = loadRun(dir.string());
  EXPECT_EQ(fs::path(run.metrics_from), dir / "metrics.json");
  EXPECT_DOUBLE_EQ(run.options.truth_max_gap_s, 0.75);
  EXPECT_DOUBLE_EQ(run.metrics.sources.at("vo_test").position_rmse_m, 7.5);
  // RPE was never set: it does not exist and its field is empty.
  EXPECT_EQ(resultsCsv(run.metrics),
            "source,position_rmse_m,rotation_rmse_deg,tracked_pct,ape_rmse_m,rpe_rmse_m\n"
            "vo_test,7.5,0.25,87.5,6.125,\n");
}

// The message of the error thrown by loadRun(dir), or "" if it did not throw.
std::string loadError(const fs::path& dir) {
  try {
    loadRun(dir.string());
  } catch (const RunDataError& error) {
    return error.what();
  }
  return "";
}

// Headings either side of south: the truth flies at yaw 179.5 deg and the
// estimate reads -179.5 deg (1 deg off); the estimate's yaw is given as 180.5 deg,
// beside the truth's, not a full turn away.
TEST(GuiRunData, EstimateYawIsDrawnOnTheTruthsSideOfSouth) {
  constexpr double kRad = std::numbers::pi / 180.0;
  const fs::path dir = test::freshDir("south");
  core::Trajectory truth, estimate;
  for (int k = 0; k < 11; ++k) {
    const double t = 100.0 + 0.1 * k;
    truth.push_back(
        {t, Eigen::Vector3d(0, 0, -100), core::quaternionFromRpy({0, 0, 179.5 * kRad})});
    estimate.push_back(
        {t, Eigen::Vector3d(0, 0, -100), core::quaternionFromRpy({0, 0, -179.5 * kRad})});
  }
  core::writeTum((dir / "truth.tum").string(), truth);
  core::writeTum((dir / "vo_test.tum").string(), estimate);
  const RunData run = loadRun(dir.string());
  const SourceSeries& vo = run.sources.at("vo_test");
  const FigureColumns pose = figureColumns(vo);
  ASSERT_EQ(pose.size(), 11u);
  for (double yaw_deg : pose.yaw_deg) EXPECT_NEAR(yaw_deg, 180.5, 1e-6);
}

TEST(GuiRunData, RefusesADamagedTumFileNamingIt) {
  const fs::path dir = test::writeTumRun("bad_tum");
  writeText(dir / "vo_bad.tum", "100.5 1 2 3 0 0 0 1\n100.6 1 two 3 0 0 0 1\n");
  const std::string message = loadError(dir);
  EXPECT_NE(message.find("vo_bad.tum"), std::string::npos) << message;
  EXPECT_NE(message.find(":2"), std::string::npos) << message;  // the line
}

TEST(GuiRunData, RefusesForeignAndMissingFiles) {
  const fs::path foreign_json = test::writeTumRun("foreign_json");
  writeText(foreign_json / "metrics.json", R"({"schema": "something.else", "version": 1})");
  std::string message = loadError(foreign_json);
  EXPECT_NE(message.find("metrics.json"), std::string::npos) << message;
  EXPECT_NE(message.find("schema"), std::string::npos) << message;

  const fs::path foreign_log = test::freshDir("foreign_log");
  writeText(foreign_log / "run.lcmlog", "this is not an LCM log\n");
  message = loadError(foreign_log);
  EXPECT_NE(message.find("run.lcmlog"), std::string::npos) << message;

  const fs::path empty_truth = test::freshDir("empty_truth");
  writeText(empty_truth / "truth.tum", "# nothing\n");
  message = loadError(empty_truth);
  EXPECT_NE(message.find("truth.tum"), std::string::npos) << message;

  const fs::path one_pose = test::freshDir("one_pose");
  writeText(one_pose / "truth.tum", "0 1 2 3 0 0 0 1\n");
  writeText(one_pose / "vo_test.tum", "0 1 2 3 0 0 0 1\n");  // a source: too few to compare
  message = loadError(one_pose);
  EXPECT_NE(message.find("truth.tum"), std::string::npos) << message;

  const fs::path metrics_only = test::freshDir("metrics_only");
  eval::writeMetricsJson((metrics_only / "metrics.json").string(), eval::RunMetrics{},
                         eval::EvalOptions{});
  message = loadError(metrics_only);
  EXPECT_NE(message.find("run.lcmlog nor a TUM file"), std::string::npos) << message;

  message = loadError(test::freshDir("x") / "missing");
  EXPECT_NE(message.find("missing: no such folder or file"), std::string::npos) << message;

  // A file given as a log must be one.
  const fs::path text = test::freshDir("text") / "notes.lcmlog";
  writeText(text, "not a log either\n");
  message = loadError(text);
  EXPECT_NE(message.find("notes.lcmlog"), std::string::npos) << message;
}

// Rows worked out from the tiny run: the truth at 10 m/s north, 5 m/s east,
// 100 m up from t = 0; vo_test (3, 4, 0) m off it from t = 0.5 s, every 0.5 s.
TEST(GuiRunData, FigureDataAtFullRate) {
  const RunData run = loadRun(test::writeTumRun("figure_data").string());
  const std::string position = figureDataCsv(run, "position");
  EXPECT_EQ(position.rfind("trajectory,time_s,north_m,east_m,down_m\ntruth,0,0,0,-100\n", 0), 0u)
      << position.substr(0, 200);
  EXPECT_NE(position.find("\ntruth,10,100,50,-100\n"), std::string::npos);
  EXPECT_NE(position.find("\nvo_test,0.5,8,6.5,-100\n"), std::string::npos);
  EXPECT_EQ(std::count(position.begin(), position.end(), '\n'), 1 + kTruthPoses + kEstimates);

  const std::string error = figureDataCsv(run, "error");
  EXPECT_EQ(error.rfind("trajectory,time_s,position_error_m\nvo_test,0.5,5", 0), 0u) << error;
  EXPECT_EQ(std::count(error.begin(), error.end(), '\n'), 1 + kEstimates);

  const std::string attitude = figureDataCsv(run, "attitude", {"truth"});
  EXPECT_EQ(attitude.find("\ntruth,"), std::string::npos);
  EXPECT_EQ(std::count(attitude.begin(), attitude.end(), '\n'), 1 + kEstimates);
  EXPECT_THROW(figureDataCsv(run, "sideways"), RunDataError);
}

// vo_test as the truth: the recorded truth becomes a source, 5 m from it wherever
// vo_test's span covers it (t = 100.5 s to 109.5 s: 91 of its 101 poses).
TEST(GuiRunData, ComparesWithAnotherTrajectoryAsTheTruth) {
  const fs::path dir = test::writeTumRun("other_truth");
  const RunData recorded = loadRun(dir.string());
  EXPECT_EQ(recorded.truth_name, "truth");
  EXPECT_TRUE(recorded.truth_note.empty());
  EXPECT_EQ(trajectoryNames(recorded), (std::vector<std::string>{"truth", "vo_test"}));

  const RunData run = compareWithTruth(recorded, "vo_test");
  EXPECT_EQ(run.truth_name, "vo_test");
  EXPECT_DOUBLE_EQ(run.t0_s, test::estimateStamp(0));
  ASSERT_EQ(run.truth.size(), static_cast<std::size_t>(kEstimates));
  EXPECT_NEAR(run.truth.front().p_ned_m.x(), 8.0, 1e-9);  // (5, 2.5) + (3, 4)
  ASSERT_EQ(run.sources.size(), 1u);
  const SourceSeries& truth = run.sources.at("truth");
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kTruthPoses));
  EXPECT_TRUE(std::isnan(truth.position_error_m.front()));  // t = 100 s: before vo_test
  EXPECT_NEAR(truth.position_error_m[5], 5.0, 1e-9);        // t = 100.5 s
  EXPECT_NEAR(truth.position_error_m[50], 5.0, 1e-9);
  EXPECT_TRUE(std::isnan(truth.position_error_m.back()));  // t = 110 s: after it

  EXPECT_TRUE(run.metrics_from.empty());
  const eval::SourceMetrics& m = run.metrics.sources.at("truth");
  EXPECT_EQ(m.estimates_evaluated, 91u);
  EXPECT_NEAR(m.position_rmse_m, 5.0, 1e-9);
  EXPECT_NEAR(m.rotation_rmse_deg, 0.0, 1e-9);
  // The names stay the run's; back to the recorded truth gives the first run again.
  EXPECT_EQ(trajectoryNames(run), trajectoryNames(recorded));
  const RunData back = compareWithTruth(run, "truth");
  EXPECT_DOUBLE_EQ(back.t0_s, test::kT0);
  EXPECT_NEAR(back.metrics.sources.at("vo_test").position_rmse_m, 5.0, 1e-9);
  // The same through loadRun.
  EXPECT_EQ(loadRun(dir.string(), "vo_test").metrics.sources.at("truth").estimates_evaluated, 91u);
}

TEST(GuiRunData, MetricsJsonHoldsOnlyAgainstTheRecordedTruth) {
  const fs::path dir = writeLogRun("json_truth");
  eval::RunMetrics metrics;
  eval::SourceMetrics m;
  m.position_rmse_m = 1234.5;  // not what the poses give: must come from the file
  metrics.sources["vo_feature"] = m;
  eval::writeMetricsJson((dir / "metrics.json").string(), metrics, {});
  const RunData recorded = loadRun(dir.string());
  EXPECT_EQ(recorded.metrics.sources.at("vo_feature").position_rmse_m, 1234.5);
  EXPECT_FALSE(recorded.metrics_from.empty());

  const RunData other = compareWithTruth(recorded, "vo_feature");
  EXPECT_TRUE(other.metrics_from.empty());
  EXPECT_EQ(other.metrics.sources.count("vo_feature"), 0u);
  // The LOST estimate is no truth pose: 18 of the 19.
  EXPECT_EQ(other.truth.size(), static_cast<std::size_t>(kEstimates - 1));
  EXPECT_NEAR(other.metrics.sources.at("truth").position_rmse_m, 5.0, 1e-6);
  EXPECT_EQ(compareWithTruth(other, "truth").metrics.sources.at("vo_feature").position_rmse_m,
            1234.5);
}

TEST(GuiRunData, RefusesATruthTheRunDoesNotHave) {
  const RunData run = loadRun(test::writeTumRun("no_such_truth").string());
  try {
    compareWithTruth(run, "vo_nope");
    FAIL() << "no error";
  } catch (const RunDataError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("no trajectory vo_nope"), std::string::npos) << message;
    EXPECT_NE(message.find("truth, vo_test"), std::string::npos) << message;  // what it has
  }
  EXPECT_THROW(loadRun(run.dir, "vo_nope"), RunDataError);
}

// Without truth.tum, a file whose name says truth is taken, else the first by name;
// either way the run says it guessed.
TEST(GuiRunData, GuessesTheTruthOfTumFilesWithoutTruthTum) {
  const fs::path named = test::freshDir("groundtruth");
  core::writeTum((named / "estimate.tum").string(), test::estimateTrajectory());
  core::writeTum((named / "groundtruth.tum").string(), test::truthTrajectory());
  ASSERT_TRUE(isRunDir(named.string()));
  const RunData run = loadRun(named.string());
  EXPECT_EQ(run.truth_name, "groundtruth");
  EXPECT_EQ(fs::path(run.poses_from), named / "groundtruth.tum");
  EXPECT_NE(run.truth_note.find("its name says so"), std::string::npos) << run.truth_note;
  EXPECT_EQ(trajectoryNames(run), (std::vector<std::string>{"groundtruth", "estimate"}));
  EXPECT_NEAR(run.metrics.sources.at("estimate").position_rmse_m, 5.0, 1e-9);

  const fs::path unnamed = test::freshDir("unnamed");
  core::writeTum((unnamed / "b.tum").string(), test::truthTrajectory());
  core::writeTum((unnamed / "a.tum").string(), test::estimateTrajectory());
  const RunData first = loadRun(unnamed.string());
  EXPECT_EQ(first.truth_name, "a");
  EXPECT_NE(first.truth_note.find("the first by name"), std::string::npos) << first.truth_note;
  EXPECT_TRUE(compareWithTruth(first, "b").truth_note.empty());
}

}  // namespace
}  // namespace nadir::gui
