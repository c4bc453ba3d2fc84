#include "gui/plot_window.h"

#include <QAction>
#include <QApplication>
#include <QChart>
#include <QChartView>
#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QImage>
#include <QKeySequence>
#include <QLabel>
#include <QLegend>
#include <QLegendMarker>
#include <QListWidget>
#include <QMenuBar>
#include <QMouseEvent>
#include <QPainter>
#include <QSignalBlocker>
#include <QSplitter>
#include <QStatusBar>
#include <QSvgGenerator>
#include <QTabWidget>
#include <QTableWidget>
#include <QToolBar>
#include <QTreeWidget>
#include <QTreeWidgetItemIterator>
#include <QVBoxLayout>
#include <QWheelEvent>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "gui/live_feed.h"
#include "gui/plots.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

constexpr int kPathRole = Qt::UserRole;  // a run's path as findRuns gave it
constexpr int kLiveRole = Qt::UserRole + 1;
constexpr int kRelativeRole = Qt::UserRole + 2;  // a run's path relative to the root
// How often live mode takes the bus's messages.
constexpr int kLivePollMs = 50;

// A chart view that zooms with a rubber band and the wheel, pans with the middle
// button (or Shift and the left button) and the arrow keys, and resets on Home
// or 0. Right click zooms back out one step (QChartView's rubber band does it).
class ZoomChartView : public QChartView {
 public:
  explicit ZoomChartView(QChart* chart) : QChartView(chart) {
    setRenderHint(QPainter::Antialiasing);
    setRubberBand(QChartView::RectangleRubberBand);
    setFocusPolicy(Qt::StrongFocus);
  }

 protected:
  void wheelEvent(QWheelEvent* event) override {
    const int delta = event->angleDelta().y();
    if (delta == 0) return;
    // The point under the cursor stays put.
    const double factor = delta > 0 ? 0.8 : 1.25;
    const QRectF area = chart()->plotArea();
    const QPointF at = chart()->mapFromScene(mapToScene(event->position().toPoint()));
    if (!area.contains(at)) return;
    const QPointF from = at - (at - area.topLeft()) * factor;
    chart()->zoomIn(QRectF(from, area.size() * factor));
    event->accept();
  }

  void mousePressEvent(QMouseEvent* event) override {
    if (isPanButton(event)) {
      panning_ = true;
      last_ = event->position();
      setCursor(Qt::ClosedHandCursor);
      event->accept();
      return;
    }
    QChartView::mousePressEvent(event);
  }

  void mouseMoveEvent(QMouseEvent* event) override {
    if (panning_) {
      const QPointF delta = event->position() - last_;
      last_ = event->position();
      chart()->scroll(-delta.x(), delta.y());
      event->accept();
      return;
    }
    QChartView::mouseMoveEvent(event);
  }

  void mouseReleaseEvent(QMouseEvent* event) override {
    if (panning_) {
      panning_ = false;
      unsetCursor();
      event->accept();
      return;
    }
    QChartView::mouseReleaseEvent(event);
  }

  void keyPressEvent(QKeyEvent* event) override {
    constexpr double kStep = 20;  // px
    switch (event->key()) {
      case Qt::Key_Left:
        chart()->scroll(-kStep, 0);
        break;
      case Qt::Key_Right:
        chart()->scroll(kStep, 0);
        break;
      case Qt::Key_Up:
        chart()->scroll(0, kStep);
        break;
      case Qt::Key_Down:
        chart()->scroll(0, -kStep);
        break;
      case Qt::Key_Plus:
      case Qt::Key_Equal:
        chart()->zoomIn();
        break;
      case Qt::Key_Minus:
        chart()->zoomOut();
        break;
      case Qt::Key_Home:
      case Qt::Key_0:
        chart()->zoomReset();
        break;
      default:
        QChartView::keyPressEvent(event);
        return;
    }
    event->accept();
  }

 private:
  static bool isPanButton(const QMouseEvent* event) {
    return event->button() == Qt::MiddleButton ||
           (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ShiftModifier));
  }

  bool panning_ = false;
  QPointF last_;
};

