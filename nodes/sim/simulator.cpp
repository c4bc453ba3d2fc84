#include "nodes/sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/clock.h"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

}  // namespace

ResolvedRoute resolveRoute(const SimParams& params, const terrain::World& world,
                           const core::LocalNedFrame& frame) {
  const RouteParams& route = params.route;
  if (route.waypoints.empty()) {
    throw core::ParamError("route.waypoints: no waypoints to fly (and no flight.path to replay)");
  }
  if (!route.leg_speeds_mps.empty() && route.leg_speeds_mps.size() != route.waypoints.size()) {
    throw core::ParamError("route.leg_speeds_mps: " + std::to_string(route.leg_speeds_mps.size()) +
                           " speeds for " + std::to_string(route.waypoints.size()) +
                           " waypoints (give one per waypoint, or none)");
  }
  ResolvedRoute resolved;
  const double start_ground_m = world.groundUp_m(params.start.north_m, params.start.east_m);
  const double start_height_m =
      params.start.at_mission_altitude ? params.vehicle.altitude_agl_m : params.start.height_agl_m;
  resolved.start_ned_m = {params.start.north_m, params.start.east_m,
                          -(start_ground_m + start_height_m)};
  std::vector<Waypoint> once;
  for (std::size_t i = 0; i < route.waypoints.size(); ++i) {
    const std::vector<double>& row = route.waypoints[i];
    Eigen::Vector2d ne;
    if (route.frame == "start") {
      ne = {params.start.north_m + row[0], params.start.east_m + row[1]};
    } else if (route.frame == "ned") {
      ne = {row[0], row[1]};
    } else {
      if (std::abs(row[0]) > 90.0) {
        throw core::ParamError("route.waypoints[" + std::to_string(i) + "]: latitude " +
                               std::to_string(row[0]) + " deg is outside [-90, 90]");
      }
      const Eigen::Vector3d p =
          frame.nedFromGeodetic(core::geodeticFromDegrees(row[0], row[1], frame.origin().alt_m));
      ne = {p.x(), p.y()};
    }
    const double height_m = row.size() == 3 ? row[2] : params.vehicle.altitude_agl_m;
    const double ground_m =
        route.follow_terrain ? world.groundUp_m(ne.x(), ne.y()) : start_ground_m;
    const double speed_mps = route.leg_speeds_mps.empty() ? 0.0 : route.leg_speeds_mps[i];
    once.push_back({Eigen::Vector3d(ne.x(), ne.y(), -(ground_m + height_m)), speed_mps});
  }
  for (int lap = 0; lap < route.repeat; ++lap) {
    resolved.waypoints.insert(resolved.waypoints.end(), once.begin(), once.end());
  }
  resolved.start_heading_rad = params.start.heading_deg * kDeg;
  const Eigen::Vector3d to_first = resolved.waypoints.front().p_ned_m - resolved.start_ned_m;
  if (params.start.face_first_waypoint && to_first.head<2>().norm() > 1e-6) {
    resolved.start_heading_rad = std::atan2(to_first.y(), to_first.x());
  }
  return resolved;
}

Simulator::Simulator(const SimParams& params, std::shared_ptr<const terrain::World> world,
                     const core::LocalNedFrame& frame, std::optional<FlightReplay> flight)
    : params_(params), world_(std::move(world)), frame_(frame), flight_(std::move(flight)) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "simulation");
  const double step_s = 1.0 / params_.truth.rate_hz;
  step_us_ = std::max<std::int64_t>(1, core::utimeFromSeconds(step_s));
  const VehicleParams& vehicle = params_.vehicle;
  external_ = !flight_ && vehicle.control == "external";
  if (external_ && vehicle.kind != "rover") {
    throw core::ParamError(
        "vehicle.control: external control is for a rover (vehicle.kind: " + vehicle.kind + ")");
  }
  if (external_ && params_.duration_s <= 0.0) {
    throw core::ParamError(
        "duration_s: a rover under external control needs a duration (it has no route to end)");
  }
  if (flight_) {
    start_utime_ = flight_->startUtime();
  } else if (external_) {
    const double ground_m = world_->groundUp_m(params_.start.north_m, params_.start.east_m);
    route_.start_ned_m = {params_.start.north_m, params_.start.east_m, -ground_m};
    route_.start_heading_rad = params_.start.heading_deg * kDeg;
    RoverParams p = vehicle.rover;
    p.step_s = step_s;
    vehicle_.emplace<Rover>(p, route_.start_ned_m, route_.start_heading_rad);
  } else {
    route_ = resolveRoute(params_, *world_, frame_);
    try {
      if (vehicle.kind == "fixed_wing") {
        FixedWingParams p = vehicle.fixed_wing;
        p.step_s = step_s;
        vehicle_.emplace<FixedWing>(p, route_.start_ned_m, route_.start_heading_rad,
                                    route_.waypoints);
      } else if (vehicle.kind == "multirotor") {
        MultirotorParams p = vehicle.multirotor;
        p.step_s = step_s;
        vehicle_.emplace<Multirotor>(p, route_.start_ned_m, route_.start_heading_rad,
                                     route_.waypoints);
      } else {
        RoverParams p = vehicle.rover;
        p.step_s = step_s;
        vehicle_.emplace<Rover>(p, route_.start_ned_m, route_.start_heading_rad, route_.waypoints);
      }
    } catch (const std::invalid_argument& error) {
      throw core::ParamError("route.waypoints: " + std::string(error.what()));
    }
  }
  utime_ = start_utime_;
  start_altitude_m_ = frame_.geodeticFromNed(currentState().p_ned_m).alt_m;

  const SensorsParams& sensors = params_.sensors;
  if (sensors.imu.enabled) imu_.emplace(sensors.imu.model);
  if (sensors.rangefinder.enabled) rangefinder_.emplace(sensors.rangefinder.model);
  if (sensors.gps.enabled) gps_.emplace(sensors.gps.model, start_utime_);
  if (sensors.barometer.enabled) barometer_.emplace(sensors.barometer.model);
  if (sensors.magnetometer.enabled) magnetometer_.emplace(sensors.magnetometer.model);
  if (!sensors.ahrs.ideal()) {
    if (!sensors.imu.enabled || !sensors.magnetometer.enabled) {
      throw core::ParamError(
          "sensors.ahrs.estimator: complementary needs sensors.imu.enabled and "
          "sensors.magnetometer.enabled (or set sensors.ahrs.estimator: ideal)");
    }
    estimator_.emplace(sensors.ahrs, frame_);
  }
}

