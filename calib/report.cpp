#include "calib/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace nadir::calib {
namespace {

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string viewName(const std::vector<View>& views, int index) {
  const std::string number = "view " + std::to_string(index);
  if (index < 0 || index >= static_cast<int>(views.size()) || views[index].name.empty())
    return number;
  return number + " (" + views[index].name + ")";
}

// "1.23 sigma" or "-" when there is no standard deviation.
std::string inSigmas(double error, double sigma) {
  if (!(sigma > 0.0)) return "-";
  return fixed(std::abs(error) / sigma, 2) + " sigma";
}

}  // namespace

std::vector<std::string> distortionNames(LensModel model) {
  if (model == LensModel::kFisheye) return {"k1", "k2", "k3", "k4"};
  return {"k1", "k2", "p1", "p2", "k3"};
}

std::string progressBar(double progress, int width) {
  const double clamped = std::clamp(std::isfinite(progress) ? progress : 0.0, 0.0, 1.0);
  const int filled = static_cast<int>(std::lround(clamped * width));
  std::string bar(static_cast<std::size_t>(width) + 2, '-');
  bar.front() = '[';
  bar.back() = ']';
  std::fill_n(bar.begin() + 1, filled, '#');
  return bar;
}

std::string formatCoverage(const Coverage& coverage, const OfferTally& tally) {
  std::ostringstream out;
  out << "coverage of the image (ROS camera_calibration's measures):\n";
  for (const ParamCoverage& param : coverage.params) {
    char name[16];
    std::snprintf(name, sizeof name, "%-5s", param.name);
    out << "  " << name << " " << progressBar(param.progress) << " "
        << fixed(100.0 * param.progress, 0) << " %  (" << fixed(param.min, 2) << " to "
        << fixed(param.max, 2) << ")\n";
  }
  out << "  " << tally.offered << " images: " << tally.kept << " views kept, " << tally.no_board
      << " without the board, " << tally.blurred << " blurred, " << tally.duplicate
      << " adding no coverage";
  if (tally.other_size > 0) out << ", " << tally.other_size << " of another size";
  out << "\n";
  out << "  " << (coverage.good_enough ? "enough views" : "not yet enough views") << "\n";
  return out.str();
}

