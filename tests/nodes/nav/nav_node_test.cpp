// NavNode on an in-process bus: a level circle flown at 20 m/s with exact IMU
// readings, the VO's poses given in the VO's own (drifted) world frame, GPS
// until a denial; what goes out on POSE_NAV and POSE_NAV_STATE.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "core/bus.h"
#include "lcmtypes/bus_io.h"
#include "nodes/nav/nav_node.h"

namespace nadir::nav {
namespace {

constexpr double kSpeed_mps = 20.0;
constexpr double kYawRate_rps = 0.1;
constexpr double kAltitude_m = 100.0;

// The circle: level, heading psi = w t, velocity V (cos psi, sin psi, 0).
msg::Pose truthAt(double t_s) {
  const double psi = kYawRate_rps * t_s;
  const double radius = kSpeed_mps / kYawRate_rps;
  msg::Pose pose;
  pose.utime = std::llround(t_s * 1e6);
  pose.p_ned_m = {radius * std::sin(psi), radius * (1.0 - std::cos(psi)), -kAltitude_m};
  pose.v_ned_mps = {kSpeed_mps * std::cos(psi), kSpeed_mps * std::sin(psi), 0.0};
  pose.a_ned_mps2 = kSpeed_mps * kYawRate_rps * Eigen::Vector3d(-std::sin(psi), std::cos(psi), 0.0);
  pose.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()));
  pose.omega_body_rps = {0.0, 0.0, kYawRate_rps};
  return pose;
}

msg::Imu imuAt(double t_s) {
  const msg::Pose pose = truthAt(t_s);
  msg::Imu imu;
  imu.utime = pose.utime;
  imu.angular_velocity_rps = pose.omega_body_rps;
  imu.linear_acceleration_mps2 =
      pose.q_world_body.conjugate() * (pose.a_ned_mps2 - Eigen::Vector3d(0.0, 0.0, kGravity_mps2));
  return imu;
}

struct NavOutput {
  std::vector<msg::VoEstimate> poses;
  std::vector<msg::NavState> states;
};

class NavNodeTest : public ::testing::Test {
 protected:
  NavNodeParams baseParams() const {
    NavNodeParams params;
    params.origin_lat_deg = 39.35;
    params.origin_lon_deg = -86.03;
    params.origin_alt_m = 200.0;
    params.use_mag = false;
    params.use_range = false;
    params.publish_rate_hz = 10.0;
    params.delay_s = 0.1;
    return params;
  }

  void startNode(const NavNodeParams& params) {
    node_ = std::make_unique<NavNode>(*bus_, params);
    subscriptions_.push_back(msg::subscribe<msg::VoEstimate>(
        *bus_, params.pose_channel,
        [this](const msg::VoEstimate& pose) { output_.poses.push_back(pose); }));
    subscriptions_.push_back(msg::subscribe<msg::NavState>(
        *bus_, params.state_channel,
        [this](const msg::NavState& state) { output_.states.push_back(state); }));
  }

  template <class T>
  void send(const std::string& channel, const T& message) {
    msg::publish(*bus_, channel, message);
    bus_->handleAvailable();
  }

  std::unique_ptr<core::Bus> bus_ = core::openBus("memq://");
  std::unique_ptr<NavNode> node_;
  NavOutput output_;
  std::vector<core::Subscription> subscriptions_;
};

