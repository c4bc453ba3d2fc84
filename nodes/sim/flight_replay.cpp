#include "nodes/sim/flight_replay.h"

#include <algorithm>

#include "core/clock.h"

namespace nadir::sim {

FlightReplay::FlightReplay(core::Trajectory flight, const std::string& source)
    : flight_(std::move(flight)) {
  core::requireIncreasing(flight_, source, 2);
  start_utime_ = core::utimeFromSeconds(flight_.front().t_s);
  end_utime_ = core::utimeFromSeconds(flight_.back().t_s);
  const double start_s = flight_.front().t_s;
  for (core::StampedPose& pose : flight_) {
    pose.t_s -= start_s;
    pose.q_world_body.normalize();
  }
}

VehicleState FlightReplay::at(std::int64_t utime) const {
  const double t_s =
      std::clamp(core::secondsFromUtime(utime - start_utime_), 0.0, flight_.back().t_s);
  const core::StampedPose pose = *core::interpolate(flight_, t_s);
  // The interval from the sample at or before t_s (the last interval at the end).
  const std::size_t i = std::min(core::bracket(flight_, t_s)->i0, flight_.size() - 2);
  const core::StampedPose& a = flight_[i];
  const core::StampedPose& b = flight_[i + 1];
  const double span_s = b.t_s - a.t_s;
  VehicleState state;
  state.utime = utime;
  state.p_ned_m = pose.p_ned_m;
  state.q_world_body = pose.q_world_body;
  state.v_ned_mps = (b.p_ned_m - a.p_ned_m) / span_s;
  // Body rate over the interval: the rotation from a to b, in a's body frame.
  const Eigen::AngleAxisd delta(a.q_world_body.conjugate() * b.q_world_body);
  state.omega_body_rps = delta.axis() * delta.angle() / span_s;
  const auto velocityOf = [this](std::size_t k) {
    return (flight_[k + 1].p_ned_m - flight_[k].p_ned_m) / (flight_[k + 1].t_s - flight_[k].t_s);
  };
  if (i + 2 < flight_.size()) {
    const double mid_span_s = 0.5 * (flight_[i + 2].t_s - flight_[i].t_s);
    state.a_ned_mps2 = (velocityOf(i + 1) - velocityOf(i)) / mid_span_s;
  } else if (i > 0) {
    const double mid_span_s = 0.5 * (flight_[i + 1].t_s - flight_[i - 1].t_s);
    state.a_ned_mps2 = (velocityOf(i) - velocityOf(i - 1)) / mid_span_s;
  }
  return state;
}

}  // namespace nadir::sim
