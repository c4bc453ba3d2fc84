// Stage timers: nesting gives paths, time added by hand is summed exactly, and
// the table's figures are the ones worked out by hand below.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "core/stage_times.h"

namespace nadir::core {
namespace {

class StageTimes : public ::testing::Test {
 protected:
  void SetUp() override {
    clearStageTimes();
    enableStageTimes(true);
  }
  void TearDown() override {
    enableStageTimes(false);
    clearStageTimes();
  }
};

const StageTime* find(const std::vector<StageTime>& stages, const std::string& path) {
  for (const StageTime& stage : stages)
    if (stage.path == path) return &stage;
  return nullptr;
}

TEST_F(StageTimes, NestedScopesAreTimedUnderTheirEnclosingStage) {
  for (int i = 0; i < 3; ++i) {
    const ScopedStage frame("frame");
    { const ScopedStage draw("draw"); }
    const ScopedStage readback("readback");
  }
  const std::vector<StageTime> stages = stageTimes();
  ASSERT_EQ(stages.size(), 3u);
  const StageTime* frame = find(stages, "frame");
  const StageTime* draw = find(stages, "frame/draw");
  const StageTime* readback = find(stages, "frame/readback");
  ASSERT_TRUE(frame && draw && readback);
  EXPECT_EQ(frame->calls, 3);
  EXPECT_EQ(draw->calls, 3);
  EXPECT_EQ(readback->calls, 3);
  // A stage encloses its sub-stages on one steady clock.
  EXPECT_GE(frame->total_s, draw->total_s + readback->total_s);
}

TEST_F(StageTimes, TimeAddedByHandIsSummedUnderTheOpenStage) {
  {
    const ScopedStage process("process");
    addStageTime("extract", 0.25);
    addStageTime("extract", 0.5, 2);
  }
  addStageTime("setup", 1.5);
  const std::vector<StageTime> stages = stageTimes();
  const StageTime* extract = find(stages, "process/extract");
  const StageTime* setup = find(stages, "setup");
  ASSERT_TRUE(extract && setup);
  EXPECT_EQ(extract->calls, 3);
  EXPECT_DOUBLE_EQ(extract->total_s, 0.75);
  EXPECT_DOUBLE_EQ(setup->total_s, 1.5);
}

TEST_F(StageTimes, EachThreadNestsItsOwnStages) {
  const ScopedStage main_stage("main");
  std::thread worker([] {
    const ScopedStage stage("worker");
    addStageTime("part", 1.0);
  });
  worker.join();
  const std::vector<StageTime> stages = stageTimes();
  EXPECT_NE(find(stages, "worker"), nullptr);
  EXPECT_NE(find(stages, "worker/part"), nullptr);
  EXPECT_EQ(find(stages, "main/worker"), nullptr);
}

TEST_F(StageTimes, NothingIsTimedWhileOff) {
  enableStageTimes(false);
  {
    const ScopedStage stage("off");
    addStageTime("added", 1.0);
  }
  EXPECT_TRUE(stageTimes().empty());
}

TEST(StageTimesTable, GivesEachStageItsShareAndTheRestOfItsParent) {
  // a: 2.0 s, of which a/b 0.5 s, so 1.5 s of a is outside b; c: 1.0 s.
  // Over 4 s of wall and 10 frames: a 200 ms/frame and 50 %, b 50 ms and
  // 12.5 %, the rest of a 150 ms and 37.5 %, c 100 ms and 25 %.
  const std::vector<StageTime> stages = {{"a/b", 1, 0.5}, {"a", 2, 2.0}, {"c", 1, 1.0}};
  const std::string table = formatStageTimes(stages, 4.0, 10);
  const auto line = [&table](const std::string& label) {
    const std::size_t at = table.find(label);
    return at == std::string::npos ? std::string() : table.substr(at, table.find('\n', at) - at);
  };
  EXPECT_NE(line("a  ").find("2.000    200.000    50.0"), std::string::npos) << table;
  EXPECT_NE(line("  b  ").find("0.500     50.000    12.5"), std::string::npos) << table;
  EXPECT_NE(line("  (rest)").find("1.500    150.000    37.5"), std::string::npos) << table;
  EXPECT_NE(line("c  ").find("1.000    100.000    25.0"), std::string::npos) << table;
  // The tree keeps a before c, and b under a.
  EXPECT_LT(table.find("\na "), table.find("  b "));
  EXPECT_LT(table.find("  b "), table.find("\nc "));
}

}  // namespace
}  // namespace nadir::core
