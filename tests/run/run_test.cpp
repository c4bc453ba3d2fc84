// nadir run, launch and sweep: determinism, replay, live processes and tables.

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "core/utc_time.h"
#include "lcmtypes/codec.h"
#include "logs/eval/run_metrics.h"
#include "nodes/scenario.h"
#include "run/launch.h"
#include "run/run.h"
#include "run/sweep.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;

std::string tempDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("nadir_run_" + name);
  fs::remove_all(dir);
  return dir.string();
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

RunOptions shortRun(const std::string& out_dir) {
  RunOptions options;
  options.scenario = "default";
  options.out_dir = out_dir;
  options.overrides = {"duration_s=3", "camera.width=320", "camera.height=240"};
  return options;
}

// A run writes its log, metrics, truth TUM, pictures and the effective scenario; the
// log holds the truth at 400 Hz and the camera at 20 frames/s, all at sim time,
// its events at the scenario's date: 2024-06-21 at 10:00 local solar time at
// 8 deg E, 10:00 - 8 / 15 h = 09:28:00 UTC (written into scenario.yaml).
TEST(Run, WritesItsFiles) {
  const RunResult result = runScenario(shortRun(tempDir("files")));
  for (const char* name : {"run.lcmlog", "metrics.json", "truth.tum", "tracks.png",
                           "last_frame.png", "scenario.yaml"}) {
    EXPECT_TRUE(fs::exists(fs::path(result.out_dir) / name)) << name;
  }
  std::map<std::string, int> counts;
  core::LcmLogReader reader(result.log_path);
  std::int64_t last_truth_event_utime = -1;
  std::int64_t last_truth_utime = -1;
  while (auto event = reader.next()) {
    ++counts[event->channel];
    if (event->channel == "POSE_TRUTH") {
      last_truth_event_utime = event->timestamp_utime;
      last_truth_utime = msg::decode<msg::Pose>(event->data).utime;
    }
  }
  EXPECT_EQ(counts["POSE_TRUTH"], 3 * 400 + 1);
  EXPECT_EQ(counts["CAMERA_DOWN"], 3 * 20 + 1);
  EXPECT_EQ(last_truth_utime, 3'000'000);
  EXPECT_EQ(last_truth_event_utime, core::utimeFromUtc("2024-06-21T09:28:00Z") + 3'000'000);
  EXPECT_NE(readFile((fs::path(result.out_dir) / "scenario.yaml").string())
                .find("start_utc: \"2024-06-21T09:28:00Z\""),
            std::string::npos);
  EXPECT_NEAR(result.metrics.truth_duration_s, 3.0, 1e-9);
  EXPECT_NEAR(result.metrics.truth_track_length_m, 3.0 * 20.0, 0.5);  // 20 m/s airspeed, no wind
}

// Every run gets its charts: nadir-plot (built beside the test, as beside nadir)
// writes the four figures into RUN_DIR/plots; a folder that holds no run gives a
// problem naming the failure instead of an exception.
TEST(Run, RenderRunPlotsWritesTheCharts) {
  const RunResult result = runScenario(shortRun(tempDir("plots")));
  const RunPlots plots = renderRunPlots(result.out_dir);
  EXPECT_TRUE(plots.problem.empty()) << plots.problem;
  std::vector<std::string> names;
  for (const std::string& path : plots.png_paths) names.push_back(fs::path(path).filename());
  EXPECT_EQ(names, (std::vector<std::string>{"attitude.png", "error.png", "position.png",
                                             "top_view.png"}));
  for (const std::string& path : plots.png_paths) EXPECT_GT(fs::file_size(path), 10000u) << path;

  const std::string empty = tempDir("plots_of_nothing");
  fs::create_directories(empty);
  const RunPlots none = renderRunPlots(empty);
  EXPECT_TRUE(none.png_paths.empty());
  EXPECT_NE(none.problem.find("nadir-plot ended with exit status 1"), std::string::npos)
      << none.problem;
}

// Two runs of one scenario produce byte-identical logs.
TEST(Run, TwoRunsGiveIdenticalLogs) {
  const RunResult a = runScenario(shortRun(tempDir("same_a")));
  const RunResult b = runScenario(shortRun(tempDir("same_b")));
  const std::string log_a = readFile(a.log_path), log_b = readFile(b.log_path);
  EXPECT_GT(log_a.size(), 1000000u);
  EXPECT_TRUE(log_a == log_b) << "the logs differ";
}

