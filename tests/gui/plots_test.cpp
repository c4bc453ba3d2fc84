#include "gui/plots.h"

#include <QApplication>
#include <QChartView>
#include <QColor>
#include <QImage>
#include <QLineSeries>
#include <QValueAxis>
#include <QWidget>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "gui_test_util.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

class GuiPlots : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (QApplication::instance() != nullptr) return;
    setenv("QT_QPA_PLATFORM", "offscreen", 1);
    static int argc = 1;
    static char name[] = "gui_plot_test";
    static char* argv[] = {name, nullptr};
    // Never destroyed: Qt must outlive every test, and ends with the process.
    new QApplication(argc, argv);
  }
};

struct PixelCounts {
  int not_white = 0;
  int near_source = 0;  // vo_test: the first colour after the known sources'
  int near_black = 0;
};

PixelCounts countPixels(const QImage& image, const QColor& source) {
  PixelCounts counts;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      if (c != QColor(Qt::white)) ++counts.not_white;
      if (std::abs(c.red() - source.red()) + std::abs(c.green() - source.green()) +
              std::abs(c.blue() - source.blue()) <
          40) {
        ++counts.near_source;
      }
      if (c == QColor(Qt::black)) ++counts.near_black;  // text is grey: only the truth
    }
  }
  return counts;
}

// A diverged estimate (thousands of km off a truth of metres) is drawn like
// any other: each figure is written, its axes spanning the estimate. (Qt laid a
// metre-sized tick interval over the widened range and hung making items.)
TEST_F(GuiPlots, ADivergedEstimateIsDrawn) {
  const fs::path dir = test::freshDir("plots_diverged");
  core::writeTum((dir / "truth.tum").string(), test::truthTrajectory());
  core::Trajectory diverged = test::estimateTrajectory();
  for (std::size_t j = 0; j < diverged.size(); ++j)
    diverged[j].p_ned_m += Eigen::Vector3d(4e7, -3e7, 1e6) * static_cast<double>(j) /
                           static_cast<double>(diverged.size());
  core::writeTum((dir / "vo_test.tum").string(), diverged);
  const RunData run = loadRun(dir.string());
  const fs::path out = test::freshDir("plots_diverged_out");
  for (Figure& figure : buildFigures(run)) {
    const std::string name = figure.name;
    const fs::path path = out / (name + ".png");
    renderFigurePng(std::move(figure), path.string(), 1200, 800);
    EXPECT_FALSE(QImage(QString::fromStdString(path.string())).isNull()) << name;
  }
}

TEST_F(GuiPlots, HeadlessRenderingWritesNonBlankPngsOfTheRightSize) {
  const RunData run = loadRun(test::writeTumRun("plots_run").string());
  const fs::path out = test::freshDir("plots_out");
  std::vector<Figure> figures = buildFigures(run);
  ASSERT_EQ(figures.size(), 4u);
  EXPECT_EQ(figures[0].charts.size(), 3u);  // north, east, down
  EXPECT_EQ(figures[1].charts.size(), 3u);  // roll, pitch, yaw
  for (Figure& figure : figures) {
    const std::string name = figure.name;
    const fs::path path = out / (name + ".png");
    renderFigurePng(std::move(figure), path.string(), 1200, 800);
    QImage image(QString::fromStdString(path.string()));
    ASSERT_FALSE(image.isNull()) << name;
    EXPECT_EQ(image.width(), 1200) << name;
    EXPECT_EQ(image.height(), 800) << name;
    const PixelCounts counts = countPixels(image, sourceColor(run, "vo_test"));
    EXPECT_GT(counts.not_white, 1200 * 800 / 50) << name;  // axes, labels and lines
    EXPECT_GT(counts.near_source, 50) << name;             // the source's line and legend
    if (name != "error") {
      EXPECT_GT(counts.near_black, 100) << name;  // the truth
    }
  }
  for (const char* name : {"position", "attitude", "error", "top_view"}) {
    EXPECT_TRUE(fs::exists(out / (std::string(name) + ".png"))) << name;
  }
}

