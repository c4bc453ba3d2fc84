#include "gui/viewer_window.h"

#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QHBoxLayout>
#include <QKeySequence>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QPixmap>
#include <QPushButton>
#include <QResizeEvent>
#include <QSignalBlocker>
#include <QSlider>
#include <QSplitter>
#include <QStatusBar>
#include <QToolButton>
#include <QVBoxLayout>
#include <QWidget>

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <utility>

#include "core/clock.h"
#include "gui/live_feed.h"
#include "gui/plots.h"
#include "gui/vo_reset_sender.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

// Slider steps per second of playback.
constexpr double kSliderStepsPerS = 100.0;
// Timer period while playing; the time advances by the wall clock, not by ticks.
constexpr int kTickMs = 33;
// How often live mode takes the bus's messages.
constexpr int kLivePollMs = 50;

QString swatch(const QColor& color, const QString& text) {
  return QStringLiteral("<span style=\"color:%1\">&#9632;</span> %2").arg(color.name(), text);
}

std::string runName(const RunData& run) { return fs::path(run.dir).filename().string(); }

bool isLogPath(const std::string& path) { return fs::path(path).extension() == ".lcmlog"; }

}  // namespace

const std::vector<double>& ViewerWindow::speeds() {
  static const std::vector<double> kSpeeds = {0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0};
  return kSpeeds;
}

QString viewerLegend(const std::vector<RunData>& runs, const std::vector<QString>& notes) {
  QStringList lines;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    QStringList items;
    items << swatch(truthColor(r), QStringLiteral("truth"));
    for (const auto& [name, source] : runs[r].sources) {
      items << swatch(sourceColor(runs[r], name), QString::fromStdString(name));
    }
    const QString dir = QString::fromStdString(runName(runs[r]));
    QString line = QStringLiteral("<b>%1</b>: %2")
                       .arg(dir.toHtmlEscaped(), items.join(QStringLiteral("&nbsp;&nbsp;")));
    if (r < notes.size() && !notes[r].isEmpty()) {
      line += QStringLiteral("&nbsp;&nbsp;<i style=\"color:#a05000\">%1</i>")
                  .arg(notes[r].toHtmlEscaped());
    }
    lines << line;
  }
  return lines.join(QStringLiteral("<br>"));
}

std::string scenarioOfRun(const std::string& run_path) {
  std::error_code error;
  const fs::path path(run_path);
  const fs::path folder = fs::is_directory(path, error) ? path : path.parent_path();
  const fs::path scenario = folder / "scenario.yaml";
  return fs::is_regular_file(scenario, error) ? scenario.string() : std::string();
}

QImage toQImage(const CameraFrame& frame) {
  const cv::Mat& m = frame.pixels;
  if (m.empty()) return {};
  const QImage::Format format =
      m.channels() == 1 ? QImage::Format_Grayscale8 : QImage::Format_RGB888;
  return QImage(m.data, m.cols, m.rows, static_cast<qsizetype>(m.step), format).copy();
}