// An earlier run is not overwritten unless asked to.
TEST(Run, RefusesToOverwriteAnEarlierRun) {
  RunOptions options = shortRun(tempDir("overwrite"));
  options.overrides.push_back("duration_s=0.5");
  runScenario(options);
  try {
    runScenario(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("already holds a run"), std::string::npos);
  }
  options.force = true;
  EXPECT_NO_THROW(runScenario(options));
}

// The run's log replayed through the log bus and recorded again (each event at
// the time the log bus gives it, its event time) is the same file and evaluates
// to the same metrics.
TEST(Run, ReplayThroughTheLogBusGivesIdenticalMetrics) {
  const RunResult result = runScenario(shortRun(tempDir("replay")));
  const std::string replayed = (fs::path(result.out_dir) / "replayed.lcmlog").string();
  {
    auto player = core::openBus("file://" + result.log_path + "?mode=r&speed=0");
    core::LcmLogWriter writer(replayed);
    auto recorder = player->subscribe(".*", [&writer](const core::RawMessage& raw) {
      writer.write(raw.recv_utime, std::string(raw.channel), raw.data, raw.size);
    });
    while (player->handle(std::chrono::milliseconds(0))) {
    }
  }
  EXPECT_EQ(readFile(replayed), readFile(result.log_path));
  const logs::LogTrajectories recorded = logs::readRunLog(replayed);
  const eval::EvalOptions options;
  const eval::RunMetrics metrics =
      eval::evaluate(recorded.truth, recorded.sources, options, recorded.filters);
  const std::string json = (fs::path(result.out_dir) / "replayed.json").string();
  eval::writeMetricsJson(json, metrics, options);
  EXPECT_EQ(readFile(json), readFile(result.metrics_path));
}

// McConville et al.'s (2020) flight, one lap, the emulated SCAMP-5 without target correction:
// within the bounds (mean absolute error <= 1 m, end point <= 0.5 % of the track).
// The host de-rotates with the true attitude here (sensors.ahrs.estimator=ideal): the
// bounds are the odometry's own; docs/benchmarks.md has the figures with the estimate.
TEST(Run, PpaOdometryOnOneLapOfTheRectangle) {
  RunOptions options;
  options.scenario = "scamp-rectangle";
  options.out_dir = tempDir("ppa_lap");
  options.overrides = {"route.repeat=1", "ppa.host.target_gate_m=0",
                       "sensors.ahrs.estimator=ideal"};
  options.record_images = false;
  const RunResult result = runScenario(options);
  ASSERT_EQ(result.metrics.sources.count("ppa"), 1u);
  const eval::SourceMetrics& ppa = result.metrics.sources.at("ppa");
  EXPECT_TRUE(ppa.initialised);
  EXPECT_GT(ppa.tracked_pct, 99.0);
  EXPECT_NEAR(ppa.truth_track_length_m, 150.0, 3.0);
  EXPECT_LT(ppa.mean_abs_error_m, 1.0);
  EXPECT_LT(ppa.end_point_pct, 0.5);
  EXPECT_NEAR(ppa.rate_hz, 200.0, 1.0);
}

// With target correction, the target by the start corner is found on every pass over it
// and leaves the position within 0.3 m.
TEST(Run, PpaTargetCorrectionOnEveryPass) {
  RunOptions options;
  options.scenario = "scamp-rectangle";
  options.out_dir = tempDir("ppa_target");
  options.overrides = {"route.repeat=1"};
  options.record_images = false;
  const RunResult result = runScenario(options);
  EXPECT_NE(result.table.find("target passes"), std::string::npos) << result.table;
  // target_passes.csv: target,start_s,end_s,frames,detections,error_before_m,error_after_m.
  std::istringstream csv(readFile((fs::path(result.out_dir) / "target_passes.csv").string()));
  std::string line;
  std::getline(csv, line);
  int passes = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    ASSERT_EQ(fields.size(), 7u) << line;
    ++passes;
    const int frames = std::stoi(fields[3]);
    EXPECT_GT(frames, 100) << line;
    EXPECT_EQ(std::stoi(fields[4]), frames) << line;
    ASSERT_FALSE(fields[6].empty()) << line;
    EXPECT_LT(std::stod(fields[6]), 0.3) << line;
  }
  // One lap passes the target as it starts and as it ends.
  EXPECT_EQ(passes, 2);
}

