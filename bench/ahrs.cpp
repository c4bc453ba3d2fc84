// nadir-bench-ahrs: the flight controller's estimate (sensors.ahrs) against
// the truth over a scenario's flight, without rendering. Prints the RMS and
// largest roll, pitch and heading errors, over the whole flight and split
// into turning (|yaw rate| > 5 deg/s) and straight stretches, the position
// and velocity errors when the GPS is on, and the gyro bias estimate at the end. NAV_* are sampled
// as the simulator publishes them.
//
//   nadir-bench-ahrs thesis-oscillating [--set sensors.gps.enabled=false]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "core/command_line.h"
#include "core/frames.h"
#include "core/params.h"
#include "nodes/scenario.h"
#include "nodes/sim/sim_node.h"
#include "nodes/sim/simulator.h"
#include "terrain/world_factory.h"

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

struct ErrorStats {
  double sum2 = 0.0;
  double max = 0.0;
  std::size_t n = 0;
  void add(double e) {
    sum2 += e * e;
    max = std::max(max, std::fabs(e));
    ++n;
  }
  double rms() const { return n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0; }
};

struct AttitudeStats {
  ErrorStats roll, pitch, yaw;
};

void printRow(const char* name, const AttitudeStats& s, double seconds) {
  std::printf("%-9s %7.1f s  %6.3f / %6.3f  %6.3f / %6.3f  %6.3f / %6.3f\n", name, seconds,
              s.roll.rms(), s.roll.max, s.pitch.rms(), s.pitch.max, s.yaw.rms(), s.yaw.max);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The flight controller's attitude and position estimate against the truth"};
  std::string scenario_name;
  std::vector<std::string> overrides;
  app.add_option("scenario", scenario_name, "a built-in scenario or a YAML path")->required();
  app.add_option("--set", overrides, "override a scenario parameter: key=value (repeatable)");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  try {
    const nadir::nodes::ScenarioParams scenario =
        nadir::nodes::loadScenario(scenario_name, overrides);
    const nadir::terrain::BuiltWorld built = nadir::terrain::makeWorld(scenario.world);
    const nadir::core::LocalNedFrame frame(built.origin);
    nadir::sim::Simulator simulator(scenario.sim, built.world, frame,
                                    nadir::sim::loadFlight(scenario.sim.flight, frame));
    AttitudeStats all, turning, straight;
    ErrorStats position_h, position_v, velocity;
    double turning_s = 0.0, straight_s = 0.0, end_s = 0.0;
    const double nav_period_s = 1.0 / scenario.sim.truth.nav_rate_hz;
    while (!simulator.finished()) {
      const nadir::sim::SimOutput out = simulator.step();
      if (!out.nav) continue;
      const nadir::core::RollPitchYaw truth =
          nadir::core::rpyFromQuaternion(out.truth.q_world_body);
      const nadir::msg::Attitude& estimate = out.nav->attitude;
      const double e_roll = nadir::core::wrapAngle_rad(estimate.roll_rad - truth.roll_rad);
      const double e_pitch = estimate.pitch_rad - truth.pitch_rad;
      const double e_yaw = nadir::core::wrapAngle_rad(estimate.yaw_rad - truth.yaw_rad);
      const Eigen::Vector3d omega_ned = out.truth.q_world_body * out.truth.omega_body_rps;
      const bool is_turning = std::fabs(omega_ned.z()) * kDeg > 5.0;
      for (AttitudeStats* s : {&all, is_turning ? &turning : &straight}) {
        s->roll.add(e_roll * kDeg);
        s->pitch.add(e_pitch * kDeg);
        s->yaw.add(e_yaw * kDeg);
      }
      (is_turning ? turning_s : straight_s) += nav_period_s;
      const Eigen::Vector3d p = frame.nedFromGeodetic(
          {out.nav->position.lat_rad, out.nav->position.lon_rad, out.nav->position.alt_m});
      position_h.add((p - out.truth.p_ned_m).head<2>().norm());
      position_v.add(p.z() - out.truth.p_ned_m.z());
      velocity.add((out.nav->velocity.v_ned_mps - out.truth.v_ned_mps).norm());
      end_s = static_cast<double>(out.truth.utime - simulator.startUtime()) * 1e-6;
    }
    const nadir::sim::SensorsParams& sensors = scenario.sim.sensors;
    std::printf("scenario  %s, %.1f s; estimator %s; GPS %s\n", scenario_name.c_str(), end_s,
                sensors.ahrs.estimator.c_str(), sensors.gps.enabled ? "on" : "off");
    std::printf("attitude error, deg: RMS / largest\n");
    std::printf("%-9s %9s  %15s  %15s  %15s\n", "", "time", "roll", "pitch", "heading");
    printRow("all", all, turning_s + straight_s);
    printRow("turning", turning, turning_s);
    printRow("straight", straight, straight_s);
    std::printf(
        "position error, m: horizontal RMS %.2f (largest %.2f), vertical RMS %.2f "
        "(largest %.2f); velocity RMS %.3f m/s%s\n",
        position_h.rms(), position_h.max, position_v.rms(), position_v.max, velocity.rms(),
        sensors.gps.enabled ? "" : " (without GPS NAV_POSITION/VELOCITY are the truth)");
    if (simulator.estimator()) {
      std::printf("gyro bias estimate at the end, deg/s: %.4f %.4f %.4f\n",
                  simulator.estimator()->gyroBias_rps().x() * kDeg,
                  simulator.estimator()->gyroBias_rps().y() * kDeg,
                  simulator.estimator()->gyroBias_rps().z() * kDeg);
    }
  } catch (const nadir::core::ParamError& error) {
    std::cerr << "nadir-bench-ahrs: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "nadir-bench-ahrs: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
