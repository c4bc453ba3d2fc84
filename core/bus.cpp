#include "core/bus.h"

#include <cstdlib>
#include <utility>

#include "core/lcm_bus.h"
#include "core/log_bus.h"

namespace nadir::core {

Subscription::Subscription(Subscription&& other) noexcept
    : bus_(std::exchange(other.bus_, nullptr)), id_(other.id_) {}

Subscription& Subscription::operator=(Subscription&& other) noexcept {
  if (this != &other) {
    unsubscribe();
    bus_ = std::exchange(other.bus_, nullptr);
    id_ = other.id_;
  }
  return *this;
}

Subscription::~Subscription() { unsubscribe(); }

void Subscription::unsubscribe() {
  if (bus_ != nullptr) {
    bus_->removeSubscription(id_);
    bus_ = nullptr;
  }
}

Subscription Bus::subscribe(const std::string& channel_regex, RawHandler handler) {
  if (!handler) throw BusError("subscribe to '" + channel_regex + "' with an empty handler");
  const int id = next_id_++;
  addSubscription(Handler{id, channel_regex, std::move(handler)});
  return Subscription(this, id);
}

int Bus::handleAvailable() {
  int count = 0;
  while (handle(std::chrono::milliseconds(0))) ++count;
  return count;
}

std::map<std::string, ChannelStats> Bus::stats() const {
  std::lock_guard lock(stats_mutex_);
  return {stats_.begin(), stats_.end()};
}

void Bus::publish(std::string_view channel, const void* data, std::size_t size,
                  std::int64_t event_utime) {
  send(channel, data, size, event_utime);
  std::lock_guard lock(stats_mutex_);
  auto it = sent_.find(channel);
  if (it == sent_.end()) it = sent_.emplace(std::string(channel), 0).first;
  ++it->second;
}

std::map<std::string, std::int64_t> Bus::sent() const {
  std::lock_guard lock(stats_mutex_);
  return {sent_.begin(), sent_.end()};
}

void Bus::countMessage(std::string_view channel, std::size_t size) {
  std::lock_guard lock(stats_mutex_);
  auto it = stats_.find(channel);
  if (it == stats_.end()) it = stats_.emplace(std::string(channel), ChannelStats{}).first;
  ++it->second.messages;
  it->second.bytes += size;
}

void Bus::countDecodeError(std::string_view channel) {
  std::lock_guard lock(stats_mutex_);
  auto it = stats_.find(channel);
  if (it == stats_.end()) it = stats_.emplace(std::string(channel), ChannelStats{}).first;
  ++it->second.decode_errors;
}

std::optional<std::int64_t> peekUtime(const RawMessage& message) {
  constexpr std::size_t kFingerprintBytes = 8;
  if (message.size < kFingerprintBytes + 8) return std::nullopt;
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < 8; ++i) value = (value << 8) | message.data[kFingerprintBytes + i];
  return static_cast<std::int64_t>(value);
}

std::string defaultBusUrl() {
  const char* env = std::getenv("LCM_DEFAULT_URL");
  if (env != nullptr && *env != '\0') return env;
  return "udpm://239.255.76.67:7667?ttl=0";
}

void BusParams::visit(ParamVisitor& v) {
  v.field("url", &url,
          {.doc = "LCM URL: udpm://ADDR:PORT?ttl=N, memq://, file://PATH?mode=r|w; "
                  "empty uses LCM_DEFAULT_URL"});
  v.field("recv_buf_size_bytes", &recv_buf_size_bytes,
          {.doc = "udpm receive buffer, bytes (capped by net.core.rmem_max); 0 uses "
                  "net.core.rmem_default",
           .min = 0,
           .max = 2147483647});
  v.field("queue_capacity", &queue_capacity,
          {.doc = "messages a subscription holds while its handler is busy before the oldest "
                  "is dropped (udpm, memq)",
           .min = 1,
           .max = 1000000});
  v.field("heartbeat_channel", &heartbeat_channel,
          {.doc = "where each live node says, once a second, that it is up (heartbeat_t)"});
}

std::string BusParams::resolvedUrl() const {
  std::string resolved = url.empty() ? defaultBusUrl() : url;
  if (recv_buf_size_bytes > 0 && resolved.starts_with("udpm://") &&
      resolved.find("recv_buf_size=") == std::string::npos) {
    resolved += resolved.find('?') == std::string::npos ? "?" : "&";
    resolved += "recv_buf_size=" + std::to_string(recv_buf_size_bytes);
  }
  return resolved;
}

std::unique_ptr<Bus> openBus(const BusParams& params) {
  const std::string resolved = params.resolvedUrl();
  if (resolved.starts_with("file://")) {
    return std::make_unique<LogBus>(LogBusOptions::fromUrl(resolved));
  }
  return std::make_unique<LcmBus>(resolved, params.queue_capacity);
}

std::unique_ptr<Bus> openBus(const std::string& url) {
  BusParams params;
  params.url = url;
  return openBus(params);
}

}  // namespace nadir::core
