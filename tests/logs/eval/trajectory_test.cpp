// evo-style timestamp association, on hand-made trajectories.

#include <gtest/gtest.h>

#include "logs/eval/trajectory.h"

namespace nadir::eval {
namespace {

core::StampedPose poseAt(double t) {
  core::StampedPose pose;
  pose.t_s = t;
  return pose;
}

// Nearest stamps within t_max_diff, one to one (a second estimate near the same ref is dropped).
TEST(EvalAssociate, NearestStampWithinMaxDiff) {
  const core::Trajectory ref = {poseAt(0), poseAt(1), poseAt(2), poseAt(3)};
  const core::Trajectory est = {poseAt(0.005), poseAt(1.02), poseAt(2.0), poseAt(2.004),
                                poseAt(3.5)};
  const auto pairs = associate(ref, est, 0.01);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], (std::pair<std::size_t, std::size_t>{0, 0}));
  EXPECT_EQ(pairs[1], (std::pair<std::size_t, std::size_t>{2, 2}));
  // A looser threshold also takes 1.02 -> 1.
  const auto loose = associate(ref, est, 0.05);
  ASSERT_EQ(loose.size(), 3u);
  EXPECT_EQ(loose[1], (std::pair<std::size_t, std::size_t>{1, 1}));
}

}  // namespace
}  // namespace nadir::eval
