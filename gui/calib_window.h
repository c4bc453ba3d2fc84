#pragma once
// nadir-calib's window: checkerboard calibration of a camera from a folder of
// images, an LCM log, a live channel or the virtual checkerboard, as ROS's
// camera_calibration does it. Each image is shown with the board's corners, or
// with why it was refused (no board, blurred, adding no coverage, another size);
// auto-capture keeps the views that add coverage (the X, Y, size and skew bars),
// Capture keeps the one shown whatever it adds. Calibrate solves with the kept
// views and shows the report, each view's RMS, and the image undistorted.
//
// Detection (0.3 to 2 s a 1280x960 image) and calibration (seconds) run on a
// worker thread of the window's that owns the source and the session; the
// window only shows their results. A live source's images that come while one
// is looked at are dropped.

#include <QImage>
#include <QMainWindow>
#include <QString>
#include <QStringList>
#include <QThread>

#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "calib/coverage.h"
#include "calib/session.h"
#include "gui/calib_sources.h"
#include "gui/image_label.h"

class QCheckBox;
class QChartView;
class QComboBox;
class QLabel;
class QPlainTextEdit;
class QProgressBar;
class QPushButton;

namespace nadir::gui {

struct CalibWindowOptions {
  calib::BoardSpec board;
  calib::LensModel model = calib::LensModel::kRadtan;
  // Where Save writes the calibration YAML (and the report beside it, .txt);
  // empty: Save asks with a file dialog.
  std::string out_path;
  bool auto_capture = true;
  // Step through the images from the start (a live source: take them).
  bool play = true;
};

class CalibWindow : public QMainWindow {
 public:
  // Throws std::invalid_argument for an invalid board.
  CalibWindow(std::unique_ptr<FrameSource> source, CalibWindowOptions options,
              QWidget* parent = nullptr);
  ~CalibWindow() override;

  // Playing, the images are offered one after the other (live: the newest, as
  // soon as the one before is done); playing stops at the source's end.
  void setPlaying(bool playing);
  bool playing() const { return playing_; }
  // Offers the next image (Next).
  void step();
  // Keeps the view shown whatever coverage it adds (Capture); false when it has
  // no board or is kept already.
  bool captureShown();
  // Calibrates the kept views (Calibrate); false when fewer than 3 are kept.
  bool calibrateNow();
  // Writes the calibration to path and the report beside it (path with .txt);
  // false with the reason in lastError() when there is none or it cannot be written.
  bool save(const std::string& path);

  // For scripts and tests: plays the source to its end with auto-capture on
  // (live: until live_frames images were offered, or live_timeout passed),
  // calibrates, and calls done with an empty string, or with what went wrong (no
  // image, no board in any image, too few views, the solve failed).
  void runToEnd(std::function<void(const QString& error)> done, int live_frames = 0,
                std::chrono::milliseconds live_timeout = std::chrono::seconds(30));

  // What the window shows.
  bool busy() const { return tasks_in_flight_ > 0; }
  bool ended() const { return ended_; }
  const std::string& sourceDescription() const { return source_description_; }
  const calib::BoardSpec& board() const { return options_.board; }
  const calib::Coverage& coverage() const { return coverage_; }
  const calib::OfferTally& tally() const { return tally_; }
  int viewsKept() const { return views_kept_; }
  // The image shown (corners drawn), its caption (the image's name and whether
  // it was kept, or why not) and the undistorted image (null before Calibrate).
  const QImage& shownImage() const { return shown_image_; }
  QString caption() const;
  const QImage& undistortedImage() const { return undistorted_image_; }
  const calib::Calibration* calibration() const { return calibration_ ? &*calibration_ : nullptr; }
  QString reportText() const;
  QChartView* viewRmsChart() const { return rms_chart_; }
  QProgressBar* coverageBar(int param) const { return coverage_bars_.at(param); }
  QPushButton* captureButton() const { return capture_; }
  QPushButton* calibrateButton() const { return calibrate_; }
  QPushButton* saveButton() const { return save_; }
  QCheckBox* autoCaptureBox() const { return auto_capture_; }
  QComboBox* modelBox() const { return model_; }
  // Images that could not be read, and other errors, in order.
  const QStringList& warnings() const { return warnings_; }
  const QString& lastError() const { return last_error_; }
  // One line: views kept, RMS, fx fy cx cy (empty before a calibration).
  std::string summary() const;

 private:
  struct Engine;
  struct StepResult;
  struct CalibrateResult;

  void buildUi();
  void maybeStep();
  void postStep();
  void showStep(const StepResult& result);
  void showSession(const calib::Coverage& coverage, const calib::OfferTally& tally, int views);
  void showCalibration(const CalibrateResult& result);
  void drawRmsChart(const calib::Calibration& calibration);
  void finishRun();
  void updateButtons();
  void saveDialog();
  calib::LensModel chosenModel() const;
  // Runs work on the worker thread, with the engine; done tasks are counted.
  void runOnWorker(std::function<void(Engine&)> work);
  void taskDone();

  CalibWindowOptions options_;
  std::string source_description_;
  int source_count_ = -1;
  bool live_ = false;
  bool true_lens_known_ = false;

  QThread worker_thread_;
  QObject* worker_ = nullptr;  // lives on worker_thread_: the context of the posted work
  std::unique_ptr<Engine> engine_;
  int tasks_in_flight_ = 0;
  bool playing_ = false;
  bool ended_ = false;

  // The view shown: its detection, for Capture.
  std::optional<calib::Detection> shown_detection_;
  std::string shown_name_;
  cv::Size shown_size_;
  bool shown_kept_ = false;
  int shown_id_ = 0;  // counts the images shown, so that a late capture finds its own
  QString caption_text_;
  bool calibrating_ = false;

  calib::Coverage coverage_;
  calib::OfferTally tally_;
  int views_kept_ = 0;
  std::optional<calib::Calibration> calibration_;
  QImage shown_image_;
  QImage undistorted_image_;
  QStringList warnings_;
  QString last_error_;

  struct AutoRun {
    std::function<void(const QString&)> done;
    int live_frames = 0;
    std::chrono::steady_clock::time_point deadline;
    bool calibrating = false;
  };
  std::optional<AutoRun> auto_run_;

  ImageLabel* image_view_ = nullptr;
  ImageLabel* undistorted_view_ = nullptr;
  QLabel* caption_ = nullptr;
  QLabel* source_label_ = nullptr;
  std::array<QProgressBar*, 4> coverage_bars_{};
  std::array<QLabel*, 4> coverage_ranges_{};
  QLabel* views_label_ = nullptr;
  QPushButton* capture_ = nullptr;
  QCheckBox* auto_capture_ = nullptr;
  QComboBox* model_ = nullptr;
  QPushButton* calibrate_ = nullptr;
  QPushButton* save_ = nullptr;
  QPushButton* next_ = nullptr;
  QPushButton* play_ = nullptr;
  QPlainTextEdit* report_ = nullptr;
  QChartView* rms_chart_ = nullptr;
};

// An RGB or grey cv::Mat as a QImage (a deep copy).
QImage calibQImage(const cv::Mat& image);

}  // namespace nadir::gui
