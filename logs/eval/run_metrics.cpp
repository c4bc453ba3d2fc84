#include "logs/eval/run_metrics.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>

#include "core/frames.h"

namespace nadir::eval {
namespace {

using logs::appendNote;

using Json = nlohmann::ordered_json;

double median(std::vector<double> values) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const std::size_t middle = values.size() / 2;
  return values.size() % 2 == 1 ? values[middle] : 0.5 * (values[middle - 1] + values[middle]);
}

double percentOf(double value, double whole) {
  if (!std::isfinite(value) || !(whole > 0)) return kNaN;
  return 100.0 * value / whole;
}

// Time during which the (sorted) estimates say TRACKING, clipped to [t0, t1].
double trackedTime(const std::vector<SourceEstimate>& estimates, double t0, double t1,
                   double hold_periods) {
  std::vector<double> intervals;
  for (std::size_t k = 1; k < estimates.size(); ++k) {
    const double dt = estimates[k].t_s - estimates[k - 1].t_s;
    if (dt > 0) intervals.push_back(dt);
  }
  if (intervals.empty()) return 0;
  const double period = median(intervals);
  const double max_hold = hold_periods * period;
  double tracked = 0;
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    if (estimates[k].status != SourceEstimate::kTracking) continue;
    const double start = estimates[k].t_s;
    const double hold = k + 1 < estimates.size() ? estimates[k + 1].t_s - start : period;
    const double end = start + std::min(hold, max_hold);
    tracked += std::max(0.0, std::min(end, t1) - std::max(start, t0));
  }
  return tracked;
}

// --------------------------------------------------------------- metrics.json

Json number(double value) { return std::isfinite(value) ? Json(value) : Json(nullptr); }

Json statisticsJson(const Statistics& s) {
  return Json{{"rmse", number(s.rmse)}, {"mean", number(s.mean)}, {"median", number(s.median)},
              {"std", number(s.std)},   {"min", number(s.min)},   {"max", number(s.max)},
              {"count", s.count}};
}

Json sourceJson(const SourceMetrics& m) {
  Json j;
  j["initialised"] = m.initialised;
  j["position_rmse_m"] = number(m.position_rmse_m);
  j["rotation_rmse_deg"] = number(m.rotation_rmse_deg);
  j["tracked_pct"] = number(m.tracked_pct);
  j["track_length_m"] = number(m.track_length_m);
  j["truth_track_length_m"] = number(m.truth_track_length_m);
  j["track_length_diff_pct"] = number(m.track_length_diff_pct);
  j["mean_abs_error_m"] = number(m.mean_abs_error_m);
  j["end_point_m"] = number(m.end_point_m);
  j["end_point_pct"] = number(m.end_point_pct);
  j["rate_hz"] = number(m.rate_hz);
  j["longest_gap_s"] = number(m.longest_gap_s);
  j["first_tracking_s"] = number(m.first_tracking_s);
  j["estimates"] = m.estimates;
  j["estimates_tracking"] = m.estimates_tracking;
  j["estimates_evaluated"] = m.estimates_evaluated;
  j["tracking_segments"] = m.tracking_segments;
  j["resets"] = m.resets ? Json(*m.resets) : Json(nullptr);
  j["ape"] = Json{{"alignment", m.alignment},
                  {"scale", number(m.alignment_scale)},
                  {"translation_m", statisticsJson(m.ape_translation_m)},
                  {"rotation_deg", statisticsJson(m.ape_rotation_deg)}};
  j["rpe"] = Json{{"delta", m.rpe_delta},
                  {"delta_unit", m.rpe_delta_unit},
                  {"translation_m", statisticsJson(m.rpe_translation_m)},
                  {"rotation_deg", statisticsJson(m.rpe_rotation_deg)}};
  j["note"] = m.note;
  if (m.filter) {
    const FilterMetrics& f = *m.filter;
    j["filter"] = Json{{"states_evaluated", f.states_evaluated},
                       {"had_gps", f.had_gps},
                       {"denial_s", number(f.denial_s)},
                       {"error_denial_60_m", number(f.error_denial_60_m)},
                       {"error_denial_120_m", number(f.error_denial_120_m)},
                       {"error_end_m", number(f.error_end_m)},
                       {"nees_position_mean", number(f.nees_position_mean)},
                       {"nees_attitude_mean", number(f.nees_attitude_mean)},
                       {"nees_position_in_band_pct", number(f.nees_position_in_band_pct)},
                       {"nees_attitude_in_band_pct", number(f.nees_attitude_in_band_pct)},
                       {"nees_band", Json::array({kNees3Low, kNees3High})}};
  }
  return j;
}