QWidget* interactiveFigure(Figure figure) {
  auto* widget = new QWidget;
  auto* layout = new QVBoxLayout(widget);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->setSpacing(0);
  for (std::unique_ptr<QChart>& chart : figure.charts) {
    makeLegendToggleable(chart.get());
    layout->addWidget(new ZoomChartView(chart.release()));
  }
  return widget;
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// Puts run against truth (its own or another of its trajectories), with its
// metrics if they can be computed (a live truth may be too short yet); if not, why
// in metrics_error. Throws RunDataError, run unchanged, for a trajectory the run
// does not have or that has no pose.
void compareAgainst(RunData& run, const std::string& truth, std::string& metrics_error) {
  if (truth != run.truth_name) run = compareWithTruth(run, truth, false);
  metrics_error.clear();
  try {
    computeMetrics(run);
  } catch (const RunDataError& error) {
    metrics_error = error.what();
  }
}

bool writeFile(const QString& path, const QByteArray& bytes) {
  QFile file(path);
  return file.open(QIODevice::WriteOnly | QIODevice::Truncate) &&
         file.write(bytes) == bytes.size() && file.flush();
}

}  // namespace

void makeLegendToggleable(QChart* chart) {
  for (QLegendMarker* marker : chart->legend()->markers()) {
    QObject::connect(marker, &QLegendMarker::clicked, chart, [chart, marker] {
      QAbstractSeries* clicked = marker->series();
      const bool visible = !clicked->isVisible();
      for (QAbstractSeries* series : chart->series()) {
        if (series->name() != clicked->name()) continue;
        series->setVisible(visible);
        // Showing a series shows its markers: only the clicked one is listed.
        for (QLegendMarker* other : chart->legend()->markers(series)) {
          other->setVisible(other == marker);
        }
      }
      QBrush label = marker->labelBrush();
      QColor color = label.color();
      color.setAlphaF(visible ? 1.0 : 0.4);
      label.setColor(color);
      marker->setLabelBrush(label);
    });
  }
}

