#include "gui/calib_window.h"

#include <QBarCategoryAxis>
#include <QBarSeries>
#include <QBarSet>
#include <QChart>
#include <QChartView>
#include <QCheckBox>
#include <QColor>
#include <QComboBox>
#include <QFileDialog>
#include <QFontDatabase>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QKeySequence>
#include <QLabel>
#include <QLineSeries>
#include <QMetaObject>
#include <QPainter>
#include <QPen>
#include <QPixmap>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QResizeEvent>
#include <QSplitter>
#include <QStatusBar>
#include <QTimer>
#include <QVBoxLayout>
#include <QValueAxis>
#include <QWidget>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <utility>

#include "calib/calibration_file.h"
#include "calib/report.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

// How often a live source is asked again when it had no new image.
constexpr int kLivePollMs = 30;

const char* const kKeptColour = "#2e7d32";
const char* const kRefusedColour = "#e65100";
const char* const kNoBoardColour = "#c62828";

QString fixed(double value, int decimals) { return QString::number(value, 'f', decimals); }

QString boardText(const calib::BoardSpec& board) {
  return QString::fromStdString(calib::describeBoard(board));
}

std::string reportPath(const std::string& yaml_path) {
  fs::path path(yaml_path);
  path.replace_extension(".txt");
  if (path == fs::path(yaml_path)) path += ".report.txt";
  return path.string();
}

}  // namespace

QImage calibQImage(const cv::Mat& image) {
  if (image.empty()) return {};
  const QImage::Format format =
      image.channels() == 1 ? QImage::Format_Grayscale8 : QImage::Format_RGB888;
  return QImage(image.data, image.cols, image.rows, static_cast<qsizetype>(image.step), format)
      .copy();
}

// What the worker thread owns; only work posted through runOnWorker touches it.
struct CalibWindow::Engine {
  std::unique_ptr<FrameSource> source;
  calib::CalibrationSession session;
  std::optional<Undistorter> undistorter;
  cv::Mat last_gray;  // the image shown, for the undistorted pane after Calibrate
};

struct CalibWindow::StepResult {
  bool got_frame = false;  // false: the source had none (its end, or live: nothing new)
  bool ended = false;
  std::string error;
  std::string name;
  int number = 0;
  cv::Size image_size;
  calib::Offer offer;
  double detect_s = 0.0;
  cv::Mat shown;        // RGB, corners drawn
  cv::Mat undistorted;  // after a calibration
  calib::Coverage coverage;
  calib::OfferTally tally;
  int views = 0;
};

struct CalibWindow::CalibrateResult {
  std::optional<calib::Calibration> calibration;
  std::string error;
  std::string report;
  std::vector<std::string> view_names;  // of the views given to the solve
  cv::Mat undistorted;
  double solve_s = 0.0;
};

CalibWindow::CalibWindow(std::unique_ptr<FrameSource> source, CalibWindowOptions options,
                         QWidget* parent)
    : QMainWindow(parent),
      options_(std::move(options)),
      source_description_(source->describe()),
      source_count_(source->count()),
      live_(source->live()),
      true_lens_known_(source->trueLens().has_value()),
      engine_(std::make_unique<Engine>(
          Engine{std::move(source), calib::CalibrationSession(options_.board), std::nullopt, {}})) {
  coverage_ = calib::coverage({});
  buildUi();
  showSession(coverage_, tally_, 0);

  worker_ = new QObject;  // no parent: it moves to the worker thread
  worker_->moveToThread(&worker_thread_);
  worker_thread_.start();
  if (options_.play) setPlaying(true);
}

CalibWindow::~CalibWindow() {
  // The source goes on the thread that used it (the virtual checkerboard's
  // OpenGL context is current there), after the work already posted.
  QMetaObject::invokeMethod(
      worker_,
      [engine = engine_.get()] {
        engine->source.reset();
        engine->undistorter.reset();
      },
      Qt::BlockingQueuedConnection);
  worker_thread_.quit();
  worker_thread_.wait();
  delete worker_;
}