Json courseJson(const logs::CourseMetrics& c) {
  Json passages = Json::array();
  for (const logs::BoardPassage& p : c.passages) {
    passages.push_back(Json{{"kind", p.kind},
                            {"passed", p.passed},
                            {"crossed", p.crossed},
                            {"hit", p.hit},
                            {"time_s", number(p.time_s)},
                            {"offset_m", number(p.offset_m)},
                            {"heading_error_deg", number(p.heading_error_deg)}});
  }
  Json stages = Json::array();
  for (const logs::PipelineStage& s : c.stages) {
    stages.push_back(Json{{"name", s.name},
                          {"instructions", number(s.instructions)},
                          {"chip_us", number(s.chip_us)},
                          {"paper_us", number(s.paper_us)}});
  }
  return Json{{"gates", c.gates},
              {"gates_passed", c.gates_passed},
              {"gates_missed", c.gates_missed},
              {"gates_hit", c.gates_hit},
              {"slalom_boards", c.slalom_boards},
              {"slalom_passed", c.slalom_passed},
              {"slalom_wrong_side", c.slalom_wrong_side},
              {"slalom_missed", c.slalom_missed},
              {"slalom_hit", c.slalom_hit},
              {"decoys_hit", c.decoys_hit},
              {"distance_m", number(c.distance_m)},
              {"duration_s", number(c.duration_s)},
              {"average_speed_mps", number(c.average_speed_mps)},
              {"peak_speed_mps", number(c.peak_speed_mps)},
              {"frames", c.frames},
              {"chip_time_us", number(c.chip_time_us)},
              {"emulated_fps", number(c.emulated_fps)},
              {"latency_mean_us", number(c.latency_mean_us)},
              {"latency_max_us", number(c.latency_max_us)},
              {"passages", passages},
              {"stages", stages}};
}

Json guidanceJson(const GuidanceMetrics& g) {
  Json passages = Json::array();
  for (const GuidancePassage& p : g.passages) {
    passages.push_back(Json{{"index", p.index},
                            {"t_s", number(p.t_s)},
                            {"source", p.source},
                            {"miss_m", number(p.miss_m)},
                            {"from_waypoint_m", number(p.from_waypoint_m)}});
  }
  return Json{{"source", g.source},
              {"waypoints", g.waypoints},
              {"waypoints_on_source", g.waypoints_on_source},
              {"max_miss_m", number(g.max_miss_m)},
              {"mean_miss_m", number(g.mean_miss_m)},
              {"end_miss_m", number(g.end_miss_m)},
              {"passages", passages}};
}

// Reading: every lookup names the key path and the file when it fails.
class JsonReader {
 public:
  explicit JsonReader(std::string path) : path_(std::move(path)) {}