std::string formatReport(const Calibration& calibration, const BoardSpec& board,
                         const std::vector<View>& views) {
  std::ostringstream out;
  const cv::Matx33d& K = calibration.camera_matrix;
  out << "calibration: " << lensModelName(calibration.model) << " lens, "
      << calibration.image_size.width << "x" << calibration.image_size.height << " px, "
      << calibration.views_used.size() << " views of the " << describeBoard(board) << " board\n";
  const IntrinsicStdDevs* sd = calibration.std_devs ? &*calibration.std_devs : nullptr;
  auto line = [&](const std::string& name, double value, double sigma, int decimals,
                  const char* unit) {
    char label[8];
    std::snprintf(label, sizeof label, "%-3s", name.c_str());
    out << "  " << label << " = " << fixed(value, decimals);
    if (sd) out << " +- " << fixed(sigma, decimals);
    out << unit << "\n";
  };
  line("fx", K(0, 0), sd ? sd->fx_px : 0.0, 3, " px");
  line("fy", K(1, 1), sd ? sd->fy_px : 0.0, 3, " px");
  line("cx", K(0, 2), sd ? sd->cx_px : 0.0, 3, " px");
  line("cy", K(1, 2), sd ? sd->cy_px : 0.0, 3, " px");
  const std::vector<std::string> names = distortionNames(calibration.model);
  for (std::size_t i = 0; i < calibration.distortion.size() && i < names.size(); ++i) {
    line(names[i], calibration.distortion[i],
         sd && i < sd->distortion.size() ? sd->distortion[i] : 0.0, 5, "");
  }
  if (!sd) {
    out << "  no standard deviations: the views do not determine the intrinsics "
           "(J^T J is singular); add views from other angles\n";
  } else {
    out << "  (+- one standard deviation)\n";
  }
  out << "reprojection RMS " << fixed(calibration.rms_px, 3) << " px";
  if (calibration.outlier_threshold_px > 0.0) {
    out << " (first solve " << fixed(calibration.first_rms_px, 3) << " px; views above "
        << fixed(calibration.outlier_threshold_px, 3) << " px dropped)";
  }
  out << "\n";
  if (!calibration.rejected.empty()) {
    out << "rejected as outliers:\n";
    for (const RejectedView& rejected : calibration.rejected)
      out << "  " << viewName(views, rejected.view) << ": " << fixed(rejected.rms_px, 3) << " px\n";
  }
  const HeldOutError& held_out = calibration.held_out;
  if (held_out.folds > 0) {
    out << "held-out error (" << held_out.folds << " folds";
    if (held_out.failed_folds > 0) out << ", " << held_out.failed_folds << " failed";
    out << "): " << fixed(held_out.mean_rms_px, 3) << " px on views left out, "
        << fixed(held_out.mean_training_rms_px, 3) << " px on the views calibrated on\n";
    const double ratio = held_out.mean_rms_px / std::max(held_out.mean_training_rms_px, 1e-12);
    if (ratio > 1.5) {
      out << "  the views left out are " << fixed(ratio, 1)
          << " times worse: the intrinsics follow the views' noise; add views, "
             "especially tilted ones and ones near the image's edges\n";
    } else {
      out << "  the views left out are explained about as well (" << fixed(ratio, 2)
          << " times): the views are enough for this lens model\n";
    }
  }
  out << "per view RMS:\n";
  for (std::size_t i = 0; i < calibration.views_used.size(); ++i) {
    out << "  " << viewName(views, calibration.views_used[i]) << ": "
        << fixed(calibration.per_view_rms_px[i], 3) << " px";
    if (i < held_out.per_view_rms_px.size() && std::isfinite(held_out.per_view_rms_px[i]))
      out << ", held out " << fixed(held_out.per_view_rms_px[i], 3) << " px";
    out << "\n";
  }
  if (!calibration.worst_corners.empty()) {
    out << "worst corners:\n";
    for (const CornerResidual& corner : calibration.worst_corners) {
      out << "  " << viewName(views, corner.view) << ", corner " << corner.corner << " (row "
          << corner.corner / board.inner_cols << ", column " << corner.corner % board.inner_cols
          << "): " << fixed(corner.residual_px, 3) << " px\n";
    }
  }
  return out.str();
}

std::string formatComparison(const Calibration& calibration,
                             const render::CameraIntrinsics& true_lens) {
  std::ostringstream out;
  out << "against the lens the images were made with:\n";
  const IntrinsicStdDevs* sd = calibration.std_devs ? &*calibration.std_devs : nullptr;
  const cv::Matx33d& K = calibration.camera_matrix;
  auto row = [&](const char* name, double estimate, double truth, double sigma, int decimals,
                 bool relative) {
    char label[8];
    std::snprintf(label, sizeof label, "%-3s", name);
    const double error = estimate - truth;
    out << "  " << label << " " << fixed(estimate, decimals) << ", true " << fixed(truth, decimals)
        << ", error " << (error >= 0 ? "+" : "") << fixed(error, decimals);
    if (relative) out << " (" << fixed(100.0 * error / truth, 3) << " %)";
    out << ", " << inSigmas(error, sigma) << "\n";
  };
  row("fx", K(0, 0), true_lens.fx, sd ? sd->fx_px : 0.0, 3, true);
  row("fy", K(1, 1), true_lens.fy, sd ? sd->fy_px : 0.0, 3, true);
  row("cx", K(0, 2), true_lens.cx, sd ? sd->cx_px : 0.0, 3, false);
  row("cy", K(1, 2), true_lens.cy, sd ? sd->cy_px : 0.0, 3, false);
  if (calibration.model == LensModel::kRadtan) {
    const std::vector<std::string> names = distortionNames(calibration.model);
    for (std::size_t i = 0; i < 5 && i < calibration.distortion.size(); ++i) {
      row(names[i].c_str(), calibration.distortion[i], true_lens.distortion[i],
          sd && i < sd->distortion.size() ? sd->distortion[i] : 0.0, 5, false);
    }
  } else {
    out << "  (the fisheye model's coefficients are not the lens's radial-tangential ones)\n";
  }
  return out.str();
}

}  // namespace nadir::calib
