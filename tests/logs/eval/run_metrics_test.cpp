// The per-run evaluation: robustness (tracked_pct), McConville et al.'s (2020) metrics, a
// source that never tracked, and the metrics.json round trip. Expected values
// are worked out by hand.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/frames.h"
#include "logs/eval/run_metrics.h"

namespace nadir::eval {
namespace {

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_eval_" + name;
}

// A straight truth along north at 10 m/s from 0 to 10 s, sampled at 100 Hz.
core::Trajectory straightTruth() {
  core::Trajectory truth;
  for (int k = 0; k <= 1000; ++k) {
    core::StampedPose pose;
    pose.t_s = k * 0.01;
    pose.p_ned_m = Eigen::Vector3d(10.0 * pose.t_s, 0, -100);
    truth.push_back(pose);
  }
  return truth;
}

// Estimates at 10 Hz from `from_s` to 9.9 s, exactly on the truth, with a status by time.
template <typename StatusOf>
std::vector<SourceEstimate> estimatesAt10Hz(int first_frame, StatusOf status_of) {
  std::vector<SourceEstimate> estimates;
  for (int k = first_frame; k < 100; ++k) {
    SourceEstimate e;
    e.t_s = k * 0.1;
    e.status = status_of(k);
    e.p_ned_m = Eigen::Vector3d(10.0 * e.t_s, 0, -100);
    estimates.push_back(e);
  }
  return estimates;
}

// LOST from 3.0 s to 5.0 s of a 10 s truth: 3 s + 5 s tracked = 80 %, in 2 segments.
TEST(EvalRunMetrics, GapInTrackingGivesHandTrackedPct) {
  const auto estimates = estimatesAt10Hz(0, [](int k) {
    return k >= 30 && k < 50 ? SourceEstimate::kLost : SourceEstimate::kTracking;
  });
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  EXPECT_NEAR(m.tracked_pct, 80.0, 1e-9);
  EXPECT_TRUE(m.initialised);
  EXPECT_EQ(m.tracking_segments, 2u);
  EXPECT_EQ(m.estimates, 100u);
  EXPECT_EQ(m.estimates_tracking, 80u);
  EXPECT_EQ(m.estimates_evaluated, 80u);
  EXPECT_NEAR(m.rate_hz, 10.0, 1e-9);
  EXPECT_NEAR(m.position_rmse_m, 0.0, 1e-9);
  // Track length within segments only: 0..2.9 s and 5.0..9.9 s at 10 m/s = 29 + 49 m.
  EXPECT_NEAR(m.track_length_m, 78.0, 1e-9);
  EXPECT_NEAR(m.truth_track_length_m, 78.0, 1e-9);
  EXPECT_NEAR(m.rpe_translation_m.rmse, 0.0, 1e-9);
  EXPECT_EQ(m.rpe_translation_m.count, 29u + 49u);  // pairs never straddle the gap
  EXPECT_NEAR(m.longest_gap_s, 0.1, 1e-9);          // LOST estimates still came every 0.1 s
}

// A node that died at 3.0 s and published again from 5.2 s: its estimates stop
// for 2.2 s (the last at 2.9 s, the next at 5.2 s), and that is the longest gap.
TEST(EvalRunMetrics, ANodeThatDiedLeavesItsLongestGap) {
  std::vector<SourceEstimate> estimates =
      estimatesAt10Hz(0, [](int) { return SourceEstimate::kTracking; });
  std::erase_if(estimates, [](const SourceEstimate& e) { return e.t_s > 2.95 && e.t_s < 5.15; });
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  EXPECT_NEAR(m.longest_gap_s, 5.2 - 2.9, 1e-9);
  EXPECT_EQ(m.tracking_segments, 1u);  // the statuses alone do not show it
}

// A node's num_resets is a running count: the source's resets are the largest
// it reported (here 0, then 1 from 4.0 s, then 2 from 7.0 s), whatever the order
// the estimates arrive in; a source with no estimates has none.
TEST(EvalRunMetrics, ResetsAreTheLargestCountReported) {
  auto estimates = estimatesAt10Hz(0, [](int) { return SourceEstimate::kTracking; });
  for (std::size_t k = 0; k < estimates.size(); ++k) estimates[k].resets = k >= 70 ? 2 : k >= 40;
  std::swap(estimates.front(), estimates.back());
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  ASSERT_TRUE(m.resets.has_value());
  EXPECT_EQ(*m.resets, 2u);
  const SourceMetrics none = evaluateSource(straightTruth(), {}, EvalOptions{});
  EXPECT_FALSE(none.resets.has_value());
}

// Starting to track at 2.0 s counts the first 2 s as not tracked: 80 %.
TEST(EvalRunMetrics, LateStartIsNotTracked) {
  const auto estimates = estimatesAt10Hz(20, [](int) { return SourceEstimate::kTracking; });
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  EXPECT_NEAR(m.tracked_pct, 80.0, 1e-9);
  EXPECT_NEAR(m.first_tracking_s, 2.0, 1e-9);
}

// A silent hole (no estimate 4.9..8.0 s) holds the last one 3 periods: 4.9 + 0.3 + 2.0 = 72 %.
TEST(EvalRunMetrics, SilentHoleHoldsThreePeriods) {
  auto estimates = estimatesAt10Hz(0, [](int) { return SourceEstimate::kTracking; });
  estimates.erase(estimates.begin() + 50, estimates.begin() + 80);
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  EXPECT_NEAR(m.tracked_pct, 72.0, 1e-9);
}

// McConville et al. (2020) on three sides of a 100 m square against the same path scaled 0.9 about
// its start: Path lengths sample every track_length_interval_s: a 200 Hz estimate that wobbles 1 cm
// across a 10 m straight flight adds 200 x 2 cm of wobble at every estimate, none at 1 s.
TEST(EvalRunMetrics, TrackLengthSamplesAtTheInterval) {
  core::Trajectory truth;
  std::vector<SourceEstimate> estimates;
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.005 * i;
    truth.push_back({t, Eigen::Vector3d(10.0 * t, 0, 0), Eigen::Quaterniond::Identity()});
    const double wobble = (i % 2 == 0 ? 0.01 : -0.01);
    estimates.push_back(
        SourceEstimate{{t, Eigen::Vector3d(10.0 * t, wobble, 0), Eigen::Quaterniond::Identity()},
                       SourceEstimate::kTracking});
  }
  EvalOptions every;
  every.track_length_interval_s = 0.0;
  // Each 5 ms step: 0.05 m along, 0.02 m across: sqrt(0.05^2 + 0.02^2) = 0.053852 m.
  EXPECT_NEAR(evaluateSource(truth, estimates, every).track_length_m, 200 * 0.0538516, 1e-4);
  // At 1 s: the first and the last estimate, 10 m apart (both wobble +1 cm).
  const SourceMetrics sampled = evaluateSource(truth, estimates, EvalOptions{});
  EXPECT_NEAR(sampled.track_length_m, 10.0, 1e-9);
  EXPECT_NEAR(sampled.truth_track_length_m, 10.0, 1e-9);
}
// length -10 %, end point 10 m = 3.333 % of 300 m, MAE (0 + 10 + 14.142 + 10) / 4.
TEST(EvalRunMetrics, Seed000SquareVersusScaledSquare) {
  const Eigen::Vector3d corners[4] = {{0, 0, 0}, {100, 0, 0}, {100, 100, 0}, {0, 100, 0}};
  core::Trajectory truth;
  for (int k = 0; k <= 30; ++k) {  // 1 Hz, 10 m/s along the sides
    const int side = std::min(k / 10, 2);
    const double u = (k - 10.0 * side) / 10.0;
    truth.push_back(core::StampedPose{static_cast<double>(k),
                                      corners[side] + u * (corners[side + 1] - corners[side]),
                                      Eigen::Quaterniond::Identity()});
  }
  std::vector<SourceEstimate> estimates;
  for (int c = 0; c < 4; ++c) {
    estimates.push_back(SourceEstimate{{10.0 * c, 0.9 * corners[c], Eigen::Quaterniond::Identity()},
                                       SourceEstimate::kTracking});
  }
  const SourceMetrics m = evaluateSource(truth, estimates, EvalOptions{});
  EXPECT_NEAR(m.truth_track_length_m, 300.0, 1e-9);
  EXPECT_NEAR(m.track_length_m, 270.0, 1e-9);
  EXPECT_NEAR(m.track_length_diff_pct, -10.0, 1e-9);
  EXPECT_NEAR(m.end_point_m, 10.0, 1e-9);
  EXPECT_NEAR(m.end_point_pct, 100.0 * 10.0 / 300.0, 1e-9);
  EXPECT_NEAR(m.mean_abs_error_m, (0 + 10 + std::sqrt(200.0) + 10) / 4, 1e-9);
  EXPECT_NEAR(m.position_rmse_m, 10.0, 1e-9);  // sqrt((0 + 100 + 200 + 100) / 4)
  EXPECT_NEAR(m.tracked_pct, 100.0, 1e-9);     // 10 s holds cover 0..30 s
  EXPECT_NEAR(m.rate_hz, 0.1, 1e-12);
  // APE with Sim(3) recovers the scale 1/0.9.
  EvalOptions sim3;
  sim3.align = "sim3";
  const SourceMetrics aligned = evaluateSource(truth, estimates, sim3);
  EXPECT_NEAR(aligned.alignment_scale, 1.0 / 0.9, 1e-9);
  EXPECT_NEAR(aligned.ape_translation_m.rmse, 0.0, 1e-9);
  EXPECT_EQ(aligned.alignment, "sim3");
}

