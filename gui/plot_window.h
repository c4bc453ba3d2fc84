#pragma once
// The interactive plot viewer: on the left the runs under a root folder as a
// directory tree and, below it, the selected run's trajectories (which to plot,
// which is the truth); on the right its figures (zoomable charts) and error table.
// Errors (a damaged run, an unwritable file) go to the status bar, never abort.

#include <QElapsedTimer>
#include <QMainWindow>
#include <QString>
#include <QTimer>

#include <cstdint>

#include <memory>
#include <optional>
#include <set>
#include <string>

#include "gui/run_data.h"

class QChart;
class QComboBox;
class QLabel;
class QListWidget;
class QTabWidget;
class QTableWidget;
class QTreeWidget;
class QTreeWidgetItem;

namespace nadir::gui {

class LiveFeed;

class PlotWindow : public QMainWindow {
 public:
  // Opens on root (see openRoot); truth, if given, is the trajectory taken as the
  // truth in every run that has one of that name (see chooseTruth).
  explicit PlotWindow(const QString& root, const QString& truth = {}, QWidget* parent = nullptr);
  ~PlotWindow() override;

  // Lists the runs under root in the tree, one level per folder of their paths
  // relative to root ("." for root itself). False, with the reason in the status
  // bar, if root is not a folder.
  bool openRoot(const QString& root);
  // Selects the run at this path relative to root ("a/b" for the run b in the
  // folder a), which loads it. False if there is no such run or it does not load
  // (the reason is in lastError()).
  bool selectRun(const QString& relative);

  // Compares the shown run with its trajectory `name` as the truth: figures,
  // errors and table are rebuilt against it, and it stays the truth of every run
  // selected later that has a trajectory of that name (others take their recorded
  // truth). False, with the reason in lastError(), if the run has no such
  // trajectory or cannot be evaluated against it; the run is then shown as before.
  bool chooseTruth(const QString& name);
  // The shown run's truth ("truth": the recorded one).
  QString truthName() const;
  // Shows or hides a trajectory (the truth's included) in every figure, for this
  // and later runs; the table keeps every source.
  void setTrajectoryShown(const QString& name, bool shown);

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

  // Shows the figure of this name (a tab); false if there is none.
  bool showFigure(const QString& name);
  // Writes the figure in the current tab as shown, PNG or SVG by the suffix.
  bool exportFigure(const QString& path);
  // Writes the error table as resultsCsv does.
  bool exportTableCsv(const QString& path);
  // Writes the data of the figure in the current tab as figureDataCsv does (the
  // trajectories plotted, at full rate).
  bool exportFigureDataCsv(const QString& path);
  // Every chart of every figure back to its initial ranges.
  void resetZoom();

  QTreeWidget* runTree() const { return tree_; }
  // The shown run's trajectories, each checkable (plotted or not).
  QListWidget* trajectoryList() const { return trajectories_; }
  QComboBox* truthBox() const { return truth_box_; }
  // What the table's numbers are: the truth they are against, where they come from.
  QLabel* tableCaption() const { return table_caption_; }
  QTabWidget* figureTabs() const { return tabs_; }
  QTableWidget* errorTable() const { return table_; }
  // The loaded run, if the last selection loaded.
  const RunData* run() const { return run_ ? &*run_ : nullptr; }
  // The last error shown, empty if the last action succeeded.
  QString lastError() const { return last_error_; }

 private:
  void loadRunAt(const QString& dir);
  // The truth run is shown against: the preferred one if it has it, else its own.
  std::string truthFor(const RunData& run) const;
  // A loaded run_ against truthFor(run_); false (error shown) if that fails,
  // run_ then kept against its recorded truth.
  bool applyPreferredTruth();
  void showRun();
  void removeFigures();
  void showFigures();
  void showTable();
  void showTrajectories();
  void clearRun();
  void fail(const QString& message);
  void chooseRoot();
  void chooseFigureExport(const QString& suffix);
  void chooseTableExport();
  void chooseFigureDataExport();
  QString suggestedPath(const QString& name) const;
  bool writeExport(const QString& path, const std::string& text);

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
  QListWidget* trajectories_ = nullptr;
  QComboBox* truth_box_ = nullptr;
  QTabWidget* tabs_ = nullptr;
  QTableWidget* table_ = nullptr;
  QLabel* table_caption_ = nullptr;
  QString preferred_truth_;       // empty: each run's recorded truth
  std::string metrics_note_;      // why run_ has no metrics; empty if it has them
  std::set<std::string> hidden_;  // trajectories left out of the figures
  QLabel* message_ = nullptr;     // shown in place of the figures when a run fails
  std::optional<RunData> run_;
  QString last_error_;
};

// Toggles a legend entry's lines on click: every series of the chart with the
// same name (a source's line is drawn as several segments), keeping the marker
// visible but dimmed while its lines are hidden.
void makeLegendToggleable(QChart* chart);

}  // namespace nadir::gui
