#include "gui/plots.h"

#include <QApplication>
#include <QChartView>
#include <QColor>
#include <QImage>
#include <QLegend>
#include <QLegendMarker>
#include <QLineSeries>
#include <QList>
#include <QPainter>
#include <QPen>
#include <QPointF>
#include <QVBoxLayout>
#include <QValueAxis>
#include <QWidget>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "gui/line_thinning.h"

namespace nadir::gui {

QColor sourceColor(const RunData& run, const std::string& name) {
  // A colour from the name's hash, so a source keeps it in every run and chart;
  // one already taken in this run by a source earlier by name moves to the next.
  // (The order puts ppa on blue, vo_feature on orange and vo_direct on green; no
  // grey, which the axes and labels use.)
  static const QColor kPalette[] = {QColor(0x94, 0x67, 0xbd), QColor(0x8c, 0x56, 0x4b),
                                    QColor(0xe3, 0x77, 0xc2), QColor(0xff, 0x7f, 0x0e),
                                    QColor(0x1f, 0x77, 0xb4), QColor(0x17, 0xbe, 0xcf),
                                    QColor(0x2c, 0xa0, 0x2c), QColor(0xbc, 0xbd, 0x22)};
  constexpr std::size_t kColors = std::size(kPalette);
  const auto hashed = [](const std::string& text) {
    std::uint64_t hash = 0xcbf29ce484222325ULL;  // FNV-1a: the same on every platform
    for (const unsigned char c : text) hash = (hash ^ c) * 0x100000001b3ULL;
    return static_cast<std::size_t>(hash % kColors);
  };
  std::vector<bool> taken(kColors, false);
  for (const auto& [other, series] : run.sources) {
    std::size_t index = hashed(other);
    for (std::size_t k = 0; k < kColors && taken[index]; ++k) index = (index + 1) % kColors;
    if (other == name) return kPalette[index];
    taken[index] = true;
  }
  return kPalette[hashed(name)];
}

QString truthLabel(const RunData& run) {
  if (run.truth_name == kRecordedTruthName) return QStringLiteral("truth");
  return QString::fromStdString(run.truth_name) + QStringLiteral(" (truth)");
}

QString sourceLabel(const RunData& run, const std::string& name) {
  // The recorded truth compared with another is not the truth of these charts.
  if (name == kRecordedTruthName && name != run.truth_name) {
    return QStringLiteral("truth (recorded)");
  }
  return QString::fromStdString(name);
}

namespace {

// Sets an axis's range, first widening a tick interval that would be far too
// fine for it: with dynamic ticks Qt lays the old interval out over the new
// range before anyone can change it, and an interval a million times too small
// (a diverged estimate's kilometres after metres) hangs it making tick items.
void setAxisRange(QValueAxis* axis, double lo, double hi) {
  if (axis->tickType() == QValueAxis::TicksDynamic && hi > lo &&
      axis->tickInterval() < (hi - lo) / 1000.0) {
    axis->setTickInterval((hi - lo) / 10.0);
  }
  axis->setRange(lo, hi);
}

// The pixels a line is thinned for while the chart's plot area is not known (it
// is laid out when first shown): as many as a wide screen's chart, so that the
// first picture already shows every spike.
constexpr int kPixelsBeforeLayout = 2000;
// A line is broken where samples are further apart than this (a gap in the
// estimates), so that no pose is drawn where there was none.
constexpr double kMaxGap_s = 1.0;

const QColor kTruthColor(Qt::black);

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    min = std::min(min, v);
    max = std::max(max, v);
  }
  bool empty() const { return min > max; }
};

// How a chart's lines are thinned (gui/line_thinning.h): against time, M4 per
// pixel column of the x axis; or as a path in the plane (the top view), to half
// a pixel on each axis.
enum class Thinning { kTimeSeries, kPath };

// A piece of a line drawn unbroken: every point of it, and the series that draws
// those kept for the current view.
struct LineSegment {
  QLineSeries* series = nullptr;
  std::vector<PlotPoint> points;
};

