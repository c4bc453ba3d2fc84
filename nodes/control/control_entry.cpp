// The rover controller's registry entry: its scenario group, and the course's
// results it adds to a batch run (gates passed, missed and hit, speeds, the
// pipeline's time per frame and the camera-to-command latency).

#include <filesystem>
#include <sstream>

#include "core/lcm_log.h"
#include "lcmtypes/codec.h"
#include "nodes/control/control_node.h"
#include "nodes/control/course_results.h"
#include "nodes/ppa/ppa_node_params.h"
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

// The PPA's pattern frames and the controller's commands in a recording.
void readPipeline(const std::string& log_path, const std::string& pattern_channel,
                  const std::string& command_channel, control::CourseRunInput& input) {
  core::LcmLogReader reader(log_path);
  while (const std::optional<core::LogEvent> event = reader.next()) {
    try {
      if (event->channel == pattern_channel) {
        const msg::GatePattern p = msg::decode<msg::GatePattern>(event->data);
        input.frames.push_back({p.utime, p.threshold_instructions, p.flood_instructions,
                                p.denoise_instructions, p.coordinates_instructions, p.chip_time_s});
      } else if (event->channel == command_channel) {
        const msg::DriveCommand c = msg::decode<msg::DriveCommand>(event->data);
        input.commands.push_back({c.frame_utime, c.utime, c.steer_rad});
      }
    } catch (const std::exception&) {
      // Not a message of the kind the channel should carry: not this run's pipeline.
    }
  }
}

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

  // The course scored from the truth (course in metrics.json).
  std::string report(const BatchReportInput& input,
                     const ControlNodeParams& params) const override {
    control::CourseRunInput course;
    course.boards = terrain::courseBoards(input.scenario.course);
    if (course.boards.empty() || input.recorded.truth.size() < 2) return {};
    course.truth = input.recorded.truth;
    const sim::RoverParams& rover = input.scenario.sim.vehicle.rover;
    course.footprint = {rover.length_m, rover.width_m, rover.rear_overhang_m};
    const auto& ppa = input.scenario.node<ppa::PpaNodeParams>("ppa");
    course.chip_instruction_rate_hz = ppa.chip_instruction_rate_hz;
    course.transfer_s = params.transfer_s;
    course.compute_s = params.compute_s;
    readPipeline(input.log_path, params.pattern_channel, params.command_channel, course);
    const logs::CourseMetrics metrics = control::courseResults(course);
    if (input.course != nullptr) *input.course = metrics;
    const std::filesystem::path out(input.out_dir);
    control::writeCoursePlots(course, metrics, (out / "course.png").string(),
                              (out / "steering.png").string());
    return control::formatCourse(metrics) + "pictures: " + (out / "course.png").string() + ", " +
           (out / "steering.png").string() + "\n";
  }
};

}  // namespace

std::unique_ptr<Entry> controlEntry() { return std::make_unique<ControlEntry>(); }

}  // namespace nadir::nodes
