#include "core/frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace nadir::core {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// Elementary rotations written out by hand (not via Eigen::AngleAxis), so that the
// expectations below do not share code with the implementation under test.
Eigen::Matrix3d handRx(double a) {
  Eigen::Matrix3d m;
  m << 1, 0, 0,                      //
      0, std::cos(a), -std::sin(a),  //
      0, std::sin(a), std::cos(a);
  return m;
}

Eigen::Matrix3d handRy(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), 0, std::sin(a),  //
      0, 1, 0,                       //
      -std::sin(a), 0, std::cos(a);
  return m;
}

Eigen::Matrix3d handRz(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), -std::sin(a), 0,  //
      std::sin(a), std::cos(a), 0,    //
      0, 0, 1;
  return m;
}

RollPitchYaw rpyDeg(double roll_deg, double pitch_deg, double yaw_deg) {
  return RollPitchYaw{roll_deg * kDeg, pitch_deg * kDeg, yaw_deg * kDeg};
}

// Difference of two angles wrapped into [-pi, pi], so that pi and -pi compare equal.
double angleDiff(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

void expectVectorNear(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(actual(i), expected(i), tol) << "component " << i << "\nactual:\n"
                                             << actual.transpose() << "\nexpected:\n"
                                             << expected.transpose();
  }
}

double maxAbsDiff(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

// q and -q are the same rotation; compare coefficients up to that global sign.
void expectQuaternionNear(const Eigen::Quaterniond& q, double w, double x, double y, double z,
                          double tol) {
  const double sign = (q.w() * w + q.x() * x + q.y() * y + q.z() * z) < 0.0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * q.w(), w, tol);
  EXPECT_NEAR(sign * q.x(), x, tol);
  EXPECT_NEAR(sign * q.y(), y, tol);
  EXPECT_NEAR(sign * q.z(), z, tol);
}

constexpr double kTight = 1e-15;

// Yaw +90 deg turns the nose (body x) to world east and the right wing (body y) to world -north.
TEST(FramesTest, YawNinetyMapsNoseToEastAndRightWingToSouth) {
  const Eigen::Matrix3d R = rotationFromRpy(rpyDeg(0, 0, 90));
  expectVectorNear(R * Eigen::Vector3d::UnitX(), Eigen::Vector3d(0, 1, 0), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitY(), Eigen::Vector3d(-1, 0, 0), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, 1), kTight);
}

// Pitch +30 deg raises the nose: body x -> (cos30, 0, -sin30) in NED (up is negative down).
TEST(FramesTest, PitchThirtyRaisesNose) {
  const Eigen::Matrix3d R = rotationFromRpy(rpyDeg(0, 30, 0));
  const double c30 = std::sqrt(3.0) / 2.0;
  expectVectorNear(R * Eigen::Vector3d::UnitX(), Eigen::Vector3d(c30, 0, -0.5), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 1, 0), kTight);
  // Body down tilts backwards (towards north for a north-facing vehicle: +sin30 north).
  expectVectorNear(R * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.5, 0, c30), kTight);
}

// Roll +90 deg lowers the right wing: body y -> world down (0, 0, 1), body z -> world west.
TEST(FramesTest, RollNinetyLowersRightWing) {
  const Eigen::Matrix3d R = rotationFromRpy(rpyDeg(90, 0, 0));
  expectVectorNear(R * Eigen::Vector3d::UnitX(), Eigen::Vector3d(1, 0, 0), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 0, 1), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, -1, 0), kTight);
}

// Yaw 90 then pitch 30: hand product Rz(90)*Ry(30) applied to the body axes.
TEST(FramesTest, YawNinetyPitchThirtyComposition) {
  // Ry(30) x = (c30, 0, -s30); Rz(90) maps (a, b, c) -> (-b, a, c), giving (0, c30, -s30):
  // nose pointing east and 30 deg up. Ry(30) z = (s30, 0, c30) -> (0, s30, c30).
  // Ry(30) y = y -> (-1, 0, 0): right wing points south.
  const Eigen::Matrix3d R = rotationFromRpy(rpyDeg(0, 30, 90));
  const double c30 = std::sqrt(3.0) / 2.0;
  expectVectorNear(R * Eigen::Vector3d::UnitX(), Eigen::Vector3d(0, c30, -0.5), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitY(), Eigen::Vector3d(-1, 0, 0), kTight);
  expectVectorNear(R * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0.5, c30), kTight);
  // A generic body vector (1, 2, 3) -> 1*(0, c30, -0.5) + 2*(-1, 0, 0) + 3*(0, 0.5, c30).
  expectVectorNear(R * Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-2, c30 + 1.5, -0.5 + 3 * c30),
                   1e-14);
}