// The whole segment in view, at kPixelsBeforeLayout: its drawing before the chart
// has axis ranges and a plot area.
PlotView wholeSegmentView(const std::vector<PlotPoint>& points) {
  PlotView view{points.front().x, points.front().x,    points.front().y,
                points.front().y, kPixelsBeforeLayout, kPixelsBeforeLayout};
  for (const PlotPoint& point : points) {
    view.x_lo = std::min(view.x_lo, point.x);
    view.x_hi = std::max(view.x_hi, point.x);
    view.y_lo = std::min(view.y_lo, point.y);
    view.y_hi = std::max(view.y_hi, point.y);
  }
  return view;
}

// Draws the segment's points kept for the view; one replace() for the whole list,
// as appending point by point redraws at each.
void drawThinned(Thinning thinning, const LineSegment& segment, const PlotView& view) {
  const std::vector<std::size_t> kept =
      thinning == Thinning::kTimeSeries
          ? keptTimeSeriesPoints(segment.points, view.x_lo, view.x_hi, view.width_px)
          : keptPathPointsInView(segment.points, view);
  QList<QPointF> drawn;
  drawn.reserve(static_cast<qsizetype>(kept.size()));
  for (const std::size_t i : kept) drawn.append(QPointF(segment.points[i].x, segment.points[i].y));
  segment.series->replace(drawn);
}

// Re-thins every segment of the chart from its full points whenever what they
// are drawn for changes: the x range (a path's y range too) or the plot area's
// size. Replacing points changes neither, so this starts no loop with the
// axes' other handlers (keepRoundTicks, keepEqualScale).
void keepThinned(QChart* chart, QValueAxis* x_axis, QValueAxis* y_axis, Thinning thinning,
                 std::shared_ptr<const std::vector<LineSegment>> segments) {
  auto drawn_for = std::make_shared<std::optional<PlotView>>();
  const auto rethin = [=] {
    const QRectF area = chart->plotArea();
    const auto pixels = [&](double length_px) {
      return area.isEmpty() ? kPixelsBeforeLayout
                            : std::max(1, static_cast<int>(std::lround(length_px)));
    };
    PlotView view;
    view.x_lo = x_axis->min();
    view.x_hi = x_axis->max();
    view.width_px = pixels(area.width());
    // A time series is thinned along x only: its y range and height change nothing.
    if (thinning == Thinning::kPath) {
      view.y_lo = y_axis->min();
      view.y_hi = y_axis->max();
      view.height_px = pixels(area.height());
    }
    // The plot area changes with every layout, mostly not its width.
    if (*drawn_for == view) return;
    *drawn_for = view;
    for (const LineSegment& segment : *segments) drawThinned(thinning, segment, view);
  };
  rethin();
  QObject::connect(x_axis, &QValueAxis::rangeChanged, chart, rethin);
  if (thinning == Thinning::kPath) {
    QObject::connect(y_axis, &QValueAxis::rangeChanged, chart, rethin);
  }
  // Queued: the chart is laying itself out when it says its plot area changed.
  QObject::connect(chart, &QChart::plotAreaChanged, chart, rethin, Qt::QueuedConnection);
}

// One chart with value axes; every line added goes on both axes, drawn thinned
// to the points that make its pixels (re-thinned on every zoom and pan).
class ChartBuilder {
 public:
  ChartBuilder(const QString& title, const QString& x_title, const QString& y_title,
               Thinning thinning = Thinning::kTimeSeries)
      : chart_(std::make_unique<QChart>()), thinning_(thinning) {
    chart_->setTitle(title);
    chart_->legend()->setVisible(true);
    chart_->legend()->setAlignment(Qt::AlignRight);
    chart_->setMargins(QMargins(4, 4, 4, 4));
    x_axis_ = new QValueAxis;
    y_axis_ = new QValueAxis;
    x_axis_->setTitleText(x_title);
    y_axis_->setTitleText(y_title);
    chart_->addAxis(x_axis_, Qt::AlignBottom);
    chart_->addAxis(y_axis_, Qt::AlignLeft);
  }