  const Json& at(const Json& object, const std::string& key, const std::string& where) const {
    if (!object.is_object()) fail(where, "is not an object");
    const auto it = object.find(key);
    if (it == object.end()) fail(where, "missing key '" + key + "'");
    return *it;
  }
  double number(const Json& object, const std::string& key, const std::string& where) const {
    const Json& value = at(object, key, where);
    if (value.is_null()) return kNaN;
    if (!value.is_number()) fail(where + "." + key, "is not a number");
    return value.get<double>();
  }
  std::size_t count(const Json& object, const std::string& key, const std::string& where) const {
    const Json& value = at(object, key, where);
    if (!value.is_number_unsigned()) fail(where + "." + key, "is not a count");
    return value.get<std::size_t>();
  }
  // Absent (older files) or null: NaN.
  double optionalNumber(const Json& object, const std::string& key,
                        const std::string& where) const {
    if (!object.is_object()) fail(where, "is not an object");
    return object.contains(key) ? number(object, key, where) : kNaN;
  }
  // Absent (older files) or null: none.
  std::optional<std::size_t> optionalCount(const Json& object, const std::string& key,
                                           const std::string& where) const {
    if (!object.is_object()) fail(where, "is not an object");
    const auto it = object.find(key);
    if (it == object.end() || it->is_null()) return std::nullopt;
    if (!it->is_number_unsigned()) fail(where + "." + key, "is not a count");
    return it->get<std::size_t>();
  }
  std::string text(const Json& object, const std::string& key, const std::string& where) const {
    const Json& value = at(object, key, where);
    if (!value.is_string()) fail(where + "." + key, "is not a string");
    return value.get<std::string>();
  }
  bool flag(const Json& object, const std::string& key, const std::string& where) const {
    const Json& value = at(object, key, where);
    if (!value.is_boolean()) fail(where + "." + key, "is not true or false");
    return value.get<bool>();
  }
  Statistics statistics(const Json& object, const std::string& key,
                        const std::string& where) const {
    const Json& s = at(object, key, where);
    const std::string here = where + "." + key;
    Statistics out;
    out.rmse = number(s, "rmse", here);
    out.mean = number(s, "mean", here);
    out.median = number(s, "median", here);
    out.std = number(s, "std", here);
    out.min = number(s, "min", here);
    out.max = number(s, "max", here);
    out.count = count(s, "count", here);
    return out;
  }
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw EvalError(path_ + ": " + where + ": " + what);
  }

 private:
  std::string path_;
};

SourceMetrics sourceFromJson(const JsonReader& r, const Json& j, const std::string& where) {
  SourceMetrics m;
  m.initialised = r.flag(j, "initialised", where);
  m.position_rmse_m = r.number(j, "position_rmse_m", where);
  m.rotation_rmse_deg = r.number(j, "rotation_rmse_deg", where);
  m.tracked_pct = r.number(j, "tracked_pct", where);
  m.track_length_m = r.number(j, "track_length_m", where);
  m.truth_track_length_m = r.number(j, "truth_track_length_m", where);
  m.track_length_diff_pct = r.number(j, "track_length_diff_pct", where);
  m.mean_abs_error_m = r.number(j, "mean_abs_error_m", where);
  m.end_point_m = r.number(j, "end_point_m", where);
  m.end_point_pct = r.number(j, "end_point_pct", where);
  m.rate_hz = r.number(j, "rate_hz", where);
  m.longest_gap_s = r.optionalNumber(j, "longest_gap_s", where);
  m.first_tracking_s = r.number(j, "first_tracking_s", where);
  m.estimates = r.count(j, "estimates", where);
  m.estimates_tracking = r.count(j, "estimates_tracking", where);
  m.estimates_evaluated = r.count(j, "estimates_evaluated", where);
  m.tracking_segments = r.count(j, "tracking_segments", where);
  m.resets = r.optionalCount(j, "resets", where);
  const Json& ape = r.at(j, "ape", where);
  m.alignment = r.text(ape, "alignment", where + ".ape");
  m.alignment_scale = r.number(ape, "scale", where + ".ape");
  m.ape_translation_m = r.statistics(ape, "translation_m", where + ".ape");
  m.ape_rotation_deg = r.statistics(ape, "rotation_deg", where + ".ape");
  const Json& rpe = r.at(j, "rpe", where);
  m.rpe_delta = r.number(rpe, "delta", where + ".rpe");
  m.rpe_delta_unit = r.text(rpe, "delta_unit", where + ".rpe");
  m.rpe_translation_m = r.statistics(rpe, "translation_m", where + ".rpe");
  m.rpe_rotation_deg = r.statistics(rpe, "rotation_deg", where + ".rpe");
  m.note = r.text(j, "note", where);
  if (const auto it = j.find("filter"); it != j.end() && !it->is_null()) {
    const std::string here = where + ".filter";
    FilterMetrics f;
    f.states_evaluated = r.count(*it, "states_evaluated", here);
    f.had_gps = r.flag(*it, "had_gps", here);
    f.denial_s = r.number(*it, "denial_s", here);
    f.error_denial_60_m = r.number(*it, "error_denial_60_m", here);
    f.error_denial_120_m = r.number(*it, "error_denial_120_m", here);
    f.error_end_m = r.number(*it, "error_end_m", here);
    f.nees_position_mean = r.number(*it, "nees_position_mean", here);
    f.nees_attitude_mean = r.number(*it, "nees_attitude_mean", here);
    f.nees_position_in_band_pct = r.number(*it, "nees_position_in_band_pct", here);
    f.nees_attitude_in_band_pct = r.number(*it, "nees_attitude_in_band_pct", here);
    m.filter = f;
  }
  return m;
}