// rotationFromRpy equals the hand-multiplied Rz(yaw)*Ry(pitch)*Rx(roll) for all three axes at once.
TEST(FramesTest, RotationMatchesHandZyxProduct) {
  for (const RollPitchYaw& rpy :
       {rpyDeg(10, 20, 30), rpyDeg(-170, 75, -45), rpyDeg(120, -60, 179), rpyDeg(-5, -89, 91)}) {
    const Eigen::Matrix3d expected =
        handRz(rpy.yaw_rad) * handRy(rpy.pitch_rad) * handRx(rpy.roll_rad);
    EXPECT_LT(maxAbsDiff(rotationFromRpy(rpy), expected), 1e-14)
        << "rpy = " << rpy.roll_rad << ", " << rpy.pitch_rad << ", " << rpy.yaw_rad;
  }
}

// Single-axis quaternions equal the half-angle hand values (Hamilton, w = cos(a/2)).
TEST(FramesTest, QuaternionFromRpySingleAxisHandValues) {
  const double c45 = std::sqrt(0.5);
  const double s45 = std::sqrt(0.5);
  expectQuaternionNear(quaternionFromRpy(rpyDeg(0, 0, 90)), c45, 0, 0, s45, kTight);
  expectQuaternionNear(quaternionFromRpy(rpyDeg(0, 30, 0)), std::cos(15 * kDeg), 0,
                       std::sin(15 * kDeg), 0, kTight);
  // Roll -60 deg: w = cos(-30) = sqrt(3)/2, x = sin(-30) = -1/2.
  expectQuaternionNear(quaternionFromRpy(rpyDeg(-60, 0, 0)), std::sqrt(3.0) / 2.0, -0.5, 0, 0,
                       kTight);
}

// Yaw 90, pitch 30 quaternion is the Hamilton product qz(90)*qy(30) worked out by hand.
TEST(FramesTest, QuaternionFromRpyCompositionHandValue) {
  // qz = (c45, 0, 0, s45), qy = (c15, 0, s15, 0). Hamilton product (w1 w2 - v1.v2,
  // w1 v2 + w2 v1 + v1 x v2) with v1 x v2 = (0, 0, s45) x (0, s15, 0) = (-s45 s15, 0, 0):
  // q = (c45 c15, -s45 s15, c45 s15, s45 c15).
  const double c45 = std::sqrt(0.5);
  const double s45 = std::sqrt(0.5);
  const double c15 = std::cos(15 * kDeg);
  const double s15 = std::sin(15 * kDeg);
  expectQuaternionNear(quaternionFromRpy(rpyDeg(0, 30, 90)), c45 * c15, -s45 * s15, c45 * s15,
                       s45 * c15, kTight);
}

// rotationFromRpy equals the matrix of quaternionFromRpy, and the quaternion is unit.
TEST(FramesTest, RotationFromRpyEqualsQuaternionMatrix) {
  for (const RollPitchYaw& rpy :
       {rpyDeg(0, 0, 90), rpyDeg(0, 30, 0), rpyDeg(90, 0, 0), rpyDeg(0, 30, 90),
        rpyDeg(-33, 12, -150), rpyDeg(180, -89, 180)}) {
    const Eigen::Quaterniond q = quaternionFromRpy(rpy);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT(maxAbsDiff(rotationFromRpy(rpy), q.toRotationMatrix()), 1e-15);
  }
}

// rpy -> rotation -> rpy round trip over a fixed grid away from gimbal lock, within 1e-12 rad.
TEST(FramesTest, RpyRoundTripGrid) {
  const double roll_yaw_deg[] = {-179, -135, -90, -45, -1, 0, 1, 30, 90, 135, 179.5, 180};
  const double pitch_deg[] = {-89, -75, -45, -10, -1e-3, 0, 1e-3, 10, 45, 75, 89};
  for (double r : roll_yaw_deg) {
    for (double p : pitch_deg) {
      for (double y : roll_yaw_deg) {
        const RollPitchYaw in = rpyDeg(r, p, y);
        const RollPitchYaw out = rpyFromRotation(rotationFromRpy(in));
        SCOPED_TRACE("roll " + std::to_string(r) + " pitch " + std::to_string(p) + " yaw " +
                     std::to_string(y) + " deg");
        // Roll and yaw are compared modulo 2 pi: +180 and -180 deg are the same angle and
        // rounding in the matrix may land on either side of the branch cut.
        EXPECT_NEAR(angleDiff(out.roll_rad, in.roll_rad), 0.0, 1e-12);
        EXPECT_NEAR(out.pitch_rad, in.pitch_rad, 1e-12);
        EXPECT_NEAR(angleDiff(out.yaw_rad, in.yaw_rad), 0.0, 1e-12);
        // Documented output ranges (allowing for -pi as the rounded image of pi).
        EXPECT_LE(std::abs(out.roll_rad), kPi);
        EXPECT_LE(std::abs(out.yaw_rad), kPi);
        EXPECT_LE(std::abs(out.pitch_rad), kPi / 2);
      }
    }
  }
}