NavMessages Simulator::navMessages(const VehicleState& truth) const {
  NavMessages nav = toNavMessages(truth, frame_, start_altitude_m_);
  if (!estimator_) return nav;
  VehicleState estimate = truth;
  estimate.q_world_body = estimator_->q_world_body();
  estimate.omega_body_rps = estimator_->rates_body_rps();
  if (gps_ && estimator_->hasPosition()) {
    estimate.p_ned_m = estimator_->p_ned_m();
    estimate.v_ned_mps = estimator_->v_ned_mps();
  }
  return toNavMessages(estimate, frame_, start_altitude_m_);
}

VehicleState Simulator::currentState() const {
  if (flight_) return flight_->at(utime_);
  return std::visit(
      [this](const auto& vehicle) -> VehicleState {
        if constexpr (std::is_same_v<std::decay_t<decltype(vehicle)>, std::monostate>) {
          return {};
        } else {
          VehicleState state = vehicle.state();
          state.utime += start_utime_;
          return state;
        }
      },
      vehicle_);
}

bool Simulator::vehicleFinished() const {
  if (flight_) return utime_ >= flight_->endUtime();
  return std::visit(
      [](const auto& vehicle) {
        if constexpr (std::is_same_v<std::decay_t<decltype(vehicle)>, std::monostate>) {
          return true;
        } else {
          return vehicle.finished();
        }
      },
      vehicle_);
}

void Simulator::drive(const DriveInput& command) {
  if (!external_) throw std::logic_error("the simulator's vehicle is not under external control");
  const auto later = std::upper_bound(
      pending_commands_.begin(), pending_commands_.end(), command.utime,
      [](std::int64_t utime, const DriveInput& pending) { return utime < pending.utime; });
  pending_commands_.insert(later, command);
}

void Simulator::applyCommands() {
  auto due = pending_commands_.begin();
  while (due != pending_commands_.end() && due->utime <= utime_) ++due;
  if (due != pending_commands_.begin()) {
    applied_command_ = *(due - 1);
    pending_commands_.erase(pending_commands_.begin(), due);
  }
  Rover& rover = std::get<Rover>(vehicle_);
  const bool stale =
      !applied_command_ ||
      utime_ - applied_command_->utime > core::utimeFromSeconds(params_.vehicle.command_timeout_s);
  if (stale) {
    rover.command(applied_command_ ? applied_command_->steer_rad : 0.0, 0.0);
  } else {
    rover.command(applied_command_->steer_rad, applied_command_->speed_mps);
  }
  if (rover.speed_mps() > 0.0) {
    rover_moved_ = true;
    rover_still_since_ = -1;
  } else if (rover_still_since_ < 0) {
    rover_still_since_ = utime_;
  }
}

bool Simulator::guidanceOnSource(std::int64_t utime) const {
  const std::string& source = params_.guidance.source;
  if (source == "truth" || flight_ || external_) return false;
  if (source == "gps") return true;
  const double denied_s = params_.sensors.gps.model.denied_after_s;
  return denied_s < 0.0 || core::secondsFromUtime(utime - start_utime_) >= denied_s;
}

std::string Simulator::guidanceSource() const {
  return guidanceOnSource(utime_) && has_source_fix_ ? params_.guidance.source : "truth";
}