GuidanceMetrics guidanceFromJson(const JsonReader& r, const Json& j) {
  const std::string where = "guidance";
  GuidanceMetrics g;
  g.source = r.text(j, "source", where);
  g.waypoints = static_cast<int>(r.count(j, "waypoints", where));
  g.waypoints_on_source = static_cast<int>(r.count(j, "waypoints_on_source", where));
  g.max_miss_m = r.number(j, "max_miss_m", where);
  g.mean_miss_m = r.number(j, "mean_miss_m", where);
  g.end_miss_m = r.number(j, "end_miss_m", where);
  const Json& passages = r.at(j, "passages", where);
  if (!passages.is_array()) r.fail("guidance.passages", "is not an array");
  for (const Json& p : passages) {
    const std::string here = "guidance.passages";
    GuidancePassage passage;
    passage.index = static_cast<int>(r.count(p, "index", here));
    passage.t_s = r.number(p, "t_s", here);
    passage.source = r.text(p, "source", here);
    passage.miss_m = r.number(p, "miss_m", here);
    passage.from_waypoint_m = r.number(p, "from_waypoint_m", here);
    g.passages.push_back(passage);
  }
  return g;
}

logs::CourseMetrics courseFromJson(const JsonReader& r, const Json& j) {
  const std::string where = "course";
  const auto integer = [&](const char* key) { return static_cast<int>(r.count(j, key, where)); };
  logs::CourseMetrics c;
  c.gates = integer("gates");
  c.gates_passed = integer("gates_passed");
  c.gates_missed = integer("gates_missed");
  c.gates_hit = integer("gates_hit");
  c.slalom_boards = integer("slalom_boards");
  c.slalom_passed = integer("slalom_passed");
  c.slalom_wrong_side = integer("slalom_wrong_side");
  c.slalom_missed = integer("slalom_missed");
  c.slalom_hit = integer("slalom_hit");
  c.decoys_hit = integer("decoys_hit");
  c.distance_m = r.number(j, "distance_m", where);
  c.duration_s = r.number(j, "duration_s", where);
  c.average_speed_mps = r.number(j, "average_speed_mps", where);
  c.peak_speed_mps = r.number(j, "peak_speed_mps", where);
  c.frames = integer("frames");
  c.chip_time_us = r.number(j, "chip_time_us", where);
  c.emulated_fps = r.number(j, "emulated_fps", where);
  c.latency_mean_us = r.number(j, "latency_mean_us", where);
  c.latency_max_us = r.number(j, "latency_max_us", where);
  const Json& passages = r.at(j, "passages", where);
  if (!passages.is_array()) r.fail("course.passages", "is not an array");
  for (const Json& p : passages) {
    const std::string here = "course.passages";
    logs::BoardPassage passage;
    passage.kind = r.text(p, "kind", here);
    passage.passed = r.flag(p, "passed", here);
    passage.crossed = r.flag(p, "crossed", here);
    passage.hit = r.flag(p, "hit", here);
    passage.time_s = r.number(p, "time_s", here);
    passage.offset_m = r.number(p, "offset_m", here);
    passage.heading_error_deg = r.number(p, "heading_error_deg", here);
    c.passages.push_back(passage);
  }
  const Json& stages = r.at(j, "stages", where);
  if (!stages.is_array()) r.fail("course.stages", "is not an array");
  for (const Json& s : stages) {
    const std::string here = "course.stages";
    logs::PipelineStage stage;
    stage.name = r.text(s, "name", here);
    stage.instructions = r.number(s, "instructions", here);
    stage.chip_us = r.number(s, "chip_us", here);
    stage.paper_us = r.number(s, "paper_us", here);
    c.stages.push_back(stage);
  }
  return c;
}

