// The interactive window under Qt's offscreen platform: the runs it lists, the
// trajectories and the truth chosen, the table against the run's metrics, the
// figures, legend toggling, zoom, exports, and a damaged run that must not take
// the window down.

#include "gui/plot_window.h"

#include <QApplication>
#include <QChart>
#include <QChartView>
#include <QColor>
#include <QComboBox>
#include <QImage>
#include <QLabel>
#include <QLegend>
#include <QLegendMarker>
#include <QListWidget>
#include <QTabWidget>
#include <QTableWidget>
#include <QTreeWidget>
#include <QValueAxis>
#include <QWheelEvent>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <string>

#include "core/bus.h"
#include "gui/live_feed.h"
#include "gui/plots.h"
#include "gui_test_util.h"
#include "tests/support/lcm_messages.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

class GuiPlotWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (QApplication::instance() != nullptr) return;
    setenv("QT_QPA_PLATFORM", "offscreen", 1);
    static int argc = 1;
    static char name[] = "gui_window_test";
    static char* argv[] = {name, nullptr};
    // Never destroyed: Qt must outlive every test, and ends with the process.
    new QApplication(argc, argv);
  }

  // root/computed (metrics from the poses), root/json (metrics.json, no RPE),
  // root/nameless (the estimates called vo_other) and root/sub/bad (a truth.tum
  // that does not parse).
  static fs::path makeRoot() {
    const fs::path root = test::freshDir("window_root");
    const fs::path source = test::writeTumRun("window_source");
    fs::copy(source, root / "computed");
    fs::copy(source, root / "json");
    eval::RunMetrics metrics;
    metrics.truth_poses = 101;
    eval::SourceMetrics m;
    m.position_rmse_m = 0.1 + 0.2;  // not short in decimal: the table must keep every digit
    m.rotation_rmse_deg = 0.25;
    m.tracked_pct = 87.5;
    m.ape_translation_m.rmse = 6.125;
    metrics.sources["vo_test"] = m;
    eval::writeMetricsJson((root / "json" / "metrics.json").string(), metrics, {});
    fs::create_directories(root / "sub");
    fs::copy(source, root / "sub" / "bad");
    fs::create_directories(root / "nameless");
    fs::copy_file(source / "truth.tum", root / "nameless" / "truth.tum");
    fs::copy_file(source / "vo_test.tum", root / "nameless" / "vo_other.tum");
    std::ofstream(root / "sub" / "bad" / "truth.tum", std::ios::app) << "oops\n";
    return root;
  }
};

void settle() {
  for (int i = 0; i < 5; ++i) QApplication::processEvents();
}

// Every row of the table, parsed back, against the run's metrics.
void expectTableMatches(const QTableWidget& table, const eval::RunMetrics& metrics) {
  ASSERT_EQ(table.columnCount(), 6);
  ASSERT_EQ(table.rowCount(), static_cast<int>(metrics.sources.size()));
  int row = 0;
  for (const auto& [name, m] : metrics.sources) {
    ASSERT_NE(table.item(row, 0), nullptr);
    EXPECT_EQ(table.item(row, 0)->text().toStdString(), name);
    const double expected[] = {m.position_rmse_m, m.rotation_rmse_deg, m.tracked_pct,
                               m.ape_translation_m.rmse, m.rpe_translation_m.rmse};
    for (int column = 1; column < 6; ++column) {
      const QTableWidgetItem* cell = table.item(row, column);
      ASSERT_NE(cell, nullptr) << row << "," << column;
      const std::string exact = cell->data(Qt::UserRole).toString().toStdString();
      const std::string shown = cell->text().toStdString();
      const double value = expected[column - 1];
      if (!std::isfinite(value)) {
        EXPECT_TRUE(exact.empty()) << column << ": " << exact;
        EXPECT_TRUE(shown.empty()) << column << ": " << shown;
      } else {
        ASSERT_FALSE(exact.empty()) << column;
        EXPECT_EQ(std::stod(exact), value) << column << ": " << exact;  // exactly
        EXPECT_NEAR(std::stod(shown), value, 0.0005) << column << ": " << shown;
      }
    }
    ++row;
  }
}

QChartView* firstChartView(QWidget* figure) {
  const QList<QChartView*> views = figure->findChildren<QChartView*>();
  return views.isEmpty() ? nullptr : views.front();
}

