#include "nodes/sim/sim_params.h"

#include <stdexcept>
#include <string>

#include "core/utc_time.h"

namespace nadir::sim {

void VehicleParams::visit(core::ParamVisitor& v) {
  v.field(
      "kind", &kind,
      {.doc = "fixed_wing, multirotor or rover", .choices = {"fixed_wing", "multirotor", "rover"}});
  v.field("control", &control,
          {.doc = "route (its own guidance on route.waypoints) or external (rover: obeys "
                  "drive_command_t on command_channel)",
           .choices = {"route", "external"}});
  v.field("command_channel", &command_channel,
          {.doc = "control external: the drive_command_t channel"});
  v.field("command_timeout_s", &command_timeout_s,
          {.doc = "control external: brake to a stop when the newest command is older, s",
           .min = 0.001,
           .max = 3600});
  v.field("altitude_agl_m", &altitude_agl_m,
          {.doc = "mission altitude above the start's ground, m", .min = 0, .max = 20000});
  fixed_wing.visit(v);
  core::visitGroup(v, "multirotor", "multirotor (kind: multirotor)", multirotor);
  core::visitGroup(v, "rover", "ground rover (kind: rover)", rover);
}

void StartParams::visit(core::ParamVisitor& v) {
  v.field("north_m", &north_m, {.doc = "start, world frame north, m", .min = -1e6, .max = 1e6});
  v.field("east_m", &east_m, {.doc = "start, world frame east, m", .min = -1e6, .max = 1e6});
  v.field("height_agl_m", &height_agl_m,
          {.doc = "start height above the ground, m", .min = 0, .max = 20000});
  v.field("at_mission_altitude", &at_mission_altitude,
          {.doc = "start at vehicle.altitude_agl_m (ignores height_agl_m)"});
  v.field("heading_deg", &heading_deg,
          {.doc = "initial heading from north, deg", .min = -360, .max = 360});
  v.field("face_first_waypoint", &face_first_waypoint,
          {.doc = "start heading towards the first waypoint (ignores heading_deg)"});
}

void RouteParams::visit(core::ParamVisitor& v) {
  v.field("frame", &frame,
          {.doc = "waypoints as start ([n, e] from the start), ned ([n, e]) or geodetic "
                  "([lat, lon] deg); optional third value: height, m",
           .choices = {"start", "ned", "geodetic"}});
  v.field("waypoints", &waypoints,
          {.doc = "waypoints, [a, b] or [a, b, height_m]",
           .min = -1e7,
           .max = 1e7,
           .row_sizes = {2, 3}});
  v.field(
      "leg_speeds_mps", &leg_speeds_mps,
      {.doc = "speed on the leg to each waypoint, m/s; 0 or [] = cruise", .min = 0, .max = 300});
  v.field("repeat", &repeat, {.doc = "fly the waypoints this many times", .min = 1, .max = 1000});
  v.field("follow_terrain", &follow_terrain,
          {.doc = "heights above each waypoint's ground instead of the start's"});
}

void FlightParams::visit(core::ParamVisitor& v) {
  v.field("path", &path, {.doc = "recorded flight to replay as truth; empty: fly the route"});
  v.field("format", &format,
          {.doc = "auto, tum, csv or lcm", .choices = {"auto", "tum", "csv", "lcm"}});
  v.field("pose_channel", &pose_channel, {.doc = "LCM log: pose_t channel"});
  v.field("position_channel", &position_channel,
          {.doc = "LCM log without poses: geodetic_position_t channel"});
  v.field("attitude_channel", &attitude_channel,
          {.doc = "LCM log without poses: attitude_t channel"});
}

void TruthParams::visit(core::ParamVisitor& v) {
  v.field("rate_hz", &rate_hz,
          {.doc = "simulation step and truth pose rate, Hz", .min = 200, .max = 5000});
  v.field("channel", &channel, {.doc = "truth pose_t channel"});
  v.field("nav_rate_hz", &nav_rate_hz,
          {.doc = "rate of the NAV_* channels, Hz; 0 = off", .min = 0, .max = 5000});
  v.field("nav_position_channel", &nav_position_channel,
          {.doc = "geodetic_position_t: lat/lon rad, altitude above the start"});
  v.field("nav_attitude_channel", &nav_attitude_channel, {.doc = "attitude_t in NED"});
  v.field("nav_velocity_channel", &nav_velocity_channel, {.doc = "velocity_t in NED"});
  v.field("nav_rates_channel", &nav_rates_channel, {.doc = "body_rates_t, deg/s FRD"});
}

void SensorsParams::visit(core::ParamVisitor& v) {
  core::visitGroup(v, "imu", "gyro and accelerometer", imu);
  core::visitGroup(v, "rangefinder", "distance along a body ray to the terrain", rangefinder);
  core::visitGroup(v, "gps", "GNSS fixes", gps);
  core::visitGroup(v, "barometer", "barometric altitude", barometer);
  core::visitGroup(v, "magnetometer", "the Earth's magnetic field in the body", magnetometer);
  core::visitGroup(v, "ahrs", "the flight controller's estimate on NAV_*", ahrs);
}

void SimParams::visit(core::ParamVisitor& v) {
  v.field(
      "duration_s", &duration_s,
      {.doc = "stop after this much sim time, s; 0 = when the route ends", .min = 0, .max = 1e6});
  core::visitGroup(v, "vehicle", "the simulated vehicle", vehicle);
  core::visitGroup(v, "start", "where the vehicle starts", start);
  core::visitGroup(v, "route", "the waypoints it follows", route);
  core::visitGroup(v, "flight", "a recorded flight replayed as truth", flight);
  core::visitGroup(v, "truth", "the truth stream", truth);
  core::visitGroup(v, "sensors", "sensor models", sensors);
}

void TimeParams::visit(core::ParamVisitor& v) {
  v.field("mode", &mode,
          {.doc = "realtime (paced at speed x real time) or batch (as fast as possible)",
           .choices = {"realtime", "batch"}});
  v.field("speed", &speed, {.doc = "realtime: multiple of real time", .min = 0.01, .max = 1000});
  v.field("start_utc", &start_utc,
          {.doc = "the run's first instant, UTC, e.g. 2024-06-21T10:00:00Z (log times, the "
                  "procedural sun); empty: 2024-06-21 at 10:00 local solar time at the origin"});
}

std::int64_t runStartUtime(const TimeParams& time) {
  const std::string text =
      time.start_utc.empty() ? std::string(kDefaultStartDate) + "T10:00:00Z" : time.start_utc;
  try {
    return core::utimeFromUtc(text);
  } catch (const std::invalid_argument& e) {
    throw core::ParamError("time.start_utc: " + std::string(e.what()));
  }
}

std::int64_t logEventOffset_us(std::int64_t start_utime, std::int64_t first_message_utime) {
  return first_message_utime >= core::kYear2000Utime ? 0 : start_utime;
}

void SimNodeParams::visit(core::ParamVisitor& v) {
  sim.visit(v);
  core::visitGroup(v, "world", "the terrain and the world frame's origin", world);
  core::visitGroup(v, "time", "how sim time runs", time);
  core::visitGroup(v, "guidance", "what the vehicle's guidance flies on (a scenario's nav.source)",
                   sim.guidance);
}

void GuidanceParams::visit(core::ParamVisitor& v) {
  v.field("source", &source,
          {.doc = "what the guidance flies on after the GPS denial: truth, gps, nav, vo_feature, "
                  "vo_direct or ppa",
           .choices = {"truth", "gps", "nav", "vo_feature", "vo_direct", "ppa"}});
  v.field("channel", &channel,
          {.doc = "the estimate's channel; empty: the source's (GPS, POSE_NAV, POSE_VO_FEATURE, "
                  "POSE_VO_DIRECT, POSE_PPA)"});
  v.field("waypoint_channel", &waypoint_channel,
          {.doc = "waypoint_reached_t out: each waypoint the guidance takes as reached"});
}

std::string GuidanceParams::estimateChannel() const {
  if (!channel.empty() || source == "truth") return channel;
  if (source == "gps") return "GPS";
  if (source == "nav") return "POSE_NAV";
  if (source == "vo_feature") return "POSE_VO_FEATURE";
  if (source == "vo_direct") return "POSE_VO_DIRECT";
  return "POSE_PPA";
}

}  // namespace nadir::sim