// The feature VO on half a minute of the demo flight (120 m AGL, 640x480 at 20 frames/s):
// it initialises, tracks and stays metric from the rangefinder.
TEST(Run, FeatureVoTracksTheDemoFlight) {
  RunOptions options;
  options.scenario = "default";
  options.out_dir = tempDir("vo_feature");
  options.overrides = {"duration_s=30", "vo_direct.enabled=false"};
  options.record_images = false;
  const RunResult result = runScenario(options);
  ASSERT_EQ(result.metrics.sources.count("vo_feature"), 1u);
  const eval::SourceMetrics& vo = result.metrics.sources.at("vo_feature");
  EXPECT_TRUE(vo.initialised);
  EXPECT_GT(vo.tracked_pct, 95.0);
  EXPECT_LT(vo.position_rmse_m, 5.0);
  EXPECT_LT(vo.rotation_rmse_deg, 1.0);
  EXPECT_LT(std::abs(vo.track_length_diff_pct), 3.0);
}

// The direct VO on 20 s of the demo flight, twice, with the navigation filter
// on it (GPS denied after 10 s): it tracks every frame, stays metric from the
// rangefinder, and its estimates on POSE_VO_DIRECT and the filter's on
// POSE_NAV and POSE_NAV_STATE are byte-identical between the runs. A third
// run with every node on the main thread (--serial) gives the VO the same
// messages, so it makes the same estimates.
TEST(Run, DirectVoTracksTheDemoFlightTheSameTwice) {
  std::vector<std::string> poses[3];
  std::vector<std::string> nav[3];
  for (int k = 0; k < 3; ++k) {
    RunOptions options;
    options.node_threads = k < 2;
    options.scenario = "default";
    options.out_dir = tempDir("vo_direct_" + std::to_string(k));
    options.overrides = {"duration_s=20", "vo_feature.enabled=false", "nav.enabled=true",
                         "nav.vo_channel=POSE_VO_DIRECT", "sensors.gps.denied_after_s=10"};
    options.record_images = false;
    const RunResult result = runScenario(options);
    ASSERT_EQ(result.metrics.sources.count("vo_direct"), 1u);
    const eval::SourceMetrics& vo = result.metrics.sources.at("vo_direct");
    if (k == 0) {
      EXPECT_TRUE(vo.initialised);
      EXPECT_GT(vo.tracked_pct, 99.0);
      EXPECT_LT(vo.position_rmse_m, 2.0);
      EXPECT_LT(vo.rotation_rmse_deg, 0.5);
      EXPECT_LT(std::abs(vo.track_length_diff_pct), 2.0);
    }
    if (k == 0) {
      ASSERT_EQ(result.metrics.sources.count("nav"), 1u);
      const eval::SourceMetrics& filter = result.metrics.sources.at("nav");
      ASSERT_TRUE(filter.filter.has_value());
      EXPECT_NEAR(filter.filter->denial_s, 10.0, 0.25);  // the last 5 Hz fix before 10 s
      EXPECT_LT(filter.position_rmse_m, 2.0);
    }
    core::LcmLogReader reader(result.log_path);
    while (auto event = reader.next()) {
      if (event->channel == "POSE_VO_DIRECT")
        poses[k].emplace_back(event->data.begin(), event->data.end());
      if (event->channel == "POSE_NAV" || event->channel == "POSE_NAV_STATE")
        nav[k].emplace_back(event->data.begin(), event->data.end());
    }
  }
  EXPECT_GT(poses[0].size(), 350u);  // 20 frames/s for 20 s
  EXPECT_TRUE(poses[0] == poses[1]) << "the estimates differ between the runs";
  EXPECT_TRUE(poses[0] == poses[2]) << "the estimates differ with the VO on the main thread";
  EXPECT_GT(nav[0].size(), 1900u);  // 50 Hz for 20 s, on two channels
  EXPECT_TRUE(nav[0] == nav[1]) << "the filter's output differs between the runs";
}