// rpyFromQuaternion agrees with the hand angles and ignores the quaternion's scale and sign.
TEST(FramesTest, RpyFromQuaternionRoundTrip) {
  const RollPitchYaw in = rpyDeg(25, -40, 110);
  const Eigen::Quaterniond q = quaternionFromRpy(in);
  for (double scale : {1.0, -1.0, 3.0}) {
    const Eigen::Quaterniond scaled(scale * q.w(), scale * q.x(), scale * q.y(), scale * q.z());
    const RollPitchYaw out = rpyFromQuaternion(scaled);
    EXPECT_NEAR(out.roll_rad, 25 * kDeg, 1e-12) << "scale " << scale;
    EXPECT_NEAR(out.pitch_rad, -40 * kDeg, 1e-12) << "scale " << scale;
    EXPECT_NEAR(out.yaw_rad, 110 * kDeg, 1e-12) << "scale " << scale;
  }
}

// Gimbal lock (pitch = +-90 deg): recovered rpy has roll == 0 and reproduces the matrix to 1e-12.
TEST(FramesTest, GimbalLockReproducesRotation) {
  const double angles_deg[] = {-180, -135, -90, -30, 0, 15, 60, 90, 150, 180};
  for (double p : {90.0, -90.0}) {
    for (double r : angles_deg) {
      for (double y : angles_deg) {
        const Eigen::Matrix3d R = rotationFromRpy(rpyDeg(r, p, y));
        const RollPitchYaw out = rpyFromRotation(R);
        SCOPED_TRACE("roll " + std::to_string(r) + " pitch " + std::to_string(p) + " yaw " +
                     std::to_string(y) + " deg");
        EXPECT_EQ(out.roll_rad, 0.0);
        EXPECT_LT(maxAbsDiff(rotationFromRpy(out), R), 1e-12);
        // Hand value of the free angle: pitch +90 fixes yaw - roll, pitch -90 fixes yaw + roll.
        const double expected_yaw = p > 0 ? (y - r) * kDeg : (y + r) * kDeg;
        EXPECT_NEAR(angleDiff(out.yaw_rad, expected_yaw), 0.0, 1e-12);
      }
    }
  }
}

// Just off gimbal lock (pitch 89.999 deg) the angles are still recovered and reproduce the matrix.
TEST(FramesTest, NearGimbalLockIsStillInvertible) {
  for (double p : {89.999, -89.999, 89.9999999}) {
    const RollPitchYaw in = rpyDeg(28.6479, p, 17.1887);  // roll 0.5 rad, yaw 0.3 rad
    const Eigen::Matrix3d R = rotationFromRpy(in);
    const RollPitchYaw out = rpyFromRotation(R);
    SCOPED_TRACE("pitch " + std::to_string(p) + " deg");
    EXPECT_LT(maxAbsDiff(rotationFromRpy(out), R), 1e-12);
    EXPECT_NEAR(out.pitch_rad, in.pitch_rad, 1e-12);
  }
}

// Down camera: optical z -> body down, image right -> right wing, image down -> tail.
TEST(FramesTest, DownCameraAxes) {
  const Eigen::Matrix3d R_body_cam = rotationBodyFromDownCamera();
  expectVectorNear(R_body_cam * Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, 1), 0.0);
  expectVectorNear(R_body_cam * Eigen::Vector3d::UnitX(), Eigen::Vector3d(0, 1, 0), 0.0);
  expectVectorNear(R_body_cam * Eigen::Vector3d::UnitY(), Eigen::Vector3d(-1, 0, 0), 0.0);
}