TEST_F(GuiPlotWindow, ListsTheRunsRelativeToTheRoot) {
  const fs::path root = makeRoot();
  PlotWindow window(QString::fromStdString(root.string()));
  QTreeWidget* tree = window.runTree();
  ASSERT_EQ(tree->topLevelItemCount(), 4);
  EXPECT_EQ(tree->topLevelItem(0)->text(0), "computed");
  EXPECT_EQ(tree->topLevelItem(1)->text(0), "json");
  EXPECT_EQ(tree->topLevelItem(2)->text(0), "nameless");
  // A directory tree: the folder sub, its run bad below it.
  QTreeWidgetItem* sub = tree->topLevelItem(3);
  EXPECT_EQ(sub->text(0), "sub");
  ASSERT_EQ(sub->childCount(), 1);
  EXPECT_EQ(sub->child(0)->text(0), "bad");
  EXPECT_TRUE(sub->isExpanded());
  // Selecting a folder loads nothing: the shown run stays.
  const RunData* shown = window.run();
  tree->setCurrentItem(sub);
  EXPECT_EQ(window.run(), shown);
  // The first run is shown at once.
  ASSERT_NE(window.run(), nullptr);
  EXPECT_EQ(window.figureTabs()->count(), 4);

  EXPECT_FALSE(window.openRoot(QString::fromStdString((root / "missing").string())));
  EXPECT_FALSE(window.lastError().isEmpty());
  EXPECT_EQ(tree->topLevelItemCount(), 0);
}

TEST_F(GuiPlotWindow, TableShowsTheRunsMetricsExactly) {
  const fs::path root = makeRoot();
  PlotWindow window(QString::fromStdString(root.string()));
  for (const char* name : {"computed", "json"}) {
    ASSERT_TRUE(window.selectRun(name)) << window.lastError().toStdString();
    ASSERT_NE(window.run(), nullptr);
    expectTableMatches(*window.errorTable(), window.run()->metrics);
  }
  // json: metrics.json's numbers, RPE absent.
  EXPECT_EQ(window.errorTable()->item(0, 1)->data(Qt::UserRole).toString(), "0.30000000000000004");
  EXPECT_EQ(window.errorTable()->item(0, 1)->text(), "0.300");
  EXPECT_TRUE(window.errorTable()->item(0, 5)->text().isEmpty());
  EXPECT_DOUBLE_EQ(window.run()->metrics.sources.at("vo_test").tracked_pct, 87.5);
}

// The series names of a figure's first chart, legend entries or not.
std::set<QString> seriesNames(QWidget* figure) {
  std::set<QString> names;
  for (QChartView* view : figure->findChildren<QChartView*>()) {
    for (QAbstractSeries* series : view->chart()->series()) names.insert(series->name());
    break;
  }
  return names;
}

TEST_F(GuiPlotWindow, ListsTheTrajectoriesAndTheTruth) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  ASSERT_TRUE(window.selectRun("computed"));
  QListWidget* list = window.trajectoryList();
  ASSERT_EQ(list->count(), 2);
  EXPECT_EQ(list->item(0)->text(), "truth");
  EXPECT_EQ(list->item(1)->text(), "vo_test");
  EXPECT_EQ(list->item(1)->checkState(), Qt::Checked);
  ASSERT_EQ(window.truthBox()->count(), 2);
  EXPECT_EQ(window.truthBox()->currentText(), "truth");
  EXPECT_TRUE(window.tableCaption()->text().startsWith("errors against truth, metrics computed"))
      << window.tableCaption()->text().toStdString();
}