ViewerWindow::ViewerWindow(std::vector<RunData> runs, std::optional<ViewerTerrain> terrain,
                           QWidget* parent)
    : QMainWindow(parent), runs_(std::move(runs)), duration_s_(playbackDuration(runs_)) {
  auto* central = new QWidget(this);
  auto* layout = new QVBoxLayout(central);
  legend_ = new QLabel(central);
  legend_->setTextFormat(Qt::RichText);
  layout->addWidget(legend_);

  auto* splitter = new QSplitter(Qt::Horizontal, central);
  view_ = new TrajectoryView(runs_, std::move(terrain), splitter);
  auto* camera_panel = new QWidget(splitter);
  auto* camera_layout = new QVBoxLayout(camera_panel);
  camera_layout->setContentsMargins(0, 0, 0, 0);
  camera_run_ = new QComboBox(camera_panel);
  camera_run_->setToolTip(QStringLiteral("whose camera to show"));
  camera_layout->addWidget(camera_run_);
  camera_view_ = new ImageLabel(camera_panel);
  camera_caption_ = new QLabel(camera_panel);
  camera_caption_->setWordWrap(true);
  camera_layout->addWidget(camera_view_, 1);
  camera_layout->addWidget(camera_caption_);
  splitter->addWidget(view_);
  splitter->addWidget(camera_panel);
  splitter->setStretchFactor(0, 3);
  splitter->setStretchFactor(1, 2);
  layout->addWidget(splitter, 1);

  auto* controls = new QHBoxLayout;
  play_ = new QPushButton(QStringLiteral("Play"), central);
  play_->setShortcut(Qt::Key_Space);
  slider_ = new QSlider(Qt::Horizontal, central);
  time_label_ = new QLabel(central);
  time_label_->setMinimumWidth(
      time_label_->fontMetrics().horizontalAdvance("0000.00 s / 0000.00 s"));
  speed_ = new QComboBox(central);
  for (double s : speeds()) speed_->addItem(QStringLiteral("%1x").arg(s), s);
  follow_ = new QCheckBox(QStringLiteral("Follow vehicle"), central);
  live_ = new QCheckBox(QStringLiteral("Live"), central);
  live_->setToolTip(QStringLiteral("stay at the newest message"));
  live_->setVisible(false);
  controls->addWidget(play_);
  controls->addWidget(slider_, 1);
  controls->addWidget(time_label_);
  go_to_ = new QDoubleSpinBox(central);
  go_to_->setPrefix(QStringLiteral("go to "));
  go_to_->setSuffix(QStringLiteral(" s"));
  go_to_->setDecimals(2);
  go_to_->setKeyboardTracking(false);
  go_to_->setToolTip(QStringLiteral("type a time and press Enter"));
  controls->addWidget(go_to_);
  controls->addWidget(speed_);
  controls->addWidget(follow_);
  controls->addWidget(live_);
  reset_ = new QToolButton(central);
  reset_->setObjectName(QStringLiteral("vo_reset"));
  reset_->setText(QStringLiteral("Reset VO"));
  reset_->setToolTip(
      QStringLiteral("restart every VO node at the newest truth pose (without a live truth: "
                     "where each estimates now); the menu resets one"));
  reset_->setPopupMode(QToolButton::MenuButtonPopup);
  reset_->setMenu(new QMenu(reset_));
  reset_->setVisible(false);
  controls->addWidget(reset_);
  layout->addLayout(controls);
  setCentralWidget(central);
  setSpeed(1.0);

  QMenu* file = menuBar()->addMenu(QStringLiteral("&File"));
  file->addAction(QStringLiteral("Open run folder..."), QKeySequence::Open,
                  [this] { openDialog(false); });
  file->addAction(QStringLiteral("Open LCM log..."), [this] { openDialog(true); });
  file->addSeparator();
  file->addAction(QStringLiteral("Quit"), QKeySequence::Quit, [this] { close(); });
  QMenu* view = menuBar()->addMenu(QStringLiteral("&View"));
  terrain_menu_ = view->addMenu(QStringLiteral("&Terrain"));

  connect(play_, &QPushButton::clicked, this, [this] { setPlaying(!playing()); });
  connect(slider_, &QSlider::valueChanged, this, [this](int value) {
    // Only the user's moves seek; showTime() moves it too.
    if (showing_time_) return;
    live_->setChecked(false);
    seek(value / kSliderStepsPerS);
  });
  connect(follow_, &QCheckBox::toggled, this, [this](bool on) { view_->setFollow(on); });
  connect(live_, &QCheckBox::toggled, this, [this](bool on) {
    if (on) {
      setPlaying(false);
      seek(duration_s_);
    }
  });
  connect(reset_, &QToolButton::clicked, this, [this] { resetVo({}); });
  connect(camera_run_, &QComboBox::currentIndexChanged, this, [this] {
    if (!showing_time_) showCamera();
  });
  connect(go_to_, &QDoubleSpinBox::editingFinished, this, [this] { goTo(go_to_->value()); });
  // Stepping through time from the keyboard, wherever the focus is.
  const auto shortcut = [this](const QKeySequence& keys, double step_s) {
    auto* action = new QAction(this);
    action->setShortcut(keys);
    action->setShortcutContext(Qt::WindowShortcut);
    connect(action, &QAction::triggered, this, [this, step_s] { goTo(time() + step_s); });
    addAction(action);
  };
  shortcut(QKeySequence(Qt::Key_Right), 1.0);
  shortcut(QKeySequence(Qt::Key_Left), -1.0);
  shortcut(QKeySequence(Qt::SHIFT | Qt::Key_Right), 10.0);
  shortcut(QKeySequence(Qt::SHIFT | Qt::Key_Left), -10.0);
  shortcut(QKeySequence(Qt::Key_Home), -1e12);
  shortcut(QKeySequence(Qt::Key_End), 1e12);
  connect(&timer_, &QTimer::timeout, this, [this] { tick(); });
  timer_.setInterval(kTickMs);
  connect(&live_timer_, &QTimer::timeout, this, [this] { pollLive(); });
  live_timer_.setInterval(kLivePollMs);
  statusBar()->showMessage(QStringLiteral(
      "left drag: rotate, right drag: pan, wheel: zoom; Space: play, Left/Right: 1 s "
      "(Shift: 10 s), Home/End"));
  setWindowTitle(QStringLiteral("nadir-viewer"));
  resize(1400, 800);

  runsChanged();
}

