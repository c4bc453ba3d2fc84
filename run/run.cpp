#include "run/run.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include "core/bus.h"
#include "core/clock.h"
#include "core/lcm_log.h"
#include "core/stage_times.h"
#include "core/worker_bus.h"
#include "lcmtypes/bus_io.h"
#include "nodes/camera/camera_node.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "nodes/sim/sim_node.h"
#include "nodes/sim/simulator.h"
#include "render/image_texture.h"
#include "run/process.h"
#include "run/track_plot.h"
#include "terrain/world.h"
#include "terrain/world_factory.h"

#include <opencv2/imgcodecs.hpp>

namespace nadir::run {
namespace {

namespace fs = std::filesystem;

// The files a run writes; an earlier run's are not overwritten without force.
constexpr const char* kLogName = "run.lcmlog";
constexpr const char* kMetricsName = "metrics.json";
constexpr const char* kScenarioName = "scenario.yaml";
constexpr const char* kStageTimesName = "stage_times.txt";

// However a run ends, its stage timers stop with it.
struct StageTimesOff {
  StageTimesOff() = default;
  StageTimesOff(const StageTimesOff&) = delete;
  StageTimesOff& operator=(const StageTimesOff&) = delete;
  ~StageTimesOff() { core::enableStageTimes(false); }
};

std::string defaultOutDir(const std::string& scenario) {
  return (fs::path("out") / fs::path(scenario).stem()).string();
}

}  // namespace

RunResult runScenario(const RunOptions& options,
                      const std::function<void(const RunProgress&)>& on_progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  core::enableStageTimes(options.stage_times);
  core::clearStageTimes();
  const StageTimesOff stop_timing_at_the_end;
  nodes::ScenarioParams scenario = nodes::loadScenario(options.scenario, options.overrides);
  terrain::requireFlightWorld(scenario.world);
  // Everything stays in this process: the bus is in-process whatever the file says.
  scenario.bus.url = "memq://";
  // Byte-identical runs; set in the scenario so that scenario.yaml says what ran.
  for (const auto& entry : nodes::registry()) entry->makeDeterministic(scenario);

  RunResult result;
  result.out_dir = options.out_dir.empty() ? defaultOutDir(options.scenario) : options.out_dir;
  const fs::path out(result.out_dir);
  if (!options.force && (fs::exists(out / kLogName) || fs::exists(out / kMetricsName))) {
    throw std::runtime_error(result.out_dir + " already holds a run (" + kLogName +
                             "); choose another --out or pass --force to replace it");
  }
  fs::create_directories(out);
  result.log_path = (out / kLogName).string();
  result.metrics_path = (out / kMetricsName).string();
  writeEffectiveScenario(result.out_dir, "nadir run " + options.scenario, scenario);

  // The nodes the scenario runs besides the simulator, with their parameters:
  // the camera, then the processing nodes.
  std::vector<std::pair<const nodes::Entry*, core::AnyParams>> running_nodes;
  for (const auto& entry : nodes::registry()) {
    if (entry->info().role != nodes::EntryInfo::Role::kSimulator && entry->enabled(scenario)) {
      running_nodes.emplace_back(entry.get(), entry->fromScenario(scenario));
    }
  }

  auto bus = core::openBus(scenario.bus);
  core::LcmLogWriter log(result.log_path);
  // Every message is recorded at its own (sim) time, images unless left out.
  std::set<std::string> unrecorded;
  if (!options.record_images) {
    for (const auto& [entry, params] : running_nodes) {
      for (const nodes::Stream& stream : entry->streams(params)) {
        if (stream.bulky) unrecorded.insert(stream.channel);
      }
    }
  }
  // Event times are the messages' own plus the offset that puts the run's
  // sim time 0 on time.start_utc, so that LCM's tools show the scenario's
  // date; a replayed real flight's messages already carry theirs.
  const std::int64_t start_utime = sim::runStartUtime(scenario.time);
  std::optional<std::int64_t> event_offset_us;
  core::Subscription recorder = bus->subscribe(".*", [&](const core::RawMessage& raw) {
    const core::ScopedStage stage("record");
    ++result.totals.messages;
    const std::string channel(raw.channel);
    if (unrecorded.count(channel) != 0) return;
    const std::int64_t utime = core::peekUtime(raw).value_or(0);
    if (!event_offset_us) event_offset_us = sim::logEventOffset_us(start_utime, utime);
    log.write(utime + *event_offset_us, channel, raw.data, raw.size);
  });

  // The simulator and the camera make the world (the camera's world serves both);
  // the processing nodes come from the registry.
  const auto camera_params = std::find_if(
      running_nodes.begin(), running_nodes.end(),
      [](const auto& node) { return node.first->info().role == nodes::EntryInfo::Role::kCamera; });
  camera::CameraNode camera(*bus, camera_params->second.as<camera::CameraNodeParams>());
  // The main camera's last image, for a picture of what it saw, and its
  // texture from one frame a second of sim time.
  cv::Mat last_image;
  render::TextureMeter texture;
  std::optional<std::int64_t> last_measured_utime;
  camera.onFrame([&](const camera::CameraFrame& frame) {
    if (frame.spec->channel != scenario.camera.channel) return;
    last_image = frame.rendered.image;
    const std::int64_t utime = frame.rendered.utime;
    if (!last_measured_utime || utime - *last_measured_utime >= 1'000'000) {
      const core::ScopedStage stage("texture");
      texture.add(frame.rendered.image);
      last_measured_utime = utime;
    }
  });
  const core::LocalNedFrame frame(camera.scene().built.origin);
  sim::Simulator simulator(scenario.sim, camera.scene().built.world, frame,
                           sim::loadFlight(scenario.sim.flight, frame));
  sim::SimPublisher publisher(*bus, scenario.sim, simulator);
  sim::DriveCommandInput drive_commands(*bus, scenario.sim, simulator);
  sim::GuidanceInput guidance(*bus, scenario.sim, simulator);
  // A node that takes camera frames works on its own thread.
  std::vector<std::unique_ptr<core::WorkerBus>> worker_buses;
  std::vector<std::unique_ptr<nodes::Node>> running;
  for (const auto& [entry, params] : running_nodes) {
    if (entry->info().role != nodes::EntryInfo::Role::kProcessing) continue;
    std::set<std::string> paced = entry->pacedChannels(params);
    if (options.node_threads && !paced.empty()) {
      worker_buses.push_back(std::make_unique<core::WorkerBus>(*bus, std::move(paced)));
      running.push_back(entry->start(*worker_buses.back(), params));
    } else {
      running.push_back(entry->start(*bus, params));
    }
  }
  // Everything the nodes have to do and say, delivered.
  const auto settle = [&] {
    do {
      for (const auto& worker : worker_buses) worker->sync();
    } while (bus->handle(std::chrono::milliseconds(0)) || bus->handleAvailable() > 0);
  };

  const auto flight_start = std::chrono::steady_clock::now();
  if (options.stage_times) {
    core::addStageTime("setup", std::chrono::duration<double>(flight_start - wall_start).count(),
                       1);
  }
  auto last_report = flight_start;
  const auto report = [&](bool force_report) {
    const auto now = std::chrono::steady_clock::now();
    if (!on_progress || (!force_report && now - last_report < std::chrono::milliseconds(500))) {
      return;
    }
    last_report = now;
    result.totals.wall_s = std::chrono::duration<double>(now - flight_start).count();
    result.totals.frames = camera.framesPublished();
    on_progress(result.totals);
  };
  result.totals.planned_s = scenario.sim.duration_s;
  while (!simulator.finished()) {
    sim::SimOutput output;
    {
      const core::ScopedStage stage("simulator");
      output = simulator.step();
    }
    result.totals.sim_s = core::secondsFromUtime(output.truth.utime - simulator.startUtime());
    {
      const core::ScopedStage stage("simulator publish");
      publisher.publish(output);
    }
    {
      // Deliver everything this step caused (images, estimates) before the next step.
      const core::ScopedStage stage("deliver");
      while (bus->handle(std::chrono::milliseconds(0))) {
      }
    }
    report(false);
  }
  {
    const core::ScopedStage stage("deliver");
    settle();
  }
  result.totals.frames = camera.framesPublished();
  report(true);
  {
    const core::ScopedStage stage("record");
    log.flush();
  }

  eval::EvalOptions eval_options;
  eval_options.tum_axes = options.tum_axes;
  std::optional<core::ScopedStage> evaluation_stage(std::in_place, "evaluation");
  const eval::RunEvaluation evaluation =
      eval::evaluateRunLog(result.log_path, out.string(), eval_options, scenario.sim.truth.channel);
  result.metrics = evaluation.metrics;
  result.metrics_path = evaluation.metrics_path;
  result.tum_paths = evaluation.tum_paths;
  result.picture_paths.push_back((out / "tracks.png").string());
  writeTrackPlot(result.picture_paths.back(), evaluation.recorded.truth, evaluation.tracked,
                 fs::path(options.scenario).stem().string() + ": top view");
  if (!last_image.empty()) {
    result.picture_paths.push_back((out / "last_frame.png").string());
    cv::imwrite(result.picture_paths.back(), last_image);
  }
  result.table = eval::formatResultsTable(result.metrics);
  if (texture.result().frames > 0)
    result.table += "camera " + render::formatTexture(texture.result()) + "\n";
  std::optional<logs::CourseMetrics> course;
  const nodes::BatchReportInput report_input{
      scenario, result.log_path, evaluation.recorded, result.out_dir, *camera.scene().built.world,
      &course};
  for (const auto& [entry, params] : running_nodes) {
    const core::ScopedStage stage("node reports");
    const std::string section = entry->batchReport(report_input, params);
    if (!section.empty()) result.table += "\n" + section;
  }
  if (course) {
    result.metrics.course = course;
    eval::writeMetricsJson(result.metrics_path, result.metrics, eval::EvalOptions{});
  }
  evaluation_stage.reset();
  if (options.stage_times) {
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    result.stage_times = core::formatStageTimes(core::stageTimes(), wall_s,
                                                static_cast<std::int64_t>(result.totals.frames));
    result.stage_times += "wall time " + std::to_string(wall_s) + " s, " +
                          std::to_string(result.totals.frames) + " frames\n";
    std::ofstream(out / kStageTimesName) << result.stage_times;
  }
  return result;
}

void writeEffectiveScenario(const std::string& dir, const std::string& command,
                            nodes::ScenarioParams& scenario) {
  std::ofstream(fs::path(dir) / kScenarioName) << "# " << command << ": the effective scenario\n"
                                               << core::formatParamsOf(scenario);
}

RunPlots renderRunPlots(const std::string& run, const std::string& plots_dir,
                        const std::string& bin_dir) {
  RunPlots plots;
  const fs::path program = fs::path(bin_dir.empty() ? selfDirectory() : bin_dir) / "nadir-plot";
  if (!fs::exists(program)) {
    plots.problem = "no plots: " + program.string() + " is not built";
    return plots;
  }
  const fs::path out = plots_dir.empty() ? fs::path(run) / "plots" : fs::path(plots_dir);
  std::error_code error;
  fs::create_directories(out, error);
  if (error) {
    plots.problem = "no plots: cannot create " + out.string() + ": " + error.message();
    return plots;
  }
  ChildProcess plotter("nadir-plot", {program.string(), "--headless", run, "--out", out.string()},
                       (out / "nadir-plot.log").string());
  try {
    plotter.start();
  } catch (const std::exception& failure) {
    plots.problem = std::string("no plots: ") + failure.what();
    return plots;
  }
  while (plotter.running()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (plotter.exitStatus() != 0) {
    plots.problem =
        "no plots: nadir-plot ended with " + plotter.describeExit() + ", see " + plotter.logPath();
    return plots;
  }
  for (const auto& entry : fs::directory_iterator(out))
    if (entry.path().extension() == ".png") plots.png_paths.push_back(entry.path().string());
  std::sort(plots.png_paths.begin(), plots.png_paths.end());
  return plots;
}

}  // namespace nadir::run