// A source that only initialises: not initialised, 0 % tracked, metrics absent (NaN).
TEST(EvalRunMetrics, NeverTrackedSourceHasNoMetrics) {
  const auto estimates = estimatesAt10Hz(0, [](int) { return SourceEstimate::kInitializing; });
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  EXPECT_FALSE(m.initialised);
  EXPECT_EQ(m.tracked_pct, 0.0);
  EXPECT_TRUE(std::isnan(m.position_rmse_m));
  EXPECT_TRUE(std::isnan(m.ape_translation_m.rmse));
  EXPECT_EQ(m.ape_translation_m.count, 0u);
  EXPECT_NEAR(m.rate_hz, 10.0, 1e-9);
  EXPECT_EQ(m.note, "never tracked");
}

// A straight truth cannot fix an SE(3) alignment: APE and RPE are absent and the note says why.
TEST(EvalRunMetrics, DegenerateAlignmentIsANote) {
  const auto estimates = estimatesAt10Hz(0, [](int) { return SourceEstimate::kTracking; });
  EvalOptions se3;
  se3.align = "se3";
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, se3);
  EXPECT_TRUE(std::isnan(m.ape_translation_m.rmse));
  EXPECT_NEAR(m.position_rmse_m, 0.0, 1e-9);  // the thesis metrics need no alignment
  EXPECT_NE(m.note.find("degenerate"), std::string::npos) << m.note;
}