ViewerWindow::~ViewerWindow() = default;

void ViewerWindow::attachLive(LiveFeed& feed, const QString& name, int rebuild_period_ms) {
  feed_ = &feed;
  rebuild_period_ms_ = rebuild_period_ms;
  live_name_ = name;
  live_->setVisible(true);
  live_->setChecked(true);
  live_timer_.start();
  pollLive();
}

bool ViewerWindow::followingLive() const { return feed_ != nullptr && live_->isChecked(); }

void ViewerWindow::pollLive() {
  if (feed_ == nullptr) return;
  try {
    feed_->poll();
  } catch (const std::exception& e) {
    live_timer_.stop();
    statusBar()->showMessage(QStringLiteral("live: the bus failed: %1").arg(e.what()));
    return;
  }
  if (feed_->version() == live_version_) return;
  // Rebuilding the run costs time in its length: a few times a second is enough.
  if (since_rebuild_.isValid() && since_rebuild_.elapsed() < rebuild_period_ms_) return;
  since_rebuild_.start();
  live_version_ = feed_->version();
  std::optional<RunData> run = feed_->run(live_name_.toStdString());
  const bool first = run && (runs_.empty() || runs_.front().dir != run->dir);
  if (run) {
    if (first) {
      runs_.insert(runs_.begin(), std::move(*run));
    } else {
      runs_.front() = std::move(*run);
    }
    // The whole flight stays in view as it grows, until the user moves the camera.
    if (!view_->cameraMovedByUser()) view_->fitToRuns();
  }
  runsChanged();
  listResetSources();
  if (first && run) showCameraOf(live_name_.toStdString());
  if (live_->isChecked()) seek(duration_s_);
}

void ViewerWindow::attachVoReset(VoResetSender& sender) {
  reset_sender_ = &sender;
  reset_->setVisible(true);
  reset_sources_.reset();
  listResetSources();
}

void ViewerWindow::listResetSources() {
  if (reset_sender_ == nullptr) return;
  std::vector<std::string> sources;
  for (const RunData& run : runs_) {
    if (feed_ != nullptr && run.dir == live_name_.toStdString()) {
      for (const auto& [name, source] : run.sources) sources.push_back(name);
    }
  }
  if (reset_sources_ == sources) return;
  reset_sources_ = sources;
  QMenu* menu = reset_->menu();
  menu->clear();
  menu->addAction(QStringLiteral("Reset every VO node"), [this] { resetVo({}); });
  if (!sources.empty()) menu->addSeparator();
  for (const std::string& source : sources) {
    menu->addAction(QStringLiteral("Reset %1").arg(QString::fromStdString(source)),
                    [this, source] { resetVo(source); });
  }
}

