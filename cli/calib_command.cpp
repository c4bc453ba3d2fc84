// nadir calib: calibrate a camera from checkerboard views (a folder of
// photographs, a camera channel of an LCM log, or the virtual checkerboard),
// print the report and write OpenCV's calibration YAML.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "calib/calibration_file.h"
#include "calib/report.h"
#include "calib/session.h"
#include "calib/sources/frame_sources.h"
#include "cli/commands.h"

namespace nadir::cli {
namespace {

namespace fs = std::filesystem;

struct CalibCommandOptions {
  std::string images;
  std::string log;
  std::string channel = "CAMERA_DOWN";
  int every_nth = 1;
  std::optional<std::string> virtual_scenario;
  std::vector<std::string> overrides;
  std::string board = "9x6";
  double square_m = 0.025;
  std::string model = "radtan";
  std::string views;  // "auto" or "all"; default: all for a folder, auto otherwise
  int max_views = 0;
  bool fix_k3 = false;
  bool zero_tangential = false;
  std::string out = "camera.yaml";
  bool force = false;
};

// The report beside the calibration file: camera.yaml -> camera_report.txt.
fs::path reportPath(const fs::path& out) {
  return out.parent_path() / (out.stem().string() + "_report.txt");
}

void runCalib(const CalibCommandOptions& options, const CLI::App& command) {
  const int sources = (options.images.empty() ? 0 : 1) + (options.log.empty() ? 0 : 1) +
                      (options.virtual_scenario ? 1 : 0);
  if (sources != 1)
    throw std::invalid_argument(
        "give one source: --images DIR, --log FILE or --virtual [SCENARIO]");
  const fs::path out(options.out);
  if (!options.force && fs::exists(out))
    throw std::runtime_error(options.out +
                             " already exists; choose another --out or pass --force to replace it");
  const std::optional<calib::LensModel> model = calib::lensModelFromName(options.model);
  if (!model) throw std::invalid_argument("--model " + options.model + ": radtan or fisheye");

  std::unique_ptr<calib::FrameSource> source;
  calib::BoardSpec board = calib::parseBoardSpec(options.board, options.square_m);
  if (!options.images.empty()) {
    source = calib::openFolderSource(options.images);
  } else if (!options.log.empty()) {
    source = calib::openLogSource(options.log, options.channel);
  } else {
    const std::string scenario =
        options.virtual_scenario->empty() ? "calibration" : *options.virtual_scenario;
    source = calib::openVirtualSource(scenario, options.overrides);
    const calib::BoardSpec scenario_board = *source->board();
    const bool board_given = command.count("--board") > 0 || command.count("--square") > 0;
    if (board_given && (scenario_board.inner_cols != board.inner_cols ||
                        scenario_board.inner_rows != board.inner_rows ||
                        scenario_board.square_m != board.square_m)) {
      throw std::invalid_argument(
          "--board " + calib::describeBoard(board) + " is not the scenario's board (" +
          calib::describeBoard(scenario_board) +
          "); change the virtual board with --set world.checkerboard.inner_cols=N (inner_rows, "
          "square_m)");
    }
    board = scenario_board;
  }
  if (!options.overrides.empty() && !options.virtual_scenario)
    throw std::invalid_argument(
        "--set changes the virtual checkerboard's scenario: it needs --virtual");
  const bool auto_capture =
      options.views.empty() ? options.images.empty() : options.views == "auto";

  std::cout << "nadir calib: " << source->describe() << " (" << source->count() << " images), "
            << calib::describeBoard(board) << " board, "
            << (auto_capture ? "views kept when they add coverage" : "every view") << "\n";
  calib::CalibrationSession session(board);
  int images = 0;
  for (int index = 0; !source->ended(); ++index) {
    std::optional<calib::SourceFrame> image;
    try {
      image = source->next();
    } catch (const std::runtime_error& error) {
      // One unreadable image is reported and skipped; the others still count.
      std::cout << "  skipped: " << error.what() << "\n";
      continue;
    }
    if (!image) break;
    if (index % options.every_nth != 0) continue;
    ++images;
    std::cout << "  " << image->name << ": ";
    const calib::Offer offer = session.offer(image->gray, image->name, auto_capture);
    bool kept = offer.kept;
    // Without auto-capture every sharp view of the board is kept, even one that adds no coverage.
    if (!auto_capture && offer.detection &&
        (offer.verdict.keep() || offer.verdict.refusal == calib::ViewRefusal::kDuplicate))
      kept = session.capture(*offer.detection, image->name, image->gray.size());
    if (kept) {
      std::cout << "view " << session.views().size() - 1 << " ("
                << calib::detectorName(offer.detection->detector) << ")\n";
    } else {
      std::cout << offer.verdict.reason << "\n";
    }
    if (options.max_views > 0 && static_cast<int>(session.views().size()) >= options.max_views) {
      std::cout << "  " << options.max_views << " views kept: enough (--max-views)\n";
      break;
    }
  }
  std::cout << "\n" << calib::formatCoverage(session.coverage(), session.tally()) << "\n";
  if (session.views().empty()) {
    throw std::runtime_error(
        "no " + calib::describeBoard(board) + " board in any of the " + std::to_string(images) +
        " images of the " + source->describe() +
        "; --board counts inner corners (a board of 10x7 squares has 9x6 inner corners)");
  }

  calib::CalibOptions calib_options;
  calib_options.model = *model;
  calib_options.fix_k3 = options.fix_k3;
  calib_options.zero_tangential = options.zero_tangential;
  const calib::Calibration calibration = session.calibrate(calib_options);
  std::string report = calib::formatReport(calibration, board, session.views());
  if (const std::optional<render::CameraIntrinsics> lens = source->trueLens())
    report += calib::formatComparison(calibration, *lens);
  std::cout << report;

  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());
  calib::writeCalibrationFile(options.out, calib::toCalibrationFile(calibration, board));
  const fs::path report_path = reportPath(out);
  std::ofstream(report_path) << "nadir calib: " << source->describe() << "\n\n"
                             << calib::formatCoverage(session.coverage(), session.tally()) << "\n"
                             << report;
  std::cout << "\nwrote " << options.out
            << " (a camera's lens: camera.calibration_file: " << options.out << ")\n      "
            << report_path.string() << "\n";
}

}  // namespace

