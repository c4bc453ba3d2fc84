#include "core/bus.h"

#include <algorithm>
#include <cstdio>
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
  std::map<std::string, ChannelStats> out;
  for (const auto& [name, entry] : channels_) {
    ChannelStats& stats = out[name] = entry.stats;
    if (!entry.gaps) continue;
    stats.missing = entry.gaps->missing();
    stats.gaps = entry.gaps->gaps();
    stats.out_of_order = entry.gaps->outOfOrder();
    stats.rate_hz = entry.gaps->rateHz();
  }
  return out;
}

void Bus::expectRate(const std::string& channel, double rate_hz) {
  std::lock_guard lock(stats_mutex_);
  expected_rates_[channel] = rate_hz;
  if (auto it = channels_.find(channel); it != channels_.end() && it->second.gaps) {
    it->second.gaps->expectRate(rate_hz);
  }
}

Bus::Channel& Bus::channel(std::string_view name) {
  auto it = channels_.find(name);
  if (it == channels_.end()) it = channels_.emplace(std::string(name), Channel{}).first;
  return it->second;
}

void Bus::publish(std::string_view channel, const void* data, std::size_t size,
                  std::int64_t event_utime) {
  if (channel.empty() || channel.size() > kMaxChannelNameBytes) {
    throw BusError("channel name '" + std::string(channel) + "' is " +
                   std::to_string(channel.size()) + " bytes: LCM's channel names are 1 to " +
                   std::to_string(kMaxChannelNameBytes) + " bytes");
  }
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

void Bus::countMessage(std::string_view channel, const void* data, std::size_t size) {
  const std::optional<std::int64_t> utime =
      peekUtime(RawMessage{channel, static_cast<const std::uint8_t*>(data), size, 0});
  std::lock_guard lock(stats_mutex_);
  Channel& entry = this->channel(channel);
  ++entry.stats.messages;
  entry.stats.bytes += size;
  if (!utime) return;
  if (!entry.gaps) {
    const auto rate = expected_rates_.find(channel);
    entry.gaps.emplace(rate == expected_rates_.end() ? 0.0 : rate->second);
  }
  entry.gaps->add(*utime);
}

void Bus::countDecodeError(std::string_view channel) {
  std::lock_guard lock(stats_mutex_);
  ++this->channel(channel).stats.decode_errors;
}

std::string describeLosses(const std::map<std::string, ChannelStats>& stats,
                           const std::string& ignore) {
  std::string lost;
  int counted = 0;
  for (const auto& [channel, channel_stats] : stats) {
    if (channel == ignore || channel_stats.rate_hz <= 0.0) continue;
    ++counted;
    if (channel_stats.missing == 0) continue;
    lost +=
        (lost.empty() ? "lost " : ", ") + channel + " " + std::to_string(channel_stats.missing) +
        " of " +
        std::to_string(static_cast<std::int64_t>(channel_stats.messages) + channel_stats.missing) +
        " (" + std::to_string(channel_stats.gaps) + (channel_stats.gaps == 1 ? " gap)" : " gaps)");
  }
  if (!lost.empty()) return lost;
  return "nothing lost on " + std::to_string(counted) + (counted == 1 ? " channel" : " channels");
}

std::string describeMalformed(const std::map<std::string, ChannelStats>& stats) {
  std::uint64_t total = 0;
  std::string where;
  for (const auto& [channel, channel_stats] : stats) {
    if (channel_stats.decode_errors == 0) continue;
    total += channel_stats.decode_errors;
    where +=
        (where.empty() ? "" : ", ") + channel + " " + std::to_string(channel_stats.decode_errors);
  }
  if (total == 0) return {};
  return "dropped " + std::to_string(total) + " malformed (" + where + ")";
}

std::string describeArrivals(const std::map<std::string, ChannelStats>& stats,
                             const std::string& ignore) {
  std::string text;
  for (const auto& [channel, channel_stats] : stats) {
    if (channel == ignore) continue;
    if (!text.empty()) text += "; ";
    text += channel + " " + std::to_string(channel_stats.messages);
    if (channel_stats.rate_hz > 0.0) {
      char rate[64];
      std::snprintf(rate, sizeof(rate), " at %.1f Hz, %lld lost", channel_stats.rate_hz,
                    static_cast<long long>(channel_stats.missing));
      text += rate;
    }
    if (channel_stats.decode_errors > 0) {
      text += ", " + std::to_string(channel_stats.decode_errors) + " malformed";
    }
  }
  return text.empty() ? "nothing" : text;
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

std::optional<int> udpmTtl(const std::string& url) {
  if (url.rfind("udpm://", 0) != 0) return std::nullopt;
  const auto query = url.find('?');
  if (query == std::string::npos) return 0;
  std::size_t at = query + 1;
  while (at < url.size()) {
    const auto end = std::min(url.find('&', at), url.size());
    if (url.compare(at, 4, "ttl=") == 0) {
      const std::string value = url.substr(at + 4, end - at - 4);
      if (value.empty() || value.find_first_not_of("0123456789") != std::string::npos ||
          value.size() > 3) {
        return std::nullopt;
      }
      return std::stoi(value);
    }
    at = end + 1;
  }
  return 0;
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
