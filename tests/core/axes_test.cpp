// Axes conventions: nadir's NED/FRD against REP-103's ENU/FLU, each conversion
// checked against rotations and vectors worked out by hand, and TUM files
// written in ENU reading back in nadir's axes.

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/axes.h"
#include "core/trajectory.h"

namespace nadir::core {
namespace {

Eigen::Quaterniond yawDeg(double deg) {
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()));
}

void expectRotation(const Eigen::Quaterniond& q, const Eigen::Matrix3d& expected) {
  EXPECT_LT((q.toRotationMatrix() - expected).cwiseAbs().maxCoeff(), 1e-15)
      << q.toRotationMatrix() << "\nexpected\n"
      << expected;
}

// Positions: north 10, east 20, down -30 (30 m up) is east 20, north 10, up 30.
TEST(Axes, WorldVectorsSwapNorthAndEastAndTurnDownIntoUp) {
  EXPECT_EQ(worldVectorIn(Axes::kEnu, {10, 20, -30}), Eigen::Vector3d(20, 10, 30));
  EXPECT_EQ(worldVectorToNed(Axes::kEnu, {20, 10, 30}), Eigen::Vector3d(10, 20, -30));
  EXPECT_EQ(worldVectorIn(Axes::kNed, {10, 20, -30}), Eigen::Vector3d(10, 20, -30));
}

// A level IMU at rest reads the specific force up: (0, 0, -9.81) in FRD, (0, 0,
// 9.81) in FLU; a roll rate to the right stays positive about x.
TEST(Axes, BodyVectorsFlipRightAndDown) {
  EXPECT_EQ(bodyVectorIn(Axes::kEnu, {0, 0, -9.81}), Eigen::Vector3d(0, 0, 9.81));
  EXPECT_EQ(bodyVectorIn(Axes::kEnu, {0.5, 0.25, -0.125}), Eigen::Vector3d(0.5, -0.25, 0.125));
}

// Level, heading north (identity in NED/FRD): the body's forward is north (ENU
// y), its left west (ENU -x), its up up: REP-103's yaw of +90 deg. Heading east
// (NED yaw 90 deg) is ENU yaw 0.
TEST(Axes, HeadingNorthIsYaw90InEnu) {
  Eigen::Matrix3d R_enu_flu_north;
  R_enu_flu_north << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  expectRotation(attitudeIn(Axes::kEnu, Eigen::Quaterniond::Identity(), BodyAxes::kVehicle),
                 R_enu_flu_north);
  expectRotation(attitudeIn(Axes::kEnu, yawDeg(90), BodyAxes::kVehicle),
                 Eigen::Matrix3d::Identity());
  // A camera keeps its optical frame: only the world's axes change.
  Eigen::Matrix3d R_enu_ned;
  R_enu_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  expectRotation(attitudeIn(Axes::kEnu, Eigen::Quaterniond::Identity(), BodyAxes::kCamera),
                 R_enu_ned);
}

// Back and forth gives the same rotation, for any attitude (fixed seed).
TEST(Axes, AttitudesConvertBackToNed) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random))
            .normalized();
    for (BodyAxes body : {BodyAxes::kVehicle, BodyAxes::kCamera}) {
      const Eigen::Quaterniond back =
          attitudeToNed(Axes::kEnu, attitudeIn(Axes::kEnu, q, body), body);
      EXPECT_LT(back.angularDistance(q), 1e-14);
    }
  }
}

// A camera 1 m forward, 0.5 m right and 0.2 m below the body origin, looking
// down (optical z along the body's z): in FLU it sits at y -0.5 (right is minus
// left) and z -0.2 (down is minus up), and its optical z points along FLU -z.
TEST(Axes, SensorExtrinsicsTakeTheFluBody) {
  Eigen::Isometry3d T_frd_cam = Eigen::Isometry3d::Identity();
  T_frd_cam.translation() = Eigen::Vector3d(1.0, 0.5, 0.2);
  Eigen::Matrix3d R_frd_cam;
  R_frd_cam << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // image right = body right, image down = back
  T_frd_cam.linear() = R_frd_cam;
  const Eigen::Isometry3d T_flu_cam = bodyToSensorIn(Axes::kEnu, T_frd_cam);
  EXPECT_LT((T_flu_cam.translation() - Eigen::Vector3d(1.0, -0.5, -0.2)).norm(), 1e-15);
  Eigen::Matrix3d R_flu_cam;
  R_flu_cam << 0, -1, 0, -1, 0, 0, 0, 0, -1;
  EXPECT_LT((T_flu_cam.linear() - R_flu_cam).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Axes, NamesParseAndUnknownOnesAreRefused) {
  EXPECT_EQ(parseAxes("ned"), Axes::kNed);
  EXPECT_EQ(parseAxes("enu"), Axes::kEnu);
  EXPECT_THROW(parseAxes("nwu"), std::invalid_argument);
  EXPECT_EQ(frameTag(Axes::kEnu, BodyAxes::kVehicle), "world=enu body=flu");
  EXPECT_EQ(frameTag(Axes::kNed, BodyAxes::kCamera), "world=ned body=camera");
}

// A TUM file in ENU: its pose line holds the ENU values worked out by hand (a
// vehicle at N 10, E 20, 30 m up, heading north: x 20, y 10, z 30, yaw +90 deg,
// q = (0, 0, sin 45, cos 45)), its header says so, and it reads back in NED.
TEST(Axes, TumInEnuSaysSoAndReadsBackInNed) {
  Trajectory trajectory = {{1.5, Eigen::Vector3d(10, 20, -30), Eigen::Quaterniond::Identity()},
                           {2.5, Eigen::Vector3d(11, 21, -31), yawDeg(30)}};
  const std::string path = ::testing::TempDir() + "nadir_axes_enu.tum";
  writeTum(path, trajectory, Axes::kEnu, BodyAxes::kVehicle);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\n# frame: world=enu body=flu\n"), std::string::npos) << text;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line) && line.starts_with('#')) {
  }
  std::istringstream fields(line);
  double t, x, y, z, qx, qy, qz, qw;
  fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  EXPECT_EQ(t, 1.5);
  EXPECT_EQ(Eigen::Vector3d(x, y, z), Eigen::Vector3d(20, 10, 30));
  const double sign = qw < 0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * qx, 0.0, 1e-15);
  EXPECT_NEAR(sign * qy, 0.0, 1e-15);
  EXPECT_NEAR(sign * qz, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(sign * qw, std::sqrt(0.5), 1e-15);
  const Trajectory read = readTum(path);
  ASSERT_EQ(read.size(), 2u);
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].p_ned_m, trajectory[i].p_ned_m);
    EXPECT_LT(read[i].q_world_body.angularDistance(trajectory[i].q_world_body), 1e-14);
  }
}

// A frame line that names no known axes, or a body that does not go with
// them, is refused with its line.
TEST(Axes, ABadFrameLineIsRefused) {
  const std::string path = ::testing::TempDir() + "nadir_axes_bad.tum";
  for (const char* frame : {"world=nwu body=flu", "world=enu body=frd", "enu flu"}) {
    std::ofstream(path) << "# frame: " << frame << "\n1 0 0 0 0 0 0 1\n";
    try {
      readTum(path);
      ADD_FAILURE() << frame << " was read";
    } catch (const TrajectoryError& error) {
      EXPECT_NE(std::string(error.what()).find(path + ":1: "), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace nadir::core