// A source keeps its colour whatever the run's other sources, two sources of one
// run never share one, and none is the truth's black.
// A navigation filter's error is drawn with its 3-sigma envelope, a series of
// its own at its states' stamps (since the truth's start); a VO's has none.
TEST_F(GuiPlots, AFiltersErrorHasItsEnvelope) {
  RunData run = loadRun(test::writeTumRun("envelope_run").string());
  ASSERT_EQ(run.sources.count("vo_test"), 1u);
  Figure plain = errorFigure(run);
  ASSERT_EQ(plain.charts.size(), 1u);
  EXPECT_EQ(plain.charts[0]->series().size(), 1);
  SourceSeries& source = run.sources.at("vo_test");
  source.sigma3_t_s = {run.t0_s + 0.5, run.t0_s + 1.0, run.t0_s + 1.5};
  source.sigma3_m = {0.3, 0.6, 0.9};
  Figure figure = errorFigure(run);
  ASSERT_EQ(figure.charts[0]->series().size(), 2);
  const auto* envelope = dynamic_cast<QLineSeries*>(figure.charts[0]->series().at(1));
  ASSERT_NE(envelope, nullptr);
  EXPECT_TRUE(envelope->name().endsWith(QString::fromUtf8(" 3\u03c3")))
      << envelope->name().toStdString();
  ASSERT_EQ(envelope->count(), 3);
  EXPECT_DOUBLE_EQ(envelope->at(1).x(), 1.0);
  EXPECT_DOUBLE_EQ(envelope->at(1).y(), 0.6);
}

TEST_F(GuiPlots, EachSourceKeepsItsColour) {
  RunData alone, together, crowd;
  alone.sources["vo_feature"];
  together.sources["vo_feature"];
  together.sources["ppa"];
  together.sources["vo_direct"];
  EXPECT_EQ(sourceColor(alone, "vo_feature"), sourceColor(together, "vo_feature"));
  for (int i = 0; i < 8; ++i) crowd.sources["source_" + std::to_string(i)];
  std::set<QRgb> colours;
  for (const auto& [name, series] : crowd.sources) {
    const QColor colour = sourceColor(crowd, name);
    EXPECT_NE(colour, QColor(Qt::black)) << name;
    colours.insert(colour.rgb());
  }
  EXPECT_EQ(colours.size(), crowd.sources.size());
  EXPECT_NE(sourceColor(together, "ppa"), sourceColor(together, "vo_feature"));
  EXPECT_NE(sourceColor(together, "ppa"), sourceColor(together, "vo_direct"));
  EXPECT_NE(sourceColor(together, "vo_feature"), sourceColor(together, "vo_direct"));
}

TEST_F(GuiPlots, TopViewHasTheSameScaleOnBothAxes) {
  const RunData run = loadRun(test::writeTumRun("top_view_run").string());
  for (const QSize size : {QSize(1200, 800), QSize(500, 900)}) {
    const std::unique_ptr<QWidget> widget = figureWidget(topViewFigure(run));
    widget->setAttribute(Qt::WA_DontShowOnScreen);
    widget->resize(size);
    widget->show();
    for (int i = 0; i < 3; ++i) QApplication::processEvents();
    const QChart* chart = widget->findChild<QChartView*>()->chart();
    const auto* x = static_cast<const QValueAxis*>(chart->axes(Qt::Horizontal).front());
    const auto* y = static_cast<const QValueAxis*>(chart->axes(Qt::Vertical).front());
    const QRectF area = chart->plotArea();
    const double x_m_per_px = (x->max() - x->min()) / area.width();
    const double y_m_per_px = (y->max() - y->min()) / area.height();
    EXPECT_NEAR(x_m_per_px / y_m_per_px, 1.0, 1e-6) << size.width() << "x" << size.height();
    // The whole flight is in view: east 0..54 m, north 0..103 m (with the offset).
    EXPECT_LE(x->min(), 0.0);
    EXPECT_GE(x->max(), 54.0);
    EXPECT_LE(y->min(), 0.0);
    EXPECT_GE(y->max(), 103.0);
  }
}