// The VO's reset mid-flight: its poses before are in one frame of its own,
// after in another 50 m and 40 deg away. With the gate off, only the chain's
// restart stands between the filter and a 50 m jump: no output moves by more
// than 3 sigma against the truth, and the error stays under 0.3 m.
TEST_F(NavNodeTest, AVoResetMidFlightMakesNoJump) {
  NavNodeParams params = baseParams();
  params.use_gps = false;
  params.gate_probability = 1.0;
  startNode(params);

  const auto voFrame = [](double t_s) {
    Eigen::Isometry3d T_vo_world = Eigen::Isometry3d::Identity();
    if (t_s < 10.0) {
      T_vo_world.linear() = Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T_vo_world.translation() = Eigen::Vector3d(10.0, -5.0, 2.0);
    } else {
      T_vo_world.linear() = Eigen::AngleAxisd(-0.70, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T_vo_world.translation() = Eigen::Vector3d(60.0, 45.0, -3.0);
    }
    return T_vo_world;
  };

  send("POSE_TRUTH", truthAt(0.0));
  for (int k = 0; k <= 4000; ++k) {  // 20 s at 200 Hz
    const double t_s = k / 200.0;
    send(params.imu_channel, imuAt(t_s));
    if (k % 4 == 0) {  // the barometer at 50 Hz
      send(params.baro_channel, msg::Baro{.utime = std::llround(t_s * 1e6),
                                          .altitude_m = params.origin_alt_m + kAltitude_m,
                                          .pressure_pa = 0.0});
    }
    if (k % 10 == 0) {  // the VO at 20 frames/s
      const msg::Pose truth = truthAt(t_s);
      Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
      T_world_body.linear() = truth.q_world_body.toRotationMatrix();
      T_world_body.translation() = truth.p_ned_m;
      const Eigen::Isometry3d T_vo_body = voFrame(t_s) * T_world_body;
      msg::VoEstimate vo;
      vo.utime = truth.utime;
      vo.source = "vo_feature";
      vo.status = msg::VoStatus::TRACKING;
      vo.p_ned_m = T_vo_body.translation();
      vo.q_world_body = Eigen::Quaterniond(T_vo_body.rotation());
      vo.num_resets = t_s < 10.0 ? 0 : 1;
      send(params.vo_channel, vo);
    }
  }

  EXPECT_EQ(node_->counts().vo_restarts, 2u);  // the first frame and the reset
  EXPECT_GE(node_->counts().vo, 37u);          // two a second, but at the two chain starts
  EXPECT_EQ(node_->counts().refused, 0u);
  ASSERT_GT(output_.poses.size(), 190u);
  ASSERT_EQ(output_.states.size(), output_.poses.size());
  double largest_error_m = 0.0;
  Eigen::Vector3d previous_error = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < output_.poses.size(); ++i) {
    const msg::VoEstimate& pose = output_.poses[i];
    const Eigen::Vector3d error = pose.p_ned_m - truthAt(pose.utime * 1e-6).p_ned_m;
    largest_error_m = std::max(largest_error_m, error.norm());
    const double sigma_m = std::sqrt(output_.states[i].position_covariance_m2.trace());
    if (i > 0) {
      EXPECT_LT((error - previous_error).norm(), 3.0 * sigma_m)
          << "at " << pose.utime * 1e-6 << " s";
    }
    previous_error = error;
  }
  EXPECT_LT(largest_error_m, 0.3);
}

// GPS until it is denied at 10 s: the state says when the last fix was fused,
// and the position's uncertainty, small with GPS, grows after the denial.
TEST_F(NavNodeTest, GpsDenialShowsInTheState) {
  NavNodeParams params = baseParams();
  params.use_vo = false;
  startNode(params);
  const core::LocalNedFrame frame(
      core::geodeticFromDegrees(params.origin_lat_deg, params.origin_lon_deg, params.origin_alt_m));

  send("POSE_TRUTH", truthAt(0.0));
  std::int64_t last_fix_utime = -1;
  for (int k = 0; k <= 6000; ++k) {  // 30 s at 200 Hz
    const double t_s = k / 200.0;
    send(params.imu_channel, imuAt(t_s));
    if (k % 40 == 0 && t_s < 10.0) {  // 5 Hz until the denial
      const msg::Pose truth = truthAt(t_s);
      const core::Geodetic where = frame.geodeticFromNed(truth.p_ned_m);
      msg::Gps gps;
      gps.utime = truth.utime;
      gps.lat_rad = where.lat_rad;
      gps.lon_rad = where.lon_rad;
      gps.alt_m = where.alt_m;
      gps.velocity_ned_mps = truth.v_ned_mps;
      gps.horizontal_accuracy_m = 1.5;
      gps.vertical_accuracy_m = 3.0;
      gps.num_satellites = 12;
      gps.fix = msg::GpsFix::FIX_3D;
      send(params.gps_channel, gps);
      last_fix_utime = gps.utime;
    }
  }
  ASSERT_FALSE(output_.states.empty());
  EXPECT_EQ(output_.states.back().last_gps_utime, last_fix_utime);
  EXPECT_EQ(node_->counts().gps, 50u);
  const auto sigmaAt = [this](double t_s) {
    for (const msg::NavState& state : output_.states)
      if (state.utime >= std::llround(t_s * 1e6))
        return std::sqrt(state.position_covariance_m2.trace());
    return 0.0;
  };
  EXPECT_LT(sigmaAt(9.5), 2.0);
  EXPECT_GT(sigmaAt(29.0), 2.0 * sigmaAt(9.5));
}

