// nadir-bench-image-codecs: what a recorded run's camera frames cost in each
// image codec, and what they lose: bytes per frame, the log they would make,
// encode and decode time per frame on one thread, and the pixels' error.
// JPEG goes through nadir's image_t codec as the camera sends it
// (camera.jpeg_quality); PNG and WebP lossless are measured beside it for the
// choice, image_t carrying raw or JPEG pixels only.
//
//   nadir run thesis-oscillating --out out/thesis          (raw frames)
//   nadir-bench-image-codecs out/thesis [--frames 24] [--jpeg 95,90,80,75]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/command_line.h"
#include "core/lcm_log.h"
#include "lcmtypes/codec.h"

namespace {

using nadir::msg::Bytes;

struct ChannelBytes {
  std::int64_t data_bytes = 0;
  std::vector<std::int64_t> image_offsets;  // image_t events, file order
  bool jpeg = false;                        // any of them JPEG
};

struct Codec {
  std::string name;
  std::function<Bytes(const nadir::msg::Image&)> encode;
  // The pixels back, of the frame's type (CV_8UC1 or CV_8UC3).
  std::function<cv::Mat(const Bytes&, int type)> decode;
};

struct CodecFigures {
  double bytes_per_frame = 0.0;
  double encode_ms = 0.0;  // median
  double decode_ms = 0.0;  // median
  double max_abs_diff = 0.0;
  double rms_diff = 0.0;
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

CodecFigures measure(const Codec& codec, const std::vector<nadir::msg::Image>& frames) {
  CodecFigures figures;
  std::vector<double> encode_ms;
  std::vector<double> decode_ms;
  double sum_squared_diff = 0.0;
  double pixels = 0.0;
  for (const nadir::msg::Image& frame : frames) {
    const auto encode_start = std::chrono::steady_clock::now();
    const Bytes bytes = codec.encode(frame);
    encode_ms.push_back(msSince(encode_start));
    const auto decode_start = std::chrono::steady_clock::now();
    const cv::Mat back = codec.decode(bytes, frame.pixels.type());
    decode_ms.push_back(msSince(decode_start));
    if (back.size() != frame.pixels.size() || back.type() != frame.pixels.type())
      throw std::runtime_error(codec.name + " did not give the frame's size and type back");
    figures.bytes_per_frame += static_cast<double>(bytes.size());
    figures.max_abs_diff =
        std::max(figures.max_abs_diff, cv::norm(frame.pixels, back, cv::NORM_INF));
    const double l2 = cv::norm(frame.pixels, back, cv::NORM_L2);
    sum_squared_diff += l2 * l2;
    pixels += static_cast<double>(frame.pixels.total() * frame.pixels.channels());
  }
  figures.bytes_per_frame /= static_cast<double>(frames.size());
  figures.encode_ms = median(encode_ms);
  figures.decode_ms = median(decode_ms);
  figures.rms_diff = std::sqrt(sum_squared_diff / pixels);
  return figures;
}

std::vector<Codec> codecsToMeasure(const std::vector<int>& jpeg_qualities, bool lossless) {
  const auto image_t = [](int quality) {
    return [quality](const nadir::msg::Image& frame) {
      nadir::msg::Image copy = frame;
      copy.jpeg_quality = quality;
      return nadir::msg::encode(copy);
    };
  };
  const auto image_t_pixels = [](const Bytes& bytes, int) {
    return nadir::msg::decode<nadir::msg::Image>(bytes).pixels;
  };
  std::vector<Codec> codecs{{"raw image_t", image_t(0), image_t_pixels}};
  for (const int quality : jpeg_qualities) {
    codecs.push_back(
        {"JPEG " + std::to_string(quality) + " image_t", image_t(quality), image_t_pixels});
  }
  if (!lossless) return codecs;
  const auto opencv = [](std::string extension, std::vector<int> params) {
    return [extension = std::move(extension),
            params = std::move(params)](const nadir::msg::Image& frame) {
      std::vector<std::uint8_t> bytes;
      if (!cv::imencode(extension, frame.pixels, bytes, params))
        throw std::runtime_error("OpenCV could not encode " + extension);
      return bytes;
    };
  };
  // WebP holds colour only: a gray frame comes back as gray from its three equal channels.
  const auto opencv_pixels = [](const Bytes& bytes, int type) {
    return cv::imdecode(bytes, type == CV_8UC1 ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
  };
  codecs.push_back(
      {"PNG 1 (lossless)", opencv(".png", {cv::IMWRITE_PNG_COMPRESSION, 1}), opencv_pixels});
  codecs.push_back(
      {"PNG 9 (lossless)", opencv(".png", {cv::IMWRITE_PNG_COMPRESSION, 9}), opencv_pixels});
  if (cv::haveImageWriter(".webp")) {
    codecs.push_back(
        {"WebP (lossless)", opencv(".webp", {cv::IMWRITE_WEBP_QUALITY, 101}), opencv_pixels});
  } else {
    std::cout << "(this OpenCV writes no WebP: its row is left out)\n";
  }
  return codecs;
}

std::string megabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f MB", bytes / 1e6);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The camera frames of a recorded run in each image codec: bytes per frame, the log they "
      "would make, encode and decode time per frame on one thread, and the pixels' error"};
  std::string input;
  std::string channel;
  int frame_count = 24;
  std::vector<int> jpeg_qualities{95, 90, 85, 80, 75, 70};
  bool lossless = true;
  app.add_option("RUN", input, "a run's folder (its run.lcmlog) or an LCM log")->required();
  app.add_option("--channel", channel,
                 "the image channel (default: the one with the most image bytes)");
  app.add_option("--frames", frame_count, "frames to measure, spread evenly over the log")
      ->check(CLI::Range(1, 100000));
  app.add_option("--jpeg", jpeg_qualities, "JPEG qualities to measure (1-100)")
      ->delimiter(',')
      ->check(CLI::Range(1, 100));
  app.add_flag("!--no-lossless", lossless, "leave out PNG and WebP lossless (slow to encode)");
  if (const auto status = nadir::core::parseCommandLine(app, argc, argv)) return *status;
  cv::setNumThreads(1);