// Estimates before the truth starts are skipped, not compared.
TEST(EvalRunMetrics, EstimatesOutsideTruthAreSkipped) {
  auto estimates = estimatesAt10Hz(0, [](int) { return SourceEstimate::kTracking; });
  for (SourceEstimate& e : estimates) e.t_s -= 5.0;  // -5.0 .. 4.9 s
  const SourceMetrics m = evaluateSource(straightTruth(), estimates, EvalOptions{});
  EXPECT_EQ(m.estimates_evaluated, 50u);
  EXPECT_NEAR(m.tracked_pct, 50.0, 1e-9);
  EXPECT_NE(m.note.find("50 TRACKING estimates outside"), std::string::npos) << m.note;
}

// ------------------------------------------------------------ metrics.json

void expectSame(double a, double b) {
  if (std::isnan(a)) {
    EXPECT_TRUE(std::isnan(b));
  } else {
    EXPECT_EQ(a, b);
  }
}

void expectSame(const Statistics& a, const Statistics& b) {
  expectSame(a.rmse, b.rmse);
  expectSame(a.mean, b.mean);
  expectSame(a.median, b.median);
  expectSame(a.std, b.std);
  expectSame(a.min, b.min);
  expectSame(a.max, b.max);
  EXPECT_EQ(a.count, b.count);
}