  // Draws (x[i], y[i]) as one legend entry; the line breaks at NaN, at time gaps
  // (t may be empty: no gap test), and, for angles, where they wrap at +-180 deg.
  void addLine(const QString& name, const QColor& color, double width, const std::vector<double>& t,
               const std::vector<double>& x, const std::vector<double>& y, bool wraps = false) {
    const std::size_t n = std::min(x.size(), y.size());
    QPen pen(color);
    pen.setWidthF(width);
    std::vector<PlotPoint> points;  // of the segment being gathered
    bool named = false;
    std::size_t last = 0;
    const auto finish = [&] {
      if (points.empty()) return;
      auto* series = new QLineSeries;
      series->setName(name);
      series->setPen(pen);
      LineSegment& segment = segments_->emplace_back(LineSegment{series, std::move(points)});
      points.clear();
      // Drawn before attaching: the axes' first ranges come from the series.
      drawThinned(thinning_, segment, wholeSegmentView(segment.points));
      attach(series, named);
      named = true;
    };
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
        finish();
        continue;
      }
      if (!points.empty()) {
        const bool gap = !t.empty() && t[i] - t[last] > kMaxGap_s;
        const bool wrap = wraps && std::abs(y[i] - y[last]) > 180.0;
        if (gap || wrap) finish();
      }
      points.push_back({x[i], y[i]});
      // The axes fit every point, not only those drawn.
      x_range_.add(x[i]);
      y_range_.add(y[i]);
      last = i;
    }
    finish();
    if (!named) {
      // Nothing to draw: still list the source, so that its absence shows.
      auto* empty = new QLineSeries;
      empty->setName(name + " (no pose)");
      empty->setPen(pen);
      attach(empty, false);
    }
  }

  Range xRange() const { return x_range_; }
  Range yRange() const { return y_range_; }

  // Fits the axes to the data, with round tick values.
  std::unique_ptr<QChart> take() {
    setRange(x_axis_, x_range_, 0.0);
    setRange(y_axis_, y_range_, 0.05);
    keepRoundTicks(chart_.get(), x_axis_);
    keepRoundTicks(chart_.get(), y_axis_);
    keepThinned(chart_.get(), x_axis_, y_axis_, thinning_, segments_);
    return std::move(chart_);
  }

  // The axes' ranges and ticks left to the caller.
  std::unique_ptr<QChart> takeAsIs() {
    keepThinned(chart_.get(), x_axis_, y_axis_, thinning_, segments_);
    return std::move(chart_);
  }

  QValueAxis* xAxis() const { return x_axis_; }
  QValueAxis* yAxis() const { return y_axis_; }

 private:
  void attach(QLineSeries* series, bool hide_from_legend) {
    chart_->addSeries(series);
    series->attachAxis(x_axis_);
    series->attachAxis(y_axis_);
    if (hide_from_legend) {
      for (QLegendMarker* marker : chart_->legend()->markers(series)) marker->setVisible(false);
    }
  }

  static void setRange(QValueAxis* axis, const Range& range, double margin) {
    if (range.empty()) {
      setAxisRange(axis, 0, 1);
      return;
    }
    double lo = range.min;
    double hi = range.max;
    const double pad = std::max((hi - lo) * margin, hi == lo ? 1.0 : 0.0);
    lo -= pad;
    hi += pad;
    setAxisRange(axis, lo, hi);
  }

  std::unique_ptr<QChart> chart_;
  Thinning thinning_;
  // Shared with the chart's re-thinning, which outlives the builder.
  std::shared_ptr<std::vector<LineSegment>> segments_ =
      std::make_shared<std::vector<LineSegment>>();
  QValueAxis* x_axis_ = nullptr;
  QValueAxis* y_axis_ = nullptr;
  Range x_range_;
  Range y_range_;
};