// The down-camera matrix is a proper rotation: orthonormal with determinant +1.
TEST(FramesTest, DownCameraIsProperRotation) {
  const Eigen::Matrix3d R_body_cam = rotationBodyFromDownCamera();
  EXPECT_NEAR(R_body_cam.determinant(), 1.0, 1e-15);
  EXPECT_LT(maxAbsDiff(R_body_cam.transpose() * R_body_cam, Eigen::Matrix3d::Identity()), 1e-15);
}

// Wire order is w first: identity is (1, 0, 0, 0) and yaw 90 is (cos45, 0, 0, sin45).
TEST(FramesTest, WireOrderIsWFirst) {
  double wire[4] = {-7, -7, -7, -7};
  quaternionToWire(Eigen::Quaterniond::Identity(), wire);
  EXPECT_EQ(wire[0], 1.0);
  EXPECT_EQ(wire[1], 0.0);
  EXPECT_EQ(wire[2], 0.0);
  EXPECT_EQ(wire[3], 0.0);

  // Eigen's constructor takes (w, x, y, z); coefficient storage is x, y, z, w.
  quaternionToWire(Eigen::Quaterniond(0.1, 0.2, 0.3, 0.4), wire);
  EXPECT_EQ(wire[0], 0.1);
  EXPECT_EQ(wire[1], 0.2);
  EXPECT_EQ(wire[2], 0.3);
  EXPECT_EQ(wire[3], 0.4);

  const double yaw180[4] = {0, 0, 0, 1};
  const Eigen::Quaterniond q = quaternionFromWire(yaw180);
  EXPECT_EQ(q.w(), 0.0);
  EXPECT_EQ(q.x(), 0.0);
  EXPECT_EQ(q.y(), 0.0);
  EXPECT_EQ(q.z(), 1.0);
  // Rotation by 180 deg about down: nose points south.
  expectVectorNear(q * Eigen::Vector3d::UnitX(), Eigen::Vector3d(-1, 0, 0), 1e-15);
}

// quaternionToWire then quaternionFromWire returns the same unit quaternion.
TEST(FramesTest, WireRoundTrip) {
  for (const RollPitchYaw& rpy :
       {rpyDeg(0, 0, 0), rpyDeg(0, 0, 90), rpyDeg(10, -20, 170), rpyDeg(-120, 60, -45)}) {
    const Eigen::Quaterniond q = quaternionFromRpy(rpy);
    double wire[4];
    quaternionToWire(q, wire);
    const Eigen::Quaterniond back = quaternionFromWire(wire);
    EXPECT_NEAR(back.w(), q.w(), 1e-15);
    EXPECT_NEAR(back.x(), q.x(), 1e-15);
    EXPECT_NEAR(back.y(), q.y(), 1e-15);
    EXPECT_NEAR(back.z(), q.z(), 1e-15);
  }
}

// quaternionFromWire rejects non-rotations: norm 2, zero, NaN or infinite components.
TEST(FramesTest, WireRejectsNonUnitAndNonFinite) {
  const double norm_two[4] = {2, 0, 0, 0};
  EXPECT_THROW(quaternionFromWire(norm_two), std::invalid_argument);
  const double norm_two_mixed[4] = {1, 1, 1, 1};
  EXPECT_THROW(quaternionFromWire(norm_two_mixed), std::invalid_argument);
  const double zero[4] = {0, 0, 0, 0};
  EXPECT_THROW(quaternionFromWire(zero), std::invalid_argument);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    double with_nan[4] = {1, 0, 0, 0};
    with_nan[i] = nan;
    EXPECT_THROW(quaternionFromWire(with_nan), std::invalid_argument) << "NaN at " << i;
    double with_inf[4] = {0, 0, 0, 0};
    with_inf[i] = inf;
    EXPECT_THROW(quaternionFromWire(with_inf), std::invalid_argument) << "inf at " << i;
  }
}

// A quaternion with norm 1 + 1e-6 (wire rounding) is accepted and normalised.
TEST(FramesTest, WireAcceptsAndNormalisesNearUnit) {
  const double scale = 1.0 + 1e-6;
  const double c = std::sqrt(0.5);
  const double wire[4] = {scale * c, 0, 0, scale * c};
  Eigen::Quaterniond q;
  ASSERT_NO_THROW(q = quaternionFromWire(wire));
  EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  EXPECT_NEAR(q.w(), c, 1e-15);
  EXPECT_NEAR(q.x(), 0.0, 1e-15);
  EXPECT_NEAR(q.y(), 0.0, 1e-15);
  EXPECT_NEAR(q.z(), c, 1e-15);
}

}  // namespace
}  // namespace nadir::core