// ------------------------------------------------------------------ the table

std::string cell(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

}  // namespace

GuidanceMetrics evaluateGuidance(const std::vector<logs::WaypointPassage>& waypoints,
                                 double truth_start_s) {
  GuidanceMetrics g;
  double sum = 0.0, worst = 0.0;
  for (const logs::WaypointPassage& w : waypoints) {
    GuidancePassage p;
    p.index = w.index;
    p.t_s = w.t_s - truth_start_s;
    p.source = w.source;
    p.miss_m = (w.true_ned_m - w.believed_ned_m).norm();
    p.from_waypoint_m = (w.true_ned_m - w.waypoint_ned_m).norm();
    g.passages.push_back(p);
    ++g.waypoints;
    g.source = w.source;
    if (w.source != "truth") {
      ++g.waypoints_on_source;
      sum += p.miss_m;
      worst = std::max(worst, p.miss_m);
    }
  }
  if (g.waypoints_on_source > 0) {
    g.max_miss_m = worst;
    g.mean_miss_m = sum / g.waypoints_on_source;
  }
  if (!g.passages.empty()) g.end_miss_m = g.passages.back().miss_m;
  return g;
}

SourceMetrics evaluateSource(const core::Trajectory& truth,
                             const std::vector<SourceEstimate>& estimates,
                             const EvalOptions& options) {
  validateOptions(options);
  if (truth.size() < 2 || !(truth.back().t_s > truth.front().t_s)) {
    throw EvalError("the truth has " + std::to_string(truth.size()) +
                    " poses over no time; need at least 2 poses spanning a time");
  }
  std::vector<SourceEstimate> sorted = estimates;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const SourceEstimate& a, const SourceEstimate& b) { return a.t_s < b.t_s; });
  const double t0 = truth.front().t_s;
  const double t1 = truth.back().t_s;

  SourceMetrics m;
  m.alignment = alignModeName(parseAlignMode(options.align));
  m.rpe_delta = options.rpe_delta;
  m.rpe_delta_unit = options.rpe_delta_unit;
  m.estimates = sorted.size();
  for (const SourceEstimate& e : sorted)
    m.resets = std::max<std::size_t>(m.resets.value_or(0),
                                     static_cast<std::size_t>(std::max(e.resets, 0)));
  if (sorted.size() >= 2 && sorted.back().t_s > sorted.front().t_s) {
    m.rate_hz = static_cast<double>(sorted.size() - 1) / (sorted.back().t_s - sorted.front().t_s);
  }
  for (std::size_t k = 1; k < sorted.size(); ++k) {
    const double gap_s = sorted[k].t_s - sorted[k - 1].t_s;
    if (!(gap_s <= m.longest_gap_s)) m.longest_gap_s = gap_s;
  }
  m.tracked_pct = 100.0 * trackedTime(sorted, t0, t1, options.tracked_hold_periods) / (t1 - t0);

  // Evaluated pairs, with the tracking segment each belongs to.
  core::Trajectory ref;
  core::Trajectory est;
  std::vector<std::size_t> segment_of;
  bool in_segment = false;
  std::size_t outside_truth = 0;
  for (const SourceEstimate& e : sorted) {
    if (e.status != SourceEstimate::kTracking) {
      in_segment = false;
      continue;
    }
    if (!in_segment) ++m.tracking_segments;
    in_segment = true;
    if (m.estimates_tracking++ == 0) m.first_tracking_s = e.t_s - t0;
    const std::optional<core::StampedPose> truth_here =
        core::interpolate(truth, e.t_s, options.truth_max_gap_s);
    if (!truth_here) {
      ++outside_truth;
      continue;
    }
    ref.push_back(*truth_here);
    est.push_back(core::StampedPose{e.t_s, e.p_ned_m, e.q_world_body.normalized()});
    segment_of.push_back(m.tracking_segments);
  }
  m.initialised = m.estimates_tracking > 0;
  m.estimates_evaluated = ref.size();
  if (outside_truth > 0) {
    appendNote(m.note, std::to_string(outside_truth) +
                           " TRACKING estimates outside the truth's time span or over a hole in "
                           "it were not compared");
  }
  if (!m.initialised) {
    appendNote(m.note, m.estimates == 0 ? "no estimates" : "never tracked");
    return m;
  }
  if (ref.empty()) return m;

  m.position_rmse_m = thesisPositionRmse(ref, est);
  m.rotation_rmse_deg = thesisRotationRmseDeg(ref, est);
  m.mean_abs_error_m = meanAbsoluteError(ref, est);
  m.end_point_m = (est.back().p_ned_m - ref.back().p_ned_m).norm();

  // Segment boundaries [begin, end) in the evaluated pairs.
  std::vector<std::pair<std::size_t, std::size_t>> segments;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (i == 0 || segment_of[i] != segment_of[i - 1]) segments.emplace_back(i, i);
    segments.back().second = i + 1;
  }
  m.track_length_m = 0;
  m.truth_track_length_m = 0;
  for (const auto& [begin, end] : segments) {
    std::size_t last = begin;
    for (std::size_t i = begin + 1; i < end; ++i) {
      if (i + 1 != end && ref[i].t_s - ref[last].t_s < options.track_length_interval_s) continue;
      m.track_length_m += (est[i].p_ned_m - est[last].p_ned_m).norm();
      m.truth_track_length_m += (ref[i].p_ned_m - ref[last].p_ned_m).norm();
      last = i;
    }
  }
  m.track_length_diff_pct =
      percentOf(m.track_length_m - m.truth_track_length_m, m.truth_track_length_m);
  m.end_point_pct = percentOf(m.end_point_m, m.truth_track_length_m);

  // evo's APE and RPE on the aligned estimate.
  Alignment alignment;
  try {
    alignment = alignTrajectories(ref, est, parseAlignMode(options.align));
  } catch (const EvalError& error) {
    appendNote(m.note, std::string("no APE or RPE: ") + error.what());
    return m;
  }
  m.alignment_scale = alignment.scale;
  core::Trajectory aligned = est;
  applyAlignment(alignment, aligned);
  m.ape_translation_m = computeStatistics(apeTranslationErrors(ref, aligned));
  m.ape_rotation_deg = computeStatistics(apeRotationErrorsDeg(ref, aligned));

  IndexPairs pairs;
  const DeltaUnit unit = parseDeltaUnit(options.rpe_delta_unit);
  for (const auto& [begin, end] : segments) {
    const core::Trajectory slice(aligned.begin() + static_cast<std::ptrdiff_t>(begin),
                                 aligned.begin() + static_cast<std::ptrdiff_t>(end));
    for (const auto& [i, j] : rpePairs(slice, options.rpe_delta, unit)) {
      pairs.emplace_back(begin + i, begin + j);
    }
  }
  if (pairs.empty()) {
    appendNote(m.note, "no RPE pose pair at this delta");
  } else {
    const RelativeErrors relative = rpeErrors(ref, aligned, pairs);
    m.rpe_translation_m = computeStatistics(relative.translation_m);
    m.rpe_rotation_deg = computeStatistics(relative.rotation_deg);
  }
  return m;
}