PlotWindow::PlotWindow(const QString& root, const QString& truth, QWidget* parent)
    : QMainWindow(parent), preferred_truth_(truth) {
  setWindowTitle("nadir-plot");
  resize(1400, 900);

  tree_ = new QTreeWidget;
  tree_->setHeaderLabel("runs");
  tree_->setSelectionMode(QAbstractItemView::SingleSelection);
  // Long names (a sweep cell's) scroll rather than being cut.
  tree_->header()->setSectionResizeMode(QHeaderView::ResizeToContents);
  tree_->header()->setStretchLastSection(false);
  truth_box_ = new QComboBox;
  truth_box_->setToolTip("the trajectory the others are compared with");
  trajectories_ = new QListWidget;
  trajectories_->setToolTip("ticked trajectories are plotted");
  auto* trajectories_pane = new QWidget;
  auto* trajectories_layout = new QVBoxLayout(trajectories_pane);
  trajectories_layout->setContentsMargins(0, 0, 0, 0);
  auto* truth_row = new QHBoxLayout;
  truth_row->addWidget(new QLabel("truth:"));
  truth_row->addWidget(truth_box_, 1);
  trajectories_layout->addLayout(truth_row);
  trajectories_layout->addWidget(new QLabel("plotted:"));
  trajectories_layout->addWidget(trajectories_);
  auto* left = new QSplitter(Qt::Vertical);
  left->addWidget(tree_);
  left->addWidget(trajectories_pane);
  left->setStretchFactor(0, 3);
  left->setStretchFactor(1, 1);
  tabs_ = new QTabWidget;
  message_ = new QLabel;
  message_->setWordWrap(true);
  message_->setAlignment(Qt::AlignCenter);
  message_->hide();
  table_ = new QTableWidget;
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  table_->verticalHeader()->hide();
  table_caption_ = new QLabel;
  table_caption_->setWordWrap(true);
  auto* table_pane = new QWidget;
  auto* table_layout = new QVBoxLayout(table_pane);
  table_layout->setContentsMargins(0, 0, 0, 0);
  table_layout->addWidget(table_caption_);
  table_layout->addWidget(table_);

  auto* figures = new QWidget;
  auto* figures_layout = new QVBoxLayout(figures);
  figures_layout->setContentsMargins(0, 0, 0, 0);
  figures_layout->addWidget(tabs_);
  figures_layout->addWidget(message_);
  auto* right = new QSplitter(Qt::Vertical);
  right->addWidget(figures);
  right->addWidget(table_pane);
  right->setStretchFactor(0, 5);
  right->setStretchFactor(1, 1);
  right->setSizes({700, 160});  // else the table's size hint takes half
  auto* split = new QSplitter(Qt::Horizontal);
  split->addWidget(left);
  split->addWidget(right);
  split->setStretchFactor(0, 1);
  split->setStretchFactor(1, 5);
  split->setSizes({260, 1140});
  setCentralWidget(split);

  QMenu* file = menuBar()->addMenu("&File");
  QToolBar* tools = addToolBar("tools");
  const auto action = [&](QMenu* menu, const QString& text, const QKeySequence& keys, auto&& slot) {
    QAction* added = menu->addAction(text);
    added->setShortcut(keys);
    connect(added, &QAction::triggered, this, slot);
    tools->addAction(added);
    return added;
  };
  action(file, "&Open folder...", QKeySequence::Open, [this] { chooseRoot(); });
  action(file, "Export figure &PNG...", QKeySequence("Ctrl+E"),
         [this] { chooseFigureExport("png"); });
  action(file, "Export figure &SVG...", QKeySequence("Ctrl+Shift+E"),
         [this] { chooseFigureExport("svg"); });
  action(file, "Export figure &data CSV...", QKeySequence("Ctrl+D"),
         [this] { chooseFigureDataExport(); });
  action(file, "Export table &CSV...", QKeySequence("Ctrl+T"), [this] { chooseTableExport(); });
  file->addSeparator();
  QAction* quit = file->addAction("&Quit");
  quit->setShortcut(QKeySequence::Quit);
  connect(quit, &QAction::triggered, this, &QWidget::close);
  QMenu* view = menuBar()->addMenu("&View");
  action(view, "&Reset zoom", QKeySequence("Ctrl+0"), [this] { resetZoom(); });

  connect(tree_, &QTreeWidget::currentItemChanged, this,
          [this](QTreeWidgetItem* item, QTreeWidgetItem*) {
            if (item == nullptr) return;
            if (item->data(0, kLiveRole).toBool()) {
              refreshLive();
            } else if (const QString path = item->data(0, kPathRole).toString(); !path.isEmpty()) {
              loadRunAt(path);
            }  // a folder: its runs are below it
          });
  connect(truth_box_, &QComboBox::activated, this,
          [this](int index) { chooseTruth(truth_box_->itemText(index)); });
  connect(trajectories_, &QListWidget::itemChanged, this, [this](QListWidgetItem* item) {
    setTrajectoryShown(item->text(), item->checkState() == Qt::Checked);
  });

  connect(&live_timer_, &QTimer::timeout, this, [this] { pollLive(); });
  openRoot(root);
}

PlotWindow::~PlotWindow() = default;

