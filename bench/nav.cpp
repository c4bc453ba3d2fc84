// nadir-bench-nav: the navigation filter over a recorded run's sensors, on one
// core, as fast as it goes. Reads RUN_DIR/run.lcmlog (any `nadir run`
// recording; images are not needed) and RUN_DIR/scenario.yaml (the filter's
// parameters, changed with --set), holds every message but the images in
// memory, then times them through the same NavNode as nadir run and the live
// node. Prints the speed against real time and the run's figures; the truth
// and the filter's output go to OUT/run.lcmlog with metrics.json.
//
//   nadir run thesis-oscillating --set vehicle.altitude_agl_m=300 --no-images --out out/cell
//   nadir-bench-nav out/cell [--out DIR] [--gps-denied-after-s 50] [--set nav.use_mag=false]
//
// --gps-denied-after-s S leaves out the GPS fixes from S seconds of sim time
// on: the denial of sensors.gps.denied_after_s, applied to a recording made
// without it.

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "bench/vo_replay.h"
#include "core/command_line.h"
#include "core/lcm_log.h"
#include "logs/eval/run_metrics.h"
#include "nodes/nav/nav_node.h"
#include "nodes/nav/nav_process_params.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"

int main(int argc, char** argv) {
  CLI::App app{"The navigation filter over a recorded run's sensors: speed and accuracy"};
  std::string run_dir;
  std::string out_dir;
  std::vector<std::string> overrides;
  double gps_denied_after_s = -1.0;
  int rounds = 1;
  app.add_option("run_dir", run_dir, "a nadir run folder")->required();
  app.add_option("--out", out_dir, "where the output and metrics go (default RUN_DIR/bench-nav)");
  app.add_option("--set", overrides, "override a scenario parameter: key=value (repeatable)");
  app.add_option("--gps-denied-after-s", gps_denied_after_s,
                 "leave out GPS fixes from this sim time on, s (-1: keep all)");
  app.add_option("--rounds", rounds, "time the filter this many times (the best is printed)")
      ->check(CLI::Range(1, 100));
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;

  try {
    const nadir::bench::RunFolder folder = nadir::bench::openRunFolder(
        run_dir,
        out_dir.empty() ? (std::filesystem::path(run_dir) / "bench-nav").string() : out_dir);
    overrides.insert(overrides.begin(), "nav.enabled=true");
    const nadir::nodes::ScenarioParams scenario =
        nadir::nodes::loadScenario(folder.scenario.string(), overrides);
    // The node's group with the scenario's sensor figures and world, as nadir run gives them.
    const auto process = nadir::nodes::entry(nadir::nav::kNavSourceName)
                             .fromScenario(scenario)
                             .as<nadir::nav::NavProcessParams>();
    const nadir::nav::NavNodeParams& params = process.node;
    const nadir::nav::GroundDown ground_down = nadir::nav::groundDownOf(process);

    // Every message the filter may read, in memory, so that the log's reading is not timed.
    std::vector<nadir::core::LogEvent> events;
    {
      nadir::core::LcmLogReader reader(folder.log.string());
      const std::int64_t denied_utime =
          gps_denied_after_s >= 0.0 ? std::llround(gps_denied_after_s * 1e6) : INT64_MAX;
      for (auto event = reader.next(); event; event = reader.next()) {
        const std::string& channel = event->channel;
        const bool wanted = channel == params.imu_channel || channel == params.baro_channel ||
                            channel == params.range_channel || channel == params.mag_channel ||
                            channel == params.vo_channel || channel == params.truth_channel ||
                            channel == params.gps_channel;
        if (!wanted) continue;
        // The message's own (sim) time: a log's event times may count from a date.
        const nadir::core::RawMessage raw{channel, event->data.data(), event->data.size(), 0};
        if (channel == params.gps_channel &&
            nadir::core::peekUtime(raw).value_or(event->timestamp_utime) >= denied_utime) {
          continue;
        }
        events.push_back(std::move(*event));
      }
    }
    if (events.empty()) throw std::runtime_error(folder.log.string() + " holds no sensor message");
    const double sim_s =
        1e-6 * static_cast<double>(events.back().timestamp_utime - events.front().timestamp_utime);

    double best_s = 1e300;
    for (int round = 0; round < rounds; ++round) {
      nadir::core::BusParams bus_params;
      bus_params.url = "memq://";
      auto bus = nadir::core::openBus(bus_params);
      const bool record = round == rounds - 1;
      std::unique_ptr<nadir::core::LcmLogWriter> writer;
      nadir::core::Subscription recorder;
      if (record) {
        writer = std::make_unique<nadir::core::LcmLogWriter>((folder.out / "run.lcmlog").string());
        recorder = bus->subscribe(
            params.truth_channel + "|" + params.pose_channel + "|" + params.state_channel,
            [&writer](const nadir::core::RawMessage& raw) {
              writer->write(nadir::core::peekUtime(raw).value_or(0), std::string(raw.channel),
                            raw.data, raw.size);
            });
      }
      nadir::nav::NavNode node(*bus, params, ground_down);
      const auto start = std::chrono::steady_clock::now();
      for (const nadir::core::LogEvent& event : events) {
        bus->publish(event.channel, event.data.data(), event.data.size(), event.timestamp_utime);
        bus->handleAvailable();
      }
      best_s = std::min(
          best_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      if (record) {
        writer->flush();
        const nadir::nav::NavCounts& counts = node.counts();
        std::printf(
            "fused             %llu IMU samples; %llu GPS, %llu baro, %llu range, %llu mag, "
            "%llu VO (%llu chain starts); refused %llu, late %lld, dropped %llu\n",
            static_cast<unsigned long long>(counts.imu),
            static_cast<unsigned long long>(counts.gps),
            static_cast<unsigned long long>(counts.baro),
            static_cast<unsigned long long>(counts.range),
            static_cast<unsigned long long>(counts.mag), static_cast<unsigned long long>(counts.vo),
            static_cast<unsigned long long>(counts.vo_restarts),
            static_cast<unsigned long long>(counts.refused), static_cast<long long>(node.late()),
            static_cast<unsigned long long>(counts.dropped));
      }
    }
    std::printf("messages          %zu over %.1f s of sim time\n", events.size(), sim_s);
    std::printf(
        "speed             %.3f s for the flight (best of %d): %.0f x real time on one core\n",
        best_s, rounds, sim_s / best_s);

    const nadir::eval::RunEvaluation evaluation =
        nadir::eval::evaluateRunLog((folder.out / "run.lcmlog").string(), folder.out.string(),
                                    nadir::eval::EvalOptions{}, params.truth_channel);
    std::cout << "\n" << nadir::eval::formatResultsTable(evaluation.metrics);
  } catch (const std::exception& error) {
    std::cerr << "nadir-bench-nav: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
