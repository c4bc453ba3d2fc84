#include "nodes/registry.h"

#include <chrono>
#include <stdexcept>

namespace nadir::nodes {

// Each node's entry, defined in its folder (nodes/<name>/<name>_entry.cpp).
std::unique_ptr<Entry> cameraEntry();
std::unique_ptr<Entry> ppaEntry();
std::unique_ptr<Entry> voFeatureEntry();
std::unique_ptr<Entry> voDirectEntry();
std::unique_ptr<Entry> navEntry();
std::unique_ptr<Entry> controlEntry();
std::unique_ptr<Entry> simEntry();

bool Node::turn(core::Bus& bus) {
  bus.handle(std::chrono::milliseconds(100));
  return true;
}

const std::vector<std::unique_ptr<Entry>>& registry() {
  static const std::vector<std::unique_ptr<Entry>> entries = [] {
    std::vector<std::unique_ptr<Entry>> list;
    list.push_back(cameraEntry());
    list.push_back(ppaEntry());
    list.push_back(voFeatureEntry());
    list.push_back(voDirectEntry());
    list.push_back(navEntry());
    list.push_back(controlEntry());
    list.push_back(simEntry());
    return list;
  }();
  return entries;
}

const Entry& entry(std::string_view name) {
  std::string names;
  for (const auto& candidate : registry()) {
    if (candidate->info().name == name) return *candidate;
    names += (names.empty() ? "" : ", ") + candidate->info().name;
  }
  throw std::invalid_argument("no node named '" + std::string(name) + "' (nodes: " + names + ")");
}

std::map<std::string, double> expectedRates(const ScenarioParams& scenario) {
  std::map<std::string, double> rates;
  for (const auto& node : registry()) {
    if (!node->enabled(scenario)) continue;
    for (const Stream& stream : node->streams(node->fromScenario(scenario))) {
      if (stream.rate_hz > 0.0) rates[stream.channel] = stream.rate_hz;
    }
  }
  return rates;
}

}  // namespace nadir::nodes