void CalibWindow::buildUi() {
  setWindowTitle(QStringLiteral("nadir-calib"));
  auto* central = new QWidget(this);
  auto* layout = new QVBoxLayout(central);
  source_label_ = new QLabel(central);
  source_label_->setText(
      QStringLiteral("%1, %2 board%3")
          .arg(QString::fromStdString(source_description_), boardText(options_.board),
               true_lens_known_ ? QStringLiteral(" (the true lens is known)") : QString()));
  layout->addWidget(source_label_);

  auto* rows = new QSplitter(Qt::Vertical, central);
  auto* top = new QSplitter(Qt::Horizontal, rows);

  auto* image_panel = new QWidget(top);
  auto* image_layout = new QVBoxLayout(image_panel);
  image_layout->setContentsMargins(0, 0, 0, 0);
  image_view_ = new ImageLabel(image_panel, QStringLiteral("waiting for the first image"));
  image_view_->setWordWrap(true);
  caption_ = new QLabel(image_panel);
  caption_->setWordWrap(true);
  caption_->setTextFormat(Qt::PlainText);
  image_layout->addWidget(image_view_, 1);
  image_layout->addWidget(caption_);

  auto* undistorted_panel = new QWidget(top);
  auto* undistorted_layout = new QVBoxLayout(undistorted_panel);
  undistorted_layout->setContentsMargins(0, 0, 0, 0);
  undistorted_view_ = new ImageLabel(
      undistorted_panel, QStringLiteral("the image undistorted, once calibrated (Calibrate)"));
  undistorted_view_->setWordWrap(true);
  undistorted_layout->addWidget(undistorted_view_, 1);
  undistorted_layout->addWidget(
      new QLabel(QStringLiteral("undistorted with the calibration"), undistorted_panel));

  auto* controls = new QWidget(top);
  auto* controls_layout = new QVBoxLayout(controls);
  auto* coverage_box = new QGroupBox(QStringLiteral("coverage"), controls);
  auto* grid = new QGridLayout(coverage_box);
  for (int i = 0; i < 4; ++i) {
    grid->addWidget(new QLabel(QString::fromUtf8(coverage_.params[i].name), coverage_box), i, 0);
    coverage_bars_[i] = new QProgressBar(coverage_box);
    coverage_bars_[i]->setRange(0, 100);
    coverage_bars_[i]->setFormat(QStringLiteral("%p %"));
    grid->addWidget(coverage_bars_[i], i, 1);
    coverage_ranges_[i] = new QLabel(coverage_box);
    grid->addWidget(coverage_ranges_[i], i, 2);
  }
  views_label_ = new QLabel(coverage_box);
  views_label_->setWordWrap(true);
  grid->addWidget(views_label_, 4, 0, 1, 3);
  controls_layout->addWidget(coverage_box);

  auto* play_row = new QHBoxLayout;
  next_ = new QPushButton(QStringLiteral("Next"), controls);
  next_->setShortcut(QKeySequence(Qt::Key_N));
  next_->setToolTip(QStringLiteral("offer the next image (N)"));
  play_ = new QPushButton(QStringLiteral("Play"), controls);
  play_->setShortcut(QKeySequence(Qt::Key_Space));
  play_->setToolTip(QStringLiteral("offer the images one after the other (Space)"));
  play_row->addWidget(next_);
  play_row->addWidget(play_);
  controls_layout->addLayout(play_row);
  // A live source always shows its newest image: there is no next one to ask for.
  next_->setVisible(!live_);
  connect(next_, &QPushButton::clicked, this, [this] { step(); });
  connect(play_, &QPushButton::clicked, this, [this] { setPlaying(!playing_); });

  auto* capture_row = new QHBoxLayout;
  capture_ = new QPushButton(QStringLiteral("Capture"), controls);
  capture_->setShortcut(QKeySequence(Qt::Key_C));
  capture_->setToolTip(QStringLiteral("keep the view shown even if it adds no coverage (C)"));
  auto_capture_ = new QCheckBox(QStringLiteral("Auto-capture"), controls);
  auto_capture_->setChecked(options_.auto_capture);
  auto_capture_->setToolTip(QStringLiteral("keep the views that add coverage"));
  capture_row->addWidget(capture_);
  capture_row->addWidget(auto_capture_);
  controls_layout->addLayout(capture_row);
  connect(capture_, &QPushButton::clicked, this, [this] { captureShown(); });

  auto* model_row = new QHBoxLayout;
  model_row->addWidget(new QLabel(QStringLiteral("lens model"), controls));
  model_ = new QComboBox(controls);
  for (const calib::LensModel model : {calib::LensModel::kRadtan, calib::LensModel::kFisheye}) {
    model_->addItem(QString::fromUtf8(calib::lensModelName(model)), static_cast<int>(model));
  }
  model_->setCurrentIndex(options_.model == calib::LensModel::kFisheye ? 1 : 0);
  model_row->addWidget(model_, 1);
  controls_layout->addLayout(model_row);

  auto* solve_row = new QHBoxLayout;
  calibrate_ = new QPushButton(QStringLiteral("Calibrate"), controls);
  calibrate_->setToolTip(QStringLiteral("solve for the lens with the views kept (3 at least)"));
  save_ = new QPushButton(QStringLiteral("Save"), controls);
  save_->setToolTip(
      options_.out_path.empty()
          ? QStringLiteral("write the calibration (OpenCV YAML) and its report (.txt)")
          : QStringLiteral("write the calibration to %1 and its report beside it")
                .arg(QString::fromStdString(options_.out_path)));
  solve_row->addWidget(calibrate_);
  solve_row->addWidget(save_);
  controls_layout->addLayout(solve_row);
  connect(calibrate_, &QPushButton::clicked, this, [this] {
    if (!calibrateNow()) statusBar()->showMessage(last_error_);
  });
  connect(save_, &QPushButton::clicked, this, [this] { saveDialog(); });
  controls_layout->addStretch(1);

  auto* bottom = new QSplitter(Qt::Horizontal, rows);
  report_ = new QPlainTextEdit(bottom);
  report_->setReadOnly(true);
  report_->setFont(QFontDatabase::systemFont(QFontDatabase::FixedFont));
  report_->setPlaceholderText(QStringLiteral("the calibration's report, once calibrated"));
  rms_chart_ = new QChartView(bottom);
  rms_chart_->setRenderHint(QPainter::Antialiasing);
  auto* empty_chart = new QChart;
  empty_chart->setTitle(QStringLiteral("RMS of each view, once calibrated"));
  rms_chart_->setChart(empty_chart);

  top->setStretchFactor(0, 1);
  top->setStretchFactor(1, 1);
  top->setStretchFactor(2, 0);
  top->setSizes({600, 600, 300});
  bottom->setSizes({800, 700});
  rows->setSizes({600, 350});
  layout->addWidget(rows, 1);
  setCentralWidget(central);
  resize(1500, 950);
  updateButtons();
}