// A sweep file's grid: every combination, last axis fastest, named by its values.
TEST(Sweep, PlansTheGrid) {
  const std::string dir = tempDir("sweep_plan");
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "sweep.yaml").string();
  std::ofstream(path) << "scenario: thesis-oscillating\nout: " << dir
                      << "\njobs: 2\nset: [camera.fps=5]\naxes:\n"
                         "  vehicle.airspeed_mps: [10, 25]\n"
                         "  vehicle.max_roll_rate_dps: [25, 45, 65]\n"
                         "  vehicle.altitude_agl_m: [50, 100]\n";
  const SweepSpec spec = loadSweep(path);
  EXPECT_EQ(spec.jobs, 2);
  ASSERT_EQ(spec.axes.size(), 3u);
  const std::vector<SweepCell> cells = planSweep(spec);
  ASSERT_EQ(cells.size(), 12u);
  EXPECT_EQ(cells[0].values, (std::vector<std::string>{"10", "25", "50"}));
  EXPECT_EQ(cells[1].values, (std::vector<std::string>{"10", "25", "100"}));
  EXPECT_EQ(cells[11].values, (std::vector<std::string>{"25", "65", "100"}));
  EXPECT_EQ(fs::path(cells[1].out_dir).filename(),
            "cell_001_airspeed_mps=10_max_roll_rate_dps=25_altitude_agl_m=100");
}

// An axis of named variants: each cell takes its variant's overrides, and is
// named and tabulated by the variant's name; a variant that is not key=value
// is refused with its line.
TEST(Sweep, PlansNamedVariants) {
  const std::string dir = tempDir("sweep_variants");
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "sweep.yaml").string();
  std::ofstream(path) << "scenario: thesis-oscillating\nout: " << dir
                      << "\naxes:\n"
                         "  effect:\n"
                         "    ideal: []\n"
                         "    noise: [camera.read_noise_counts=2, "
                         "camera.shot_noise_electrons_per_count=10]\n"
                         "  vehicle.altitude_agl_m: [100, 300]\n";
  const SweepSpec spec = loadSweep(path);
  ASSERT_EQ(spec.axes.size(), 2u);
  EXPECT_EQ(spec.axes[0].values, (std::vector<std::string>{"ideal", "noise"}));
  EXPECT_TRUE(spec.axes[0].overrides(0).empty());
  EXPECT_EQ(spec.axes[0].overrides(1),
            (std::vector<std::string>{"camera.read_noise_counts=2",
                                      "camera.shot_noise_electrons_per_count=10"}));
  EXPECT_EQ(spec.axes[1].overrides(1), (std::vector<std::string>{"vehicle.altitude_agl_m=300"}));
  const std::vector<SweepCell> cells = planSweep(spec);
  ASSERT_EQ(cells.size(), 4u);
  EXPECT_EQ(fs::path(cells[3].out_dir).filename(), "cell_003_effect=noise_altitude_agl_m=300");
  EXPECT_NE(sweepMarkdown(spec, cells).find("| effect | vehicle.altitude_agl_m |"),
            std::string::npos);

  std::ofstream(path, std::ios::trunc) << "scenario: box\naxes:\n  effect:\n    blur: [on]\n";
  try {
    loadSweep(path);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":4: axes.effect.blur: expected key=value"),
              std::string::npos)
        << error.what();
  }
}

// A sweep file with an unknown key or an empty axis is refused with the line named.
TEST(Sweep, BadFilesAreRefused) {
  const std::string dir = tempDir("sweep_bad");
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "sweep.yaml").string();
  std::ofstream(path) << "scenario: box\naxis:\n  vehicle.airspeed_mps: [10]\n";
  try {
    loadSweep(path);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":2: axis: unknown key"), std::string::npos)
        << error.what();
  }
  std::ofstream(path, std::ios::trunc) << "scenario: box\naxes:\n  vehicle.airspeed_mps: []\n";
  EXPECT_THROW(loadSweep(path), core::ParamError);
  // A key given twice (found by fuzzing: a file of many "axes" took seconds to plan).
  std::ofstream(path, std::ios::trunc) << "scenario: box\naxes: {a.b: [1]}\naxes: {c.d: [2]}\n";
  try {
    loadSweep(path);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":3: axes: given twice"), std::string::npos)
        << error.what();
  }
  std::ofstream(path, std::ios::trunc) << "scenario: box\naxes:\n  a.b: [1]\n  a.b: [2]\n";
  try {
    loadSweep(path);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":4: axes.a.b: given twice"), std::string::npos)
        << error.what();
  }
}