std::vector<double> sinceStart(const std::vector<double>& t_s, double t0_s) {
  std::vector<double> out(t_s.size());
  std::transform(t_s.begin(), t_s.end(), out.begin(), [t0_s](double t) { return t - t0_s; });
  return out;
}

QString runName(const RunData& run) {
  std::filesystem::path path = std::filesystem::path(run.dir).lexically_normal();
  if (!path.has_filename()) path = path.parent_path();  // "dir/" names dir
  return QString::fromStdString(path.filename().string());
}

using Field = std::vector<double> FigureColumns::*;

// One chart per field of the pose, truth and every source on each.
Figure timeFigure(const RunData& run, const HiddenTrajectories& hidden, const std::string& name,
                  const QString& title, const std::vector<std::pair<Field, QString>>& fields,
                  bool angles) {
  Figure figure;
  figure.name = name;
  const FigureColumns truth = figureColumns(run.truth);
  std::map<std::string, FigureColumns> sources;
  for (const auto& [source, series] : run.sources) sources[source] = figureColumns(series);
  const std::vector<double> truth_t = sinceStart(truth.t_s, run.t0_s);
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const auto& [field, label] = fields[k];
    ChartBuilder chart(k == 0 ? title + ": " + runName(run) : QString(), "time (s)", label);
    if (!hidden.contains(run.truth_name)) {
      chart.addLine(truthLabel(run), kTruthColor, 2.0, truth_t, truth_t, truth.*field, angles);
    }
    for (const auto& [source, columns] : sources) {
      if (hidden.contains(source)) continue;
      const std::vector<double> t = sinceStart(columns.t_s, run.t0_s);
      chart.addLine(sourceLabel(run, source), sourceColor(run, source), 1.5, t, t, columns.*field,
                    angles);
    }
    figure.charts.push_back(chart.take());
  }
  return figure;
}

double metresPerPixel(const QValueAxis* axis, double length_px) {
  return (axis->max() - axis->min()) / length_px;
}

// Fits both axes to the whole track, with the same metres per pixel.
void equalizeAxes(QValueAxis* x_axis, QValueAxis* y_axis, const Range& x, const Range& y,
                  const QRectF& area) {
  if (area.width() <= 0 || area.height() <= 0 || x.empty() || y.empty()) return;
  const double pad = 0.05 * std::max({x.max - x.min, y.max - y.min, 1.0});
  const double scale =
      std::max((x.max - x.min + 2 * pad) / area.width(), (y.max - y.min + 2 * pad) / area.height());
  const double x_mid = 0.5 * (x.min + x.max);
  const double y_mid = 0.5 * (y.min + y.max);
  setAxisRange(x_axis, x_mid - 0.5 * scale * area.width(), x_mid + 0.5 * scale * area.width());
  setAxisRange(y_axis, y_mid - 0.5 * scale * area.height(), y_mid + 0.5 * scale * area.height());
}

// Keeps the same metres per pixel on both axes: fitted to the whole track (x, y)
// while the chart is not zoomed, and after any range change (a zoom rectangle, a
// pan) or resize of a zoomed chart by widening the axis with fewer metres per
// pixel about its centre to match the other.
void keepEqualScale(QChart* chart, QValueAxis* x_axis, QValueAxis* y_axis, const Range& x,
                    const Range& y) {
  auto adjusting = std::make_shared<bool>(false);
  const auto match = [=] {
    const QRectF area = chart->plotArea();
    if (*adjusting || area.width() <= 0 || area.height() <= 0) return;
    const double x_mpp = metresPerPixel(x_axis, area.width());
    const double y_mpp = metresPerPixel(y_axis, area.height());
    if (std::abs(x_mpp - y_mpp) <= 1e-9 * std::max(x_mpp, y_mpp)) return;
    *adjusting = true;
    QValueAxis* widened = x_mpp < y_mpp ? x_axis : y_axis;
    const double length_px = x_mpp < y_mpp ? area.width() : area.height();
    const double mid = 0.5 * (widened->min() + widened->max());
    const double half = 0.5 * std::max(x_mpp, y_mpp) * length_px;
    setAxisRange(widened, mid - half, mid + half);
    *adjusting = false;
  };
  equalizeAxes(x_axis, y_axis, x, y, chart->plotArea());
  // The plot area is known only once the chart is laid out, and changes with it
  // (and with the width of the tick labels). Queued: a range set while the chart
  // is laying itself out re-enters the layout.
  QObject::connect(
      chart, &QChart::plotAreaChanged, chart,
      [=](const QRectF& area) {
        if (chart->isZoomed()) {
          match();
        } else {
          *adjusting = true;
          equalizeAxes(x_axis, y_axis, x, y, area);
          *adjusting = false;
        }
      },
      Qt::QueuedConnection);
  // Queued: a zoom sets one axis and then the other; match the pair it leaves.
  QObject::connect(x_axis, &QValueAxis::rangeChanged, chart, match, Qt::QueuedConnection);
  QObject::connect(y_axis, &QValueAxis::rangeChanged, chart, match, Qt::QueuedConnection);
}

}  // namespace