void CalibWindow::setPlaying(bool playing) {
  playing_ = playing && !ended_;
  play_->setText(playing_ ? QStringLiteral("Pause") : QStringLiteral("Play"));
  updateButtons();
  maybeStep();
}

void CalibWindow::step() {
  if (ended_) return;
  postStep();
}

void CalibWindow::maybeStep() {
  if (!playing_ || busy() || ended_) return;
  postStep();
}

void CalibWindow::runOnWorker(std::function<void(Engine&)> work) {
  ++tasks_in_flight_;
  updateButtons();
  QMetaObject::invokeMethod(
      worker_, [engine = engine_.get(), work = std::move(work)] { work(*engine); },
      Qt::QueuedConnection);
}

void CalibWindow::taskDone() {
  --tasks_in_flight_;
  updateButtons();
}

void CalibWindow::postStep() {
  const bool auto_capture = auto_capture_->isChecked();
  runOnWorker([this, auto_capture](Engine& engine) {
    auto result = std::make_shared<StepResult>();
    try {
      if (std::optional<SourceFrame> frame = engine.source->next()) {
        result->got_frame = true;
        result->name = frame->name;
        result->number = frame->number;
        result->image_size = frame->gray.size();
        const auto start = std::chrono::steady_clock::now();
        result->offer = engine.session.offer(frame->gray, frame->name, auto_capture);
        result->detect_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        result->shown = drawDetection(frame->gray, result->offer.detection, engine.session.board());
        engine.last_gray = frame->gray;
        if (engine.undistorter) result->undistorted = engine.undistorter->undistort(frame->gray);
      }
    } catch (const std::exception& error) {
      result->error = error.what();
    }
    result->ended = engine.source->ended();
    result->coverage = engine.session.coverage();
    result->tally = engine.session.tally();
    result->views = static_cast<int>(engine.session.views().size());
    QMetaObject::invokeMethod(
        this,
        [this, result] {
          taskDone();
          showStep(*result);
        },
        Qt::QueuedConnection);
  });
}

