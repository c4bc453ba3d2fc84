#pragma once
// The interactive plot viewer: the runs under a root folder on the left, the
// selected run's figures (zoomable charts) and error table on the right.
// Errors (a damaged run, an unwritable file) go to the status bar, never abort.

#include <QElapsedTimer>
#include <QMainWindow>
#include <QString>
#include <QTimer>

#include <cstdint>

#include <memory>
#include <optional>

#include "gui/run_data.h"

class QChart;
class QLabel;
class QTabWidget;
class QTableWidget;
class QTreeWidget;
class QTreeWidgetItem;

namespace nadir::gui {

class LiveFeed;

class PlotWindow : public QMainWindow {
 public:
  // Opens on root (see openRoot).
  explicit PlotWindow(const QString& root, QWidget* parent = nullptr);
  ~PlotWindow() override;

  // Lists the runs under root in the tree, paths relative to root ("." for root
  // itself). False, with the reason in the status bar, if root is not a folder.
  bool openRoot(const QString& root);
  // Selects the run at this path relative to the root, which loads it. False if
  // there is no such run or it does not load (the reason is in lastError()).
  bool selectRun(const QString& relative);

  // Live mode: a "live" entry heads the tree; while it is selected its figures and
  // table are rebuilt from feed (which must outlive the window) every
  // refresh_period_ms as messages come, unless a chart is zoomed (which would be
  // lost): View > Reset zoom resumes.
  void attachLive(LiveFeed& feed, int refresh_period_ms = 1000);
  // Takes the bus's messages, and refreshes the live figures when due (the
  // window's timer calls it).
  void pollLive();
  // Rebuilds the live run's figures and table now.
  void refreshLive();
  // The tree entry of the live run.
  static QString liveName() { return QStringLiteral("live (bus)"); }

  // Writes the figure in the current tab as shown, PNG or SVG by the suffix.
  bool exportFigure(const QString& path);
  // Writes the error table as resultsCsv does.
  bool exportTableCsv(const QString& path);
  // Every chart of every figure back to its initial ranges.
  void resetZoom();

  QTreeWidget* runTree() const { return tree_; }
  QTabWidget* figureTabs() const { return tabs_; }
  QTableWidget* errorTable() const { return table_; }
  // The loaded run, if the last selection loaded.
  const RunData* run() const { return run_ ? &*run_ : nullptr; }
  // The last error shown, empty if the last action succeeded.
  QString lastError() const { return last_error_; }

 private:
  void loadRunAt(const QString& dir);
  void showRun();
  void clearRun();
  void fail(const QString& message);
  void chooseRoot();
  void chooseFigureExport(const QString& suffix);
  void chooseTableExport();

  void addLiveItem();
  bool liveSelected() const;
  bool anyChartZoomed() const;

  QString root_;
  LiveFeed* feed_ = nullptr;
  QTreeWidgetItem* live_item_ = nullptr;
  QTimer live_timer_;
  QElapsedTimer since_refresh_;
  int refresh_period_ms_ = 1000;
  std::uint64_t shown_version_ = 0;
  QTreeWidget* tree_ = nullptr;
  QTabWidget* tabs_ = nullptr;
  QTableWidget* table_ = nullptr;
  QLabel* message_ = nullptr;  // shown in place of the figures when a run fails
  std::optional<RunData> run_;
  QString last_error_;
};

// Toggles a legend entry's lines on click: every series of the chart with the
// same name (a source's line is drawn as several segments), keeping the marker
// visible but dimmed while its lines are hidden.
void makeLegendToggleable(QChart* chart);

}  // namespace nadir::gui
