#pragma once
// Messages on a bus as plain structs: publish encodes with the codec, subscribe
// decodes. A node's adapter uses these and never the generated types.

#include <functional>
#include <string>
#include <string_view>

#include "core/bus.h"
#include "core/stage_times.h"
#include "lcmtypes/codec.h"

namespace nadir::msg {

// The stage names of a type's encoding and decoding (core/stage_times.h).
template <class T>
std::string_view encodeStageName() {
  static const std::string name = std::string("encode ") + typeNameOf<T>();
  return name;
}
template <class T>
std::string_view decodeStageName() {
  static const std::string name = std::string("decode ") + typeNameOf<T>();
  return name;
}

template <class T>
void publish(core::Bus& bus, std::string_view channel, const T& message) {
  Bytes bytes;
  {
    const core::ScopedStage stage(encodeStageName<T>());
    bytes = encode(message);
  }
  const core::ScopedStage stage("send");
  bus.publish(channel, bytes.data(), bytes.size(), message.utime);
}

// Why a message was dropped, for a node that counts its drops.
using InvalidHandler = std::function<void(const std::string& reason)>;

// Calls on_message with each message on channel_regex that decodes as T. Bytes
// that are not a T are counted in the bus's decode errors; a T with values it
// does not allow goes to on_invalid with the reason when one is given, and is
// counted likewise when not.
template <class T>
core::Subscription subscribe(core::Bus& bus, const std::string& channel_regex,
                             std::function<void(const T&)> on_message,
                             InvalidHandler on_invalid = {}) {
  return bus.subscribe(channel_regex,
                       [&bus, on_message = std::move(on_message),
                        on_invalid = std::move(on_invalid)](const core::RawMessage& raw) {
                         T message;
                         try {
                           const core::ScopedStage stage(decodeStageName<T>());
                           message = decode<T>(raw.data, raw.size);
                         } catch (const DecodeError&) {
                           bus.countDecodeError(raw.channel);
                           return;
                         } catch (const InvalidMessage& error) {
                           if (on_invalid) {
                             on_invalid(error.what());
                           } else {
                             bus.countDecodeError(raw.channel);
                           }
                           return;
                         }
                         on_message(message);
                       });
}

}  // namespace nadir::msg