// write -> read gives the same numbers; a never-tracked source is null, never NaN, in the file.
TEST(EvalMetricsJson, RoundTrip) {
  std::map<std::string, std::vector<SourceEstimate>> sources;
  sources["vo_feature"] = estimatesAt10Hz(0, [](int k) {
    return k >= 30 && k < 50 ? SourceEstimate::kLost : SourceEstimate::kTracking;
  });
  for (SourceEstimate& e : sources["vo_feature"]) e.p_ned_m.y() += 0.1 * std::sin(e.t_s);
  for (SourceEstimate& e : sources["vo_feature"]) e.resets = e.t_s >= 5.0 ? 3 : 0;
  sources["vo_direct"] = estimatesAt10Hz(0, [](int) { return SourceEstimate::kInitializing; });
  EvalOptions options;
  options.align = "none";
  options.rpe_delta = 2.0;
  options.rpe_delta_unit = "meters";
  const RunMetrics written = evaluate(straightTruth(), sources, options);
  const std::string path = tempPath("metrics.json");
  writeMetricsJson(path, written, options);

  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  EXPECT_EQ(text.str().find("NaN"), std::string::npos);
  EXPECT_EQ(text.str().find("nan"), std::string::npos);
  EXPECT_NE(text.str().find("\"initialised\": false"), std::string::npos);
  EXPECT_NE(text.str().find("\"position_rmse_m\": null"), std::string::npos);

  EvalOptions read_options;
  const RunMetrics read = readMetricsJson(path, &read_options);
  EXPECT_EQ(read_options.align, "none");
  EXPECT_EQ(read_options.rpe_delta_unit, "meters");
  EXPECT_EQ(read.truth_track_length_m, written.truth_track_length_m);
  EXPECT_EQ(read.truth_duration_s, written.truth_duration_s);
  EXPECT_EQ(read.truth_poses, written.truth_poses);
  ASSERT_EQ(read.sources.size(), 2u);
  for (const auto& [name, w] : written.sources) {
    SCOPED_TRACE(name);
    const SourceMetrics& r = read.sources.at(name);
    EXPECT_EQ(r.initialised, w.initialised);
    expectSame(r.position_rmse_m, w.position_rmse_m);
    expectSame(r.rotation_rmse_deg, w.rotation_rmse_deg);
    expectSame(r.tracked_pct, w.tracked_pct);
    expectSame(r.track_length_diff_pct, w.track_length_diff_pct);
    expectSame(r.mean_abs_error_m, w.mean_abs_error_m);
    expectSame(r.end_point_m, w.end_point_m);
    expectSame(r.end_point_pct, w.end_point_pct);
    expectSame(r.rate_hz, w.rate_hz);
    expectSame(r.longest_gap_s, w.longest_gap_s);
    expectSame(r.first_tracking_s, w.first_tracking_s);
    expectSame(r.alignment_scale, w.alignment_scale);
    EXPECT_EQ(r.alignment, w.alignment);
    EXPECT_EQ(r.rpe_delta, w.rpe_delta);
    EXPECT_EQ(r.rpe_delta_unit, w.rpe_delta_unit);
    EXPECT_EQ(r.estimates_evaluated, w.estimates_evaluated);
    EXPECT_EQ(r.tracking_segments, w.tracking_segments);
    EXPECT_EQ(r.resets, w.resets);
    EXPECT_EQ(r.note, w.note);
    expectSame(r.ape_translation_m, w.ape_translation_m);
    expectSame(r.ape_rotation_deg, w.ape_rotation_deg);
    expectSame(r.rpe_translation_m, w.rpe_translation_m);
    expectSame(r.rpe_rotation_deg, w.rpe_rotation_deg);
  }
  EXPECT_GT(read.sources.at("vo_feature").rpe_translation_m.count, 0u);
  EXPECT_EQ(read.sources.at("vo_feature").resets, std::optional<std::size_t>(3));
  EXPECT_EQ(read.sources.at("vo_direct").resets, std::optional<std::size_t>(0));

  // A metrics.json from before resets were recorded reads as "not known".
  std::string old_text = text.str();
  for (std::size_t at; (at = old_text.find("\"resets\"")) != std::string::npos;)
    old_text.erase(at, old_text.find('\n', at) - at + 1);
  const std::string old_path = tempPath("old_metrics.json");
  std::ofstream(old_path) << old_text;
  for (const auto& [name, r] : readMetricsJson(old_path).sources) {
    SCOPED_TRACE(name);
    EXPECT_FALSE(r.resets.has_value());
  }

  // The table has one row per source and "-" for what does not exist.
  const std::string table = formatResultsTable(read);
  EXPECT_NE(table.find("vo_direct"), std::string::npos);
  EXPECT_NE(table.find("vo_feature"), std::string::npos);
  EXPECT_EQ(table.find("as a filter"), std::string::npos);
  EXPECT_FALSE(read.sources.at("vo_feature").filter.has_value());
}

