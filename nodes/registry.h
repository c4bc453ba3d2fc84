#pragma once
// The node registry: one entry per node (its name, its parameters, how it is
// built on a bus, what it publishes), which the node programs, `nadir run`,
// `nadir launch` and `nadir sweep` iterate over. Adding a node is its folder
// under nodes/ with an entry there, and one line in registry.cpp.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/bus.h"
#include "core/params.h"
#include "logs/course_metrics.h"
#include "logs/run_log.h"

namespace nadir::terrain {
class World;
}

namespace nadir::nodes {

struct ScenarioParams;

// A node at work on a bus, built the same way for a batch run (memq, sim time)
// and a live process (UDP). It is told of messages through the subscriptions it
// made; it outlives none of them.
class Node {
 public:
  virtual ~Node() = default;
  // Live: one turn of the process's loop; false when the node is done (the
  // simulator at the end of its flight). Reactive nodes wait for messages.
  virtual bool turn(core::Bus& bus);
  // What it has done so far, in one line: the heartbeat's and the last line's.
  virtual std::string summary() const = 0;
  // What it works on (its world, its renderer), printed once when it starts.
  virtual std::string describe() const { return {}; }
  // This process replaces one that died (nadir launch --restart): a VO node
  // counts its fresh start as a reset, so its num_resets goes on from
  // resets_before and a reader sees its estimate restart. Others ignore it.
  virtual void continueResetCount(int resets_before) { (void)resets_before; }
};

// A stream a node publishes, for launch's health report and sweeps' logs.
struct Stream {
  std::string channel;
  double rate_hz = 0.0;  // expected, in sim time; 0 when it follows its input
  bool bulky = false;    // images: left out of sweep logs
};

// What a node may add to a batch run's results (the PPA's target passes).
struct BatchReportInput {
  const ScenarioParams& scenario;
  std::string log_path;                   // the run's recording
  const logs::LogTrajectories& recorded;  // its truth and estimates, as evaluated
  std::string out_dir;                    // where the run's files go
  const terrain::World& world;
  // Where a node puts a ground vehicle's course it scored (for metrics.json).
  std::optional<logs::CourseMetrics>* course = nullptr;
};

struct EntryInfo {
  std::string name;         // "ppa": scenario group, source name in metrics, log names
  std::string program;      // "nadir-ppa"
  std::string description;  // one line for --help
  std::string default_scenario;
  // Where the node sits in a run: the simulator drives time (launch starts it
  // last); the camera renders the world (a batch run builds it with the world);
  // the VO nodes process what the others publish.
  enum class Role { kSimulator, kCamera, kProcessing };
  Role role = Role::kProcessing;
};

class Entry {
 public:
  virtual ~Entry() = default;
  const EntryInfo& info() const { return info_; }

  // The node's group in a scenario (its name as key) with its defaults and
  // documentation; nothing for the simulator and the camera, whose parameters
  // are the scenario's top-level keys.
  virtual std::optional<core::AnyParams> scenarioGroup() const { return std::nullopt; }
  virtual std::string scenarioGroupDoc() const { return {}; }
  // Whether a scenario runs it (its group's `enabled`).
  virtual bool enabled(const ScenarioParams& scenario) const = 0;

  // Everything the node needs (what --config reads, what it prints at start).
  virtual core::AnyParams defaultParams() const = 0;
  virtual core::AnyParams fromScenario(const ScenarioParams& scenario) const = 0;
  // For byte-identical batch runs, sets the node's group in the scenario so that
  // no wall-clock time or thread timing reaches its output.
  virtual void makeDeterministic(ScenarioParams& scenario) const { (void)scenario; }

  // Builds the node on the bus; throws naming what is wrong in the params.
  virtual std::unique_ptr<Node> start(core::Bus& bus, const core::AnyParams& params) const = 0;
  // The channels each of whose messages waits until the node has finished
  // with everything before it (its camera's frames). In `nadir run` a node
  // with any works on its own thread beside the camera (core/worker_bus.h).
  virtual std::set<std::string> pacedChannels(const core::AnyParams& params) const {
    (void)params;
    return {};
  }
  virtual std::vector<Stream> streams(const core::AnyParams& params) const = 0;
  // A section for a batch run's results table; empty for none.
  virtual std::string batchReport(const BatchReportInput& input,
                                  const core::AnyParams& params) const {
    (void)input;
    (void)params;
    return {};
  }

 protected:
  explicit Entry(EntryInfo info) : info_(std::move(info)) {}

 private:
  EntryInfo info_;
};

// An entry whose node takes parameters of type P: the type-erased calls cast once.
template <class P>
class TypedEntry : public Entry {
 public:
  core::AnyParams defaultParams() const override { return core::AnyParams(P{}); }
  core::AnyParams fromScenario(const ScenarioParams& scenario) const override {
    return core::AnyParams(paramsFrom(scenario));
  }
  std::unique_ptr<Node> start(core::Bus& bus, const core::AnyParams& params) const override {
    return build(bus, params.as<P>());
  }
  std::set<std::string> pacedChannels(const core::AnyParams& params) const override {
    return paced(params.as<P>());
  }
  std::vector<Stream> streams(const core::AnyParams& params) const override {
    return publishes(params.as<P>());
  }
  std::string batchReport(const BatchReportInput& input,
                          const core::AnyParams& params) const override {
    return report(input, params.as<P>());
  }

 protected:
  using Entry::Entry;
  virtual P paramsFrom(const ScenarioParams& scenario) const = 0;
  virtual std::unique_ptr<Node> build(core::Bus& bus, const P& params) const = 0;
  virtual std::vector<Stream> publishes(const P& params) const = 0;
  virtual std::set<std::string> paced(const P& params) const {
    (void)params;
    return {};
  }
  virtual std::string report(const BatchReportInput& input, const P& params) const {
    (void)input;
    (void)params;
    return {};
  }
};

// Every node, in the order launch starts them (the simulator last) and a scenario
// lists their groups.
const std::vector<std::unique_ptr<Entry>>& registry();

// The entry named `name`; throws std::invalid_argument listing the names.
const Entry& entry(std::string_view name);

// The rate of every stream with one that the nodes a scenario runs publish,
// by channel (Hz of sim time): what a receiver counts its losses against.
std::map<std::string, double> expectedRates(const ScenarioParams& scenario);

}  // namespace nadir::nodes
