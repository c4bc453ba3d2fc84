#include "gui/viewer_window.h"

#include <QCheckBox>
#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QStatusBar>
#include <QVBoxLayout>
#include <QWidget>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include "gui/plots.h"

namespace nadir::gui {
namespace {

// Slider steps per second of playback.
constexpr double kSliderStepsPerS = 100.0;
// Timer period while playing; the time advances by the wall clock, not by ticks.
constexpr int kTickMs = 33;

QString swatch(const QColor& color, const QString& text) {
  return QStringLiteral("<span style=\"color:%1\">&#9632;</span> %2").arg(color.name(), text);
}

}  // namespace

const std::vector<double>& ViewerWindow::speeds() {
  static const std::vector<double> kSpeeds = {0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0};
  return kSpeeds;
}

QString viewerLegend(const std::vector<RunData>& runs) {
  QStringList lines;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    QStringList items;
    items << swatch(truthColor(r), QStringLiteral("truth"));
    for (const auto& [name, source] : runs[r].sources) {
      items << swatch(sourceColor(runs[r], name), QString::fromStdString(name));
    }
    const QString dir =
        QString::fromStdString(std::filesystem::path(runs[r].dir).filename().string());
    lines << QStringLiteral("<b>%1</b>: %2")
                 .arg(dir.toHtmlEscaped(), items.join(QStringLiteral("&nbsp;&nbsp;")));
  }
  return lines.join(QStringLiteral("<br>"));
}

ViewerWindow::ViewerWindow(std::vector<RunData> runs, std::optional<ViewerTerrain> terrain,
                           QWidget* parent)
    : QMainWindow(parent), runs_(std::move(runs)), duration_s_(playbackDuration(runs_)) {
  auto* central = new QWidget(this);
  auto* layout = new QVBoxLayout(central);
  auto* legend = new QLabel(viewerLegend(runs_), central);
  legend->setTextFormat(Qt::RichText);
  layout->addWidget(legend);
  view_ = new TrajectoryView(runs_, std::move(terrain), central);
  layout->addWidget(view_, 1);

  auto* controls = new QHBoxLayout;
  play_ = new QPushButton(QStringLiteral("Play"), central);
  play_->setShortcut(Qt::Key_Space);
  slider_ = new QSlider(Qt::Horizontal, central);
  slider_->setRange(0, static_cast<int>(std::ceil(duration_s_ * kSliderStepsPerS)));
  time_label_ = new QLabel(central);
  time_label_->setMinimumWidth(
      time_label_->fontMetrics().horizontalAdvance("0000.00 s / 0000.00 s"));
  speed_ = new QComboBox(central);
  for (double s : speeds()) speed_->addItem(QStringLiteral("%1x").arg(s), s);
  follow_ = new QCheckBox(QStringLiteral("Follow vehicle"), central);
  controls->addWidget(play_);
  controls->addWidget(slider_, 1);
  controls->addWidget(time_label_);
  controls->addWidget(speed_);
  controls->addWidget(follow_);
  layout->addLayout(controls);
  setCentralWidget(central);
  setSpeed(1.0);

  connect(play_, &QPushButton::clicked, this, [this] { setPlaying(!playing()); });
  connect(slider_, &QSlider::valueChanged, this, [this](int value) {
    // Only the user's moves seek; showTime() moves it too.
    if (!showing_time_) seek(value / kSliderStepsPerS);
  });
  connect(follow_, &QCheckBox::toggled, this, [this](bool on) { view_->setFollow(on); });
  connect(&timer_, &QTimer::timeout, this, [this] { tick(); });
  timer_.setInterval(kTickMs);
  statusBar()->showMessage(QStringLiteral("left drag: rotate, right drag: pan, wheel: zoom"));
  setWindowTitle(QStringLiteral("nadir-viewer"));
  resize(1200, 800);
  showTime();
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
}

}  // namespace nadir::gui