bool PlotWindow::openRoot(const QString& root) {
  tree_->blockSignals(true);
  tree_->clear();
  live_item_ = nullptr;
  addLiveItem();
  tree_->blockSignals(false);
  clearRun();
  root_ = root;
  std::vector<std::string> runs;
  try {
    runs = findRuns(root.toStdString());
  } catch (const std::exception& error) {
    fail(QString::fromStdString(error.what()));
    return false;
  }
  setWindowTitle("nadir-plot: " + QDir(root).absolutePath());
  QTreeWidgetItem* first_run = nullptr;
  std::map<fs::path, QTreeWidgetItem*> folders;  // by path relative to root
  for (const std::string& run : runs) {
    const fs::path relative = fs::path(run).lexically_relative(root.toStdString());
    // One tree level per folder of the path: a sweep's cells under the sweep.
    QTreeWidgetItem* parent = nullptr;
    fs::path folder;
    for (const fs::path& part : relative.parent_path()) {
      folder /= part;
      QTreeWidgetItem*& item = folders[folder];
      if (item == nullptr) {
        const QStringList text{QString::fromStdString(part.string())};
        item = parent ? new QTreeWidgetItem(parent, text) : new QTreeWidgetItem(tree_, text);
        item->setExpanded(true);
        item->setToolTip(0, QString::fromStdString(folder.string()));
      }
      parent = item;
    }
    const QStringList text{QString::fromStdString(relative.filename().string())};
    auto* item = parent ? new QTreeWidgetItem(parent, text) : new QTreeWidgetItem(tree_, text);
    item->setData(0, kPathRole, QString::fromStdString(run));
    item->setData(0, kRelativeRole, QString::fromStdString(relative.string()));
    item->setToolTip(0, QString::fromStdString(relative.string()));
    if (first_run == nullptr) first_run = item;
  }
  last_error_.clear();
  // The first run is shown at once: a single run needs no click.
  if (first_run != nullptr && live_item_ == nullptr) {
    tree_->setCurrentItem(first_run);
    if (!run_) return true;  // its error is in the status bar
  }
  statusBar()->showMessage(runs.empty() ? root +
                                              ": no run here (a run is a folder with "
                                              "run.lcmlog, metrics.json or TUM files, "
                                              "or an LCM log)"
                                        : QString("%1 runs under %2").arg(runs.size()).arg(root));
  return true;
}

bool PlotWindow::selectRun(const QString& relative) {
  QTreeWidgetItem* found = nullptr;
  for (QTreeWidgetItemIterator it(tree_); *it != nullptr && found == nullptr; ++it) {
    if ((*it)->data(0, kRelativeRole).toString() == relative) found = *it;
  }
  if (found == nullptr) {
    fail(root_ + ": no run " + relative);
    return false;
  }
  if (tree_->currentItem() == found) {
    loadRunAt(found->data(0, kPathRole).toString());
  } else {
    tree_->setCurrentItem(found);
  }
  return run_.has_value();
}

bool PlotWindow::chooseTruth(const QString& name) {
  if (!run_) {
    fail("no run to compare: select a run first");
    return false;
  }
  try {
    compareAgainst(*run_, name.toStdString(), metrics_note_);
  } catch (const std::exception& error) {
    fail(QString::fromStdString(error.what()));
    showTrajectories();  // the box back on the truth that stands
    return false;
  }
  // The recorded truth is no preference: each run then takes its own.
  preferred_truth_ = name.toStdString() == trajectoryNames(*run_).front() ? QString() : name;
  last_error_.clear();
  const int tab = tabs_->currentIndex();
  showRun();
  if (tab >= 0 && tab < tabs_->count()) tabs_->setCurrentIndex(tab);
  return true;
}

QString PlotWindow::truthName() const {
  return run_ ? QString::fromStdString(run_->truth_name) : QString();
}

void PlotWindow::setTrajectoryShown(const QString& name, bool shown) {
  if (shown) {
    hidden_.erase(name.toStdString());
  } else {
    hidden_.insert(name.toStdString());
  }
  for (int i = 0; i < trajectories_->count(); ++i) {
    QListWidgetItem* item = trajectories_->item(i);
    if (item->text() != name) continue;
    const QSignalBlocker quiet(trajectories_);
    item->setCheckState(shown ? Qt::Checked : Qt::Unchecked);
  }
  if (!run_) return;
  const int tab = tabs_->currentIndex();
  showFigures();
  if (tab >= 0 && tab < tabs_->count()) tabs_->setCurrentIndex(tab);
}

std::string PlotWindow::truthFor(const RunData& run) const {
  const std::string wanted = preferred_truth_.toStdString();
  const std::vector<std::string> names = trajectoryNames(run);
  const bool has = std::find(names.begin(), names.end(), wanted) != names.end();
  return !wanted.empty() && has ? wanted : run.truth_name;
}

bool PlotWindow::applyPreferredTruth() {
  const std::string truth = truthFor(*run_);
  if (truth == run_->truth_name) return true;
  try {
    compareAgainst(*run_, truth, metrics_note_);
  } catch (const std::exception& error) {
    fail(QString::fromStdString(error.what()));
    return false;
  }
  return true;
}

