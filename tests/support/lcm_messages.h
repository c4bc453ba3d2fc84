#pragma once
// Generated LCM types on a bus or in bytes, for tests that build messages field by
// field (a malformed one, a foreign system's). The project itself goes through
// lcmtypes/codec.h.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/bus.h"

namespace nadir::test {

template <class Msg>
std::vector<std::uint8_t> encodeMessage(const Msg& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  if (msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0) {
    throw std::logic_error(std::string("cannot encode ") + Msg::getTypeName());
  }
  return bytes;
}

// True if the bytes are a whole Msg.
template <class Msg>
bool decodeMessage(const void* data, std::size_t size, Msg& msg) {
  return msg.decode(data, 0, static_cast<int>(size)) == static_cast<int>(size);
}

template <class Msg>
void publish(core::Bus& bus, std::string_view channel, const Msg& msg) {
  const std::vector<std::uint8_t> bytes = encodeMessage(msg);
  bus.publish(channel, bytes.data(), bytes.size(), msg.utime);
}

}  // namespace nadir::test