// json has metrics.json: against vo_test the table is computed, the recorded truth
// 5 m off it; the choice holds for every run that has vo_test.
TEST_F(GuiPlotWindow, ChoosingTheTruthRecomputesFiguresAndTable) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  ASSERT_TRUE(window.selectRun("json"));
  window.figureTabs()->setCurrentIndex(3);
  ASSERT_TRUE(window.chooseTruth("vo_test")) << window.lastError().toStdString();
  EXPECT_EQ(window.truthName(), "vo_test");
  EXPECT_EQ(window.truthBox()->currentText(), "vo_test");
  EXPECT_EQ(window.figureTabs()->currentIndex(), 3);  // the figure looked at stays
  EXPECT_TRUE(window.run()->metrics_from.empty());
  ASSERT_EQ(window.errorTable()->rowCount(), 1);
  EXPECT_EQ(window.errorTable()->item(0, 0)->text(), "truth");
  EXPECT_NEAR(window.errorTable()->item(0, 1)->data(Qt::UserRole).toString().toDouble(), 5.0, 1e-9);
  EXPECT_TRUE(window.tableCaption()->text().startsWith("errors against vo_test (truth)"))
      << window.tableCaption()->text().toStdString();
  const std::set<QString> names = seriesNames(window.figureTabs()->widget(0));
  EXPECT_TRUE(names.contains("vo_test (truth)"));
  EXPECT_TRUE(names.contains("truth (recorded)"));

  ASSERT_TRUE(window.selectRun("computed"));
  EXPECT_EQ(window.truthName(), "vo_test");
  // A run without it keeps its recorded truth, and says why.
  ASSERT_TRUE(window.selectRun("nameless"));
  EXPECT_EQ(window.truthName(), "truth");
  EXPECT_TRUE(window.tableCaption()->text().contains("this run has no vo_test"))
      << window.tableCaption()->text().toStdString();
  ASSERT_TRUE(window.selectRun("computed"));
  // A name the run does not have is refused, and the run stays as it was.
  EXPECT_FALSE(window.chooseTruth("vo_nope"));
  EXPECT_NE(window.lastError().indexOf("no trajectory vo_nope"), -1);
  EXPECT_EQ(window.truthName(), "vo_test");
  EXPECT_EQ(window.truthBox()->currentText(), "vo_test");
  // Back to the recorded truth: metrics.json's numbers again.
  ASSERT_TRUE(window.chooseTruth("truth"));
  ASSERT_TRUE(window.selectRun("json"));
  EXPECT_EQ(window.truthName(), "truth");
  EXPECT_EQ(window.errorTable()->item(0, 1)->data(Qt::UserRole).toString(), "0.30000000000000004");
}

TEST_F(GuiPlotWindow, AnUntickedTrajectoryIsLeftOutOfTheFigures) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  ASSERT_TRUE(window.selectRun("computed"));
  ASSERT_TRUE(seriesNames(window.figureTabs()->widget(0)).contains("vo_test"));
  // Unticked as a user does: through the list.
  window.trajectoryList()->item(1)->setCheckState(Qt::Unchecked);
  for (int tab = 0; tab < window.figureTabs()->count(); ++tab) {
    EXPECT_FALSE(seriesNames(window.figureTabs()->widget(tab)).contains("vo_test")) << tab;
  }
  EXPECT_TRUE(seriesNames(window.figureTabs()->widget(0)).contains("truth"));
  EXPECT_EQ(window.errorTable()->rowCount(), 1);  // the table keeps every source
  // It stays unticked in the next run.
  ASSERT_TRUE(window.selectRun("json"));
  EXPECT_EQ(window.trajectoryList()->item(1)->checkState(), Qt::Unchecked);
  EXPECT_FALSE(seriesNames(window.figureTabs()->widget(0)).contains("vo_test"));
  window.setTrajectoryShown("vo_test", true);
  EXPECT_EQ(window.trajectoryList()->item(1)->checkState(), Qt::Checked);
  EXPECT_TRUE(seriesNames(window.figureTabs()->widget(0)).contains("vo_test"));
}

TEST_F(GuiPlotWindow, ShowsTheFiguresInTabs) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  ASSERT_TRUE(window.selectRun("computed"));
  QTabWidget* tabs = window.figureTabs();
  ASSERT_EQ(tabs->count(), 4);
  const char* names[] = {"position", "attitude", "error", "top_view"};
  const int charts[] = {3, 3, 1, 1};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(tabs->tabText(i), names[i]);
    EXPECT_EQ(tabs->widget(i)->findChildren<QChartView*>().size(), charts[i]) << names[i];
  }
}

TEST_F(GuiPlotWindow, ClickingALegendMarkerTogglesItsSeries) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  ASSERT_TRUE(window.selectRun("computed"));
  window.show();  // a legend marker is visible only in a shown chart
  settle();
  QChartView* view = firstChartView(window.figureTabs()->widget(0));
  ASSERT_NE(view, nullptr);
  QChart* chart = view->chart();
  QLegendMarker* marker = nullptr;
  for (QLegendMarker* m : chart->legend()->markers()) {
    if (m->label() == "vo_test" && m->isVisible()) marker = m;
  }
  ASSERT_NE(marker, nullptr);
  const auto visibleSeries = [chart](bool visible) {
    int count = 0;
    for (QAbstractSeries* series : chart->series()) {
      if (series->name() == "vo_test" && series->isVisible() == visible) ++count;
    }
    return count;
  };
  const int segments = visibleSeries(true);
  ASSERT_GT(segments, 0);

  emit marker->clicked();
  EXPECT_EQ(visibleSeries(true), 0);
  EXPECT_EQ(visibleSeries(false), segments);
  EXPECT_TRUE(marker->isVisible());  // still there, to click again
  for (QAbstractSeries* series : chart->series()) {
    if (series->name() == "truth") {
      EXPECT_TRUE(series->isVisible());
    }
  }

  emit marker->clicked();
  EXPECT_EQ(visibleSeries(true), segments);
  int listed = 0;
  for (QLegendMarker* m : chart->legend()->markers()) {
    if (m->label() == "vo_test" && m->isVisible()) ++listed;
  }
  EXPECT_EQ(listed, 1);  // one entry, not one per segment
}