void CalibWindow::showStep(const StepResult& result) {
  if (!result.error.empty()) {
    const QString error = QString::fromStdString(result.error);
    warnings_ << error;
    statusBar()->showMessage(error);
    // A live bus that failed fails again on every ask.
    if (live_) setPlaying(false);
  }
  if (result.got_frame) {
    ++shown_id_;
    shown_detection_ = result.offer.detection;
    shown_name_ = result.name;
    shown_size_ = result.image_size;
    shown_kept_ = result.offer.kept;
    shown_image_ = calibQImage(result.shown);
    image_view_->setImage(shown_image_);
    if (!result.undistorted.empty()) {
      undistorted_image_ = calibQImage(result.undistorted);
      undistorted_view_->setImage(undistorted_image_);
    }
    QString where = QString::fromStdString(result.name);
    if (source_count_ > 0) {
      where += QStringLiteral(" (%1 of %2)").arg(result.number + 1).arg(source_count_);
    }
    const calib::ViewVerdict& verdict = result.offer.verdict;
    QString what;
    const char* colour = kRefusedColour;
    if (result.offer.kept) {
      what = QStringLiteral("kept as view %1").arg(result.views - 1);
      colour = kKeptColour;
    } else if (verdict.keep()) {
      what = QStringLiteral("board found: Capture keeps it");
      colour = kKeptColour;
    } else {
      what = QString::fromStdString(verdict.reason);
      if (result.offer.detection) what += QStringLiteral("; Capture keeps it anyway");
      if (verdict.refusal == calib::ViewRefusal::kNoBoard) colour = kNoBoardColour;
    }
    caption_text_ = QStringLiteral("%1: %2 (%3 s)").arg(where, what, fixed(result.detect_s, 2));
    caption_->setText(caption_text_);
    caption_->setStyleSheet(QStringLiteral("color: %1; font-weight: bold;").arg(colour));
  }
  showSession(result.coverage, result.tally, result.views);

  if (result.ended && !ended_) {
    ended_ = true;
    playing_ = false;
    play_->setText(QStringLiteral("Play"));
    statusBar()->showMessage(
        QStringLiteral("end of the images: %1 views kept%2")
            .arg(views_kept_)
            .arg(views_kept_ >= 3 ? QStringLiteral("; Calibrate solves with them") : QString()));
  }
  updateButtons();

  if (auto_run_ && !auto_run_->calibrating) {
    const bool enough_live =
        live_ && ((auto_run_->live_frames > 0 && tally_.offered >= auto_run_->live_frames) ||
                  std::chrono::steady_clock::now() >= auto_run_->deadline);
    // A failed bus gives nothing more: calibrate with what came.
    const bool live_failed = live_ && !result.error.empty();
    if (ended_ || enough_live || live_failed) {
      finishRun();
      return;
    }
  }
  if (result.got_frame || !live_) {
    maybeStep();
  } else {
    QTimer::singleShot(kLivePollMs, this, [this] { maybeStep(); });
  }
}

void CalibWindow::showSession(const calib::Coverage& coverage, const calib::OfferTally& tally,
                              int views) {
  coverage_ = coverage;
  tally_ = tally;
  views_kept_ = views;
  for (int i = 0; i < 4; ++i) {
    const calib::ParamCoverage& param = coverage.params[i];
    coverage_bars_[i]->setValue(static_cast<int>(std::lround(100.0 * param.progress)));
    coverage_ranges_[i]->setText(
        views > 0 ? QStringLiteral("%1 to %2").arg(fixed(param.min, 2), fixed(param.max, 2))
                  : QString());
  }
  QString text = QStringLiteral("<b>%1 views kept</b> of %2 images").arg(views).arg(tally.offered);
  QStringList refused;
  if (tally.no_board > 0) refused << QStringLiteral("%1 without the board").arg(tally.no_board);
  if (tally.blurred > 0) refused << QStringLiteral("%1 blurred").arg(tally.blurred);
  if (tally.duplicate > 0) refused << QStringLiteral("%1 adding no coverage").arg(tally.duplicate);
  if (tally.other_size > 0) refused << QStringLiteral("%1 of another size").arg(tally.other_size);
  if (!refused.isEmpty()) text += QStringLiteral(" (%1)").arg(refused.join(QStringLiteral(", ")));
  text += coverage.good_enough ? QStringLiteral("<br>enough views to calibrate well")
                               : QStringLiteral("<br>not yet enough views to cover the image");
  views_label_->setText(text);
  updateButtons();
}

