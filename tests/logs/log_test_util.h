#pragma once
// Synthetic LCM logs for the logs/ tests: events whose payload starts with an
// 8-byte fingerprint and a big-endian int64 utime, as every nadir message does.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/lcm_log.h"

namespace nadir::logs::test {

inline std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_logs_" + name;
}

struct Event {
  std::int64_t timestamp_utime = 0;
  std::string channel;
  std::vector<std::uint8_t> data;
};

// size bytes: 8 fingerprint bytes, message_utime (big-endian), then a counter
// pattern. Sizes under 16 carry no utime and are only the pattern.
inline std::vector<std::uint8_t> payload(std::size_t size, std::int64_t message_utime) {
  std::vector<std::uint8_t> data(size);
  for (std::size_t i = 0; i < size; ++i) data[i] = static_cast<std::uint8_t>(i * 7 + 3);
  if (size >= 16) {
    for (std::size_t i = 0; i < 8; ++i) data[i] = 0x11;
    auto value = static_cast<std::uint64_t>(message_utime);
    for (int i = 15; i >= 8; --i) {
      data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(value & 0xFF);
      value >>= 8;
    }
  }
  return data;
}

inline void writeLog(const std::string& path, const std::vector<Event>& events) {
  core::LcmLogWriter writer(path);
  for (const Event& e : events)
    writer.write(e.timestamp_utime, e.channel, e.data.data(), e.data.size());
}

// Byte offset where each event starts (header 28 bytes, channel, data), and
// the file size as the last entry.
inline std::vector<std::int64_t> eventOffsets(const std::vector<Event>& events) {
  std::vector<std::int64_t> offsets;
  std::int64_t at = 0;
  for (const Event& e : events) {
    offsets.push_back(at);
    at += 28 + static_cast<std::int64_t>(e.channel.size() + e.data.size());
  }
  offsets.push_back(at);
  return offsets;
}

inline std::vector<std::uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

inline void writeBytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

}  // namespace nadir::logs::test