std::optional<msg::VoCommand> ViewerWindow::resetVo(const std::string& source) {
  if (reset_sender_ == nullptr) return std::nullopt;
  const std::optional<msg::Pose> truth =
      feed_ != nullptr ? feed_->liveTruth(kTruthLiveAge) : std::nullopt;
  const QString whom =
      source.empty() ? QStringLiteral("every VO node") : QString::fromStdString(source);
  msg::VoCommand sent;
  try {
    sent = reset_sender_->send(source, truth, core::wallClockUtime());
  } catch (const std::exception& e) {
    statusBar()->showMessage(QStringLiteral("reset: the bus failed: %1").arg(e.what()));
    return std::nullopt;
  }
  if (truth) {
    const Eigen::Vector3d& p = truth->p_ned_m;
    statusBar()->showMessage(
        QStringLiteral("sent RESET to %1 on %2 at the truth's pose (N %3 E %4 D %5 m)")
            .arg(whom, QString::fromStdString(reset_sender_->channel()))
            .arg(p.x(), 0, 'f', 1)
            .arg(p.y(), 0, 'f', 1)
            .arg(p.z(), 0, 'f', 1));
  } else {
    statusBar()->showMessage(
        QStringLiteral("sent RESET to %1 on %2 without a pose (no live truth): each restarts "
                       "where it estimates now")
            .arg(whom, QString::fromStdString(reset_sender_->channel())));
  }
  return sent;
}

void ViewerWindow::openRun(const std::string& path) {
  RunData run = loadRun(path);
  if (!run.damage.empty()) statusBar()->showMessage(QString::fromStdString(run.damage));
  runs_.push_back(std::move(run));
  if (!view_->hasTerrain()) {
    const std::string scenario = scenarioOfRun(path);
    if (!scenario.empty()) {
      try {
        view_->setTerrain(terrainOfScenario(scenario));
      } catch (const std::exception& e) {
        statusBar()->showMessage(QStringLiteral("no terrain: %1").arg(e.what()));
      }
    }
  }
  if (runs_.size() == 1) view_->fitToRuns();
  runsChanged();
}

bool ViewerWindow::showTerrainOf(const std::string& run_dir) {
  if (run_dir.empty()) {
    view_->setTerrain(std::nullopt);
    runsChanged();
    return true;
  }
  const std::string scenario = scenarioOf(run_dir);
  if (scenario.empty()) {
    statusBar()->showMessage(
        QStringLiteral("%1 has no scenario.yaml: no terrain").arg(QString::fromStdString(run_dir)));
    return false;
  }
  try {
    view_->setTerrain(terrainOfScenario(scenario));
  } catch (const std::exception& e) {
    statusBar()->showMessage(QStringLiteral("no terrain: %1").arg(e.what()));
    return false;
  }
  runsChanged();
  return true;
}

std::string ViewerWindow::scenarioOf(const std::string& run_dir) const {
  // The live run is no folder (a folder of its name may exist here).
  if (feed_ != nullptr && run_dir == live_name_.toStdString()) return {};
  return scenarioOfRun(run_dir);
}

const std::string& ViewerWindow::worldOfRun(const std::string& run_dir) {
  auto found = run_worlds_.find(run_dir);
  if (found == run_worlds_.end()) {
    std::string world;
    if (const std::string scenario = scenarioOf(run_dir); !scenario.empty()) {
      try {
        world = gui::worldOfScenario(scenario);
      } catch (const std::exception& e) {
        statusBar()->showMessage(QString::fromUtf8(e.what()));
      }
    }
    found = run_worlds_.emplace(run_dir, std::move(world)).first;
  }
  return found->second;
}

QString ViewerWindow::legendText() const { return legend_->text(); }

