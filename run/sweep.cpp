#include "run/sweep.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/csv.h"
#include "core/params.h"
#include "run/process.h"
#include "run/yaml_file.h"

namespace nadir::run {
namespace {

namespace fs = std::filesystem;

std::string lastPart(const std::string& key) {
  const auto dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

constexpr std::size_t kMaxCellNameBytes = 200;
// More runs than anyone flies in one sweep: a typing slip, refused before the
// plan of its cells fills the memory.
constexpr double kMaxCells = 10000;

// Text as part of a folder name: letters, digits and ._+-= kept, anything else
// (a '/', a space) '_'. The cell's number keeps two names apart.
std::string folderSafe(const std::string& text) {
  std::string safe = text;
  for (char& c : safe) {
    if (std::isalnum(static_cast<unsigned char>(c)) == 0 &&
        std::string_view("._+-=").find(c) == std::string_view::npos)
      c = '_';
  }
  return safe;
}

// The sources any cell reports, in name order.
std::vector<std::string> sourceNames(const std::vector<SweepCell>& cells) {
  std::set<std::string> names;
  for (const SweepCell& cell : cells) {
    if (!cell.metrics) continue;
    for (const auto& entry : cell.metrics->sources) names.insert(entry.first);
  }
  return {names.begin(), names.end()};
}

// A source's resets: the count, or "-" where it is not known.
std::string resetsText(const eval::SourceMetrics& m) {
  return m.resets ? std::to_string(*m.resets) : "-";
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", value);
  return text;
}

const eval::SourceMetrics* sourceOf(const SweepCell& cell, const std::string& name) {
  if (!cell.metrics) return nullptr;
  const auto it = cell.metrics->sources.find(name);
  return it == cell.metrics->sources.end() ? nullptr : &it->second;
}

}  // namespace

std::vector<std::string> SweepAxis::overrides(std::size_t i) const {
  if (!variants.empty()) return variants.at(i);
  return {key + "=" + values.at(i)};
}

SweepSpec loadSweep(const std::string& path) {
  const YAML::Node root = loadYamlFile(path, "sweep file");
  if (!root.IsMap())
    throw core::ParamError(path + ": expected a map (scenario, out, jobs, set, axes)");
  SweepSpec spec;
  std::set<std::string> seen;
  for (const auto& entry : root) {
    const std::string key = keyText(path, entry.first, "sweep file");
    if (!seen.insert(key).second) failAt(path, entry.first, key, "given twice");
    const YAML::Node& value = entry.second;
    try {
      if (key == "scenario") {
        spec.scenario = value.as<std::string>();
      } else if (key == "out") {
        spec.out_dir = value.as<std::string>();
      } else if (key == "jobs") {
        spec.jobs = value.as<int>();
        if (spec.jobs < 1) failAt(path, value, key, "must be at least 1");
      } else if (key == "images") {
        spec.images = value.as<bool>();
      } else if (key == "slurm") {
        if (!value.IsMap())
          failAt(path, value, key, "expected a map (cpus_per_task, mem, time, ...)");
        for (const auto& field : value) {
          const std::string name = keyText(path, field.first, "slurm");
          const std::string where = "slurm." + name;
          try {
            if (name == "cpus_per_task") {
              spec.slurm.cpus_per_task = field.second.as<int>();
              if (spec.slurm.cpus_per_task < 1)
                failAt(path, field.second, where, "must be at least 1");
            } else if (name == "mem") {
              spec.slurm.mem = field.second.as<std::string>();
            } else if (name == "time") {
              spec.slurm.time = field.second.as<std::string>();
            } else if (name == "partition") {
              spec.slurm.partition = field.second.as<std::string>();
            } else if (name == "account") {
              spec.slurm.account = field.second.as<std::string>();
            } else if (name == "extra") {
              spec.slurm.extra = field.second.as<std::vector<std::string>>();
            } else {
              failAt(path, field.first, where,
                     "unknown key (known: cpus_per_task, mem, time, partition, account, extra)");
            }
          } catch (const YAML::BadConversion&) {
            failAt(path, field.second, where, "has the wrong type");
          }
        }
      } else if (key == "set") {
        spec.shared_overrides = value.as<std::vector<std::string>>();
      } else if (key == "axes") {
        if (!value.IsMap()) failAt(path, value, key, "expected a map of key: [values]");
        std::set<std::string> axis_keys;
        for (const auto& axis : value) {
          SweepAxis parsed{keyText(path, axis.first, "axes"), {}, {}};
          if (!axis_keys.insert(parsed.key).second) {
            failAt(path, axis.first, "axes." + parsed.key, "given twice");
          }
          const std::string where = "axes." + parsed.key;
          if (axis.second.IsMap() && axis.second.size() > 0) {
            for (const auto& variant : axis.second) {
              const std::string name = keyText(path, variant.first, where);
              if (!variant.second.IsSequence())
                failAt(path, variant.second, where + "." + name, "expected a list of key=value");
              std::vector<std::string> overrides;
              for (const auto& v : variant.second) {
                if (!v.IsScalar() || v.Scalar().find('=') == std::string::npos)
                  failAt(path, v, where + "." + name,
                         "expected key=value, got '" + v.Scalar() + "'");
                overrides.push_back(v.Scalar());
              }
              parsed.values.push_back(name);
              parsed.variants.push_back(std::move(overrides));
            }
          } else if (axis.second.IsSequence() && axis.second.size() > 0) {
            for (const auto& v : axis.second) {
              if (!v.IsScalar()) failAt(path, v, where, "values must be scalars");
              parsed.values.push_back(v.Scalar());
            }
          } else {
            failAt(path, axis.second, where,
                   "expected a non-empty list of values or a map of named variants");
          }
          spec.axes.push_back(std::move(parsed));
        }
      } else {
        failAt(path, entry.first, key,
               "unknown key (known: scenario, out, jobs, set, images, axes, slurm)");
      }
    } catch (const YAML::BadConversion&) {
      failAt(path, value, key, "has the wrong type");
    }
  }
  if (spec.scenario.empty()) throw core::ParamError(path + ": scenario: missing");
  if (spec.axes.empty()) throw core::ParamError(path + ": axes: missing (nothing to sweep)");
  double cells = 1.0;
  for (const SweepAxis& axis : spec.axes) {
    if (axis.values.empty()) {
      throw core::ParamError(path + ": axes." + axis.key + ": no values (nothing to sweep)");
    }
    cells *= static_cast<double>(axis.values.size());
  }
  if (cells > kMaxCells) {
    throw core::ParamError(path + ": axes: " + std::to_string(static_cast<long long>(cells)) +
                           " cells, more than a sweep plans (" +
                           std::to_string(static_cast<long long>(kMaxCells)) + ")");
  }
  return spec;
}

std::vector<SweepCell> planSweep(const SweepSpec& spec) {
  std::vector<SweepCell> cells(1);
  for (const SweepAxis& axis : spec.axes) {
    std::vector<SweepCell> next;
    for (const SweepCell& cell : cells) {
      for (const std::string& value : axis.values) {
        SweepCell extended = cell;
        extended.values.push_back(value);
        next.push_back(std::move(extended));
      }
    }
    cells = std::move(next);
  }
  for (std::size_t i = 0; i < cells.size(); ++i) {
    char index[32];
    std::snprintf(index, sizeof(index), "%03zu", i);
    std::string name = std::string("cell_") + index;
    for (std::size_t a = 0; a < spec.axes.size(); ++a) {
      name.append(1, '_')
          .append(folderSafe(lastPart(spec.axes[a].key)))
          .append(1, '=')
          .append(folderSafe(cells[i].values[a]));
    }
    // Within a file name's 255 bytes, with room for the sweep's own suffixes.
    if (name.size() > kMaxCellNameBytes) name.resize(kMaxCellNameBytes);
    cells[i].out_dir = (fs::path(spec.out_dir) / name).string();
  }
  return cells;
}

std::string describeProgress(const SweepProgress& p) {
  char text[256];
  std::snprintf(text, sizeof(text), "%zu/%zu done", p.done, p.total);
  std::string line = text;
  if (p.done_before > 0) line += " (" + std::to_string(p.done_before) + " before)";
  std::snprintf(text, sizeof(text), ", %zu failed, %zu running, %zu waiting", p.failed, p.running,
                p.pending);
  line += text;
  if (p.remaining_s > 0.0) {
    std::snprintf(text, sizeof(text),
                  p.remaining_s >= 120.0 ? ", about %.0f min to go" : ", about %.0f s to go",
                  p.remaining_s >= 120.0 ? p.remaining_s / 60.0 : p.remaining_s);
    line += text;
  }
  return line;
}

std::vector<std::string> cellCommand(const SweepSpec& spec, const SweepCell& cell,
                                     const std::string& nadir_program) {
  std::vector<std::string> argv = {nadir_program, "run",        spec.scenario,
                                   "--out",       cell.out_dir, "--force"};
  if (!spec.images) argv.push_back("--no-images");
  for (const std::string& assignment : spec.shared_overrides) {
    argv.push_back("--set");
    argv.push_back(assignment);
  }
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    const SweepAxis& axis = spec.axes[a];
    const auto value = std::find(axis.values.begin(), axis.values.end(), cell.values[a]);
    for (const std::string& assignment :
         axis.overrides(static_cast<std::size_t>(value - axis.values.begin()))) {
      argv.push_back("--set");
      argv.push_back(assignment);
    }
  }
  return argv;
}

namespace {

// The command that made a cell, one word a line, without the program (the
// same run made by another build or another machine's path is the same run).
std::string commandRecord(const std::vector<std::string>& command) {
  std::string text;
  for (std::size_t i = 1; i < command.size(); ++i) text += command[i] + "\n";
  return text;
}

fs::path commandFile(const SweepCell& cell) { return fs::path(cell.out_dir) / "sweep_cell.txt"; }

// Before a cell runs: what will make it, and no metrics from an earlier run.
void prepareCell(const SweepCell& cell, const std::vector<std::string>& command) {
  fs::create_directories(cell.out_dir);
  fs::remove(fs::path(cell.out_dir) / "metrics.json");
  std::ofstream(commandFile(cell)) << commandRecord(command);
}

}  // namespace

bool cellDone(SweepCell& cell, const std::vector<std::string>& command) {
  std::ifstream in(commandFile(cell));
  if (!in) return false;
  std::stringstream recorded;
  recorded << in.rdbuf();
  if (recorded.str() != commandRecord(command)) return false;
  SweepCell read = cell;
  readCellMetrics(read);
  if (!read.metrics) return false;
  cell.metrics = std::move(read.metrics);
  return true;
}

int runCell(const SweepSpec& spec, std::size_t index, const std::string& nadir_program) {
  const std::vector<SweepCell> cells = planSweep(spec);
  if (index >= cells.size()) {
    throw std::invalid_argument("no cell " + std::to_string(index) + ": the sweep has " +
                                std::to_string(cells.size()) + " (0-" +
                                std::to_string(cells.size() - 1) + ")");
  }
  const SweepCell& cell = cells[index];
  const std::vector<std::string> command = cellCommand(spec, cell, nadir_program);
  prepareCell(cell, command);
  ChildProcess child("cell " + std::to_string(index), command,
                     (fs::path(cell.out_dir) / "run.out").string());
  child.start();
  while (child.running()) std::this_thread::sleep_for(std::chrono::milliseconds(200));
  return child.exitStatus();
}

std::vector<SweepCell> runSweep(const SweepSpec& spec, const std::string& nadir_program,
                                const std::function<void(const SweepProgress&)>& on_progress,
                                bool rerun) {
  std::vector<SweepCell> cells = planSweep(spec);
  const std::size_t jobs = spec.jobs > 0 ? static_cast<std::size_t>(spec.jobs)
                                         : std::max(1u, std::thread::hardware_concurrency());
  SweepProgress progress;
  progress.total = cells.size();
  std::vector<std::size_t> to_run;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (!rerun && cellDone(cells[i], cellCommand(spec, cells[i], nadir_program))) {
      cells[i].exit_status = 0;
      ++progress.done_before;
    } else {
      to_run.push_back(i);
    }
  }
  progress.done = progress.done_before;
  const auto started = std::chrono::steady_clock::now();
  std::map<std::size_t, std::unique_ptr<ChildProcess>> running;
  std::size_t next = 0;  // into to_run
  std::size_t finished_here = 0;
  while (next < to_run.size() || !running.empty()) {
    while (next < to_run.size() && running.size() < jobs) {
      const std::size_t index = to_run[next++];
      const std::vector<std::string> command = cellCommand(spec, cells[index], nadir_program);
      prepareCell(cells[index], command);
      auto child =
          std::make_unique<ChildProcess>("run " + std::to_string(index), command,
                                         (fs::path(cells[index].out_dir) / "run.out").string());
      child->start();
      running.emplace(index, std::move(child));
    }
    for (auto it = running.begin(); it != running.end();) {
      if (it->second->running()) {
        ++it;
        continue;
      }
      SweepCell& cell = cells[it->first];
      cell.exit_status = it->second->exitStatus();
      if (cell.exit_status == 0) {
        readCellMetrics(cell);
      } else {
        cell.error = it->second->describeExit() + " (see " + it->second->logPath() + ")";
      }
      ++progress.done;
      ++finished_here;
      if (!cell.metrics) ++progress.failed;
      it = running.erase(it);
    }
    progress.running = running.size();
    progress.pending = to_run.size() - next;
    progress.elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    // At the pace so far: cells finished per second here, over what is left.
    progress.remaining_s = finished_here > 0
                               ? progress.elapsed_s / static_cast<double>(finished_here) *
                                     static_cast<double>(progress.running + progress.pending)
                               : 0.0;
    if (on_progress) on_progress(progress);
    if (!running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  if (to_run.empty() && on_progress) on_progress(progress);  // every cell was done before
  return cells;
}

void readCellMetrics(SweepCell& cell) {
  const fs::path metrics = fs::path(cell.out_dir) / "metrics.json";
  if (!fs::exists(metrics)) {
    cell.error = metrics.string() + " does not exist (the cell has not run, or failed)";
    return;
  }
  try {
    cell.metrics = eval::readMetricsJson(metrics.string());
  } catch (const std::exception& error) {
    cell.error = error.what();
  }
}

std::vector<SweepCell> readSweep(const SweepSpec& spec) {
  std::vector<SweepCell> cells = planSweep(spec);
  for (SweepCell& cell : cells) readCellMetrics(cell);
  return cells;
}

namespace {

bool anyCourse(const std::vector<SweepCell>& cells) {
  return std::any_of(cells.begin(), cells.end(),
                     [](const SweepCell& cell) { return cell.metrics && cell.metrics->course; });
}

bool anyGuidance(const std::vector<SweepCell>& cells) {
  return std::any_of(cells.begin(), cells.end(), [](const SweepCell& cell) {
    return cell.metrics && cell.metrics->guidance &&
           cell.metrics->guidance->waypoints_on_source > 0;
  });
}

constexpr const char* kGuidanceColumns[] = {"guidance.source", "guidance.waypoints_on_source",
                                            "guidance.max_miss_m", "guidance.mean_miss_m",
                                            "guidance.end_miss_m"};

std::vector<std::string> guidanceCells(const eval::GuidanceMetrics& g) {
  return {g.source, std::to_string(g.waypoints_on_source) + "/" + std::to_string(g.waypoints),
          number(g.max_miss_m), number(g.mean_miss_m), number(g.end_miss_m)};
}

// Each cell's guidance: how far the truth was from where the vehicle believed.
std::string guidanceMarkdown(const SweepSpec& spec, const std::vector<SweepCell>& cells) {
  std::string md =
      "## Guidance: the truth against where the vehicle believed it was, at each "
      "waypoint reached on its source (m)\n\n|";
  std::string rule = "|";
  for (const SweepAxis& axis : spec.axes) {
    md.append(" ").append(axis.key).append(" |");
    rule += "---|";
  }
  for (const char* column : {"source", "waypoints on it", "max", "mean", "at the last"}) {
    md.append(" ").append(column).append(" |");
    rule += "---|";
  }
  md += "\n" + rule + "\n";
  for (const SweepCell& cell : cells) {
    md += "|";
    for (const std::string& value : cell.values) md.append(" ").append(value).append(" |");
    if (!cell.metrics || !cell.metrics->guidance) {
      for (std::size_t i = 0; i < std::size(kGuidanceColumns); ++i) md += " - |";
    } else {
      for (const std::string& text : guidanceCells(*cell.metrics->guidance))
        md.append(" ").append(text).append(" |");
    }
    md += "\n";
  }
  return md + "\n";
}

// A course's figures in sweep columns, in kCourseColumns' order.
constexpr const char* kCourseColumns[] = {
    "course.gates_passed",  "course.gates_missed",      "course.gates_hit",
    "course.slalom_passed", "course.slalom_wrong_side", "course.slalom_hit",
    "course.decoys_hit",    "course.average_speed_mps", "course.peak_speed_mps"};

std::vector<std::string> courseCells(const logs::CourseMetrics& c) {
  return {std::to_string(c.gates_passed) + "/" + std::to_string(c.gates),
          std::to_string(c.gates_missed),
          std::to_string(c.gates_hit),
          std::to_string(c.slalom_passed) + "/" + std::to_string(c.slalom_boards),
          std::to_string(c.slalom_wrong_side),
          std::to_string(c.slalom_hit),
          std::to_string(c.decoys_hit),
          number(c.average_speed_mps),
          number(c.peak_speed_mps)};
}

// The course of each cell, and all cells together.
std::string courseMarkdown(const SweepSpec& spec, const std::vector<SweepCell>& cells) {
  std::string md = "## Course\n\n|";
  std::string rule = "|";
  for (const SweepAxis& axis : spec.axes) {
    md.append(" ").append(axis.key).append(" |");
    rule += "---|";
  }
  for (const char* column : kCourseColumns) {
    md.append(" ").append(column + 7).append(" |");
    rule += "---|";
  }
  md += "\n" + rule + "\n";
  int gates = 0, passed = 0, hit = 0, boards = 0, on_side = 0, runs = 0;
  double slowest = 1e300, fastest_peak = 0.0;
  for (const SweepCell& cell : cells) {
    md += "|";
    for (const std::string& value : cell.values) md.append(" ").append(value).append(" |");
    if (!cell.metrics || !cell.metrics->course) {
      for (std::size_t i = 0; i < std::size(kCourseColumns); ++i) md += " - |";
      md += "\n";
      continue;
    }
    const logs::CourseMetrics& c = *cell.metrics->course;
    for (const std::string& text : courseCells(c)) md.append(" ").append(text).append(" |");
    md += "\n";
    ++runs;
    gates += c.gates;
    passed += c.gates_passed;
    hit += c.gates_hit + c.slalom_hit + c.decoys_hit;
    boards += c.slalom_boards;
    on_side += c.slalom_passed;
    if (std::isfinite(c.average_speed_mps)) slowest = std::min(slowest, c.average_speed_mps);
    if (std::isfinite(c.peak_speed_mps)) fastest_peak = std::max(fastest_peak, c.peak_speed_mps);
  }
  md += "\nAll " + std::to_string(runs) + " runs: " + std::to_string(passed) + " of " +
        std::to_string(gates) + " gates passed";
  if (boards > 0)
    md += ", " + std::to_string(on_side) + " of " + std::to_string(boards) +
          " slalom boards passed on their side";
  md += ", " + std::to_string(hit) + " posts hit; lowest average speed " +
        (runs > 0 ? number(slowest) : std::string("-")) + " m/s, highest peak " +
        (runs > 0 ? number(fastest_peak) : std::string("-")) + " m/s.\n";
  return md;
}

}  // namespace

std::string sweepCsv(const SweepSpec& spec, const std::vector<SweepCell>& cells) {
  const std::vector<std::string> sources = sourceNames(cells);
  const bool course = anyCourse(cells);
  const bool guidance = anyGuidance(cells);
  std::string csv;
  for (const SweepAxis& axis : spec.axes) csv += core::csvField(axis.key) + ",";
  csv += "run,truth_track_length_m";
  // A filter's own figures, for the sources that are filters in some cell.
  std::set<std::string> filters;
  for (const SweepCell& cell : cells) {
    if (!cell.metrics) continue;
    for (const auto& [name, metrics] : cell.metrics->sources)
      if (metrics.filter) filters.insert(name);
  }
  for (const std::string& source : sources) {
    for (const char* column : {".position_rmse_m", ".rotation_rmse_deg", ".tracked_pct", ".resets"})
      csv += "," + core::csvField(source + column);
    if (filters.contains(source)) {
      for (const char* column : {".error_denial_60_m", ".error_denial_120_m", ".error_end_m",
                                 ".nees_position_mean", ".nees_attitude_mean"})
        csv += "," + core::csvField(source + column);
    }
  }
  if (course) {
    for (const char* column : kCourseColumns) csv += std::string(",") + column;
  }
  if (guidance) {
    for (const char* column : kGuidanceColumns) csv += std::string(",") + column;
  }
  csv += "\n";
  for (const SweepCell& cell : cells) {
    for (const std::string& value : cell.values) csv += core::csvField(value) + ",";
    csv += cell.metrics ? "ok," + number(cell.metrics->truth_track_length_m) : "failed,";
    for (const std::string& source : sources) {
      const eval::SourceMetrics* metrics = sourceOf(cell, source);
      if (metrics == nullptr) {
        csv += ",,,,";
      } else if (!metrics->initialised) {
        csv += ",X,X," + number(0.0) + "," + resetsText(*metrics);
      } else {
        csv += "," + number(metrics->position_rmse_m) + "," + number(metrics->rotation_rmse_deg) +
               "," + number(metrics->tracked_pct) + "," + resetsText(*metrics);
      }
      if (!filters.contains(source)) continue;
      if (metrics == nullptr || !metrics->filter) {
        csv += ",,,,,";
      } else {
        const eval::FilterMetrics& f = *metrics->filter;
        for (double value : {f.error_denial_60_m, f.error_denial_120_m, f.error_end_m,
                             f.nees_position_mean, f.nees_attitude_mean})
          csv += "," + (std::isfinite(value) ? number(value) : std::string());  // none: empty
      }
    }
    if (course) {
      if (cell.metrics && cell.metrics->course) {
        for (const std::string& text : courseCells(*cell.metrics->course)) csv += "," + text;
      } else {
        csv += std::string(std::size(kCourseColumns), ',');
      }
    }
    if (guidance) {
      if (cell.metrics && cell.metrics->guidance) {
        for (const std::string& text : guidanceCells(*cell.metrics->guidance)) csv += "," + text;
      } else {
        csv += std::string(std::size(kGuidanceColumns), ',');
      }
    }
    csv += "\n";
  }
  return csv;
}

std::string sweepMarkdown(const SweepSpec& spec, const std::vector<SweepCell>& cells) {
  const std::vector<std::string> sources = sourceNames(cells);
  const bool split = spec.axes.size() >= 3;
  const std::size_t first_row_axis = split ? 1 : 0;
  std::string md = "# Sweep: " + spec.scenario + "\n\n";
  if (anyGuidance(cells)) md += guidanceMarkdown(spec, cells);
  if (anyCourse(cells)) {
    md += courseMarkdown(spec, cells);
    if (sources.empty()) return md;
    md += "\n## Poses\n\n";
  }
  if (sources.empty()) {
    md += "No pose source (VO node) ran in these cells: the table holds the truth only.\n\n";
  }
  const auto header = [&] {
    std::string line = "|", rule = "|";
    for (std::size_t a = first_row_axis; a < spec.axes.size(); ++a) {
      line.append(" ").append(spec.axes[a].key).append(" |");
      rule += "---|";
    }
    line += " track (m) |";
    rule += "---|";
    for (const char* metric :
         {"position RMSE (m)", "rotation RMSE (deg)", "tracked (%)", "resets"}) {
      for (const std::string& source : sources) {
        line.append(" ").append(metric).append(" ").append(source).append(" |");
        rule += "---|";
      }
    }
    return line + "\n" + rule + "\n";
  };
  const auto row = [&](const SweepCell& cell) {
    std::string line = "|";
    for (std::size_t a = first_row_axis; a < cell.values.size(); ++a) {
      line.append(" ").append(cell.values[a]).append(" |");
    }
    if (!cell.metrics) {
      line += " failed |";
      for (std::size_t i = 0; i < 4 * sources.size(); ++i) line += " failed |";
      return line + "\n";
    }
    line.append(" ").append(number(cell.metrics->truth_track_length_m)).append(" |");
    // The lowest position and rotation error of the row in bold, as in the thesis.
    double best_position = 1e300, best_rotation = 1e300;
    for (const std::string& source : sources) {
      const eval::SourceMetrics* m = sourceOf(cell, source);
      if (m != nullptr && m->initialised) {
        best_position = std::min(best_position, m->position_rmse_m);
        best_rotation = std::min(best_rotation, m->rotation_rmse_deg);
      }
    }
    for (int metric = 0; metric < 4; ++metric) {
      for (const std::string& source : sources) {
        const eval::SourceMetrics* m = sourceOf(cell, source);
        if (m == nullptr) {
          line += " |";
        } else if (metric == 3) {
          line.append(" ").append(resetsText(*m)).append(" |");
        } else if (metric < 2 && !m->initialised) {
          line += " X |";
        } else {
          const double value = metric == 0   ? m->position_rmse_m
                               : metric == 1 ? m->rotation_rmse_deg
                                             : m->tracked_pct;
          const bool best =
              (metric == 0 && value == best_position) || (metric == 1 && value == best_rotation);
          const bool bold = best && sources.size() > 1;
          line.append(bold ? " **" : " ").append(number(value)).append(bold ? "** |" : " |");
        }
      }
    }
    return line + "\n";
  };
  if (!split) {
    md += header();
    for (const SweepCell& cell : cells) md += row(cell);
    return md;
  }
  for (const std::string& value : spec.axes.front().values) {
    md.append("## ").append(spec.axes.front().key).append(" = ").append(value).append("\n\n");
    md += header();
    for (const SweepCell& cell : cells) {
      if (cell.values.front() == value) md += row(cell);
    }
    md += "\n";
  }
  return md;
}

}  // namespace nadir::run
