#pragma once
// Where a program's wall time goes: time summed per named stage, stages
// nested within stages, for `nadir run --timing` and the benchmarks
// (docs/benchmarks.md). Off until enabled; then a stage costs two clock reads
// and a short lock, and while off one relaxed load.

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace nadir::core {

struct StageTime {
  // The enclosing stages' names and its own, joined by '/': "camera/draw".
  std::string path;
  std::int64_t calls = 0;
  double total_s = 0.0;
};

// Starts (or stops) timing stages, process-wide.
void enableStageTimes(bool enabled);
bool stageTimesEnabled();
// Forgets what was timed so far.
void clearStageTimes();
// Every stage timed so far, in the order each was first entered.
std::vector<StageTime> stageTimes();
// Adds time measured elsewhere (a VO's own stage clocks) as the stage name,
// inside whatever stage this thread is in. Nothing while off.
void addStageTime(std::string_view name, double seconds, std::int64_t calls = 1);

// Times its scope as the stage name, inside whatever stage this thread is in.
// name must outlive the scope (a literal, or a static string).
class [[nodiscard]] ScopedStage {
 public:
  explicit ScopedStage(std::string_view name);
  ~ScopedStage();
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  bool active_ = false;
  std::chrono::steady_clock::time_point start_;
};

// A table of the stages as a tree: calls, total s, ms per frame (per_frame
// frames; none when 0) and share of wall_s, with each stage's time outside
// its sub-stages on a "(rest)" line.
std::string formatStageTimes(const std::vector<StageTime>& stages, double wall_s,
                             std::int64_t frames);

}  // namespace nadir::core
