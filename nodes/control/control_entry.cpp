// The rover controller's registry entry: its scenario group, and the course's
// results it adds to a batch run (gates passed, missed and hit, speeds, the
// pipeline's time per frame and the camera-to-command latency).

#include <sstream>

#include "nodes/control/control_node.h"
#include "nodes/registry.h"
#include "nodes/scenario.h"

namespace nadir::nodes {
namespace {

using control::ControlNodeParams;

class ControlLiveNode final : public Node {
 public:
  ControlLiveNode(core::Bus& bus, const ControlNodeParams& params) : node_(bus, params) {}

  std::string summary() const override {
    const control::ControlCounts& counts = node_.counts();
    const std::vector<std::int64_t>& modes = node_.modes();
    std::ostringstream out;
    out << counts.patterns << " patterns, " << counts.commands << " commands (" << modes[0]
        << " tracking, " << modes[1] << " coasting, " << modes[2] << " stopping, " << modes[3]
        << " turning, " << modes[4] << " stopped)";
    if (counts.without_lens > 0) out << "; " << counts.without_lens << " before the lens was known";
    if (counts.dropped > 0)
      out << "; dropped " << counts.dropped << " messages, the first: " << node_.firstDropReason();
    return out.str();
  }

 private:
  control::ControlNode node_;
};

class ControlEntry final : public TypedEntry<ControlNodeParams> {
 public:
  ControlEntry()
      : TypedEntry({.name = control::kControlName,
                    .program = "nadir-control",
                    .description = "the rover's reactive controller: PPA patterns in, steering "
                                   "and speed out",
                    .default_scenario = "gates",
                    .role = EntryInfo::Role::kProcessing}) {}

  std::optional<core::AnyParams> scenarioGroup() const override {
    return core::AnyParams(ControlNodeParams{});
  }
  std::string scenarioGroupDoc() const override {
    return "the rover's reactive controller (nadir-control)";
  }
  bool enabled(const ScenarioParams& scenario) const override {
    return scenario.node<ControlNodeParams>(info().name).enabled;
  }

 protected:
  ControlNodeParams paramsFrom(const ScenarioParams& scenario) const override {
    return scenario.node<ControlNodeParams>(info().name);
  }
  std::unique_ptr<Node> build(core::Bus& bus, const ControlNodeParams& params) const override {
    return std::make_unique<ControlLiveNode>(bus, params);
  }
  std::vector<Stream> publishes(const ControlNodeParams& params) const override {
    return {{.channel = params.command_channel}};
  }
};

}  // namespace

std::unique_ptr<Entry> controlEntry() { return std::make_unique<ControlEntry>(); }

}  // namespace nadir::nodes