void addCalibCommand(CLI::App& app) {
  auto options = std::make_shared<CalibCommandOptions>();
  auto* command = app.add_subcommand(
      "calib",
      "Calibrate a camera from checkerboard views: intrinsics, distortion, how far to trust "
      "them; writes OpenCV's calibration YAML");
  command->add_option("--images", options->images, "a folder of photographs of the board");
  command->add_option("--log", options->log, "an LCM log with the camera's image_t");
  command->add_option("--channel", options->channel, "the log's image_t channel")
      ->capture_default_str();
  command->add_option("--every", options->every_nth, "take every Nth image of the log")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  command
      ->add_option("--virtual", options->virtual_scenario,
                   "the virtual checkerboard of a scenario (default: calibration)")
      ->expected(0, 1);
  command->add_option("--set", options->overrides,
                      "override a parameter of the virtual scenario: key=value (repeatable)");
  command->add_option("--board", options->board, "inner corners, COLSxROWS")->capture_default_str();
  command->add_option("--square", options->square_m, "side of a square, m")->capture_default_str();
  command->add_option("--model", options->model, "radtan (k1 k2 p1 p2 k3) or fisheye (k1..k4)")
      ->capture_default_str()
      ->check(CLI::IsMember({"radtan", "fisheye"}));
  command
      ->add_option("--views", options->views,
                   "auto: keep a view only when it adds coverage; all: every view with the board "
                   "(default: all for --images, auto otherwise)")
      ->check(CLI::IsMember({"auto", "all"}));
  command->add_option("--max-views", options->max_views, "stop once this many views are kept")
      ->check(CLI::NonNegativeNumber);
  command->add_flag("--fix-k3", options->fix_k3, "radtan: hold k3 at 0");
  command->add_flag("--zero-tangential", options->zero_tangential, "radtan: hold p1 = p2 = 0");
  command->add_option("--out", options->out, "the calibration file")->capture_default_str();
  command->add_flag("--force", options->force, "replace an existing --out");
  command->callback([options, command] { runCalib(*options, *command); });
}

}  // namespace nadir::cli