// The rangefinder against a known map: over ground that rises 5 m per 100 m
// north, with neither GPS nor barometer, the ranges straight down hold the
// height to 0.1 m over the 20 s circle. Asked for without a map, the node refuses.
TEST_F(NavNodeTest, RangeAgainstAKnownMapHoldsTheHeight) {
  NavNodeParams params = baseParams();
  params.use_gps = false;
  params.use_baro = false;
  params.use_vo = false;
  params.use_range = true;
  params.range_against_map = true;
  EXPECT_THROW(NavNode(*bus_, params), core::ParamError);
  const GroundDown ground_down = [](double north_m, double) { return -0.05 * north_m; };
  node_ = std::make_unique<NavNode>(*bus_, params, ground_down);
  subscriptions_.push_back(msg::subscribe<msg::NavState>(
      *bus_, params.state_channel,
      [this](const msg::NavState& state) { output_.states.push_back(state); }));
  send("POSE_TRUTH", truthAt(0.0));
  for (int k = 0; k <= 4000; ++k) {
    const double t_s = k / 200.0;
    send(params.imu_channel, imuAt(t_s));
    if (k % 4 != 0) continue;
    const msg::Pose truth = truthAt(t_s);
    msg::Range range;
    range.utime = truth.utime;
    range.range_m = ground_down(truth.p_ned_m.x(), truth.p_ned_m.y()) - truth.p_ned_m.z();
    range.status = msg::RangeStatus::VALID;
    range.min_range_m = 0.1;
    range.max_range_m = 1000.0;
    send(params.range_channel, range);
  }
  EXPECT_GT(node_->counts().range, 900u);
  ASSERT_FALSE(output_.states.empty());
  for (const msg::NavState& state : output_.states) {
    if (state.utime < 2'000'000) continue;
    EXPECT_NEAR(state.p_ned_m.z(), -kAltitude_m, 0.1) << "at " << state.utime * 1e-6 << " s";
  }
}

// A fix without an accuracy is dropped and counted, naming the message; what
// was fused before stays.
TEST_F(NavNodeTest, ABadFixIsDroppedAndNamed) {
  NavNodeParams params = baseParams();
  startNode(params);
  send("POSE_TRUTH", truthAt(0.0));
  send(params.imu_channel, imuAt(0.0));
  msg::Gps gps;
  gps.utime = 5000;
  gps.fix = msg::GpsFix::FIX_3D;
  send(params.gps_channel, gps);
  send(params.imu_channel, imuAt(0.005));
  EXPECT_EQ(node_->counts().dropped, 1u);
  EXPECT_NE(node_->firstDropReason().find("gps_t at utime 5000"), std::string::npos)
      << node_->firstDropReason();
  EXPECT_EQ(node_->counts().imu, 2u);
}

// Parameters out of their range are refused, naming the key.
TEST_F(NavNodeTest, AnImpossibleParameterIsNamed) {
  NavNodeParams params = baseParams();
  params.delay_s = -0.1;
  try {
    NavNode node(*bus_, params);
    FAIL() << "a negative delay was taken";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("delay_s"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace nadir::nav
