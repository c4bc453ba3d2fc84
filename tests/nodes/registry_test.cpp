// The node registry: every node listed once with a program, its parameters good
// for a --config file, its group in a scenario, and the streams it publishes.

#include "nodes/registry.h"

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <string>

#include "core/params.h"
#include "nodes/scenario.h"

namespace nadir::nodes {
namespace {

// Each node once, named and with a program; the simulator last (launch starts it last).
TEST(Registry, ListsEveryNodeOnceWithTheSimulatorLast) {
  std::set<std::string> names, programs;
  for (const auto& entry : registry()) {
    EXPECT_TRUE(names.insert(entry->info().name).second) << entry->info().name;
    EXPECT_TRUE(programs.insert(entry->info().program).second) << entry->info().program;
    EXPECT_EQ(entry->info().program.rfind("nadir-", 0), 0u) << entry->info().program;
  }
  EXPECT_EQ(names, (std::set<std::string>{"sim", "camera", "ppa", "vo_feature", "vo_direct", "nav",
                                          "control"}));
  EXPECT_EQ(registry().back()->info().role, EntryInfo::Role::kSimulator);
  EXPECT_EQ(&entry("ppa"), registry()[1].get());
  try {
    entry("vo_nothing");
    FAIL() << "an unknown node was found";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(
        std::string(error.what()).find("camera, ppa, vo_feature, vo_direct, nav, control, sim"),
        std::string::npos)
        << error.what();
  }
}

// A processing node's group is in every scenario, under its name, and the
// scenario's value reaches the node's params; the others have no group.
TEST(Registry, ProcessingNodesHaveTheirScenarioGroup) {
  const ScenarioParams scenario =
      loadScenario("default", {"ppa.enabled=true", "ppa.pose_channel=MY_PPA"});
  for (const auto& entry : registry()) {
    const bool processing = entry->info().role == EntryInfo::Role::kProcessing;
    EXPECT_EQ(entry->scenarioGroup().has_value(), processing) << entry->info().name;
  }
  ASSERT_EQ(scenario.nodes.size(), 5u);
  EXPECT_EQ(scenario.nodes[0].name, "ppa");
  EXPECT_EQ(scenario.nodes[1].name, "vo_feature");
  EXPECT_EQ(scenario.nodes[2].name, "vo_direct");
  EXPECT_EQ(scenario.nodes[3].name, "nav");
  EXPECT_EQ(scenario.nodes[4].name, "control");
  EXPECT_TRUE(entry("ppa").enabled(scenario));
  EXPECT_TRUE(entry("vo_feature").enabled(scenario));  // default.yaml enables both VOs
  EXPECT_TRUE(entry("vo_direct").enabled(scenario));
  EXPECT_TRUE(entry("nav").enabled(scenario));       // and the filter
  EXPECT_FALSE(entry("control").enabled(scenario));  // no rover to steer
  bool renamed = false;
  for (const Stream& stream : entry("ppa").streams(entry("ppa").fromScenario(scenario))) {
    renamed = renamed || stream.channel == "MY_PPA";
  }
  EXPECT_TRUE(renamed);
}

// Every node's parameters, written out as its effective parameters are printed,
// read back as a --config file: the same text again.
TEST(Registry, DefaultParamsRoundTripThroughAConfigFile) {
  for (const auto& entry : registry()) {
    core::AnyParams params = entry->defaultParams();
    const std::string text = core::formatParamsOf(params);
    const std::string path =
        ::testing::TempDir() + "nadir_registry_" + entry->info().name + ".yaml";
    std::ofstream(path) << text;
    core::AnyParams read = entry->defaultParams();
    core::applyYamlFile(path, [&read](core::ParamVisitor& v) { read.visit(v); });
    EXPECT_EQ(core::formatParamsOf(read), text) << entry->info().name;
  }
}

// What launch expects of a scenario: the truth at its rate, each camera at its frames/s.
TEST(Registry, StreamsSayWhatLaunchShouldExpect) {
  const ScenarioParams scenario = loadScenario("scamp-rectangle");
  const auto rateOf = [&](const std::string& node, const std::string& channel) {
    for (const Stream& stream : entry(node).streams(entry(node).fromScenario(scenario))) {
      if (stream.channel == channel) return stream.rate_hz;
    }
    return -1.0;
  };
  EXPECT_EQ(rateOf("sim", "POSE_TRUTH"), 400.0);
  EXPECT_EQ(rateOf("camera", "CAMERA_PPA"), 200.0);
  EXPECT_EQ(rateOf("ppa", "POSE_PPA"), 0.0);
}

}  // namespace
}  // namespace nadir::nodes