// A zoom rectangle, tall or wide, ends with the same metres per pixel on both
// axes and the whole rectangle still in view.
TEST_F(GuiPlots, TopViewKeepsTheSameScaleAfterAZoomRectangle) {
  const RunData run = loadRun(test::writeTumRun("top_view_zoom").string());
  for (const QSizeF rectangle : {QSizeF(40, 300), QSizeF(400, 30)}) {
    const std::unique_ptr<QWidget> widget = figureWidget(topViewFigure(run));
    widget->setAttribute(Qt::WA_DontShowOnScreen);
    widget->resize(900, 700);
    widget->show();
    for (int i = 0; i < 3; ++i) QApplication::processEvents();
    QChart* chart = widget->findChild<QChartView*>()->chart();
    const auto* x = static_cast<const QValueAxis*>(chart->axes(Qt::Horizontal).front());
    const auto* y = static_cast<const QValueAxis*>(chart->axes(Qt::Vertical).front());
    const QRectF area = chart->plotArea();
    const QRectF zoom(area.topLeft() + QPointF(50, 60), rectangle);
    // The rectangle's corners in metres, before the zoom.
    const QPointF top_left = chart->mapToValue(zoom.topLeft());
    const QPointF bottom_right = chart->mapToValue(zoom.bottomRight());
    chart->zoomIn(zoom);
    for (int i = 0; i < 3; ++i) QApplication::processEvents();
    const double x_mpp = (x->max() - x->min()) / chart->plotArea().width();
    const double y_mpp = (y->max() - y->min()) / chart->plotArea().height();
    EXPECT_NEAR(x_mpp / y_mpp, 1.0, 1e-6) << rectangle.width() << "x" << rectangle.height();
    EXPECT_LE(x->min(), top_left.x() + 1e-6);
    EXPECT_GE(x->max(), bottom_right.x() - 1e-6);
    EXPECT_LE(y->min(), bottom_right.y() + 1e-6);
    EXPECT_GE(y->max(), top_left.y() - 1e-6);
    // Zoomed in: the longer side of the rectangle spans the view on its axis.
    const double x_zoom_m = bottom_right.x() - top_left.x();
    const double y_zoom_m = top_left.y() - bottom_right.y();
    if (rectangle.height() > rectangle.width()) {
      EXPECT_NEAR(y->max() - y->min(), y_zoom_m, 1e-6 * y_zoom_m);
    } else {
      EXPECT_NEAR(x->max() - x->min(), x_zoom_m, 1e-6 * x_zoom_m);
    }
  }
}

// Tick steps are 1, 2 or 5 times a power of ten, about 90 px apart, and the
// labels carry the step's decimals and no more.
TEST_F(GuiPlots, TickStepsAreRound) {
  EXPECT_DOUBLE_EQ(roundTickStep(37.3, 600.0), 5.0);      // 5.6 units per 90 px
  EXPECT_DOUBLE_EQ(roundTickStep(149.44, 1000.0), 10.0);  // 13.4
  EXPECT_DOUBLE_EQ(roundTickStep(1.0, 900.0), 0.1);       // 0.1
  EXPECT_DOUBLE_EQ(roundTickStep(0.37, 300.0), 0.1);      // 0.111
  EXPECT_DOUBLE_EQ(roundTickStep(2500.0, 600.0), 500.0);  // 375
  EXPECT_DOUBLE_EQ(roundTickStep(80.0, 400.0), 20.0);     // 18
  EXPECT_EQ(tickLabelFormat(500.0), QStringLiteral("%.0f"));
  EXPECT_EQ(tickLabelFormat(1.0), QStringLiteral("%.0f"));
  EXPECT_EQ(tickLabelFormat(0.2), QStringLiteral("%.1f"));
  EXPECT_EQ(tickLabelFormat(0.05), QStringLiteral("%.2f"));
}

