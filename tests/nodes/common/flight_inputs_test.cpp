// FlightInputs on an in-process bus: the range at an image's time is
// interpolated between the readings around it, the latest one serves an image
// newer than every reading, and an invalid reading gives no range.
#include "nodes/common/flight_inputs.h"

#include <gtest/gtest.h>

#include <memory>

#include "core/bus.h"
#include "lcmtypes/bus_io.h"

namespace nadir::nodes {
namespace {

class FlightInputsTest : public ::testing::Test {
 protected:
  void range(std::int64_t utime, double range_m, bool valid = true) {
    msg::Range r;
    r.utime = utime;
    r.range_m = range_m;
    r.max_range_m = 1000.0;
    r.status = valid ? msg::RangeStatus::VALID : msg::RangeStatus::OUT_OF_RANGE;
    msg::publish(*bus_, "RANGE", r);
    bus_->handleAvailable();
  }

  std::unique_ptr<core::Bus> bus_ = core::openBus("memq://");
  FlightInputs inputs_{*bus_, "RANGE", "ATTITUDE"};
};

TEST_F(FlightInputsTest, TheRangeAtAnImagesTimeIsInterpolatedBetweenTheReadingsAroundIt) {
  EXPECT_FALSE(inputs_.rangeAt_m(0));
  // 50 Hz readings of a slant range growing 4 m per reading, as in a bank.
  range(1'000'000, 300.0);
  range(1'020'000, 304.0);
  range(1'040'000, 308.0);
  // An image stamped 5 ms after the first reading: a quarter of the way.
  EXPECT_NEAR(*inputs_.rangeAt_m(1'005'000), 301.0, 1e-9);
  EXPECT_NEAR(*inputs_.rangeAt_m(1'030'000), 306.0, 1e-9);
  EXPECT_NEAR(*inputs_.rangeAt_m(1'020'000), 304.0, 1e-9);
  // Newer than every reading: the latest.
  EXPECT_NEAR(*inputs_.rangeAt_m(1'050'000), 308.0, 1e-9);
  // Older than every reading kept: none.
  EXPECT_FALSE(inputs_.rangeAt_m(999'999));
}

TEST_F(FlightInputsTest, AnInvalidReadingAroundTheImageGivesNoRange) {
  range(1'000'000, 300.0);
  range(1'020'000, 0.0, false);
  EXPECT_FALSE(inputs_.rangeAt_m(1'010'000));
  EXPECT_FALSE(inputs_.rangeAt_m(1'030'000));
  range(1'040'000, 308.0);
  EXPECT_FALSE(inputs_.rangeAt_m(1'030'000));
  EXPECT_NEAR(*inputs_.rangeAt_m(1'045'000), 308.0, 1e-9);
}

}  // namespace
}  // namespace nadir::nodes