TEST_F(GuiPlotWindow, WheelZoomsAndResetRestores) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  ASSERT_TRUE(window.selectRun("computed"));
  window.show();
  settle();
  QChartView* view = firstChartView(window.figureTabs()->widget(0));
  ASSERT_NE(view, nullptr);
  auto* x_axis = static_cast<QValueAxis*>(view->chart()->axes(Qt::Horizontal).front());
  const double span = x_axis->max() - x_axis->min();
  const QPointF center =
      view->mapFromScene(view->chart()->mapToScene(view->chart()->plotArea().center()));
  QWheelEvent wheel(center, view->mapToGlobal(center.toPoint()), QPoint(), QPoint(0, 120),
                    Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
  QApplication::sendEvent(view->viewport(), &wheel);
  EXPECT_LT(x_axis->max() - x_axis->min(), 0.9 * span);
  window.resetZoom();
  EXPECT_NEAR(x_axis->max() - x_axis->min(), span, 1e-9 * span);
}

TEST_F(GuiPlotWindow, ExportsTheFigureItsDataAndTheTable) {
  const fs::path root = makeRoot();
  const fs::path out = test::freshDir("window_out");
  PlotWindow window(QString::fromStdString(root.string()));
  ASSERT_TRUE(window.selectRun("json"));
  window.figureTabs()->setCurrentIndex(3);  // top_view

  const fs::path png = out / "top_view.png";
  ASSERT_TRUE(window.exportFigure(QString::fromStdString(png.string())))
      << window.lastError().toStdString();
  EXPECT_GT(fs::file_size(png), 1000u);
  const QImage image(QString::fromStdString(png.string()));
  ASSERT_FALSE(image.isNull());
  int not_white = 0;  // the whole figure drawn: axes, labels, lines
  int black = 0;      // the truth
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      if (c != QColor(Qt::white)) ++not_white;
      if (c == QColor(Qt::black)) ++black;
    }
  }
  EXPECT_GT(not_white, image.width() * image.height() / 50);
  EXPECT_GT(black, 100);

  const fs::path svg = out / "top_view.svg";
  ASSERT_TRUE(window.exportFigure(QString::fromStdString(svg.string())));
  std::ifstream svg_in(svg);
  const std::string svg_text((std::istreambuf_iterator<char>(svg_in)), {});
  EXPECT_NE(svg_text.find("<svg"), std::string::npos);

  const fs::path csv = out / "results.csv";
  ASSERT_TRUE(window.exportTableCsv(QString::fromStdString(csv.string())));
  std::ifstream csv_in(csv);
  const std::string csv_text((std::istreambuf_iterator<char>(csv_in)), {});
  EXPECT_EQ(csv_text, resultsCsv(window.run()->metrics));

  // The top view's data: the truth's 101 samples and vo_test's 19, north and east.
  const fs::path data = out / "top_view.csv";
  ASSERT_TRUE(window.exportFigureDataCsv(QString::fromStdString(data.string())));
  std::ifstream data_in(data);
  const std::string data_text((std::istreambuf_iterator<char>(data_in)), {});
  EXPECT_EQ(data_text.rfind("trajectory,time_s,north_m,east_m\ntruth,0,0,0\n", 0), 0u)
      << data_text.substr(0, 200);
  EXPECT_NE(data_text.find("\nvo_test,0.5,8,6.5\n"), std::string::npos);
  EXPECT_EQ(std::count(data_text.begin(), data_text.end(), '\n'), 1 + 101 + 19);

  EXPECT_FALSE(window.exportTableCsv(QString::fromStdString((out / "no" / "x.csv").string())));
  EXPECT_FALSE(window.lastError().isEmpty());
  EXPECT_NE(window.run(), nullptr);  // a failed export keeps the run
}