// Every axis of every figure keeps round ticks anchored at 0, also after a zoom.
TEST_F(GuiPlots, AxesKeepRoundTicksAfterZoom) {
  const RunData run = loadRun(test::writeTumRun("ticks_run").string());
  for (Figure& figure : buildFigures(run)) {
    const std::string name = figure.name;
    const std::unique_ptr<QWidget> widget = figureWidget(std::move(figure));
    widget->setAttribute(Qt::WA_DontShowOnScreen);
    widget->resize(1000, 800);
    widget->show();
    for (int i = 0; i < 3; ++i) QApplication::processEvents();
    for (QChartView* view : widget->findChildren<QChartView*>()) {
      QChart* chart = view->chart();
      chart->zoomIn(QRectF(chart->plotArea().topLeft() + QPointF(13, 17), QSizeF(77, 61)));
      for (int i = 0; i < 3; ++i) QApplication::processEvents();
      for (QAbstractAxis* abstract : chart->axes()) {
        const auto* axis = static_cast<const QValueAxis*>(abstract);
        EXPECT_EQ(axis->tickType(), QValueAxis::TicksDynamic) << name;
        EXPECT_DOUBLE_EQ(axis->tickAnchor(), 0.0) << name;
        const double step = axis->tickInterval();
        const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
        EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                    std::abs(mantissa - 5) < 1e-9)
            << name << " step " << step;
        const double length_px = axis->orientation() == Qt::Horizontal ? chart->plotArea().width()
                                                                       : chart->plotArea().height();
        const double spacing_px = step / (axis->max() - axis->min()) * length_px;
        // Rounding the aimed step to 1, 2, 5 or 10 (at mantissas 1.5, 3.5 and 7.5)
        // scales it by 2/3.5 at least and 5/3.5 at most.
        const double aimed_px = axis->orientation() == Qt::Horizontal ? kHorizontalTickSpacingPx
                                                                      : kVerticalTickSpacingPx;
        EXPECT_GE(spacing_px, aimed_px * 2.0 / 3.5 - 1e-6) << name;
        EXPECT_LE(spacing_px, aimed_px * 5.0 / 3.5 + 1e-6) << name;
      }
    }
  }
}

// Every point the chart's line series draw, all segments together.
std::vector<QPointF> drawnPoints(const QChart* chart) {
  std::vector<QPointF> points;
  for (QAbstractSeries* series : chart->series()) {
    if (const auto* line = qobject_cast<const QLineSeries*>(series)) {
      for (const QPointF& point : line->points()) points.push_back(point);
    }
  }
  return points;
}

bool drawsPoint(const QChart* chart, double x, double y) {
  const std::vector<QPointF> points = drawnPoints(chart);
  return std::any_of(points.begin(), points.end(), [&](const QPointF& point) {
    return std::abs(point.x() - x) < 1e-6 && std::abs(point.y() - y) < 1e-6;
  });
}

// A long run: 100 000 samples at 10 Hz (t = 0 to 9999.9 s), all 1 m but one of
// 51 m at t = 6123.4 s (sample 61234). The old thinning to every 25th sample
// lost it (61234 is no multiple of 25).
constexpr int kLongRunSamples = 100000;
constexpr int kSpikeSample = 61234;
constexpr double kSpikeTime_s = 6123.4;

