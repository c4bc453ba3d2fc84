#pragma once
// A progress line on stderr for the verbs that read or write big files (log
// info, log cut, eval, export): shown only when stderr is a terminal, redrawn
// at most four times a second, cleared when it goes. stdout keeps the results.
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>
#include <utility>

#include "core/lcm_log.h"

namespace nadir::cli {

class ProgressLine {
 public:
  explicit ProgressLine(std::string label)
      : label_(std::move(label)), terminal_(isatty(STDERR_FILENO) != 0) {}
  ~ProgressLine() {
    if (shown_) std::cerr << "\r\033[K" << std::flush;
  }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // "LABEL: 1.25 of 5.30 GB (23 %)"
  void bytes(std::int64_t done, std::int64_t total) {
    if (!due(done == total)) return;
    char text[96];
    std::snprintf(
        text, sizeof(text), ": %.2f of %.2f GB (%.0f %%)", done / 1e9, total / 1e9,
        total > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0);
    draw(text);
  }
  // "LABEL: 120 of 400 images"
  void count(std::int64_t done, std::int64_t total, const std::string& things) {
    if (!due(done == total)) return;
    draw(": " + std::to_string(done) + " of " + std::to_string(total) + " " + things);
  }
  // For a log reader (core::LcmLogReader::onProgress); lives as long as this line.
  core::ReadProgress reading() {
    return [this](std::int64_t done, std::int64_t total) { bytes(done, total); };
  }

 private:
  bool due(bool last) {
    if (!terminal_) return false;
    const auto now = std::chrono::steady_clock::now();
    if (!last && shown_ && now - last_drawn_ < std::chrono::milliseconds(250)) return false;
    last_drawn_ = now;
    return true;
  }
  void draw(const std::string& text) {
    std::cerr << "\r\033[K" << label_ << text << std::flush;
    shown_ = true;
  }

  std::string label_;
  bool terminal_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_drawn_{};
};

}  // namespace nadir::cli