void Simulator::setPositionError(const Eigen::Vector3d& error_m) {
  position_error_m_ = error_m;
  std::visit(
      [&error_m](auto& vehicle) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(vehicle)>, std::monostate>) {
          vehicle.setPositionError(error_m);
        }
      },
      vehicle_);
}

std::size_t Simulator::vehicleNextWaypoint() const {
  return std::visit(
      [](const auto& vehicle) -> std::size_t {
        if constexpr (std::is_same_v<std::decay_t<decltype(vehicle)>, std::monostate>) {
          return 0;
        } else {
          return vehicle.nextWaypoint();
        }
      },
      vehicle_);
}

void Simulator::positionFix(std::int64_t utime, const Eigen::Vector3d& p_ned_m) {
  if (!guidanceOnSource(utime) || recent_truth_.empty() || !p_ned_m.allFinite()) return;
  if (utime < recent_truth_.front().first || utime > recent_truth_.back().first) return;
  const auto after = std::lower_bound(recent_truth_.begin(), recent_truth_.end(), utime,
                                      [](const std::pair<std::int64_t, Eigen::Vector3d>& sample,
                                         std::int64_t t) { return sample.first < t; });
  Eigen::Vector3d p_true = after->second;
  if (after != recent_truth_.begin() && after->first != utime) {
    const auto before = after - 1;
    const double share = static_cast<double>(utime - before->first) /
                         static_cast<double>(after->first - before->first);
    p_true = before->second + share * (after->second - before->second);
  }
  setPositionError(p_ned_m - p_true);
  has_source_fix_ = true;
}

bool Simulator::finished() const {
  if (!started_) return false;
  if (external_ && rover_moved_ && rover_still_since_ >= 0 &&
      utime_ - rover_still_since_ >= 1'000'000) {
    return true;
  }
  if (params_.duration_s > 0.0 &&
      utime_ - start_utime_ >= core::utimeFromSeconds(params_.duration_s)) {
    return true;
  }
  return vehicleFinished();
}

SimOutput Simulator::step() {
  const std::size_t heading_for = vehicleNextWaypoint();
  if (started_) {
    utime_ += step_us_;
    if (external_) applyCommands();
    std::visit(
        [](auto& vehicle) {
          if constexpr (!std::is_same_v<std::decay_t<decltype(vehicle)>, std::monostate>) {
            vehicle.step();
          }
        },
        vehicle_);
  }
  started_ = true;
  SimOutput out;
  out.truth = currentState();
  out.truth.utime = utime_;
  if (!flight_) {
    // Only a source's fixes need the truth of the recent past.
    if (params_.guidance.source != "truth") {
      recent_truth_.emplace_back(utime_, out.truth.p_ned_m);
      while (recent_truth_.front().first < utime_ - 5'000'000) recent_truth_.pop_front();
    }
    const std::size_t now_heading_for = vehicleNextWaypoint();
    if (!external_ && now_heading_for > heading_for && heading_for < route_.waypoints.size()) {
      WaypointEvent event;
      event.utime = utime_;
      event.index = static_cast<int>(heading_for);
      event.count = static_cast<int>(route_.waypoints.size());
      event.waypoint_ned_m = route_.waypoints[heading_for].p_ned_m;
      event.true_ned_m = out.truth.p_ned_m;
      event.believed_ned_m = out.truth.p_ned_m + position_error_m_;
      event.source = guidanceSource();
      out.waypoint = event;
    }
  }
  const std::int64_t t = utime_;
  if (imu_) {
    imu_->accumulate(out.truth);
    if (core::due(t, params_.sensors.imu.model.rate_hz, imu_due_))
      out.imu = imu_->sample(out.truth);
  }
  if (rangefinder_ && core::due(t, params_.sensors.rangefinder.model.rate_hz, range_due_)) {
    out.range = rangefinder_->sample(out.truth, *world_);
  }
  if (gps_ && core::due(t, params_.sensors.gps.model.rate_hz, gps_due_)) {
    out.gps = gps_->sample(out.truth, frame_);
  }
  if (barometer_ && core::due(t, params_.sensors.barometer.model.rate_hz, baro_due_)) {
    out.baro = barometer_->sample(out.truth, frame_);
  }
  if (magnetometer_ && core::due(t, params_.sensors.magnetometer.model.rate_hz, mag_due_)) {
    out.mag = magnetometer_->sample(out.truth);
  }
  if (estimator_) {
    if (out.imu) estimator_->addImu(*out.imu);
    if (out.mag) estimator_->addMagnetometer(*out.mag);
    if (out.gps) estimator_->addGps(*out.gps);
    if (out.baro) estimator_->addBaro(*out.baro);
  }
  if (params_.truth.nav_rate_hz > 0.0 && core::due(t, params_.truth.nav_rate_hz, nav_due_) &&
      (!estimator_ || estimator_->hasAttitude())) {
    out.nav = navMessages(out.truth);
  }
  return out;
}

}  // namespace nadir::sim
