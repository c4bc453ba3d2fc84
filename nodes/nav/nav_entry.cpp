// The navigation filter's registry entry: its scenario group, with the
// scenario's sensor figures and origin copied in when it asks for them.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "nodes/nav/nav_node.h"
#include "nodes/nav/nav_process_params.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"

namespace nadir::nodes {
namespace {

using nav::NavProcessParams;

class NavLiveNode final : public Node {
 public:
  NavLiveNode(core::Bus& bus, const NavProcessParams& params)
      : node_(bus, params.node, nav::groundDownOf(params)) {}

  std::string summary() const override {
    const nav::NavCounts& counts = node_.counts();
    std::ostringstream out;
    out << counts.imu << " IMU samples; fused " << counts.gps << " GPS, " << counts.baro
        << " baro, " << counts.range << " range, " << counts.mag << " mag, " << counts.vo << " VO ("
        << counts.vo_restarts << " chain starts); refused " << counts.refused << ", late "
        << node_.late();
    if (const nav::ErrorStateFilter* filter = node_.filter()) {
      const auto& P = filter->covariance();
      out << "; position sigma " << std::sqrt(P.block<3, 3>(nav::idx::kP, nav::idx::kP).trace())
          << " m";
    }
    if (counts.dropped > 0)
      out << "; dropped " << counts.dropped << " messages, the first: " << node_.firstDropReason();
    return out.str();
  }

 private:
  nav::NavNode node_;
};

class NavEntry final : public TypedEntry<NavProcessParams> {
 public:
  NavEntry()
      : TypedEntry({.name = nav::kNavSourceName,
                    .program = "nadir-nav",
                    .description = "navigation filter: IMU, barometer, rangefinder, GPS, "
                                   "magnetometer and a VO node fused over LCM",
                    .default_scenario = "thesis-oscillating",
                    .role = EntryInfo::Role::kProcessing}) {}

  std::optional<core::AnyParams> scenarioGroup() const override {
    return core::AnyParams(nav::NavNodeParams{});
  }
  std::string scenarioGroupDoc() const override { return "the navigation filter (nadir-nav)"; }
  bool enabled(const ScenarioParams& scenario) const override {
    return scenario.node<nav::NavNodeParams>(info().name).enabled;
  }

 protected:
  NavProcessParams paramsFrom(const ScenarioParams& scenario) const override {
    NavProcessParams process;
    process.world = scenario.world;
    nav::NavNodeParams& params = process.node;
    params = scenario.node<nav::NavNodeParams>(info().name);
    if (!params.match_scenario_sensors) return process;
    const core::Geodetic origin = scenarioOrigin(scenario);
    constexpr double kRadToDeg = 180.0 / std::numbers::pi;
    params.origin_lat_deg = origin.lat_rad * kRadToDeg;
    params.origin_lon_deg = origin.lon_rad * kRadToDeg;
    params.origin_alt_m = origin.alt_m;
    const sim::SensorsParams& sensors = scenario.sim.sensors;
    nav::NavSensorModel& model = params.sensors;
    model.gyro_noise_density_rps_rthz = sensors.imu.model.gyro_noise_density_rps_rthz;
    model.accel_noise_density_mps2_rthz = sensors.imu.model.accel_noise_density_mps2_rthz;
    model.gyro_bias_random_walk_rps_rts = sensors.imu.model.gyro_bias_random_walk_rps_rts;
    model.accel_bias_random_walk_mps2_rts = sensors.imu.model.accel_bias_random_walk_mps2_rts;
    model.baro_sigma_m = sensors.barometer.model.noise_sigma_m;
    model.baro_bias_random_walk_m_rts = sensors.barometer.model.bias_random_walk_m_rts;
    // The flat ground's own error stays the filter's: the sensor's noise is a floor.
    model.range_sigma_m = std::max(model.range_sigma_m, sensors.rangefinder.model.noise_sigma_m);
    model.gps_velocity_sigma_mps = sensors.gps.model.velocity_sigma_mps;
    model.declination_deg = sensors.magnetometer.model.declination_deg;
    model.inclination_deg = sensors.magnetometer.model.inclination_deg;
    model.field_ut = sensors.magnetometer.model.field_ut;
    // The heading's white noise: the sensor's across the field's horizontal part.
    const double horizontal_ut =
        model.field_ut * std::cos(model.inclination_deg * std::numbers::pi / 180.0);
    if (horizontal_ut > 0.0)
      model.heading_sigma_deg =
          std::atan2(sensors.magnetometer.model.noise_sigma_ut, horizontal_ut) * kRadToDeg;
    return process;
  }
  std::unique_ptr<Node> build(core::Bus& bus, const NavProcessParams& params) const override {
    return std::make_unique<NavLiveNode>(bus, params);
  }
  std::vector<Stream> publishes(const NavProcessParams& params) const override {
    return {{.channel = params.node.pose_channel, .rate_hz = params.node.publish_rate_hz},
            {.channel = params.node.state_channel, .rate_hz = params.node.publish_rate_hz}};
  }
};

}  // namespace

std::unique_ptr<Entry> navEntry() { return std::make_unique<NavEntry>(); }

}  // namespace nadir::nodes