void PlotWindow::attachLive(LiveFeed& feed, int refresh_period_ms) {
  feed_ = &feed;
  refresh_period_ms_ = refresh_period_ms;
  tree_->blockSignals(true);
  addLiveItem();
  tree_->blockSignals(false);
  live_timer_.start(kLivePollMs);
  tree_->setCurrentItem(live_item_);
}

void PlotWindow::addLiveItem() {
  if (feed_ == nullptr || live_item_ != nullptr) return;
  live_item_ = new QTreeWidgetItem({liveName()});
  live_item_->setData(0, kLiveRole, true);
  tree_->insertTopLevelItem(0, live_item_);
}

bool PlotWindow::liveSelected() const {
  return live_item_ != nullptr && tree_->currentItem() == live_item_;
}

bool PlotWindow::anyChartZoomed() const {
  for (const QChartView* view : tabs_->findChildren<QChartView*>()) {
    if (view->chart()->isZoomed()) return true;
  }
  return false;
}

void PlotWindow::pollLive() {
  if (feed_ == nullptr) return;
  try {
    feed_->poll();
  } catch (const std::exception& error) {
    live_timer_.stop();
    fail(QStringLiteral("live: the bus failed: %1").arg(error.what()));
    return;
  }
  if (!liveSelected() || feed_->version() == shown_version_) return;
  if (since_refresh_.isValid() && since_refresh_.elapsed() < refresh_period_ms_) return;
  if (anyChartZoomed()) {
    statusBar()->showMessage(
        QStringLiteral("live: paused while a chart is zoomed (View > Reset zoom resumes)"));
    return;
  }
  refreshLive();
}

void PlotWindow::refreshLive() {
  if (feed_ == nullptr) return;
  since_refresh_.start();
  shown_version_ = feed_->version();
  const int tab = tabs_->currentIndex();
  clearRun();
  std::optional<RunData> live;
  try {
    live = feed_->run("live");
  } catch (const std::exception& error) {
    fail(QString::fromStdString(error.what()));
    return;
  }
  if (!live) {
    fail(QStringLiteral("live: waiting for the truth (pose_t)"));
    return;
  }
  // The metrics once, against the truth shown.
  run_ = std::move(live);
  bool compared = true;
  try {
    compareAgainst(*run_, truthFor(*run_), metrics_note_);
  } catch (const std::exception& error) {
    compared = false;
    fail(QString::fromStdString(error.what()));
    compareAgainst(*run_, run_->truth_name, metrics_note_);
  }
  if (compared) last_error_.clear();
  showRun();
  if (tab >= 0 && tab < tabs_->count()) tabs_->setCurrentIndex(tab);
  if (!compared) {
    statusBar()->showMessage(last_error_);  // showRun wrote over it
    return;
  }
  QString status = QStringLiteral("live: %1 truth poses").arg(run_->truth.size());
  for (const auto& [name, source] : run_->sources) {
    status +=
        QStringLiteral(", %1 %2 estimates").arg(QString::fromStdString(name)).arg(source.size());
  }
  if (!metrics_note_.empty()) {
    status += QStringLiteral("; no metrics yet: ") + QString::fromStdString(metrics_note_);
  }
  if (!run_->damage.empty()) status += "; left out: " + QString::fromStdString(run_->damage);
  statusBar()->showMessage(status);
}

void PlotWindow::loadRunAt(const QString& dir) {
  clearRun();
  try {
    run_ = loadRun(dir.toStdString());
  } catch (const std::exception& error) {
    fail(QString::fromStdString(error.what()));
    showTrajectories();
    return;
  }
  const bool compared = applyPreferredTruth();
  if (compared) last_error_.clear();
  showRun();
  if (!compared) statusBar()->showMessage(last_error_);
}

void PlotWindow::clearRun() {
  run_.reset();
  metrics_note_.clear();
  removeFigures();
  table_->clear();
  table_->setRowCount(0);
  table_->setColumnCount(0);
  table_caption_->clear();
  message_->hide();
  tabs_->show();
}

void PlotWindow::removeFigures() {
  while (tabs_->count() > 0) {
    QWidget* page = tabs_->widget(0);
    tabs_->removeTab(0);
    delete page;
  }
}

