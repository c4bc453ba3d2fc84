#pragma once
// The message bus: LCM behind an interface, so nodes run unchanged on UDP
// multicast, in one process (memq://) or against a log file.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/params.h"
#include "core/stream_gaps.h"

namespace nadir::core {

class BusError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One message as delivered to a handler. The bytes are valid only during the call.
struct RawMessage {
  std::string_view channel;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  // When the bus received it: wall clock for udpm and memq, the event time for a log.
  std::int64_t recv_utime = 0;
};

using RawHandler = std::function<void(const RawMessage&)>;

// Per-channel counters, for health reports.
struct ChannelStats {
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
  std::uint64_t decode_errors = 0;
  // Lost on the way, from the messages' times (core/stream_gaps.h): messages
  // and places, at rate_hz (given by expectRate or learnt; 0 when unknown or
  // irregular, and then nothing is counted).
  std::int64_t missing = 0;
  std::int64_t gaps = 0;
  std::int64_t out_of_order = 0;
  double rate_hz = 0.0;
};

class Bus;

// Keeps a subscription alive; unsubscribes when destroyed. Must not outlive its bus.
class [[nodiscard]] Subscription {
 public:
  Subscription() = default;
  Subscription(Bus* bus, int id) : bus_(bus), id_(id) {}
  Subscription(Subscription&& other) noexcept;
  Subscription& operator=(Subscription&& other) noexcept;
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;
  ~Subscription();

  void unsubscribe();
  bool active() const { return bus_ != nullptr; }

 private:
  Bus* bus_ = nullptr;
  int id_ = -1;
};

class Bus {
 public:
  virtual ~Bus() = default;
  Bus() = default;
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  // The URL this bus was opened with, after defaults were applied.
  virtual std::string url() const = 0;

  // LCM's longest channel name, bytes (LCM_MAX_CHANNEL_NAME_LENGTH).
  static constexpr std::size_t kMaxChannelNameBytes = 63;

  // Sends one encoded message and counts it. event_utime is the message's own
  // time; a log writer stores it as the event timestamp, live transports ignore it.
  // Throws BusError for an empty channel name or one over kMaxChannelNameBytes
  // (every transport: a log's channel would not go onto the network).
  void publish(std::string_view channel, const void* data, std::size_t size,
               std::int64_t event_utime);

  // Calls handler for every message whose channel fully matches channel_regex
  // (LCM's POSIX extended regex semantics).
  Subscription subscribe(const std::string& channel_regex, RawHandler handler);

  // Waits up to timeout for one message and dispatches it to every matching
  // handler. Returns false when nothing arrived (or a log has ended). An
  // exception thrown by a handler is re-raised here, after the dispatch.
  virtual bool handle(std::chrono::milliseconds timeout) = 0;

  // Dispatches what is already waiting without blocking; returns how many messages.
  int handleAvailable();

  // Counters per channel, of every message this bus received.
  std::map<std::string, ChannelStats> stats() const;
  // The rate a channel's sender keeps, in its messages' time, for counting
  // what was lost; a channel not named here has its rate learnt.
  void expectRate(const std::string& channel, double rate_hz);
  // Messages sent through this bus per channel (what a node says it published).
  std::map<std::string, std::int64_t> sent() const;

  // Called by the typed subscribe when bytes do not decode as the expected type.
  void countDecodeError(std::string_view channel);

 protected:
  struct Handler {
    int id;
    std::string channel_regex;
    RawHandler callback;
  };
  // The transport's send of publish().
  virtual void send(std::string_view channel, const void* data, std::size_t size,
                    std::int64_t event_utime) = 0;
  virtual void addSubscription(const Handler& handler) = 0;
  virtual void removeSubscription(int id) = 0;
  void countMessage(std::string_view channel, const void* data, std::size_t size);

 private:
  friend class Subscription;
  int next_id_ = 0;
  mutable std::mutex stats_mutex_;
  // A channel's counters and what it lost (its gaps once a message carried a time).
  struct Channel {
    ChannelStats stats;
    std::optional<StreamGaps> gaps;
  };
  Channel& channel(std::string_view name);  // stats_mutex_ held
  std::map<std::string, Channel, std::less<>> channels_;
  std::map<std::string, double, std::less<>> expected_rates_;
  std::map<std::string, std::int64_t, std::less<>> sent_;
};

// Where a node's bus goes; every node has these under "bus" in its parameters.
struct BusParams {
  std::string url;
  std::int64_t recv_buf_size_bytes = 0;
  // LCM (udpm, memq): messages each subscription may hold while its handler
  // is busy before LCM drops the oldest; LCM's own default is 30, which a
  // camera loses poses at 400 Hz with while it renders a frame.
  int queue_capacity = kDefaultQueueCapacity;
  static constexpr int kDefaultQueueCapacity = 1000;
  // Live node programs publish heartbeat_t here (nadir launch listens).
  std::string heartbeat_channel = "NADIR_HEARTBEAT";

  void visit(ParamVisitor& v);
  // url with defaults applied and, for udpm://, recv_buf_size added when set here.
  std::string resolvedUrl() const;
};

// Opens a bus from a URL:
//   udpm://ADDR:PORT?ttl=N[&recv_buf_size=BYTES]   UDP multicast (LCM)
//   memq://                                         in this process only
//   file://PATH?mode=r[&speed=S] | ?mode=w          an LCM log file (see LogBus)
// An empty URL means $LCM_DEFAULT_URL, else LCM's default udpm URL.
std::unique_ptr<Bus> openBus(const std::string& url);

std::unique_ptr<Bus> openBus(const BusParams& params);

// The URL an empty url resolves to here.
std::string defaultBusUrl();

// A udpm:// URL's ttl (0 when it gives none, as LCM takes it: the messages
// stay on this host); nothing for any other URL or a ttl that is no number.
std::optional<int> udpmTtl(const std::string& url);

// What stats say was lost, for a status line: "nothing lost on 7 channels" or
// "lost CAMERA_DOWN 3 of 1863 (2 gaps), RANGE 1 of 400 (1 gap)". Channels
// without a known rate (irregular, or too few messages yet) and ignore are left out.
std::string describeLosses(const std::map<std::string, ChannelStats>& stats,
                           const std::string& ignore = {});

// Messages dropped because they did not decode as their channel's type (a
// foreign sender, a wrong fingerprint, truncated or random bytes), for a
// status line: "dropped 3 malformed (POSE_TRUTH 2, RANGE 1)", or empty if none.
std::string describeMalformed(const std::map<std::string, ChannelStats>& stats);

// Every channel's messages in one line: "CAMERA_DOWN 1860 at 31.0 Hz, 0 lost;
// VO_COMMAND 2" (no rate: irregular, or too few to learn one), with ", 3
// malformed" where some did not decode.
std::string describeArrivals(const std::map<std::string, ChannelStats>& stats,
                             const std::string& ignore = {});

// Every nadir message starts with int64 utime right after LCM's 8-byte
// fingerprint; this reads it without knowing the type (nothing if too short).
std::optional<std::int64_t> peekUtime(const RawMessage& message);

}  // namespace nadir::core