double roundTickStep(double span_units, double length_px, double spacing_px) {
  if (!(span_units > 0) || !(length_px > 0)) return 1.0;
  const double rough = span_units * std::max(spacing_px, 1.0) / length_px;
  const double decade = std::pow(10.0, std::floor(std::log10(rough)));
  const double mantissa = rough / decade;
  return decade * (mantissa < 1.5 ? 1 : mantissa < 3.5 ? 2 : mantissa < 7.5 ? 5 : 10);
}

QString tickLabelFormat(double step) {
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  return QStringLiteral("%.%1f").arg(decimals);
}

void keepRoundTicks(QChart* chart, QValueAxis* axis) {
  const auto apply = [chart, axis] {
    const QRectF area = chart->plotArea();
    const bool horizontal = axis->orientation() == Qt::Horizontal;
    // Before the first layout there is no plot area: assume a 1200x800 chart's.
    const double length_px = area.isEmpty() ? (horizontal ? 1000.0 : 600.0)
                                            : (horizontal ? area.width() : area.height());
    const double step =
        roundTickStep(axis->max() - axis->min(), length_px,
                      horizontal ? kHorizontalTickSpacingPx : kVerticalTickSpacingPx);
    axis->setTickType(QValueAxis::TicksDynamic);
    axis->setTickAnchor(0.0);
    axis->setTickInterval(step);
    axis->setLabelFormat(tickLabelFormat(step));
  };
  apply();
  QObject::connect(axis, &QValueAxis::rangeChanged, chart, apply);
  QObject::connect(chart, &QChart::plotAreaChanged, axis, apply);
}

Figure positionFigure(const RunData& run, const HiddenTrajectories& hidden) {
  return timeFigure(run, hidden, "position", "Position (world NED)",
                    {{&FigureColumns::x_m, "north x (m)"},
                     {&FigureColumns::y_m, "east y (m)"},
                     {&FigureColumns::z_m, "down z (m)"}},
                    false);
}

Figure attitudeFigure(const RunData& run, const HiddenTrajectories& hidden) {
  return timeFigure(run, hidden, "attitude", "Attitude (Z-Y-X)",
                    {{&FigureColumns::roll_deg, "roll (deg)"},
                     {&FigureColumns::pitch_deg, "pitch (deg)"},
                     {&FigureColumns::yaw_deg, "yaw (deg)"}},
                    true);
}