bool CalibWindow::captureShown() {
  if (!shown_detection_ || shown_kept_) return false;
  const int id = shown_id_;
  runOnWorker([this, id, detection = *shown_detection_, name = shown_name_,
               size = shown_size_](Engine& engine) {
    const bool kept = engine.session.capture(detection, name, size);
    const calib::Coverage coverage = engine.session.coverage();
    const calib::OfferTally tally = engine.session.tally();
    const int views = static_cast<int>(engine.session.views().size());
    QMetaObject::invokeMethod(
        this,
        [this, id, kept, coverage, tally, views] {
          taskDone();
          showSession(coverage, tally, views);
          if (!kept) {
            statusBar()->showMessage(QStringLiteral("the view was not kept: another image size"));
          } else if (id == shown_id_) {
            shown_kept_ = true;
            caption_->setText(caption_text_ +
                              QStringLiteral(": captured as view %1").arg(views - 1));
            caption_->setStyleSheet(
                QStringLiteral("color: %1; font-weight: bold;").arg(kKeptColour));
          }
          updateButtons();
          maybeStep();
        },
        Qt::QueuedConnection);
  });
  return true;
}

calib::LensModel CalibWindow::chosenModel() const {
  return static_cast<calib::LensModel>(model_->currentData().toInt());
}

bool CalibWindow::calibrateNow() {
  if (views_kept_ < 3) {
    last_error_ = QStringLiteral("calibration needs at least 3 views; %1 kept").arg(views_kept_);
    return false;
  }
  if (calibrating_) {
    last_error_ = QStringLiteral("already calibrating");
    return false;
  }
  calibrating_ = true;
  calib::CalibOptions options;
  options.model = chosenModel();
  statusBar()->showMessage(QStringLiteral("calibrating with %1 views (%2 lens)...")
                               .arg(views_kept_)
                               .arg(QString::fromUtf8(calib::lensModelName(options.model))));
  runOnWorker([this, options](Engine& engine) {
    auto result = std::make_shared<CalibrateResult>();
    try {
      const auto start = std::chrono::steady_clock::now();
      const calib::Calibration calibration = engine.session.calibrate(options);
      result->solve_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::vector<calib::View>& views = engine.session.views();
      result->report = calib::formatReport(calibration, engine.session.board(), views);
      if (const std::optional<render::CameraIntrinsics> lens = engine.source->trueLens()) {
        result->report.append("\n").append(calib::formatComparison(calibration, *lens));
      }
      result->report.append("\n").append(
          calib::formatCoverage(engine.session.coverage(), engine.session.tally()));
      for (const calib::View& view : views) result->view_names.push_back(view.name);
      engine.undistorter.emplace(calibration);
      if (!engine.last_gray.empty()) {
        result->undistorted = engine.undistorter->undistort(engine.last_gray);
      }
      result->calibration = calibration;
    } catch (const std::exception& error) {
      result->error = error.what();
    }
    QMetaObject::invokeMethod(
        this,
        [this, result] {
          taskDone();
          showCalibration(*result);
        },
        Qt::QueuedConnection);
  });
  return true;
}

