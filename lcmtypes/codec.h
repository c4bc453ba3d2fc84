#pragma once
// One codec per message type: the plain structs of lcmtypes/messages.h and
// lcmtypes/image.h to LCM bytes and back. The only code that knows the
// generated nadir/*.hpp types is behind these functions.
//
// decode<T>() throws DecodeError when the bytes are not a whole T (another
// type, truncated) and InvalidMessage when they are, but hold values T does not
// allow (a non-finite position, a quaternion that is not a rotation, an image
// whose sizes disagree); both messages name the type, utime and field.
// Quaternions come back normalised (core::quaternionFromWire).

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "lcmtypes/image.h"
#include "lcmtypes/messages.h"

namespace nadir::msg {

class DecodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InvalidMessage : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

using Bytes = std::vector<std::uint8_t>;

Bytes encode(const Pose& message);
Bytes encode(const Imu& message);
Bytes encode(const Range& message);
Bytes encode(const Gps& message);
Bytes encode(const Baro& message);
Bytes encode(const Magnetometer& message);
Bytes encode(const GeodeticPosition& message);
Bytes encode(const Attitude& message);
Bytes encode(const Velocity& message);
Bytes encode(const BodyRates& message);
Bytes encode(const CameraInfo& message);
// Raw GRAY or RGB pixels, or MJPEG when message.jpeg_quality > 0.
Bytes encode(const Image& message);
Bytes encode(const VoEstimate& message);
Bytes encode(const NavState& message);
Bytes encode(const PpaOdometry& message);
Bytes encode(const TargetDetection& message);
Bytes encode(const VoCommand& message);
Bytes encode(const GatePattern& message);
Bytes encode(const DriveCommand& message);
Bytes encode(const WaypointReached& message);
Bytes encode(const Heartbeat& message);
Bytes encode(const BusCheck& message);

template <class T>
T decode(const void* data, std::size_t size);

template <class T>
T decode(const Bytes& bytes) {
  return decode<T>(bytes.data(), bytes.size());
}

// True when the bytes carry T's LCM fingerprint (they may still not decode).
template <class T>
bool isType(const void* data, std::size_t size);

// True when the bytes are an image_t whose pixels are JPEG (MJPEG), read from
// its header without decoding the pixels.
bool isJpegImage(const void* data, std::size_t size);

// The LCM type name the fingerprint says ("pose_t"), or empty for none of nadir's.
std::string typeName(const void* data, std::size_t size);

// The LCM type name of T ("pose_t").
template <class T>
const char* typeNameOf();

}  // namespace nadir::msg