TEST_F(GuiPlotWindow, ADamagedRunShowsAnErrorAndTheWindowLivesOn) {
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  window.show();
  settle();
  EXPECT_FALSE(window.selectRun("sub/bad"));
  EXPECT_EQ(window.run(), nullptr);
  EXPECT_NE(window.lastError().toStdString().find("truth.tum"), std::string::npos)
      << window.lastError().toStdString();
  EXPECT_EQ(window.figureTabs()->count(), 0);
  EXPECT_EQ(window.errorTable()->rowCount(), 0);
  EXPECT_FALSE(window.exportFigure(
      QString::fromStdString((test::freshDir("window_bad_out") / "x.png").string())));
  EXPECT_FALSE(window.selectRun("no/such/run"));
  settle();
  EXPECT_TRUE(window.isVisible());
  ASSERT_TRUE(window.selectRun("computed"));
  EXPECT_TRUE(window.lastError().isEmpty());
  EXPECT_EQ(window.figureTabs()->count(), 4);
}

// Live mode: the live entry heads the tree and shows the run on the bus, its
// table computed from what came (every estimate 5 m off: position RMSE 5 m); it
// is rebuilt as more comes, but not while a chart is zoomed.
TEST_F(GuiPlotWindow, LiveRunIsPlottedAsItComes) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  LiveFeedParams params;
  params.camera_channel.clear();
  LiveFeed feed(*bus, params);
  PlotWindow window(QString::fromStdString(makeRoot().string()));
  window.attachLive(feed, 0);
  window.show();
  settle();
  ASSERT_GT(window.runTree()->topLevelItemCount(), 1);
  EXPECT_EQ(window.runTree()->topLevelItem(0)->text(0), PlotWindow::liveName());
  EXPECT_EQ(window.run(), nullptr);  // nothing on the bus yet
  EXPECT_TRUE(window.lastError().contains(QStringLiteral("waiting for the truth")));

  const core::Trajectory truth = test::truthTrajectory();
  const core::Trajectory estimates = test::estimateTrajectory();
  double published_s = 0.0;
  const auto publish = [&](double until_s) {
    for (const core::StampedPose& pose : truth) {
      if (pose.t_s > until_s || pose.t_s <= published_s) continue;
      ::nadir::test::publish(*bus, "POSE_TRUTH",
                             test::poseMessage(pose.t_s, pose.p_ned_m, pose.q_world_body));
    }
    for (const core::StampedPose& pose : estimates) {
      if (pose.t_s > until_s || pose.t_s <= published_s) continue;
      nadir::vo_estimate_t message{};
      message.pose = test::poseMessage(pose.t_s, pose.p_ned_m, pose.q_world_body);
      message.utime = message.pose.utime;
      message.source = "vo_feature";
      message.status = nadir::vo_estimate_t::STATUS_TRACKING;
      ::nadir::test::publish(*bus, "POSE_VO_FEATURE", message);
    }
    published_s = until_s;
  };
  publish(test::kT0 + 5.0);
  window.pollLive();
  ASSERT_NE(window.run(), nullptr) << window.lastError().toStdString();
  EXPECT_EQ(window.run()->truth.size(), 51u);
  ASSERT_EQ(window.run()->metrics.sources.count("vo_feature"), 1u);
  EXPECT_NEAR(window.run()->metrics.sources.at("vo_feature").position_rmse_m, 5.0, 1e-6);
  expectTableMatches(*window.errorTable(), window.run()->metrics);
  EXPECT_EQ(window.figureTabs()->count(), 4);

  // Zoomed: the figures stay as they are.
  window.figureTabs()->setCurrentIndex(3);
  QChartView* view = firstChartView(window.figureTabs()->currentWidget());
  ASSERT_NE(view, nullptr);
  view->chart()->zoomIn();
  settle();
  publish(test::kT0 + 8.0);
  window.pollLive();
  EXPECT_EQ(window.run()->truth.size(), 51u);
  window.resetZoom();
  window.pollLive();
  EXPECT_EQ(window.run()->truth.size(), 81u);
  EXPECT_EQ(window.figureTabs()->currentIndex(), 3);  // the tab shown is kept

  // The live run against its estimates as the truth, through the next refreshes:
  // the recorded truth 5 m from them.
  ASSERT_TRUE(window.chooseTruth("vo_feature")) << window.lastError().toStdString();
  publish(test::kT0 + 9.0);
  window.pollLive();
  EXPECT_EQ(window.truthName(), "vo_feature");
  EXPECT_EQ(window.run()->truth.size(), 18u);  // 100.5 s to 109 s every 0.5 s
  EXPECT_NEAR(window.run()->metrics.sources.at("truth").position_rmse_m, 5.0, 1e-6);
  ASSERT_TRUE(window.chooseTruth("truth"));

  // Another run in the tree is still there to look at.
  EXPECT_TRUE(window.selectRun("computed"));
  EXPECT_EQ(window.run()->dir, (makeRoot() / "computed").string());
}

}  // namespace
}  // namespace nadir::gui