RunMetrics evaluate(const core::Trajectory& truth,
                    const std::map<std::string, std::vector<SourceEstimate>>& sources,
                    const EvalOptions& options,
                    const std::map<std::string, std::vector<logs::FilterState>>& filters) {
  RunMetrics run;
  run.truth_poses = truth.size();
  run.truth_track_length_m = core::trackLength(truth);
  run.truth_duration_s = truth.empty() ? 0.0 : truth.back().t_s - truth.front().t_s;
  for (const auto& [name, estimates] : sources) {
    run.sources[name] = evaluateSource(truth, estimates, options);
  }
  for (const auto& [name, states] : filters) {
    const auto source = run.sources.find(name);
    if (source == run.sources.end() || states.empty()) continue;
    source->second.filter = evaluateFilter(truth, states, options.truth_max_gap_s);
  }
  if (sources.empty()) validateOptions(options);
  return run;
}

RunEvaluation evaluateRunLog(const std::string& log_path, const std::string& out_dir,
                             const EvalOptions& options, const std::string& truth_channel,
                             const core::ReadProgress& progress) {
  RunEvaluation run;
  run.recorded = logs::readRunLog(log_path, truth_channel, progress);
  run.metrics = evaluate(run.recorded.truth, run.recorded.sources, options, run.recorded.filters);
  if (!run.recorded.waypoints.empty()) {
    run.metrics.guidance = evaluateGuidance(
        run.recorded.waypoints, run.recorded.truth.empty() ? 0.0 : run.recorded.truth.front().t_s);
  }
  const std::filesystem::path dir(out_dir.empty() ? std::string(".") : out_dir);
  run.metrics_path = (dir / "metrics.json").string();
  writeMetricsJson(run.metrics_path, run.metrics, options);
  run.tum_paths.push_back((dir / "truth.tum").string());
  core::writeTum(run.tum_paths.back(), run.recorded.truth, options.tum_axes);
  for (const auto& [name, estimates] : run.recorded.sources) {
    core::Trajectory tracked = logs::trackingTrajectory(estimates);
    if (tracked.empty()) continue;  // never tracked: a TUM file needs at least one pose
    run.tum_paths.push_back((dir / (name + ".tum")).string());
    core::writeTum(run.tum_paths.back(), tracked, options.tum_axes);
    run.tracked.emplace(name, std::move(tracked));
  }
  return run;
}

