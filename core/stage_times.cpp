#include "core/stage_times.h"

#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <unordered_map>

namespace nadir::core {
namespace {

struct Table {
  std::mutex mutex;
  std::unordered_map<std::string, std::size_t> index;  // path -> position in stages
  std::vector<StageTime> stages;
};

Table& table() {
  static Table instance;
  return instance;
}

std::atomic<bool> g_enabled{false};

// This thread's open stages, innermost last.
thread_local std::vector<std::string_view> t_open;

void add(const std::string& path, double seconds, std::int64_t calls) {
  Table& t = table();
  const std::lock_guard lock(t.mutex);
  const auto [found, inserted] = t.index.try_emplace(path, t.stages.size());
  if (inserted) t.stages.push_back({path, 0, 0.0});
  StageTime& stage = t.stages[found->second];
  stage.calls += calls;
  stage.total_s += seconds;
}

// The path of a stage named innermost inside this thread's open stages.
std::string openPath(std::string_view innermost) {
  std::string path;
  for (const std::string_view name : t_open) {
    path += name;
    path += '/';
  }
  path += innermost;
  return path;
}

struct Node {
  std::string name;
  std::int64_t calls = 0;
  double total_s = 0.0;
  bool timed = false;  // its own time was measured (not only its sub-stages')
  std::vector<std::unique_ptr<Node>> children;

  Node& child(const std::string& child_name) {
    for (auto& c : children)
      if (c->name == child_name) return *c;
    children.push_back(std::make_unique<Node>());
    children.back()->name = child_name;
    return *children.back();
  }
  double seconds() const {
    if (timed) return total_s;
    double sum = 0.0;
    for (const auto& c : children) sum += c->seconds();
    return sum;
  }
};

void formatRow(std::string& out, int depth, const std::string& name, std::int64_t calls,
               double seconds, double wall_s, std::int64_t frames) {
  char line[256];
  const std::string label = std::string(static_cast<std::size_t>(2 * depth), ' ') + name;
  const std::string calls_text = calls > 0 ? std::to_string(calls) : "";
  char per_frame[32] = "";
  if (frames > 0)
    std::snprintf(per_frame, sizeof per_frame, "%.3f",
                  1000.0 * seconds / static_cast<double>(frames));
  std::snprintf(line, sizeof line, "%-40s %9s %10.3f %10s %7.1f\n", label.c_str(),
                calls_text.c_str(), seconds, per_frame,
                wall_s > 0.0 ? 100.0 * seconds / wall_s : 0.0);
  out += line;
}

void formatNode(std::string& out, const Node& node, int depth, double wall_s, std::int64_t frames) {
  formatRow(out, depth, node.name, node.calls, node.seconds(), wall_s, frames);
  if (node.children.empty()) return;
  double children_s = 0.0;
  for (const auto& c : node.children) {
    formatNode(out, *c, depth + 1, wall_s, frames);
    children_s += c->seconds();
  }
  if (node.timed) formatRow(out, depth + 1, "(rest)", 0, node.total_s - children_s, wall_s, frames);
}

}  // namespace

void enableStageTimes(bool enabled) { g_enabled.store(enabled, std::memory_order_relaxed); }

bool stageTimesEnabled() { return g_enabled.load(std::memory_order_relaxed); }

void clearStageTimes() {
  Table& t = table();
  const std::lock_guard lock(t.mutex);
  t.index.clear();
  t.stages.clear();
}

std::vector<StageTime> stageTimes() {
  Table& t = table();
  const std::lock_guard lock(t.mutex);
  return t.stages;
}

void addStageTime(std::string_view name, double seconds, std::int64_t calls) {
  if (stageTimesEnabled()) add(openPath(name), seconds, calls);
}

ScopedStage::ScopedStage(std::string_view name) {
  if (!stageTimesEnabled()) return;
  active_ = true;
  t_open.push_back(name);
  start_ = std::chrono::steady_clock::now();
}

ScopedStage::~ScopedStage() {
  if (!active_) return;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const std::string_view name = t_open.back();
  t_open.pop_back();
  add(openPath(name), seconds, 1);
}

std::string formatStageTimes(const std::vector<StageTime>& stages, double wall_s,
                             std::int64_t frames) {
  Node root;
  for (const StageTime& stage : stages) {
    Node* node = &root;
    std::size_t begin = 0;
    while (true) {
      const std::size_t slash = stage.path.find('/', begin);
      node = &node->child(stage.path.substr(begin, slash - begin));
      if (slash == std::string::npos) break;
      begin = slash + 1;
    }
    node->calls += stage.calls;
    node->total_s += stage.total_s;
    node->timed = true;
  }
  char header[256];
  std::snprintf(header, sizeof header, "%-40s %9s %10s %10s %7s\n", "stage", "calls", "total s",
                frames > 0 ? "ms/frame" : "", "% wall");
  std::string out = header;
  for (const auto& top : root.children) formatNode(out, *top, 0, wall_s, frames);
  return out;
}

}  // namespace nadir::core