// A filter's block goes out and comes back, null where a figure does not
// exist, and the table gets its line.
TEST(EvalMetricsJson, FilterFiguresRoundTrip) {
  RunMetrics written;
  written.truth_poses = 10;
  SourceMetrics& nav = written.sources["nav"];
  FilterMetrics filter;
  filter.states_evaluated = 42;
  filter.had_gps = true;
  filter.denial_s = 50.0;
  filter.error_denial_60_m = 2.5;
  filter.error_end_m = 3.25;
  filter.nees_position_mean = 3.1;
  filter.nees_attitude_mean = 4.2;
  filter.nees_position_in_band_pct = 95.5;
  filter.nees_attitude_in_band_pct = 80.0;
  nav.filter = filter;
  const std::string path = tempPath("filter_metrics.json");
  writeMetricsJson(path, written, EvalOptions{});
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  EXPECT_NE(text.str().find("\"error_denial_120_m\": null"), std::string::npos);
  const RunMetrics read = readMetricsJson(path);
  ASSERT_TRUE(read.sources.at("nav").filter.has_value());
  const FilterMetrics& back = *read.sources.at("nav").filter;
  EXPECT_EQ(back.states_evaluated, 42u);
  EXPECT_TRUE(back.had_gps);
  EXPECT_EQ(back.denial_s, 50.0);
  EXPECT_EQ(back.error_denial_60_m, 2.5);
  EXPECT_TRUE(std::isnan(back.error_denial_120_m));
  EXPECT_EQ(back.error_end_m, 3.25);
  EXPECT_EQ(back.nees_attitude_in_band_pct, 80.0);
  const std::string table = formatResultsTable(read);
  EXPECT_NE(table.find("nav as a filter: GPS last fused at 50.0 s; error at denial +60 s 2.50 m, "
                       "+120 s - m, end 3.25 m; NEES position 3.10, attitude 4.20"),
            std::string::npos)
      << table;
}

