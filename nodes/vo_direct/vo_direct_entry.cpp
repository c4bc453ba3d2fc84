// The direct VO's registry entry: its scenario group is its params.

#include "nodes/common/vo_node_summary.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"
#include "nodes/vo_direct/vo_direct_node.h"

namespace nadir::nodes {
namespace {

class VoDirectLiveNode final : public Node {
 public:
  VoDirectLiveNode(core::Bus& bus, const vo::VoDirectNodeParams& params) : node_(bus, params) {}

  std::string summary() const override { return voNodeSummary(node_); }
  void continueResetCount(int resets_before) override { node_.continueResetCount(resets_before); }

 private:
  vo::VoDirectNode node_;
};

class VoDirectEntry final : public TypedEntry<vo::VoDirectNodeParams> {
 public:
  VoDirectEntry()
      : TypedEntry({.name = vo::kDirectSourceName,
                    .program = "nadir-vo-direct",
                    .description = "direct (photometric) monocular visual odometry over LCM",
                    .default_scenario = "thesis-oscillating",
                    .role = EntryInfo::Role::kProcessing}) {}

  std::optional<core::AnyParams> scenarioGroup() const override {
    return core::AnyParams(vo::VoDirectNodeParams{});
  }
  std::string scenarioGroupDoc() const override { return "the direct VO (nadir-vo-direct)"; }
  bool enabled(const ScenarioParams& scenario) const override {
    return scenario.node<vo::VoDirectNodeParams>(info().name).enabled;
  }
  // No wall-clock times in the estimates.
  void makeDeterministic(ScenarioParams& scenario) const override {
    auto& params = scenario.node<vo::VoDirectNodeParams>(info().name);
    params.wall_clock_timing = false;
  }

 protected:
  vo::VoDirectNodeParams paramsFrom(const ScenarioParams& scenario) const override {
    return scenario.node<vo::VoDirectNodeParams>(info().name);
  }
  std::unique_ptr<Node> build(core::Bus& bus, const vo::VoDirectNodeParams& params) const override {
    return std::make_unique<VoDirectLiveNode>(bus, params);
  }
  std::set<std::string> paced(const vo::VoDirectNodeParams& params) const override {
    return {params.image_channel};
  }
  std::vector<Stream> publishes(const vo::VoDirectNodeParams& params) const override {
    return {{.channel = params.pose_channel}, {.channel = params.debug_channel, .bulky = true}};
  }
};

}  // namespace

std::unique_ptr<Entry> voDirectEntry() { return std::make_unique<VoDirectEntry>(); }

}  // namespace nadir::nodes