Figure errorFigure(const RunData& run, const HiddenTrajectories& hidden) {
  Figure figure;
  figure.name = "error";
  ChartBuilder chart("Position error: " + runName(run), "time (s)", "|p_est - p_truth| (m)");
  for (const auto& [source, series] : run.sources) {
    if (hidden.contains(source)) continue;
    std::vector<double> t;
    for (const logs::SourceEstimate& estimate : series.estimates)
      t.push_back(estimate.t_s - run.t0_s);
    chart.addLine(sourceLabel(run, source), sourceColor(run, source), 1.5, t, t,
                  series.position_error_m);
    if (!series.sigma3_m.empty()) {
      const std::vector<double> sigma_t = sinceStart(series.sigma3_t_s, run.t0_s);
      chart.addLine(sourceLabel(run, source) + " 3\u03c3", sourceColor(run, source).lighter(160),
                    1.0, sigma_t, sigma_t, series.sigma3_m);
    }
  }
  std::unique_ptr<QChart> built = chart.take();
  // An error axis starts at zero: the error's size, not its wiggle, is the point.
  auto* y_axis = static_cast<QValueAxis*>(built->axes(Qt::Vertical).front());
  if (!chart.yRange().empty()) setAxisRange(y_axis, 0, chart.yRange().max * 1.05);
  figure.charts.push_back(std::move(built));
  return figure;
}

Figure topViewFigure(const RunData& run, const HiddenTrajectories& hidden) {
  Figure figure;
  figure.name = "top_view";
  ChartBuilder chart("Top view: " + runName(run), "east y (m)", "north x (m)", Thinning::kPath);
  const FigureColumns truth = figureColumns(run.truth);
  const std::vector<double> truth_t = sinceStart(truth.t_s, run.t0_s);
  if (!hidden.contains(run.truth_name)) {
    chart.addLine(truthLabel(run), kTruthColor, 2.0, truth_t, truth.y_m, truth.x_m);
  }
  for (const auto& [source, series] : run.sources) {
    if (hidden.contains(source)) continue;
    const FigureColumns columns = figureColumns(series);
    const std::vector<double> t = sinceStart(columns.t_s, run.t0_s);
    chart.addLine(sourceLabel(run, source), sourceColor(run, source), 1.5, t, columns.y_m,
                  columns.x_m);
  }
  const Range x = chart.xRange();
  const Range y = chart.yRange();
  QValueAxis* x_axis = chart.xAxis();
  QValueAxis* y_axis = chart.yAxis();
  std::unique_ptr<QChart> built = chart.takeAsIs();
  QChart* raw = built.get();
  keepEqualScale(raw, x_axis, y_axis, x, y);
  keepRoundTicks(raw, x_axis);
  keepRoundTicks(raw, y_axis);
  figure.charts.push_back(std::move(built));
  return figure;
}

std::vector<Figure> buildFigures(const RunData& run, const HiddenTrajectories& hidden) {
  std::vector<Figure> figures;
  figures.push_back(positionFigure(run, hidden));
  figures.push_back(attitudeFigure(run, hidden));
  figures.push_back(errorFigure(run, hidden));
  figures.push_back(topViewFigure(run, hidden));
  return figures;
}

std::unique_ptr<QWidget> figureWidget(Figure figure) {
  auto widget = std::make_unique<QWidget>();
  widget->setWindowTitle(QString::fromStdString(figure.name));
  auto* layout = new QVBoxLayout(widget.get());
  layout->setContentsMargins(0, 0, 0, 0);
  layout->setSpacing(0);
  for (std::unique_ptr<QChart>& chart : figure.charts) {
    auto* view = new QChartView(chart.release());
    view->setRenderHint(QPainter::Antialiasing);
    layout->addWidget(view);
  }
  return widget;
}

void renderFigurePng(Figure figure, const std::string& path, int width, int height) {
  std::unique_ptr<QWidget> widget = figureWidget(std::move(figure));
  widget->resize(width, height);
  // Drawing once delivers the resize; the charts then lay themselves out (and the
  // top view reacts to its plot area) in the events that follow. No window is shown.
  QImage image(width, height, QImage::Format_RGB32);
  widget->render(&image);
  for (int i = 0; i < 3; ++i) QApplication::processEvents();
  image.fill(Qt::white);
  QPainter painter(&image);
  widget->render(&painter);
  painter.end();
  if (!image.save(QString::fromStdString(path), "PNG")) {
    throw RunDataError(path + ": cannot write the PNG file");
  }
}

}  // namespace nadir::gui