void CalibWindow::showCalibration(const CalibrateResult& result) {
  calibrating_ = false;
  if (!result.calibration) {
    last_error_ =
        QStringLiteral("calibration failed: %1").arg(QString::fromStdString(result.error));
    statusBar()->showMessage(last_error_);
    updateButtons();
    if (auto_run_) {
      const auto done = std::move(auto_run_->done);
      auto_run_.reset();
      done(last_error_);
    }
    return;
  }
  calibration_ = result.calibration;
  report_->setPlainText(QString::fromStdString(result.report));
  drawRmsChart(*calibration_);
  if (!result.undistorted.empty()) {
    undistorted_image_ = calibQImage(result.undistorted);
    undistorted_view_->setImage(undistorted_image_);
  }
  // Views named in the chart's note of outliers.
  if (!calibration_->rejected.empty()) {
    QStringList names;
    for (const calib::RejectedView& rejected : calibration_->rejected) {
      const std::size_t i = static_cast<std::size_t>(rejected.view);
      names << QStringLiteral("view %1%2 (%3 px)")
                   .arg(rejected.view)
                   .arg(i < result.view_names.size()
                            ? QStringLiteral(" ") + QString::fromStdString(result.view_names[i])
                            : QString())
                   .arg(fixed(rejected.rms_px, 2));
    }
    rms_chart_->chart()->setTitle(
        rms_chart_->chart()->title() +
        QStringLiteral("<br>rejected as outliers: %1").arg(names.join(QStringLiteral(", "))));
  }
  statusBar()->showMessage(QStringLiteral("calibrated in %1 s: RMS %2 px with %3 views")
                               .arg(fixed(result.solve_s, 1), fixed(calibration_->rms_px, 3))
                               .arg(calibration_->views_used.size()));
  updateButtons();
  if (auto_run_) {
    const auto done = std::move(auto_run_->done);
    auto_run_.reset();
    done(QString());
  }
}

void CalibWindow::drawRmsChart(const calib::Calibration& calibration) {
  auto* chart = new QChart;
  auto* used = new QBarSet(QStringLiteral("views used"));
  QStringList categories;
  double largest_px = 0.0;
  for (std::size_t i = 0; i < calibration.views_used.size(); ++i) {
    const double rms_px = calibration.per_view_rms_px[i];
    *used << rms_px;
    largest_px = std::max(largest_px, rms_px);
    categories << QString::number(calibration.views_used[i]);
  }
  // A threshold far above the bars (set by a gross outlier) would flatten them:
  // it is then only named in the title.
  const double threshold_px = calibration.outlier_threshold_px;
  const bool threshold_drawn = threshold_px > 0.0 && threshold_px <= 3.0 * largest_px;
  const double top_px = threshold_drawn ? std::max(largest_px, threshold_px) : largest_px;
  auto* bars = new QBarSeries;
  bars->append(used);
  chart->addSeries(bars);
  auto* x_axis = new QBarCategoryAxis;
  x_axis->append(categories);
  x_axis->setTitleText(QStringLiteral("view (numbered as in the report)"));
  auto* y_axis = new QValueAxis;
  y_axis->setRange(0.0, top_px > 0.0 ? 1.15 * top_px : 1.0);
  y_axis->setTitleText(QStringLiteral("RMS, px"));
  chart->addAxis(x_axis, Qt::AlignBottom);
  chart->addAxis(y_axis, Qt::AlignLeft);
  bars->attachAxis(x_axis);
  bars->attachAxis(y_axis);
  const QString threshold_text =
      QStringLiteral("outlier threshold %1 px").arg(fixed(threshold_px, 2));
  if (threshold_drawn && !categories.isEmpty()) {
    // Bars sit at 0 .. n-1 on the category axis: the line spans them all.
    auto* threshold = new QLineSeries;
    threshold->setName(threshold_text);
    threshold->append(-0.5, threshold_px);
    threshold->append(categories.size() - 0.5, threshold_px);
    QPen pen{QColor(QString::fromLatin1(kNoBoardColour))};
    pen.setStyle(Qt::DashLine);
    pen.setWidth(2);
    threshold->setPen(pen);
    chart->addSeries(threshold);
    threshold->attachAxis(x_axis);
    threshold->attachAxis(y_axis);
  }
  QString title = QStringLiteral("RMS of each view used: %1 views, %2 px in all")
                      .arg(calibration.views_used.size())
                      .arg(fixed(calibration.rms_px, 3));
  if (threshold_px > 0.0 && !threshold_drawn) title += QStringLiteral("; ") + threshold_text;
  chart->setTitle(title);
  QChart* old = rms_chart_->chart();
  rms_chart_->setChart(chart);
  delete old;
}