// The guidance's waypoints: the truth against where the vehicle believed it
// was, worked by hand (a 3-4-5 miss, then 0 and 12 m), over the waypoints
// reached on the source only; and the figures and a course through metrics.json.
TEST(EvalMetricsJson, GuidanceAndCourseRoundTrip) {
  const auto passage = [](double t, int index, const char* source, Eigen::Vector3d truth,
                          Eigen::Vector3d believed) {
    logs::WaypointPassage w;
    w.t_s = t;
    w.index = index;
    w.count = 3;
    w.waypoint_ned_m = believed;
    w.believed_ned_m = believed;
    w.true_ned_m = truth;
    w.source = source;
    return w;
  };
  const GuidanceMetrics guidance =
      evaluateGuidance({passage(110.0, 0, "truth", {1.0, 2.0, 0.0}, {1.0, 2.0, 0.0}),
                        passage(130.0, 1, "nav", {103.0, 4.0, 0.0}, {100.0, 0.0, 0.0}),
                        passage(150.0, 2, "nav", {200.0, 12.0, 0.0}, {200.0, 0.0, 0.0})},
                       100.0);
  EXPECT_EQ(guidance.waypoints, 3);
  EXPECT_EQ(guidance.waypoints_on_source, 2);
  EXPECT_EQ(guidance.source, "nav");
  EXPECT_DOUBLE_EQ(guidance.passages[1].miss_m, 5.0);
  EXPECT_DOUBLE_EQ(guidance.passages[1].t_s, 30.0);
  EXPECT_DOUBLE_EQ(guidance.max_miss_m, 12.0);
  EXPECT_DOUBLE_EQ(guidance.mean_miss_m, 8.5);
  EXPECT_DOUBLE_EQ(guidance.end_miss_m, 12.0);

  RunMetrics written;
  written.truth_poses = 10;
  written.guidance = guidance;
  logs::CourseMetrics course;
  course.gates = 8;
  course.gates_passed = 7;
  course.gates_hit = 1;
  course.average_speed_mps = 2.3;
  course.passages.push_back({"gate", true, true, false, 1.5, 0.02, -3.0});
  course.stages.push_back({"de-noising", 10.0, 1.0, 4.0});
  written.course = course;
  const std::string path = tempPath("guidance_metrics.json");
  writeMetricsJson(path, written, EvalOptions{});
  const RunMetrics read = readMetricsJson(path);
  ASSERT_TRUE(read.guidance.has_value());
  EXPECT_EQ(read.guidance->waypoints_on_source, 2);
  EXPECT_DOUBLE_EQ(read.guidance->max_miss_m, 12.0);
  ASSERT_EQ(read.guidance->passages.size(), 3u);
  EXPECT_EQ(read.guidance->passages[2].source, "nav");
  ASSERT_TRUE(read.course.has_value());
  EXPECT_EQ(read.course->gates_passed, 7);
  EXPECT_EQ(read.course->gates_hit, 1);
  EXPECT_DOUBLE_EQ(read.course->average_speed_mps, 2.3);
  EXPECT_TRUE(std::isnan(read.course->peak_speed_mps));
  ASSERT_EQ(read.course->passages.size(), 1u);
  EXPECT_DOUBLE_EQ(read.course->passages[0].offset_m, 0.02);
  EXPECT_EQ(read.course->stages[0].name, "de-noising");
  const std::string table = formatResultsTable(read);
  EXPECT_NE(table.find("guidance on nav: 2 of 3 waypoints reached on it, the truth 12.00 m from "
                       "where it believed at most (8.50 m on average), 12.00 m at the last"),
            std::string::npos)
      << table;
}

// A damaged metrics.json is refused with the file and the key.
TEST(EvalMetricsJson, MissingKeyIsNamed) {
  const std::string path = tempPath("bad_metrics.json");
  std::ofstream(path) << R"({"schema": "nadir.metrics", "version": 1, "truth": {"duration_s": 1}})";
  try {
    readMetricsJson(path);
    FAIL();
  } catch (const EvalError& error) {
    EXPECT_NE(std::string(error.what()).find(path + ": truth: missing key 'track_length_m'"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace nadir::eval
