// nadir-calib: its image sources (a folder, an LCM log, the virtual
// checkerboard), the images it draws, the window run through OpenCV's 13 sample
// photographs (tests/data/calib/opencv_left) under Qt's offscreen platform, and
// the program's --screenshot and errors.

#include <sys/wait.h>

#include <QApplication>
#include <QBarSeries>
#include <QBarSet>
#include <QChart>
#include <QChartView>
#include <QCheckBox>
#include <QColor>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QProgressBar>
#include <QPushButton>
#include <QTimer>

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/board.h"
#include "calib/calibration_file.h"
#include "calib/image_folder.h"
#include "core/bus.h"
#include "core/lcm_log.h"
#include "gui/calib_sources.h"
#include "gui/calib_window.h"
#include "lcmtypes/bus_io.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/image.h"

namespace nadir::gui {
namespace {

namespace fs = std::filesystem;

std::string photoDir() { return std::string(NADIR_TEST_DATA_DIR) + "/calib/opencv_left"; }

// fx of OpenCV's own calibration of the photographs (left_intrinsics.yml).
double sampleFx() {
  cv::FileStorage file(photoDir() + "/left_intrinsics.yml", cv::FileStorage::READ);
  cv::Mat camera_matrix;
  file["camera_matrix"] >> camera_matrix;
  return camera_matrix.at<double>(0, 0);
}

calib::BoardSpec board9x6() { return calib::parseBoardSpec("9x6", 0.025); }

// A fresh, empty folder named after the running test (ctest runs the tests of
// one binary as parallel processes).
fs::path freshDir(const std::string& name) {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::path(::testing::TempDir()) /
      ("nadir_calib_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

fs::path greyFolder() {
  const fs::path dir = freshDir("grey");
  cv::imwrite((dir / "grey.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  return dir;
}

struct ProgramRun {
  int status = -1;
  std::string output;  // stdout and stderr
};

ProgramRun runCalib(const std::string& arguments) {
  setenv("QT_QPA_PLATFORM", "offscreen", 1);
  const std::string command = std::string(NADIR_CALIB_BIN) + " " + arguments + " 2>&1";
  ProgramRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) {
    run.output += buffer.data();
  }
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

class GuiCalibWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (QApplication::instance() != nullptr) return;
    setenv("QT_QPA_PLATFORM", "offscreen", 1);
    static int argc = 1;
    static char name[] = "gui_calib_window_test";
    static char* argv[] = {name, nullptr};
    // Never destroyed: Qt must outlive every test, and ends with the process.
    new QApplication(argc, argv);
  }

  static std::unique_ptr<CalibWindow> photoWindow(bool auto_capture = true) {
    CalibWindowOptions options;
    options.board = board9x6();
    options.play = false;
    options.auto_capture = auto_capture;
    return std::make_unique<CalibWindow>(openFolderSource(photoDir()), options);
  }

  // Runs the window's source to its end and calibrates; the error, if any.
  static QString runToEnd(CalibWindow& window) {
    std::optional<QString> error;
    QEventLoop loop;
    window.runToEnd([&](const QString& what) {
      error = what;
      loop.quit();
    });
    QTimer::singleShot(120000, &loop, &QEventLoop::quit);
    if (!error) loop.exec();
    return error.value_or(QStringLiteral("timed out"));
  }

  // Lets the worker's tasks finish and their results show.
  static void waitIdle(const CalibWindow& window) {
    QElapsedTimer clock;
    clock.start();
    while ((window.busy() || clock.elapsed() < 20) && clock.elapsed() < 60000) {
      QApplication::processEvents(QEventLoop::AllEvents, 10);
    }
  }
};

// The whole folder with auto-capture: views kept, the report, one bar per view
// used, the undistorted image, fx within 1 % of OpenCV's own calibration of these
// photographs, and Save's two files.
TEST_F(GuiCalibWindow, CalibratesOpenCvSamplePhotographs) {
  const auto window = photoWindow();
  window->show();
  ASSERT_EQ(runToEnd(*window).toStdString(), "");
  EXPECT_TRUE(window->ended());
  EXPECT_EQ(window->tally().offered, 13);
  EXPECT_GT(window->viewsKept(), 0);
  ASSERT_NE(window->calibration(), nullptr);
  const calib::Calibration& calibration = *window->calibration();

  const QString report = window->reportText();
  EXPECT_FALSE(report.isEmpty());
  EXPECT_TRUE(report.contains(QStringLiteral("fx"))) << report.toStdString();

  QBarSeries* bars = nullptr;
  for (QAbstractSeries* series : window->viewRmsChart()->chart()->series()) {
    if (auto* found = qobject_cast<QBarSeries*>(series)) bars = found;
  }
  ASSERT_NE(bars, nullptr);
  ASSERT_EQ(bars->count(), 1);
  EXPECT_EQ(bars->barSets().front()->count(), static_cast<int>(calibration.views_used.size()));

  EXPECT_FALSE(window->undistortedImage().isNull());
  EXPECT_EQ(window->undistortedImage().size(), QSize(640, 480));
  EXPECT_FALSE(window->shownImage().isNull());
  EXPECT_TRUE(window->saveButton()->isEnabled());

  const double fx_px = calibration.camera_matrix(0, 0);
  EXPECT_NEAR(fx_px, sampleFx(), 0.01 * sampleFx());

  const fs::path dir = freshDir("save");
  ASSERT_TRUE(window->save((dir / "camera.yaml").string())) << window->lastError().toStdString();
  const calib::CalibrationFile file = calib::readCalibrationFile((dir / "camera.yaml").string());
  EXPECT_DOUBLE_EQ(file.camera_matrix(0, 0), fx_px);
  EXPECT_EQ(file.board_width, 9);
  EXPECT_GT(fs::file_size(dir / "camera.txt"), 100u);
}

// Without auto-capture a found board waits for Capture, which keeps the view
// shown; Calibrate stays off below 3 views; an image without the board says so.
TEST_F(GuiCalibWindow, CaptureKeepsTheViewShown) {
  const auto window = photoWindow(/*auto_capture=*/false);
  EXPECT_FALSE(window->autoCaptureBox()->isChecked());
  window->step();
  waitIdle(*window);
  EXPECT_EQ(window->viewsKept(), 0);
  EXPECT_TRUE(window->caption().contains(QStringLiteral("left01.jpg")))
      << window->caption().toStdString();
  EXPECT_TRUE(window->caption().contains(QStringLiteral("Capture keeps it")));
  EXPECT_TRUE(window->captureButton()->isEnabled());
  ASSERT_TRUE(window->captureShown());
  waitIdle(*window);
  EXPECT_EQ(window->viewsKept(), 1);
  EXPECT_TRUE(window->caption().contains(QStringLiteral("captured as view 0")));
  EXPECT_FALSE(window->captureButton()->isEnabled());
  EXPECT_FALSE(window->captureShown());  // kept already
  EXPECT_FALSE(window->calibrateButton()->isEnabled());
  EXPECT_FALSE(window->calibrateNow());
  EXPECT_GT(window->coverageBar(2)->value(), 0);  // size: one view has some
}

// Closing the window while its worker looks for a board waits for it and ends
// cleanly (the source goes on the worker's thread).
TEST_F(GuiCalibWindow, ClosesWhileBusy) {
  CalibWindowOptions options;
  options.board = board9x6();
  options.play = true;
  auto window = std::make_unique<CalibWindow>(openFolderSource(photoDir()), options);
  EXPECT_TRUE(window->playing());
  EXPECT_TRUE(window->busy());
  QApplication::processEvents();
  window.reset();
}

// A folder whose one image has no board: the run ends with an error naming
// the folder, and the image is framed in red.
TEST_F(GuiCalibWindow, FolderWithoutBoardFailsNamingIt) {
  const fs::path dir = greyFolder();
  CalibWindowOptions options;
  options.board = board9x6();
  options.play = false;
  CalibWindow window(openFolderSource(dir.string()), options);
  const QString error = runToEnd(window);
  EXPECT_TRUE(error.contains(QString::fromStdString(dir.string()))) << error.toStdString();
  EXPECT_TRUE(error.contains(QStringLiteral("no 9x6"))) << error.toStdString();
  EXPECT_EQ(window.calibration(), nullptr);
  ASSERT_FALSE(window.shownImage().isNull());
  EXPECT_EQ(window.shownImage().pixelColor(0, 0), QColor(255, 0, 0));
}

// The program on the photographs: a PNG of the window and one summary line.
TEST(GuiCalibProgram, ScreenshotWritesThePngAndASummary) {
  const fs::path dir = freshDir("shot");
  const fs::path png = dir / "window.png";
  const ProgramRun run = runCalib("--images " + photoDir() + " --screenshot " + png.string() +
                                  " --out " + (dir / "camera.yaml").string());
  ASSERT_EQ(run.status, 0) << run.output;
  ASSERT_TRUE(fs::exists(png)) << run.output;
  EXPECT_GT(fs::file_size(png), 10000u);
  EXPECT_NE(run.output.find("views kept of 13 images"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(" fx "), std::string::npos) << run.output;
  EXPECT_TRUE(fs::exists(dir / "camera.yaml"));
  EXPECT_TRUE(fs::exists(dir / "camera.txt"));
}

// No board in any image: exit status not 0, the message names the folder.
TEST(GuiCalibProgram, FolderWithoutBoardExitsNonZero) {
  const fs::path dir = greyFolder();
  const ProgramRun run =
      runCalib("--images " + dir.string() + " --screenshot " + (dir / "x.png").string());
  EXPECT_NE(run.status, 0) << run.output;
  EXPECT_NE(run.output.find(dir.string()), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

// Bad input: exit status 1 and a message naming what is wrong.
TEST(GuiCalibProgram, BadInputIsRefusedWithStatus1) {
  const fs::path dir = freshDir("bad");
  const struct {
    std::string arguments;
    std::string names;
  } cases[] = {
      {"", "--images"},
      {"--images " + (dir / "missing").string(), (dir / "missing").string()},
      {"--images " + photoDir() + " --board 9y6", "9y6"},
      {"--images " + photoDir() + " --model pinhole", "pinhole"},
      {"--log " + (dir / "none.lcmlog").string(), (dir / "none.lcmlog").string()},
      {"--virtual --board 8x6", "world.checkerboard.inner_cols=8"},
      {"--images " + photoDir() + " --virtual", "not several"},
  };
  for (const auto& bad : cases) {
    const ProgramRun run = runCalib(bad.arguments);
    EXPECT_EQ(run.status, 1) << bad.arguments << ": " << run.output;
    EXPECT_NE(run.output.find(bad.names), std::string::npos) << bad.arguments << ": " << run.output;
  }
}

// Live over UDP multicast: the program listens (and says so), the test sends the
// photographs over and over; once 13 images were offered it calibrates, saves
// the window and prints its summary.
TEST(GuiCalibProgram, LiveCalibratesFromTheBus) {
  const std::string url = "udpm://239.255.76.67:7863?ttl=0";
  const fs::path png = freshDir("live") / "live.png";
  setenv("QT_QPA_PLATFORM", "offscreen", 1);
  const std::string command = std::string(NADIR_CALIB_BIN) + " --live CAM_LIVE --bus '" + url +
                              "' --screenshot " + png.string() + " --frames 13 --timeout 60 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::vector<cv::Mat> photos;
  for (const std::string& file : calib::imageFiles(photoDir())) {
    photos.push_back(cv::imread(file, cv::IMREAD_GRAYSCALE));
  }
  std::atomic<bool> stop{false};
  std::thread sender;
  std::string output;
  std::array<char, 4096> line;
  while (std::fgets(line.data(), static_cast<int>(line.size()), pipe) != nullptr) {
    output += line.data();
    if (!sender.joinable() && output.find("listening to live CAM_LIVE") != std::string::npos) {
      sender = std::thread([&] {
        const std::unique_ptr<core::Bus> bus = core::openBus(url);
        for (std::int64_t i = 0; !stop; ++i) {
          msg::Image image;
          image.utime = 1000000 + i * 100000;
          image.pixels = photos[static_cast<std::size_t>(i) % photos.size()];
          msg::publish(*bus, "CAM_LIVE", image);
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
      });
    }
  }
  const int status = pclose(pipe);
  stop = true;
  if (sender.joinable()) sender.join();
  ASSERT_TRUE(WIFEXITED(status)) << output;
  ASSERT_EQ(WEXITSTATUS(status), 0) << output;
  EXPECT_NE(output.find("views kept of 13 images"), std::string::npos) << output;
  EXPECT_GT(fs::file_size(png), 10000u);
}

// A log: the images of its channel, in order, grey, named by channel and
// number; a log without the channel names the channels it has.
TEST(GuiCalibSources, LogGivesTheChannelsImages) {
  const fs::path log = freshDir("log") / "images.lcmlog";
  const cv::Mat first = cv::imread(photoDir() + "/left01.jpg", cv::IMREAD_GRAYSCALE);
  const cv::Mat second = cv::imread(photoDir() + "/left02.jpg", cv::IMREAD_GRAYSCALE);
  {
    core::LcmLogWriter writer(log.string());
    std::int64_t utime = 1000000;
    for (const cv::Mat& pixels : {first, second}) {
      msg::Image image;
      image.utime = utime;
      image.pixels = pixels;
      const msg::Bytes bytes = msg::encode(image);
      writer.write(utime, "CAM", bytes.data(), bytes.size());
      writer.write(utime + 1, "OTHER", bytes.data(), bytes.size());
      utime += 100000;
    }
  }
  const std::unique_ptr<FrameSource> source = openLogSource(log.string(), "CAM");
  EXPECT_EQ(source->count(), 2);
  EXPECT_FALSE(source->live());
  std::optional<SourceFrame> frame = source->next();
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->name, "CAM #0");
  EXPECT_EQ(cv::norm(frame->gray, first, cv::NORM_INF), 0.0);
  frame = source->next();
  ASSERT_TRUE(frame);
  EXPECT_EQ(cv::norm(frame->gray, second, cv::NORM_INF), 0.0);
  EXPECT_TRUE(source->ended());
  EXPECT_FALSE(source->next());

  try {
    openLogSource(log.string(), "CAMERA_DOWN");
    FAIL() << "no CAMERA_DOWN in the log";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("CAM, OTHER"), std::string::npos) << error.what();
  }
}

// The virtual checkerboard: the scenario's board and lens, its views counted
// from the scenario, and rendered on another thread than the one that opened
// it (as the window's worker does).
TEST(GuiCalibSources, VirtualSourceRendersOnTheWorkerThread) {
  const std::unique_ptr<FrameSource> source = openVirtualSource(
      "calibration", {"calibration.views=2", "camera.width=640", "camera.height=480"});
  EXPECT_EQ(source->count(), 2);
  ASSERT_TRUE(source->board());
  EXPECT_EQ(source->board()->inner_cols, 9);
  EXPECT_EQ(source->board()->inner_rows, 6);
  ASSERT_TRUE(source->trueLens());
  EXPECT_EQ(source->trueLens()->width, 640);
  EXPECT_DOUBLE_EQ(source->trueLens()->distortion[0], -0.2);
  std::optional<SourceFrame> frame;
  std::thread worker([&] {
    frame = source->next();
    frame = source->next();
  });
  worker.join();
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->name, "virtual view 1");
  EXPECT_EQ(frame->gray.type(), CV_8UC1);
  EXPECT_EQ(frame->gray.size(), cv::Size(640, 480));
  EXPECT_TRUE(source->ended());
}

// The corners drawn in drawChessboardCorners' row colours; without a board a
// red frame; a lens without distortion undistorts to the same image.
TEST(GuiCalibSources, DrawsTheDetectionAndUndistorts) {
  const calib::BoardSpec board = board9x6();
  const cv::Mat gray = cv::imread(photoDir() + "/left01.jpg", cv::IMREAD_GRAYSCALE);
  const std::optional<calib::Detection> detection = calib::detectBoard(gray, board);
  ASSERT_TRUE(detection);
  const cv::Mat drawn = drawDetection(gray, detection, board);
  ASSERT_EQ(drawn.type(), CV_8UC3);
  // The first row red (255, 0, 0), as OpenCV's first colour.
  const cv::Point first = detection->corners_px.front();
  bool red_near_first = false;
  for (int dy = -6; dy <= 6; ++dy) {
    for (int dx = -6; dx <= 6; ++dx) {
      const cv::Vec3b rgb = drawn.at<cv::Vec3b>(first + cv::Point(dx, dy));
      red_near_first = red_near_first || (rgb[0] > 200 && rgb[1] < 60 && rgb[2] < 60);
    }
  }
  EXPECT_TRUE(red_near_first);
  const cv::Mat none = drawDetection(gray, std::nullopt, board);
  EXPECT_EQ(none.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 0));
  EXPECT_EQ(none.at<cv::Vec3b>(479, 639), cv::Vec3b(255, 0, 0));

  calib::Calibration pinhole;
  pinhole.image_size = gray.size();
  pinhole.camera_matrix = cv::Matx33d(500, 0, 319.5, 0, 500, 239.5, 0, 0, 1);
  pinhole.distortion = {0, 0, 0, 0, 0};
  const cv::Mat same = Undistorter(pinhole).undistort(gray);
  EXPECT_LE(cv::norm(same, gray, cv::NORM_INF), 1.0);
}

}  // namespace
}  // namespace nadir::gui