void ViewerWindow::openDialog(bool log_file) {
  const QString path =
      log_file ? QFileDialog::getOpenFileName(this, QStringLiteral("Open an LCM log"), QString(),
                                              QStringLiteral("LCM logs (*.lcmlog);;All files (*)"))
               : QFileDialog::getExistingDirectory(this, QStringLiteral("Open a run folder"));
  if (path.isEmpty()) return;
  try {
    openRun(path.toStdString());
  } catch (const std::exception& e) {
    QMessageBox::warning(this, QStringLiteral("nadir-viewer"), QString::fromUtf8(e.what()));
  }
}

void ViewerWindow::runsChanged() {
  duration_s_ = playbackDuration(runs_);
  // A run over another world than the terrain's is drawn in its own frame: say so.
  const ViewerTerrain* terrain = view_->terrain();
  std::vector<QString> notes;
  for (const RunData& run : runs_) {
    const std::string& world = worldOfRun(run.dir);
    notes.push_back(terrain != nullptr && !world.empty() && world != terrain->world
                        ? QStringLiteral("(over another world than the terrain shown)")
                        : QString());
  }
  legend_->setText(runs_.empty() ? QStringLiteral("waiting for the truth (pose_t)")
                                 : viewerLegend(runs_, notes));
  // View > Terrain: the scenario of any run that has one, or none; rebuilt only
  // when that changes (live mode comes here several times a second).
  std::vector<std::pair<std::string, std::string>> choices;  // run dir, scenario
  for (const RunData& run : runs_) {
    if (std::string scenario = scenarioOf(run.dir); !scenario.empty()) {
      choices.emplace_back(run.dir, std::move(scenario));
    }
  }
  const std::string shown = terrain != nullptr ? terrain->scenario_path : std::string();
  if (choices != terrain_choices_ || shown != terrain_shown_) {
    terrain_choices_ = choices;
    terrain_shown_ = shown;
    terrain_menu_->clear();
    for (const auto& [dir, scenario] : choices) {
      QAction* action = terrain_menu_->addAction(
          QStringLiteral("of %1").arg(QString::fromStdString(fs::path(dir).filename().string())),
          [this, dir = dir] { showTerrainOf(dir); });
      action->setCheckable(true);
      action->setChecked(scenario == shown);
    }
    QAction* none = terrain_menu_->addAction(QStringLiteral("None (plain ground)"),
                                             [this] { showTerrainOf({}); });
    none->setCheckable(true);
    none->setChecked(terrain == nullptr);
  }
  showing_time_ = true;
  slider_->setRange(0, static_cast<int>(std::ceil(duration_s_ * kSliderStepsPerS)));
  go_to_->setRange(0.0, duration_s_);
  // The camera choice lists the runs by name, keeping the one chosen (the first
  // run's by default).
  QStringList names;
  for (const RunData& run : runs_) names << QString::fromStdString(run.dir);
  QStringList listed;
  for (int i = 0; i < camera_run_->count(); ++i) listed << camera_run_->itemData(i).toString();
  if (names != listed) {
    const QString chosen = camera_run_->currentData().toString();
    camera_run_->clear();
    for (const RunData& run : runs_) {
      camera_run_->addItem(QString::fromStdString(runName(run)), QString::fromStdString(run.dir));
    }
    camera_run_->setCurrentIndex(std::max(0, static_cast<int>(names.indexOf(chosen))));
  }
  showing_time_ = false;
  seek(time());
}

void ViewerWindow::goTo(double t_s) {
  live_->setChecked(false);
  seek(t_s);
}

void ViewerWindow::seek(double t_s) {
  view_->setTime(std::clamp(t_s, 0.0, duration_s_));
  showTime();
}

QString ViewerWindow::timeText() const {
  return QString::asprintf("%.2f s / %.2f s", time(), duration_s_);
}

void ViewerWindow::setPlaying(bool playing) {
  if (playing == this->playing()) return;
  if (playing) {
    live_->setChecked(false);
    // Play from the start again once at the end.
    if (time() >= duration_s_) seek(0.0);
    clock_.start();
    timer_.start();
  } else {
    timer_.stop();
  }
  play_->setText(playing ? QStringLiteral("Pause") : QStringLiteral("Play"));
}