void CalibWindow::runToEnd(std::function<void(const QString& error)> done, int live_frames,
                           std::chrono::milliseconds live_timeout) {
  auto_capture_->setChecked(true);
  auto_run_ =
      AutoRun{std::move(done), live_frames, std::chrono::steady_clock::now() + live_timeout, false};
  // Always through a step, so that done comes from the event loop.
  playing_ = true;
  play_->setText(QStringLiteral("Pause"));
  if (!busy()) postStep();
}

void CalibWindow::finishRun() {
  playing_ = false;
  play_->setText(QStringLiteral("Play"));
  updateButtons();
  const QString source = QString::fromStdString(source_description_);
  const int with_board = tally_.offered - tally_.no_board - tally_.other_size;
  QString error;
  if (tally_.offered == 0) {
    error = QStringLiteral("no image came from %1").arg(source);
  } else if (with_board <= 0 && views_kept_ == 0) {
    error =
        QStringLiteral("no %1 board found in %2 of %3")
            .arg(boardText(options_.board),
                 tally_.offered == 1 ? QStringLiteral("the one image")
                                     : QStringLiteral("any of the %1 images").arg(tally_.offered),
                 source);
  } else if (views_kept_ < 3) {
    error = QStringLiteral(
                "only %1 views of the %2 board kept from the %3 images of %4; calibration needs 3")
                .arg(views_kept_)
                .arg(boardText(options_.board))
                .arg(tally_.offered)
                .arg(source);
  }
  if (!error.isEmpty() || !calibrateNow()) {
    if (error.isEmpty()) error = last_error_;
    last_error_ = error;
    statusBar()->showMessage(error);
    const auto done = std::move(auto_run_->done);
    auto_run_.reset();
    done(error);
    return;
  }
  auto_run_->calibrating = true;
}

void CalibWindow::updateButtons() {
  capture_->setEnabled(shown_detection_.has_value() && !shown_kept_);
  calibrate_->setEnabled(views_kept_ >= 3 && !calibrating_);
  save_->setEnabled(calibration_.has_value());
  next_->setEnabled(!ended_ && !playing_);
  play_->setEnabled(!ended_);
}

bool CalibWindow::save(const std::string& path) {
  if (!calibration_) {
    last_error_ = QStringLiteral("nothing to save: calibrate first");
    return false;
  }
  const std::string text_path = reportPath(path);
  try {
    calib::writeCalibrationFile(path, calib::toCalibrationFile(*calibration_, options_.board));
    std::ofstream text(text_path, std::ios::trunc);
    text << reportText().toStdString();
    text.flush();
    if (!text) throw std::runtime_error(text_path + ": cannot write the file");
  } catch (const std::exception& error) {
    last_error_ = QString::fromStdString(error.what());
    statusBar()->showMessage(last_error_);
    return false;
  }
  statusBar()->showMessage(
      QStringLiteral("wrote %1 and %2")
          .arg(QString::fromStdString(path), QString::fromStdString(text_path)));
  return true;
}

void CalibWindow::saveDialog() {
  std::string path = options_.out_path;
  if (path.empty()) {
    path = QFileDialog::getSaveFileName(this, QStringLiteral("Save the calibration"),
                                        QStringLiteral("camera.yaml"),
                                        QStringLiteral("OpenCV calibration (*.yaml *.yml)"))
               .toStdString();
    if (path.empty()) return;
  }
  save(path);
}

QString CalibWindow::caption() const { return caption_->text(); }

QString CalibWindow::reportText() const { return report_->toPlainText(); }

std::string CalibWindow::summary() const {
  if (!calibration_) return {};
  const cv::Matx33d& K = calibration_->camera_matrix;
  char line[320];
  std::snprintf(line, sizeof line,
                "%d views kept of %d images, %zu used, %s lens, RMS %.3f px, fx %.2f fy %.2f "
                "cx %.2f cy %.2f px",
                views_kept_, tally_.offered, calibration_->views_used.size(),
                calib::lensModelName(calibration_->model), calibration_->rms_px, K(0, 0), K(1, 1),
                K(0, 2), K(1, 2));
  return line;
}

}  // namespace nadir::gui
