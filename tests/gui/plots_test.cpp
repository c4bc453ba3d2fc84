#include "gui/plots.h"

#include <QApplication>
#include <QChartView>
#include <QColor>
#include <QImage>
#include <QValueAxis>
#include <QWidget>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

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
    const PixelCounts counts = countPixels(image, QColor(0x94, 0x67, 0xbd));
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