void PlotWindow::showFigures() {
  removeFigures();
  for (Figure& figure : buildFigures(*run_, hidden_)) {
    const QString name = QString::fromStdString(figure.name);
    tabs_->addTab(interactiveFigure(std::move(figure)), name);
  }
}

void PlotWindow::showTrajectories() {
  const QSignalBlocker quiet_box(truth_box_);
  const QSignalBlocker quiet_list(trajectories_);
  truth_box_->clear();
  trajectories_->clear();
  if (!run_) return;
  for (const std::string& name : trajectoryNames(*run_)) {
    const QString text = QString::fromStdString(name);
    truth_box_->addItem(text);
    auto* item = new QListWidgetItem(text, trajectories_);
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    item->setCheckState(hidden_.contains(name) ? Qt::Unchecked : Qt::Checked);
    const QColor color = name == run_->truth_name ? QColor(Qt::black) : sourceColor(*run_, name);
    item->setForeground(color);
  }
  truth_box_->setCurrentText(QString::fromStdString(run_->truth_name));
}

void PlotWindow::showTable() {
  table_->clear();
  table_->setRowCount(0);
  // The table holds resultsCsv's text, so the numbers of metrics.json (and of an
  // export) exactly.
  std::istringstream csv(resultsCsv(run_->metrics));
  std::string line;
  std::getline(csv, line);  // the header: the columns below say it with units
  table_->setColumnCount(6);
  table_->setHorizontalHeaderLabels({"source", "position RMSE (m)", "rotation RMSE (deg)",
                                     "tracked (%)", "APE RMSE (m)", "RPE RMSE (m)"});
  while (std::getline(csv, line)) {
    const std::vector<std::string> fields = splitCsvLine(line);
    const int row = table_->rowCount();
    table_->insertRow(row);
    for (int column = 0; column < 6 && column < static_cast<int>(fields.size()); ++column) {
      const QString exact = QString::fromStdString(fields[column]);
      auto* cell = new QTableWidgetItem(exact);
      if (column > 0) {
        // Shown to a millimetre, a thousandth of a degree or percent; the exact
        // value of metrics.json stays in the cell's data and tooltip.
        if (!exact.isEmpty()) cell->setText(QString::number(exact.toDouble(), 'f', 3));
        cell->setData(Qt::UserRole, exact);
        cell->setToolTip(exact);
        cell->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
      }
      table_->setItem(row, column, cell);
    }
  }
  QString caption =
      "errors against " + truthLabel(*run_) + ", metrics " +
      (run_->metrics_from.empty() ? QString("computed here")
                                  : "from " + QString::fromStdString(run_->metrics_from));
  if (!run_->truth_note.empty()) caption += " (" + QString::fromStdString(run_->truth_note) + ")";
  if (!preferred_truth_.isEmpty() && run_->truth_name != preferred_truth_.toStdString()) {
    caption += " (this run has no " + preferred_truth_ + ")";
  }
  if (!metrics_note_.empty()) caption += "; none yet: " + QString::fromStdString(metrics_note_);
  table_caption_->setText(caption);
}

void PlotWindow::showRun() {
  showFigures();
  showTable();
  showTrajectories();
  QString status = QString::fromStdString(run_->dir) + ": poses from " +
                   QString::fromStdString(run_->poses_from);
  if (!run_->damage.empty()) {
    status += "; damaged, showing what could be read: " + QString::fromStdString(run_->damage);
  }
  statusBar()->showMessage(status);
}

void PlotWindow::fail(const QString& message) {
  last_error_ = message;
  statusBar()->showMessage(message);
  if (!run_) {
    tabs_->hide();
    message_->setText(message);
    message_->show();
  }
}

bool PlotWindow::showFigure(const QString& name) {
  for (int i = 0; i < tabs_->count(); ++i) {
    if (tabs_->tabText(i) != name) continue;
    tabs_->setCurrentIndex(i);
    return true;
  }
  return false;
}