  try {
    const std::filesystem::path log_path = std::filesystem::is_directory(input)
                                               ? std::filesystem::path(input) / "run.lcmlog"
                                               : std::filesystem::path(input);
    nadir::core::LcmLogReader reader(log_path.string());
    std::map<std::string, ChannelBytes> channels;
    while (auto event = reader.next()) {
      ChannelBytes& entry = channels[event->channel];
      entry.data_bytes += static_cast<std::int64_t>(event->data.size());
      if (nadir::msg::isType<nadir::msg::Image>(event->data.data(), event->data.size())) {
        entry.image_offsets.push_back(event->offset);
        entry.jpeg = entry.jpeg || nadir::msg::isJpegImage(event->data.data(), event->data.size());
      }
    }
    if (channel.empty()) {
      std::int64_t most = 0;
      for (const auto& [name, entry] : channels) {
        if (!entry.image_offsets.empty() && entry.data_bytes > most) {
          most = entry.data_bytes;
          channel = name;
        }
      }
      if (channel.empty()) throw std::runtime_error(log_path.string() + " holds no images");
    }
    const auto found = channels.find(channel);
    if (found == channels.end() || found->second.image_offsets.empty())
      throw std::runtime_error(log_path.string() + " has no images on " + channel);
    const ChannelBytes& camera = found->second;

    const auto available = static_cast<std::int64_t>(camera.image_offsets.size());
    const std::int64_t measured = std::min<std::int64_t>(frame_count, available);
    std::vector<nadir::msg::Image> frames;
    for (std::int64_t i = 0; i < measured; ++i) {
      reader.seek(
          camera.image_offsets[static_cast<std::size_t>((2 * i + 1) * available / (2 * measured))]);
      const auto event = reader.next();
      if (!event) throw std::runtime_error(log_path.string() + " ended while reading a frame");
      frames.push_back(nadir::msg::decode<nadir::msg::Image>(event->data));
    }

    const std::int64_t file_bytes = reader.fileSize();
    const cv::Mat& first = frames.front().pixels;
    std::cout << log_path.string() << ": " << megabytes(static_cast<double>(file_bytes)) << "; "
              << channel << ": " << available << " frames of " << first.cols << "x" << first.rows
              << (first.channels() == 1 ? " gray" : " RGB") << ", "
              << megabytes(static_cast<double>(camera.data_bytes)) << ", " << measured
              << " measured, spread evenly\n";
    if (camera.jpeg) {
      std::cout << "(the log's frames are JPEG: every row re-encodes their decoded pixels, and "
                   "the error is against those)\n";
    }
    std::cout << "\ncodec                  bytes/frame  ratio  log        encode ms  decode ms  "
                 "max |diff|  RMS diff\n";
    double raw_bytes_per_frame = 0.0;
    for (const Codec& codec : codecsToMeasure(jpeg_qualities, lossless)) {
      const CodecFigures figures = measure(codec, frames);
      if (raw_bytes_per_frame == 0.0) raw_bytes_per_frame = figures.bytes_per_frame;
      // The other channels and the events' headers stay; the frames change.
      const double log_bytes = static_cast<double>(file_bytes - camera.data_bytes) +
                               figures.bytes_per_frame * static_cast<double>(available);
      std::printf("%-22s %8.1f kB  %5.2f  %-9s  %9.2f  %9.2f  %10.0f  %8.2f\n", codec.name.c_str(),
                  figures.bytes_per_frame / 1e3, raw_bytes_per_frame / figures.bytes_per_frame,
                  megabytes(log_bytes).c_str(), figures.encode_ms, figures.decode_ms,
                  figures.max_abs_diff, figures.rms_diff);
    }
    std::cout << "\nlog: the file with these frames in place of its own. diff: counts.\n";
  } catch (const std::exception& error) {
    std::cerr << "nadir-bench-image-codecs: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