// Found by fuzzing (fuzz/regressions/sweep): a '/' in an axis key or value
// put a cell's folder elsewhere than the sweep's. Cell folders keep letters,
// digits and ._+-=, anything else becomes '_', and stay under 200 bytes.
TEST(Sweep, CellFoldersStayInTheSweepsFolder) {
  const std::string dir = tempDir("sweep_folders");
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "sweep.yaml").string();
  std::ofstream(path) << "scenario: box\nout: " << dir
                      << "\naxes:\n"
                         "  vehicle./airspeed_mps: [10]\n"
                         "  camera.calibration_file: [../../etc/lens.yaml, \"a b\", "
                      << std::string(300, 'x') << "]\n";
  const std::vector<SweepCell> cells = planSweep(loadSweep(path));
  ASSERT_EQ(cells.size(), 3u);
  EXPECT_EQ(fs::path(cells[0].out_dir).filename(),
            "cell_000__airspeed_mps=10_calibration_file=.._.._etc_lens.yaml");
  EXPECT_EQ(fs::path(cells[1].out_dir).filename(),
            "cell_001__airspeed_mps=10_calibration_file=a_b");
  EXPECT_EQ(fs::path(cells[2].out_dir).filename().string().size(), 200u);
  for (const SweepCell& cell : cells) EXPECT_EQ(fs::path(cell.out_dir).parent_path(), dir);
}

// A sweep of more cells than anyone flies (ten axes of ten values: 10^10) and
// an axis of no named variants are refused before anything is planned.
TEST(Sweep, ImpossibleGridsAreRefused) {
  const std::string dir = tempDir("sweep_huge");
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "sweep.yaml").string();
  std::ofstream huge(path);
  huge << "scenario: box\naxes:\n";
  for (int axis = 0; axis < 10; ++axis) huge << "  a" << axis << ".x: [0,1,2,3,4,5,6,7,8,9]\n";
  huge.close();
  try {
    loadSweep(path);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what())
                  .find(path + ": axes: 10000000000 cells, more than a sweep plans (10000)"),
              std::string::npos)
        << error.what();
  }
  std::ofstream(path, std::ios::trunc) << "scenario: box\naxes:\n  effect: {}\n";
  try {
    loadSweep(path);
    FAIL() << "no error";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("axes.effect"), std::string::npos) << error.what();
  }
}

eval::SourceMetrics sourceMetrics(bool initialised, double position, double rotation,
                                  double tracked) {
  eval::SourceMetrics metrics{};
  metrics.initialised = initialised;
  metrics.position_rmse_m = position;
  metrics.rotation_rmse_deg = rotation;
  metrics.tracked_pct = tracked;
  return metrics;
}