void writeMetricsJson(const std::string& path, const RunMetrics& metrics,
                      const EvalOptions& options) {
  Json j;
  j["schema"] = "nadir.metrics";
  j["version"] = 1;
  j["truth"] = Json{{"track_length_m", number(metrics.truth_track_length_m)},
                    {"duration_s", number(metrics.truth_duration_s)},
                    {"poses", metrics.truth_poses}};
  j["options"] = Json{{"align", options.align},
                      {"t_max_diff_s", options.t_max_diff_s},
                      {"rpe_delta", options.rpe_delta},
                      {"rpe_delta_unit", options.rpe_delta_unit},
                      {"tracked_hold_periods", options.tracked_hold_periods},
                      {"truth_max_gap_s", options.truth_max_gap_s},
                      {"track_length_interval_s", options.track_length_interval_s}};
  Json sources = Json::object();
  for (const auto& [name, source] : metrics.sources) sources[name] = sourceJson(source);
  j["sources"] = sources;
  if (metrics.course) j["course"] = courseJson(*metrics.course);
  if (metrics.guidance) j["guidance"] = guidanceJson(*metrics.guidance);
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw EvalError(path + ": cannot open the file for writing");
  out << j.dump(2) << "\n";
  out.flush();
  if (!out) throw EvalError(path + ": write error");
}

RunMetrics readMetricsJson(const std::string& path, EvalOptions* options) {
  std::ifstream in(path);
  if (!in) throw EvalError(path + ": cannot open the file for reading");
  Json j;
  try {
    j = Json::parse(in);
  } catch (const nlohmann::json::parse_error& error) {
    throw EvalError(path + ": not valid JSON: " + error.what());
  }
  const JsonReader r(path);
  if (r.text(j, "schema", "top level") != "nadir.metrics") {
    r.fail("schema", "is not 'nadir.metrics'");
  }
  if (r.number(j, "version", "top level") != 1) r.fail("version", "is not 1 (not supported)");
  RunMetrics metrics;
  const Json& truth = r.at(j, "truth", "top level");
  metrics.truth_track_length_m = r.number(truth, "track_length_m", "truth");
  metrics.truth_duration_s = r.number(truth, "duration_s", "truth");
  metrics.truth_poses = r.count(truth, "poses", "truth");
  if (options != nullptr) {
    const Json& o = r.at(j, "options", "top level");
    options->align = r.text(o, "align", "options");
    options->t_max_diff_s = r.number(o, "t_max_diff_s", "options");
    options->rpe_delta = r.number(o, "rpe_delta", "options");
    options->rpe_delta_unit = r.text(o, "rpe_delta_unit", "options");
    options->tracked_hold_periods = r.number(o, "tracked_hold_periods", "options");
    options->track_length_interval_s = r.number(o, "track_length_interval_s", "options");
    options->truth_max_gap_s = r.number(o, "truth_max_gap_s", "options");
  }
  const Json& sources = r.at(j, "sources", "top level");
  if (!sources.is_object()) r.fail("sources", "is not an object");
  for (const auto& [name, source] : sources.items()) {
    metrics.sources[name] = sourceFromJson(r, source, "sources." + name);
  }
  if (const auto it = j.find("course"); it != j.end() && !it->is_null()) {
    metrics.course = courseFromJson(r, *it);
  }
  if (const auto it = j.find("guidance"); it != j.end() && !it->is_null()) {
    metrics.guidance = guidanceFromJson(r, *it);
  }
  return metrics;
}