// The error figure of the long run draws the spike over the whole run, zoomed to
// a window about it, and not in a window away from it, where the line still runs
// to both edges. The axes fit every sample (0 to 51 m * 1.05 = 53.55 m).
TEST_F(GuiPlots, AnErrorSpikeIsDrawnAtEveryZoom) {
  RunData run;
  SourceSeries& source = run.sources["vo_test"];
  for (int i = 0; i < kLongRunSamples; ++i) {
    logs::SourceEstimate estimate;
    estimate.t_s = 0.1 * i;
    estimate.status = logs::SourceEstimate::kTracking;
    source.estimates.push_back(estimate);
    source.position_error_m.push_back(i == kSpikeSample ? 51.0 : 1.0);
  }
  const std::unique_ptr<QWidget> widget = figureWidget(errorFigure(run));
  widget->setAttribute(Qt::WA_DontShowOnScreen);
  widget->resize(1200, 800);
  widget->show();
  for (int i = 0; i < 3; ++i) QApplication::processEvents();
  QChart* chart = widget->findChild<QChartView*>()->chart();
  auto* x = static_cast<QValueAxis*>(chart->axes(Qt::Horizontal).front());
  const auto* y = static_cast<const QValueAxis*>(chart->axes(Qt::Vertical).front());
  EXPECT_NEAR(x->min(), 0.0, 1e-9);
  EXPECT_NEAR(x->max(), 9999.9, 1e-9);
  EXPECT_NEAR(y->max(), 53.55, 1e-9);

  EXPECT_TRUE(drawsPoint(chart, kSpikeTime_s, 51.0));
  // At most 4 points per pixel column of the plot area, plus the 2 outside it.
  const double width_px = chart->plotArea().width();
  ASSERT_GT(width_px, 0.0);
  EXPECT_LE(drawnPoints(chart).size(), 4 * static_cast<std::size_t>(std::lround(width_px)) + 2);

  for (const auto& [lo_s, hi_s, spike_inside] :
       {std::tuple(6100.0, 6150.0, true), std::tuple(7000.0, 7050.0, false)}) {
    x->setRange(lo_s, hi_s);
    for (int i = 0; i < 3; ++i) QApplication::processEvents();
    EXPECT_EQ(drawsPoint(chart, kSpikeTime_s, 51.0), spike_inside) << lo_s;
    const std::vector<QPointF> points = drawnPoints(chart);
    ASSERT_FALSE(points.empty()) << lo_s;
    const auto [left, right] =
        std::minmax_element(points.begin(), points.end(),
                            [](const QPointF& a, const QPointF& b) { return a.x() < b.x(); });
    // The samples just outside the window: 0.1 s before and after it.
    EXPECT_NEAR(left->x(), lo_s - 0.1, 1e-6) << lo_s;
    EXPECT_NEAR(right->x(), hi_s + 0.1, 1e-6) << lo_s;
  }
}

// The top view of a long flight north (0.1 m a sample, 0 to 9999.9 m) with one
// sample 50 m east, at north 6123.4 m, draws that sample, also zoomed to a 40 px
// square about it (about 600 m across: some 6000 samples in view), with far fewer
// points than the flight has.
TEST_F(GuiPlots, ATopViewExcursionIsDrawnAtEveryZoom) {
  RunData run;
  for (int i = 0; i < kLongRunSamples; ++i) {
    const double east_m = i == kSpikeSample ? 50.0 : 0.0;
    run.truth.push_back({0.1 * i, Eigen::Vector3d(0.1 * i, east_m, -100.0), test::attitude()});
  }
  const std::unique_ptr<QWidget> widget = figureWidget(topViewFigure(run));
  widget->setAttribute(Qt::WA_DontShowOnScreen);
  widget->resize(1200, 800);
  widget->show();
  for (int i = 0; i < 3; ++i) QApplication::processEvents();
  QChart* chart = widget->findChild<QChartView*>()->chart();
  const auto* x = static_cast<const QValueAxis*>(chart->axes(Qt::Horizontal).front());
  EXPECT_TRUE(drawsPoint(chart, 50.0, kSpikeTime_s));
  EXPECT_LT(drawnPoints(chart).size(), static_cast<std::size_t>(kLongRunSamples) / 10);
  const QPointF spike_px = chart->mapToPosition(QPointF(50.0, kSpikeTime_s));
  chart->zoomIn(QRectF(spike_px - QPointF(20, 20), QSizeF(40, 40)));
  for (int i = 0; i < 3; ++i) QApplication::processEvents();
  EXPECT_LT(x->max() - x->min(), 2000.0);  // zoomed in from 15 900 m
  EXPECT_TRUE(drawsPoint(chart, 50.0, kSpikeTime_s));
  EXPECT_LT(drawnPoints(chart).size(), static_cast<std::size_t>(kLongRunSamples) / 10);
}

TEST_F(GuiPlots, AnUnwritablePathIsNamed) {
  const RunData run = loadRun(test::writeTumRun("unwritable_run").string());
  const std::string path = (test::freshDir("unwritable") / "no" / "such" / "error.png").string();
  try {
    renderFigurePng(errorFigure(run), path, 300, 200);
    FAIL() << "no error";
  } catch (const RunDataError& error) {
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace nadir::gui
