// The filter in message time: measurements that come late (within the delay)
// give the same filter as if they had come on time; older ones are refused;
// the present estimate is the delayed one carried forward.

#include <gtest/gtest.h>

#include <vector>

#include "nodes/nav/delayed_fusion.h"

namespace nadir::nav {
namespace {

constexpr std::int64_t kImuUs = 5000;

ImuSample levelImu(std::int64_t utime) {
  ImuSample imu;
  imu.utime = utime;
  imu.angular_velocity_rps = Eigen::Vector3d(0.0, 0.0, 0.05);
  imu.linear_acceleration_mps2 = Eigen::Vector3d(0.3, 0.0, -kGravity_mps2);
  return imu;
}

ErrorStateFilter makeFilter() {
  NavState start;
  start.p_ned_m = Eigen::Vector3d(0.0, 0.0, -100.0);
  start.v_ned_mps = Eigen::Vector3d(15.0, 0.0, 0.0);
  return ErrorStateFilter(ProcessNoise{}, start, Covariance::Identity() * 0.01);
}

// A GPS fix every 0.2 s: given right after the IMU sample of its stamp, or
// 0.15 s later (within the 0.25 s delay); the delayed filters agree bit for bit.
TEST(DelayedFusion, LateMeasurementsWithinTheDelayChangeNothing) {
  DelayedFusion on_time(makeFilter(), 0.25);
  DelayedFusion late(makeFilter(), 0.25);
  std::vector<std::pair<std::int64_t, Eigen::Vector3d>> waiting;
  for (int i = 0; i <= 2000; ++i) {
    const std::int64_t utime = i * kImuUs;
    on_time.addImu(levelImu(utime));
    late.addImu(levelImu(utime));
    if (i % 40 == 0) {
      const Eigen::Vector3d fix(15.0 * utime * 1e-6 + 0.5, 0.2, -100.0);
      auto update = [fix](ErrorStateFilter& f) {
        f.updatePosition(fix, Eigen::Matrix3d::Identity());
      };
      ASSERT_TRUE(on_time.addMeasurement(utime, update));
      waiting.emplace_back(utime, fix);
    }
    // Fixes 0.15 s old now arrive.
    while (!waiting.empty() && waiting.front().first <= utime - 150'000) {
      const Eigen::Vector3d fix = waiting.front().second;
      ASSERT_TRUE(late.addMeasurement(waiting.front().first, [fix](ErrorStateFilter& f) {
        f.updatePosition(fix, Eigen::Matrix3d::Identity());
      }));
      waiting.erase(waiting.begin());
    }
  }
  EXPECT_EQ(on_time.delayed().state().utime, late.delayed().state().utime);
  EXPECT_EQ(on_time.delayed().state().p_ned_m, late.delayed().state().p_ned_m);
  EXPECT_EQ(on_time.delayed().covariance(), late.delayed().covariance());
  EXPECT_EQ(late.late(), 0);
  // The horizon is the newest sample less the delay.
  EXPECT_EQ(late.horizonUtime(), 2000 * kImuUs - 250'000);
}

// A measurement older than the horizon is refused, counted, and changes nothing.
TEST(DelayedFusion, MeasurementOlderThanTheHorizonIsRefused) {
  DelayedFusion fusion(makeFilter(), 0.1);
  for (int i = 0; i <= 100; ++i) fusion.addImu(levelImu(i * kImuUs));
  const NavState before = fusion.delayed().state();
  const bool taken = fusion.addMeasurement(fusion.horizonUtime() - 1, [](ErrorStateFilter& f) {
    f.updatePosition(Eigen::Vector3d(1000.0, 0.0, 0.0), Eigen::Matrix3d::Identity());
  });
  EXPECT_FALSE(taken);
  EXPECT_EQ(fusion.late(), 1);
  EXPECT_EQ(fusion.delayed().state().p_ned_m, before.p_ned_m);
}

// With no measurement, the present estimate is what a filter without delay
// has, to rounding: the delayed one carried forward over the delay.
TEST(DelayedFusion, PresentIsTheDelayedStateCarriedForward) {
  DelayedFusion fusion(makeFilter(), 0.25);
  ErrorStateFilter direct = makeFilter();
  for (int i = 0; i <= 1000; ++i) {
    fusion.addImu(levelImu(i * kImuUs));
    direct.propagate(levelImu(i * kImuUs));
  }
  const NavState present = fusion.present();
  EXPECT_EQ(present.utime, 1000 * kImuUs);
  EXPECT_EQ(fusion.delayed().state().utime, 1000 * kImuUs - 250'000);
  EXPECT_LT((present.p_ned_m - direct.state().p_ned_m).norm(), 1e-9);
  EXPECT_LT((present.v_ned_mps - direct.state().v_ned_mps).norm(), 1e-9);
  EXPECT_LT(present.q_world_body.angularDistance(direct.state().q_world_body), 1e-12);
  // Before any sample has been fused, the present starts at the first one.
  DelayedFusion fresh(makeFilter(), 1.0);
  fresh.addImu(levelImu(7 * kImuUs));
  fresh.addImu(levelImu(8 * kImuUs));
  EXPECT_EQ(fresh.present().utime, 8 * kImuUs);
  EXPECT_LT((fresh.present().p_ned_m - Eigen::Vector3d(0.075, 0.0, -100.0)).norm(), 1e-3);
}

}  // namespace
}  // namespace nadir::nav
