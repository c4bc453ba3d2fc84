#pragma once
// nadir-viewer's window: the 3D view of one or more runs over the terrain of a
// chosen run's scenario (the first's by default), a chosen run's camera image beside it, and
// playback synchronised over every run and trajectory (play/pause, seek slider, time readout, speed
// 0.1x to 20x, follow the vehicle). Runs come from run folders and LCM logs (File menu or the
// constructor) or, in live mode, from a LiveFeed on a bus, where a Reset button restarts the VO
// nodes.

#include <QElapsedTimer>
#include <QImage>
#include <QMainWindow>
#include <QString>
#include <QTimer>

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gui/camera_frames.h"
#include "gui/image_label.h"
#include "gui/run_data.h"
#include "gui/trajectory_view.h"
#include "lcmtypes/messages.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QMenu;
class QPushButton;
class QSlider;
class QToolButton;

namespace nadir::gui {

class LiveFeed;
class VoResetSender;

class ViewerWindow : public QMainWindow {
 public:
  ViewerWindow(std::vector<RunData> runs, std::optional<ViewerTerrain> terrain,
               QWidget* parent = nullptr);
  ~ViewerWindow() override;

  // Live mode: the run is taken from feed (which must outlive the window) as it
  // grows, and is always the first run; rebuilding it costs time in its length,
  // so it is done at most every rebuild_period_ms. With "Live" on, playback
  // stays at the newest truth.
  void attachLive(LiveFeed& feed, const QString& name, int rebuild_period_ms = 200);
  // Takes the bus's messages and, when due, shows the run they make (the live
  // timer calls it).
  void pollLive();
  bool followingLive() const;

  // The truth is live while its newest pose is at most this old (wall time).
  static constexpr std::chrono::milliseconds kTruthLiveAge{2000};
  // Live mode: the Reset button (and its menu of the sources seen) sends RESETs
  // through sender, which must outlive the window.
  void attachVoReset(VoResetSender& sender);
  // What the Reset button does: a RESET to `source` (empty: every VO node), to
  // the newest truth pose while the truth is live, else without a pose (each
  // node restarts where it estimates now). Returns what was sent; nothing
  // without a sender or when the bus failed (the status bar says why).
  std::optional<msg::VoCommand> resetVo(const std::string& source);

  // Opens a run folder or an LCM log and adds it to the runs; the terrain is
  // taken from its scenario.yaml if the window has none yet. Throws RunDataError.
  void openRun(const std::string& path);

  // Draws the terrain of this run's scenario.yaml (View > Terrain); false, with
  // the reason in the status bar, if it has none or it does not build (the
  // terrain drawn stays). An empty run_dir leaves the ground plain.
  bool showTerrainOf(const std::string& run_dir);
  // Runs are drawn in their own world frame: a run whose scenario flies over
  // another world than the terrain drawn is marked so in the legend. Its
  // world, as worldOfScenario gives it; empty if unknown (no scenario.yaml).
  const std::string& worldOfRun(const std::string& run_dir);
  QString legendText() const;

  TrajectoryView& view() { return *view_; }
  const std::vector<RunData>& runs() const { return runs_; }
  double duration() const { return duration_s_; }
  // Playback time, s since each run's truth start, clamped to [0, duration()].
  void seek(double t_s);
  // Seeks as the user does (the go-to box, the arrow keys): leaves live following.
  void goTo(double t_s);
  double time() const { return view_->time(); }
  // The time readout as shown, "12.34 s / 60.00 s".
  QString timeText() const;
  void setPlaying(bool playing);
  bool playing() const { return timer_.isActive(); }
  // One of speeds(); others are taken to the nearest.
  void setSpeed(double speed);
  double speed() const;
  static const std::vector<double>& speeds();

  // Whose camera image is shown: the run whose dir is given (the first by default).
  void showCameraOf(const std::string& run_dir);
  // The image_t channel shown (CAMERA_DOWN by default).
  void setCameraChannel(const std::string& channel);
  // The camera image shown (full resolution; null when none) and its caption.
  const QImage& cameraImage() const { return camera_image_; }
  QString cameraCaption() const;

 private:
  void tick();
  void showTime();
  void showCamera();
  void runsChanged();
  void listResetSources();
  void openDialog(bool log_file);
  const RunData* cameraRun() const;
  // The run's scenario.yaml; empty for the live run and a run without one.
  std::string scenarioOf(const std::string& run_dir) const;
  // The images of a run (live, or from its log); null with the reason in note.
  CameraFrames* framesOf(const RunData& run, std::string& note);

  std::vector<RunData> runs_;
  double duration_s_ = 0.0;
  TrajectoryView* view_ = nullptr;
  QLabel* legend_ = nullptr;
  QComboBox* camera_run_ = nullptr;
  ImageLabel* camera_view_ = nullptr;
  QLabel* camera_caption_ = nullptr;
  QPushButton* play_ = nullptr;
  QSlider* slider_ = nullptr;
  QLabel* time_label_ = nullptr;
  QDoubleSpinBox* go_to_ = nullptr;
  QComboBox* speed_ = nullptr;
  QCheckBox* follow_ = nullptr;
  QCheckBox* live_ = nullptr;
  QToolButton* reset_ = nullptr;
  VoResetSender* reset_sender_ = nullptr;
  // The sources in the Reset button's menu; nothing before it is made.
  std::optional<std::vector<std::string>> reset_sources_;
  QTimer timer_;
  QTimer live_timer_;
  QElapsedTimer clock_;
  bool showing_time_ = false;
  // Each run's images by its log's path, indexed when first shown; null if unreadable.
  std::map<std::string, std::unique_ptr<CameraFrames>> log_frames_;
  std::string camera_channel_ = kDefaultCameraChannel;
  LiveFeed* feed_ = nullptr;
  QString live_name_;
  std::uint64_t live_version_ = 0;
  QElapsedTimer since_rebuild_;
  int rebuild_period_ms_ = 200;
  QImage camera_image_;
  QMenu* terrain_menu_ = nullptr;
  std::vector<std::pair<std::string, std::string>> terrain_choices_;  // run dir, scenario
  std::string terrain_shown_;                      // the scenario of the terrain drawn
  std::map<std::string, std::string> run_worlds_;  // run dir -> worldOfRun
};

// The HTML legend: each run's truth and sources in their colours, and after the
// run's line its note if it has one (notes are by run, none if empty).
QString viewerLegend(const std::vector<RunData>& runs, const std::vector<QString>& notes = {});

// scenario.yaml of a run folder, or beside an LCM log; empty if there is none.
std::string scenarioOfRun(const std::string& run_path);

// A camera frame as a QImage (Format_Grayscale8 or Format_RGB888; a deep copy).
QImage toQImage(const CameraFrame& frame);

}  // namespace nadir::gui
