#pragma once
// What the fuzz targets share. nadir's readers take paths, so an input is
// written to a file first (in memory where /dev/shm is).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace nadir::fuzz {

// The most samples the dem and imagery targets let a reader give in all the bands
// it reads (an SRTM tile's). Reading costs time in proportion to the samples a
// raster declares (about 0.3 us a sample with the sanitizers and libFuzzer's
// instrumentation) and finds no new path beyond the first blocks, so a few
// hundred bytes declaring millions of samples would stop a target at its hang
// limit without a hang (docs/reliability.md).
inline constexpr std::int64_t kMaxSamplesRead = 1201 * 1201;

// A promise the code under test broke: says which, then aborts (libFuzzer
// keeps the input, the replay test fails).
inline void require(bool condition, const char* promise) {
  if (condition) return;
  std::fprintf(stderr, "broken promise: %s\n", promise);
  std::abort();
}

// The condition, checked and named in the message.
#define NADIR_FUZZ_REQUIRE(condition) ::nadir::fuzz::require((condition), #condition)

// This process's own folder (libFuzzer's -jobs run several processes), removed at exit.
inline const std::filesystem::path& scratchFolder() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path base = std::filesystem::is_directory("/dev/shm")
                                           ? std::filesystem::path("/dev/shm")
                                           : std::filesystem::temp_directory_path();
    std::filesystem::path made = base / ("nadir-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(made);
    std::atexit([] { std::filesystem::remove_all(scratchFolder()); });
    return made;
  }();
  return folder;
}

// Writes bytes to scratchFolder()/name and returns the path.
inline std::string writeInput(const void* data, std::size_t size, const std::string& name) {
  const std::string path = (scratchFolder() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

inline std::string writeInput(std::string_view text, const std::string& name) {
  return writeInput(text.data(), text.size(), name);
}

// The input cut at every separator (an input without one is one part).
inline std::vector<std::string_view> split(const std::uint8_t* data, std::size_t size,
                                           char separator) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> parts;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = text.find(separator, begin);
    parts.push_back(
        text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin));
    if (end == std::string_view::npos) return parts;
    begin = end + 1;
  }
}

}  // namespace nadir::fuzz