void ViewerWindow::setSpeed(double speed) {
  const auto& all = speeds();
  const auto nearest = std::min_element(all.begin(), all.end(), [speed](double a, double b) {
    return std::abs(std::log(a / speed)) < std::abs(std::log(b / speed));
  });
  speed_->setCurrentIndex(static_cast<int>(nearest - all.begin()));
}

double ViewerWindow::speed() const { return speed_->currentData().toDouble(); }

void ViewerWindow::tick() {
  const double wall_s = static_cast<double>(clock_.restart()) / 1000.0;
  seek(time() + wall_s * speed());
  if (time() >= duration_s_) setPlaying(false);
}

void ViewerWindow::showTime() {
  showing_time_ = true;
  slider_->setValue(static_cast<int>(std::lround(time() * kSliderStepsPerS)));
  showing_time_ = false;
  time_label_->setText(timeText());
  if (!go_to_->hasFocus()) {
    const QSignalBlocker quiet(go_to_);
    go_to_->setValue(time());
  }
  showCamera();
}

void ViewerWindow::showCameraOf(const std::string& run_dir) {
  const int index = camera_run_->findData(QString::fromStdString(run_dir));
  if (index >= 0) camera_run_->setCurrentIndex(index);
}

void ViewerWindow::setCameraChannel(const std::string& channel) {
  camera_channel_ = channel;
  log_frames_.clear();
  showCamera();
}

QString ViewerWindow::cameraCaption() const { return camera_caption_->text(); }

const RunData* ViewerWindow::cameraRun() const {
  const std::string dir = camera_run_->currentData().toString().toStdString();
  for (const RunData& run : runs_) {
    if (run.dir == dir) return &run;
  }
  return nullptr;
}

CameraFrames* ViewerWindow::framesOf(const RunData& run, std::string& note) {
  if (feed_ != nullptr && run.dir == live_name_.toStdString()) return feed_->frames();
  if (!isLogPath(run.poses_from)) {
    note = "no camera images: " + runName(run) + " has no log";
    return nullptr;
  }
  auto found = log_frames_.find(run.poses_from);
  if (found == log_frames_.end()) {
    // Indexed when first shown: a log of images takes a moment to read.
    std::unique_ptr<CameraFrames> frames;
    try {
      frames = std::make_unique<LogCameraFrames>(run.poses_from, camera_channel_);
    } catch (const std::exception& e) {
      note = e.what();
    }
    found = log_frames_.emplace(run.poses_from, std::move(frames)).first;
  }
  if (!found->second && note.empty()) note = run.poses_from + ": cannot be read";
  return found->second.get();
}

void ViewerWindow::showCamera() {
  const RunData* run = cameraRun();
  std::string note;
  CameraFrames* frames = run != nullptr ? framesOf(*run, note) : nullptr;
  QString caption;
  std::optional<CameraFrame> frame;
  if (run == nullptr) {
    caption = QStringLiteral("no run");
  } else if (frames == nullptr) {
    caption = QString::fromStdString(note);
  } else if (frames->count() == 0) {
    caption = QStringLiteral("no images on %1").arg(QString::fromStdString(frames->describe()));
  } else {
    try {
      frame = frames->frameAt(run->t0_s + time());
    } catch (const std::exception& e) {
      caption = QString::fromUtf8(e.what());
    }
    if (frame) {
      caption = QStringLiteral("%1, image %2 at %3 s")
                    .arg(QString::fromStdString(frames->describe()))
                    .arg(frame->number)
                    .arg(frame->t_s - run->t0_s, 0, 'f', 2);
      if (!frame->error.empty()) {
        caption += QStringLiteral(": ") + QString::fromStdString(frame->error);
      }
    } else if (caption.isEmpty()) {
      caption = QStringLiteral("%1: no image yet").arg(QString::fromStdString(frames->describe()));
    }
  }
  camera_image_ = frame ? toQImage(*frame) : QImage();
  camera_view_->setImage(camera_image_);
  if (camera_image_.isNull()) camera_view_->setText(QStringLiteral("no image"));
  camera_caption_->setText(caption);
}

}  // namespace nadir::gui