std::string formatResultsTable(const RunMetrics& metrics) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "truth: %.1f m in %.1f s (%zu poses)\n",
                metrics.truth_track_length_m, metrics.truth_duration_s, metrics.truth_poses);
  out += line;
  const char* const row_format = "%-12s %5s %9s %11s %13s %11s %11s %11s %9s %9s %7s %8s %7s\n";
  std::snprintf(line, sizeof line, row_format, "source", "init", "tracked%", "pos RMSE m",
                "rot RMSE deg", "APE RMSE m", "RPE RMSE m", "len diff %", "MAE m", "end m", "end %",
                "rate Hz", "resets");
  out += line;
  for (const auto& [name, m] : metrics.sources) {
    std::snprintf(line, sizeof line, row_format, name.c_str(), m.initialised ? "yes" : "no",
                  cell(m.tracked_pct, 1).c_str(), cell(m.position_rmse_m, 3).c_str(),
                  cell(m.rotation_rmse_deg, 3).c_str(), cell(m.ape_translation_m.rmse, 3).c_str(),
                  cell(m.rpe_translation_m.rmse, 3).c_str(),
                  cell(m.track_length_diff_pct, 2).c_str(), cell(m.mean_abs_error_m, 3).c_str(),
                  cell(m.end_point_m, 3).c_str(), cell(m.end_point_pct, 2).c_str(),
                  cell(m.rate_hz, 1).c_str(), m.resets ? std::to_string(*m.resets).c_str() : "-");
    out += line;
  }
  for (const auto& [name, m] : metrics.sources) {
    if (!m.filter) continue;
    const FilterMetrics& f = *m.filter;
    std::snprintf(line, sizeof line,
                  "%s as a filter: %s %s s; error at denial +60 s %s m, +120 s %s m, end %s m; "
                  "NEES position %s, attitude %s (95 %% band %.2f-%.2f; in it %s %%, %s %%)\n",
                  name.c_str(), f.had_gps ? "GPS last fused at" : "no GPS; started at",
                  cell(f.denial_s, 1).c_str(), cell(f.error_denial_60_m, 2).c_str(),
                  cell(f.error_denial_120_m, 2).c_str(), cell(f.error_end_m, 2).c_str(),
                  cell(f.nees_position_mean, 2).c_str(), cell(f.nees_attitude_mean, 2).c_str(),
                  kNees3Low, kNees3High, cell(f.nees_position_in_band_pct, 1).c_str(),
                  cell(f.nees_attitude_in_band_pct, 1).c_str());
    out += line;
  }
  if (metrics.guidance && metrics.guidance->waypoints > 0) {
    const GuidanceMetrics& g = *metrics.guidance;
    if (g.waypoints_on_source > 0) {
      std::snprintf(line, sizeof line,
                    "guidance on %s: %d of %d waypoints reached on it, the truth %s m from where "
                    "it believed at most (%s m on average), %s m at the last\n",
                    g.source.c_str(), g.waypoints_on_source, g.waypoints,
                    cell(g.max_miss_m, 2).c_str(), cell(g.mean_miss_m, 2).c_str(),
                    cell(g.end_miss_m, 2).c_str());
    } else {
      std::snprintf(line, sizeof line, "guidance on the truth: %d waypoints reached\n",
                    g.waypoints);
    }
    out += line;
  }
  if (metrics.sources.empty()) {
    out += "(no VO source in the run)\n";
  } else {
    const SourceMetrics& first = metrics.sources.begin()->second;
    std::snprintf(line, sizeof line, "APE alignment: %s; RPE delta: %g %s\n",
                  first.alignment.c_str(), first.rpe_delta, first.rpe_delta_unit.c_str());
    out += line;
  }
  return out;
}

}  // namespace nadir::eval