bool PlotWindow::exportFigure(const QString& path) {
  QWidget* figure = tabs_->currentWidget();
  if (!run_ || figure == nullptr) {
    fail("no figure to export: select a run first");
    return false;
  }
  // A window never shown has no layout yet: lay it out without showing it.
  const bool hidden = !isVisible();
  if (hidden) {
    setAttribute(Qt::WA_DontShowOnScreen, true);
    show();
  }
  for (int i = 0; i < 3; ++i) QApplication::processEvents();
  const QSize size = figure->size();
  bool written = false;
  if (QFileInfo(path).suffix().compare("svg", Qt::CaseInsensitive) == 0) {
    QSvgGenerator svg;
    svg.setFileName(path);
    svg.setSize(size);
    svg.setViewBox(QRect(QPoint(0, 0), size));
    svg.setTitle(tabs_->tabText(tabs_->currentIndex()));
    QPainter painter;
    if (painter.begin(&svg)) {
      figure->render(&painter);
      written = painter.end();
    }
    written = written && QFileInfo(path).size() > 0;
  } else {
    QImage image(size, QImage::Format_RGB32);
    image.fill(Qt::white);
    QPainter painter(&image);
    figure->render(&painter);
    painter.end();
    written = image.save(path, "PNG");
  }
  if (hidden) {
    hide();
    setAttribute(Qt::WA_DontShowOnScreen, false);
  }
  if (!written) {
    fail(path + ": cannot write the file");
    return false;
  }
  last_error_.clear();
  statusBar()->showMessage("wrote " + path);
  return true;
}

bool PlotWindow::exportTableCsv(const QString& path) {
  if (!run_) {
    fail("no table to export: select a run first");
    return false;
  }
  return writeExport(path, resultsCsv(run_->metrics));
}

bool PlotWindow::exportFigureDataCsv(const QString& path) {
  if (!run_ || tabs_->count() == 0) {
    fail("no figure to export: select a run first");
    return false;
  }
  return writeExport(
      path, figureDataCsv(*run_, tabs_->tabText(tabs_->currentIndex()).toStdString(), hidden_));
}

bool PlotWindow::writeExport(const QString& path, const std::string& text) {
  if (!writeFile(path, QByteArray::fromStdString(text))) {
    fail(path + ": cannot write the file");
    return false;
  }
  last_error_.clear();
  statusBar()->showMessage("wrote " + path);
  return true;
}

void PlotWindow::resetZoom() {
  for (QChartView* view : tabs_->findChildren<QChartView*>()) view->chart()->zoomReset();
}

void PlotWindow::chooseRoot() {
  const QString dir = QFileDialog::getExistingDirectory(this, "Open a folder of runs", root_);
  if (!dir.isEmpty()) openRoot(dir);
}

QString PlotWindow::suggestedPath(const QString& name) const {
  // Beside the run: in its folder, or in a log's.
  const fs::path run(run_ ? run_->dir : root_.toStdString());
  std::error_code error;
  const fs::path folder = fs::is_directory(run, error) ? run : run.parent_path();
  return QString::fromStdString((folder / name.toStdString()).string());
}

void PlotWindow::chooseFigureExport(const QString& suffix) {
  if (!run_) {
    fail("no figure to export: select a run first");
    return;
  }
  const QString suggested = suggestedPath(tabs_->tabText(tabs_->currentIndex()) + "." + suffix);
  const QString path = QFileDialog::getSaveFileName(this, "Export the figure", suggested,
                                                    suffix.toUpper() + " (*." + suffix + ")");
  if (!path.isEmpty()) exportFigure(path);
}

void PlotWindow::chooseTableExport() {
  if (!run_) {
    fail("no table to export: select a run first");
    return;
  }
  const QString path = QFileDialog::getSaveFileName(this, "Export the error table",
                                                    suggestedPath("results.csv"), "CSV (*.csv)");
  if (!path.isEmpty()) exportTableCsv(path);
}

void PlotWindow::chooseFigureDataExport() {
  if (!run_) {
    fail("no figure to export: select a run first");
    return;
  }
  const QString path = QFileDialog::getSaveFileName(
      this, "Export the figure's data",
      suggestedPath(tabs_->tabText(tabs_->currentIndex()) + ".csv"), "CSV (*.csv)");
  if (!path.isEmpty()) exportFigureDataCsv(path);
}

}  // namespace nadir::gui
