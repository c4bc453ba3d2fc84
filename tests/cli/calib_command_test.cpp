// nadir calib end to end: the program on a folder of photographs, a log, and
// the bad inputs a user gives it (each a clear error, nothing written).

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/calibration_file.h"
#include "calib/image_folder.h"
#include "core/lcm_log.h"
#include "lcmtypes/codec.h"
#include "tests/support/run_command.h"

namespace nadir {
namespace {

namespace fs = std::filesystem;

const std::string kPhotos = std::string(NADIR_TEST_DATA_DIR) + "/calib/opencv_left";

std::pair<int, std::string> run(const std::string& command) {
  return nadir::test::runCommand(command);
}

fs::path freshFolder(const std::string& name) {
  const fs::path folder = fs::path(::testing::TempDir()) / ("nadir_calib_cli_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::string calib(const std::string& args) { return std::string(NADIR_BIN) + " calib " + args; }

// OpenCV's 13 sample photographs calibrate; the file holds the report's
// intrinsics, near OpenCV's own calibration of the same photographs
// (left_intrinsics.yml: fx = fy = 535.9 px with the aspect ratio held, cx
// 342.3, cy 235.6), and the report is written beside it.
TEST(CalibCommand, CalibratesAFolderOfPhotographs) {
  const fs::path out = freshFolder("photos") / "camera.yaml";
  const auto [status, output] = run(calib("--images " + kPhotos + " --out " + out.string()));
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("13 views of the 9x6"), std::string::npos) << output;
  EXPECT_NE(output.find("held-out error"), std::string::npos) << output;
  const calib::CalibrationFile file = calib::readCalibrationFile(out.string());
  EXPECT_EQ(file.image_width, 640);
  EXPECT_EQ(file.image_height, 480);
  EXPECT_EQ(file.nframes, 13);
  EXPECT_NEAR(file.camera_matrix(0, 0), 535.9, 0.01 * 535.9);
  EXPECT_NEAR(file.camera_matrix(1, 1), 535.9, 0.01 * 535.9);
  EXPECT_NEAR(file.camera_matrix(0, 2), 342.3, 3.0);
  EXPECT_NEAR(file.camera_matrix(1, 2), 235.6, 3.0);
  EXPECT_TRUE(fs::exists(out.parent_path() / "camera_report.txt"));
  // An existing file is not replaced without --force.
  const auto before = fs::last_write_time(out);
  const auto [again, again_output] = run(calib("--images " + kPhotos + " --out " + out.string()));
  EXPECT_EQ(again, 1);
  EXPECT_NE(again_output.find("already exists"), std::string::npos) << again_output;
  EXPECT_EQ(fs::last_write_time(out), before);
}

// A folder whose images hold no board, and a board size that matches none
// of the photographs: each an error naming the board and the folder; no file.
TEST(CalibCommand, NoBoardIsAClearError) {
  const fs::path folder = freshFolder("blank");
  cv::imwrite((folder / "grey.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  cv::Mat noise(480, 640, CV_8UC1);
  cv::randu(noise, 0, 255);
  cv::imwrite((folder / "noise.png").string(), noise);
  const fs::path out = folder / "camera.yaml";
  const auto [status, output] =
      run(calib("--images " + folder.string() + " --out " + out.string()));
  EXPECT_EQ(status, 1);
  EXPECT_NE(output.find("no 9x6, 0.025 m squares board in any of the 2 images of the folder "),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(folder.string()), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));

  const auto [wrong, wrong_output] =
      run(calib("--images " + kPhotos + " --board 7x5 --out " + out.string()));
  EXPECT_EQ(wrong, 1);
  EXPECT_NE(wrong_output.find("no 7x5, 0.025 m squares board in any of the 13 images"),
            std::string::npos)
      << wrong_output;
  EXPECT_FALSE(fs::exists(out));
}

// Bad arguments are named: a missing folder, a board that is not COLSxROWS,
// two sources, a virtual scenario whose world is no board.
TEST(CalibCommand, BadArgumentsAreNamed) {
  const fs::path out = freshFolder("bad") / "camera.yaml";
  const auto [missing, missing_output] =
      run(calib("--images /nonexistent/folder --out " + out.string()));
  EXPECT_EQ(missing, 1);
  EXPECT_NE(missing_output.find("/nonexistent/folder: no such folder"), std::string::npos)
      << missing_output;
  const auto [board, board_output] =
      run(calib("--images " + kPhotos + " --board 9by6 --out " + out.string()));
  EXPECT_EQ(board, 1);
  EXPECT_NE(board_output.find("board '9by6'"), std::string::npos) << board_output;
  const auto [two, two_output] =
      run(calib("--images " + kPhotos + " --virtual --out " + out.string()));
  EXPECT_EQ(two, 1);
  EXPECT_NE(two_output.find("give one source"), std::string::npos) << two_output;
  const auto [flight, flight_output] = run(calib("--virtual default --out " + out.string()));
  EXPECT_EQ(flight, 1);
  EXPECT_NE(flight_output.find("world.kind procedural, not checkerboard"), std::string::npos)
      << flight_output;
  EXPECT_FALSE(fs::exists(out));
}

// Images from an LCM log's camera channel (here the photographs as image_t,
// one in three after a message that is not an image on the same channel):
// the same corners as from the folder; a channel without images names those
// that have some.
TEST(CalibCommand, CalibratesFromALog) {
  const fs::path folder = freshFolder("log");
  const std::string log = (folder / "photos.lcmlog").string();
  {
    core::LcmLogWriter writer(log);
    std::int64_t utime = 1'000'000;
    const std::vector<std::uint8_t> junk = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    writer.write(utime, "CAMERA_DOWN", junk.data(), junk.size());
    for (const std::string& path : calib::imageFiles(kPhotos)) {
      msg::Image image;
      image.utime = utime += 100'000;
      image.pixels = cv::imread(path, cv::IMREAD_GRAYSCALE);
      const msg::Bytes bytes = msg::encode(image);
      writer.write(image.utime, "CAMERA_DOWN", bytes.data(), bytes.size());
      writer.write(image.utime, "CAMERA_FRONT", bytes.data(), bytes.size());
    }
  }
  const fs::path out = folder / "camera.yaml";
  const auto [status, output] =
      run(calib("--log " + log + " --views all --every 1 --out " + out.string()));
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("skipped: " + log + ": CAMERA_DOWN #0 is not an image_t"),
            std::string::npos)
      << output;
  EXPECT_EQ(calib::readCalibrationFile(out.string()).nframes, 13);

  const auto [none, none_output] =
      run(calib("--log " + log + " --channel CAMERA_UP --out " + (folder / "up.yaml").string()));
  EXPECT_EQ(none, 1);
  EXPECT_NE(none_output.find("no message on channel CAMERA_UP (it has CAMERA_DOWN, CAMERA_FRONT)"),
            std::string::npos)
      << none_output;
}

}  // namespace
}  // namespace nadir