// The results tables: one per value of the first axis, X where a source never initialised,
// the lowest error of a row in bold, a failed run marked, and one CSV row per cell.
TEST(Sweep, TablesLikeTheThesis) {
  SweepSpec spec;
  spec.scenario = "thesis-oscillating";
  spec.axes = {{"vehicle.airspeed_mps", {"10", "25"}},
               {"vehicle.max_roll_rate_dps", {"25"}},
               {"vehicle.altitude_agl_m", {"50"}}};
  std::vector<SweepCell> cells = planSweep(spec);
  eval::RunMetrics metrics;
  metrics.truth_track_length_m = 3203.0;
  metrics.sources["vo_direct"] = sourceMetrics(true, 12.5, 3.25, 97.0);
  metrics.sources["vo_direct"].resets = 2;
  metrics.sources["vo_feature"] = sourceMetrics(false, 0.0, 0.0, 0.0);
  metrics.sources["ppa"] = sourceMetrics(true, 20.0, 1.5, 100.0);
  metrics.sources["ppa"].resets = 0;
  cells[0].metrics = metrics;
  cells[1].error = "exit status 1";
  const std::string md = sweepMarkdown(spec, cells);
  EXPECT_NE(md.find("## vehicle.airspeed_mps = 10"), std::string::npos) << md;
  EXPECT_NE(md.find("## vehicle.airspeed_mps = 25"), std::string::npos) << md;
  // Columns in source order: ppa, vo_direct, vo_feature.
  // Resets: a count, "-" where not known.
  EXPECT_NE(md.find("| 25 | 50 | 3203.000 | 20.000 | **12.500** | X | **1.500** | 3.250 | X | "
                    "100.000 | 97.000 | 0.000 | 0 | 2 | - |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| 25 | 50 | failed |"), std::string::npos) << md;
  const std::string csv = sweepCsv(spec, cells);
  EXPECT_NE(csv.find("10,25,50,ok,3203.000,20.000,1.500,100.000,0,12.500,3.250,97.000,2,X,X,"
                     "0.000,-"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("25,25,50,failed,"), std::string::npos) << csv;
}

// --tabulate: the cells of a sweep that ran are read back from their
// metrics.json; a cell without one is named, not mistaken for a result.
TEST(Sweep, TablesFromTheCellsThatRan) {
  SweepSpec spec;
  spec.scenario = "default";
  spec.out_dir = tempDir("sweep_tabulate");
  spec.axes = {{"vehicle.altitude_agl_m", {"100", "200"}}};
  std::vector<SweepCell> planned = planSweep(spec);
  eval::RunMetrics metrics;
  metrics.truth_track_length_m = 500.0;
  metrics.truth_duration_s = 20.0;
  metrics.truth_poses = 2000;
  metrics.sources["vo_direct"] = sourceMetrics(true, 1.25, 0.5, 100.0);
  metrics.sources["vo_direct"].resets = 1;
  fs::create_directories(planned[0].out_dir);
  eval::writeMetricsJson((fs::path(planned[0].out_dir) / "metrics.json").string(), metrics,
                         eval::EvalOptions{});
  const std::vector<SweepCell> cells = readSweep(spec);
  ASSERT_EQ(cells.size(), 2u);
  ASSERT_TRUE(cells[0].metrics.has_value()) << cells[0].error;
  EXPECT_EQ(cells[0].metrics->sources.at("vo_direct").position_rmse_m, 1.25);
  EXPECT_EQ(cells[0].metrics->sources.at("vo_direct").resets, std::optional<std::size_t>(1));
  EXPECT_FALSE(cells[1].metrics.has_value());
  EXPECT_NE(cells[1].error.find("metrics.json does not exist"), std::string::npos)
      << cells[1].error;
  EXPECT_NE(sweepMarkdown(spec, cells).find("| 100 | 500.000 | 1.250 | 0.500 | 100.000 | 1 |"),
            std::string::npos)
      << sweepMarkdown(spec, cells);
}

// A filter's figures get their columns in results.csv, empty where a figure
// does not exist (a flight that ends before the denial + 120 s); a VO's do not.
TEST(Sweep, FilterFiguresInTheCsv) {
  SweepSpec spec;
  spec.scenario = "default";
  spec.out_dir = tempDir("sweep_filter");
  spec.axes = {{"vehicle.altitude_agl_m", {"100"}}};
  const std::vector<SweepCell> planned = planSweep(spec);
  eval::RunMetrics metrics;
  metrics.truth_track_length_m = 500.0;
  metrics.sources["vo_feature"] = sourceMetrics(true, 2.5, 0.2, 100.0);
  metrics.sources["nav"] = sourceMetrics(true, 0.75, 0.125, 100.0);
  eval::FilterMetrics filter;
  filter.error_denial_60_m = 1.5;
  filter.error_end_m = 1.25;
  filter.nees_position_mean = 2.5;
  filter.nees_attitude_mean = 3.25;
  metrics.sources["nav"].filter = filter;
  fs::create_directories(planned[0].out_dir);
  eval::writeMetricsJson((fs::path(planned[0].out_dir) / "metrics.json").string(), metrics,
                         eval::EvalOptions{});
  const std::string csv = sweepCsv(spec, readSweep(spec));
  EXPECT_NE(csv.find("nav.resets,nav.error_denial_60_m,nav.error_denial_120_m,nav.error_end_m,"
                     "nav.nees_position_mean,nav.nees_attitude_mean,vo_feature.position_rmse_m"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",1.500,,1.250,2.500,3.250,2.500,"), std::string::npos) << csv;
  EXPECT_EQ(csv.find("vo_feature.nees"), std::string::npos) << csv;
}

// Live: the nodes start as processes, the scenario ends, every node stops cleanly, the
// recording holds the truth and the camera, and the scenario and the charts lie beside
// it. Needs UDP multicast (skipped without it).
TEST(Launch, FliesAndStopsCleanly) {
  const std::string dir = tempDir("launch");
  LaunchOptions options;
  options.scenario = "default";
  options.out_dir = dir;
  // A bus of its own: a second simulator on one bus is refused.
  options.overrides = {"duration_s=2", "camera.width=160", "camera.height=120",
                       "bus.url=udpm://239.255.76.67:7873?ttl=0"};
  options.bin_dir = NADIR_BIN_DIR;
  options.report_period_s = 1.0;
  std::atomic<bool> stop{false};
  std::ostringstream out;
  const int status = launchScenario(options, out, stop);
  const std::string recording = (fs::path(dir) / "launch.lcmlog").string();
  if (!fs::exists(recording) || fs::file_size(recording) == 0) {
    GTEST_SKIP() << "UDP multicast does not reach this process here (see nadir doctor)\n"
                 << out.str();
  }
  EXPECT_EQ(status, 0) << out.str();
  EXPECT_NE(out.str().find("the scenario has ended"), std::string::npos) << out.str();
  // What arrived is what was sent: the nodes' last heartbeats against the recording
  // (launch waits for it, however loaded the machine), and the simulator's 2 s at
  // 400 Hz from 0 s, ends included.
  EXPECT_NE(out.str().find("the recording holds every message the nodes said they sent"),
            std::string::npos)
      << out.str();
  std::map<std::string, int> counts;
  core::LcmLogReader reader(recording);
  while (auto event = reader.next()) ++counts[event->channel];
  EXPECT_EQ(counts["POSE_TRUTH"], 2 * 400 + 1) << out.str();
  EXPECT_GT(counts["CAMERA_DOWN"], 0) << out.str();
  EXPECT_GT(counts["NADIR_HEARTBEAT"], 0) << out.str();
  // Beside the recording: the effective scenario (the viewers' terrain) and the charts.
  const nodes::ScenarioParams written =
      nodes::loadScenario((fs::path(dir) / "scenario.yaml").string());
  EXPECT_EQ(written.camera.camera.width, 160);
  EXPECT_NE(out.str().find("launch: charts in"), std::string::npos) << out.str();
  EXPECT_GT(fs::file_size(fs::path(dir) / "plots" / "top_view.png"), 10000u);
  EXPECT_TRUE(fs::exists(fs::path(dir) / "plots" / "results.csv"));
}

// A node that dies is reported with its exit status and stops the launch with status 1.
TEST(Launch, ADeadNodeIsReported) {
  const std::string dir = tempDir("launch_dead");
  const fs::path bin = fs::path(dir) / "bin";
  fs::create_directories(bin);
  // The real camera, which comes up (its heartbeat), then fails once the simulator
  // has started (its log exists beside the camera's); the real simulator.
  std::ofstream(bin / "nadir-camera")
      << "#!/bin/sh\n"
         "dir=$(dirname \"$(readlink /proc/$$/fd/1)\")\n"
      << "'" << (fs::path(NADIR_BIN_DIR) / "nadir-camera").string() << "' \"$@\" &\n"
      << "camera=$!\n"
         "until [ -e \"$dir/sim.log\" ]; do sleep 0.1; done\n"
         "kill -9 $camera\n"
         "exit 3\n";
  fs::permissions(bin / "nadir-camera", fs::perms::owner_all);
  fs::create_symlink(fs::path(NADIR_BIN_DIR) / "nadir-sim", bin / "nadir-sim");
  fs::create_symlink(fs::path(NADIR_BIN_DIR) / "nadir", bin / "nadir");  // the logger
  LaunchOptions options;
  options.scenario = "default";
  options.out_dir = (fs::path(dir) / "out").string();
  options.overrides = {"duration_s=30", "vo_feature.enabled=false", "vo_direct.enabled=false",
                       "nav.enabled=false", "bus.url=udpm://239.255.76.67:7874?ttl=0"};
  options.bin_dir = bin.string();
  std::atomic<bool> stop{false};
  std::ostringstream out;
  EXPECT_EQ(launchScenario(options, out, stop), 1) << out.str();
  EXPECT_NE(out.str().find("nadir-camera died (exit status 3)"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("nadir-sim: "), std::string::npos) << out.str();
}

}  // namespace
}  // namespace nadir::run
