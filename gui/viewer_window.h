#pragma once
// nadir-viewer's window: the 3D view of one or more runs over the first run's
// terrain, and playback synchronised over every run and trajectory (play/pause,
// seek slider, time readout, speed 0.1x to 20x, follow the vehicle).

#include <QElapsedTimer>
#include <QMainWindow>
#include <QString>
#include <QTimer>

#include <optional>
#include <vector>

#include "gui/run_data.h"
#include "gui/trajectory_view.h"

class QCheckBox;
class QComboBox;
class QLabel;
class QPushButton;
class QSlider;

namespace nadir::gui {

class ViewerWindow : public QMainWindow {
 public:
  ViewerWindow(std::vector<RunData> runs, std::optional<ViewerTerrain> terrain,
               QWidget* parent = nullptr);

  TrajectoryView& view() { return *view_; }
  const std::vector<RunData>& runs() const { return runs_; }
  double duration() const { return duration_s_; }
  // Playback time, s since each run's truth start, clamped to [0, duration()].
  void seek(double t_s);
  double time() const { return view_->time(); }
  // The time readout as shown, "12.34 s / 60.00 s".
  QString timeText() const;
  void setPlaying(bool playing);
  bool playing() const { return timer_.isActive(); }
  // One of speeds(); others are taken to the nearest.
  void setSpeed(double speed);
  double speed() const;
  static const std::vector<double>& speeds();

 private:
  void tick();
  void showTime();

  std::vector<RunData> runs_;
  double duration_s_ = 0.0;
  TrajectoryView* view_ = nullptr;
  QPushButton* play_ = nullptr;
  QSlider* slider_ = nullptr;
  QLabel* time_label_ = nullptr;
  QComboBox* speed_ = nullptr;
  QCheckBox* follow_ = nullptr;
  QTimer timer_;
  QElapsedTimer clock_;
  bool showing_time_ = false;
};

// The HTML legend: each run's truth and sources in their colours.
QString viewerLegend(const std::vector<RunData>& runs);

}  // namespace nadir::gui
