#include "core/lcm_bus.h"

#include <lcm/lcm.h>

#include <cerrno>
#include <string>
#include <utility>

namespace nadir::core {
namespace {
constexpr int kCounterQueueFactor = 100;
}  // namespace

struct LcmBus::Entry {
  LcmBus* bus;
  RawHandler callback;
  lcm_subscription_t* subscription = nullptr;
};

LcmBus::LcmBus(const std::string& url, int queue_capacity)
    : url_(url), queue_capacity_(queue_capacity) {
  lcm_ = lcm_create(url_.c_str());
  if (lcm_ == nullptr) {
    throw BusError("cannot open LCM URL '" + url_ +
                   "' (for udpm://, a multicast route is needed: run `nadir doctor`)");
  }
  counter_ = lcm_subscribe(lcm_, ".*", &LcmBus::onAnyMessage, this);
  // The counter queues every channel's messages, a node's subscription one
  // channel's: with the same capacity it would drop first while the node
  // lags and count losses the node never had.
  lcm_subscription_set_queue_capacity(counter_, kCounterQueueFactor * queue_capacity_);
}

LcmBus::~LcmBus() {
  for (auto& [id, entry] : entries_) lcm_unsubscribe(lcm_, entry->subscription);
  lcm_unsubscribe(lcm_, counter_);
  lcm_destroy(lcm_);
}

void LcmBus::send(std::string_view channel, const void* data, std::size_t size,
                  std::int64_t /*event_utime*/) {
  const std::string name(channel);
  if (lcm_publish(lcm_, name.c_str(), data, static_cast<unsigned int>(size)) != 0) {
    throw BusError("LCM could not publish " + std::to_string(size) + " bytes on '" + name +
                   "' over " + url_);
  }
}

bool LcmBus::handle(std::chrono::milliseconds timeout) {
  const int status = lcm_handle_timeout(lcm_, static_cast<int>(timeout.count()));
  if (pending_) std::rethrow_exception(std::exchange(pending_, nullptr));
  // A signal (Ctrl-C) interrupting the wait is not a failure: nothing arrived.
  if (status < 0 && errno == EINTR) return false;
  if (status < 0) throw BusError("LCM failed while waiting for messages on " + url_);
  return status > 0;
}

void LcmBus::addSubscription(const Handler& handler) {
  auto entry = std::make_unique<Entry>(Entry{this, handler.callback});
  entry->subscription =
      lcm_subscribe(lcm_, handler.channel_regex.c_str(), &LcmBus::onMessage, entry.get());
  if (entry->subscription == nullptr) {
    throw BusError("LCM refused the subscription to '" + handler.channel_regex + "'");
  }
  lcm_subscription_set_queue_capacity(entry->subscription, queue_capacity_);
  entries_.emplace(handler.id, std::move(entry));
}

void LcmBus::removeSubscription(int id) {
  const auto it = entries_.find(id);
  if (it == entries_.end()) return;
  lcm_unsubscribe(lcm_, it->second->subscription);
  entries_.erase(it);
}

// Exceptions must not cross LCM's C frames: keep the first, re-raise it from handle().
void LcmBus::onMessage(const lcm_recv_buf_t* buffer, const char* channel, void* user) {
  auto* entry = static_cast<Entry*>(user);
  if (entry->bus->pending_) return;
  try {
    entry->callback(RawMessage{channel, static_cast<const std::uint8_t*>(buffer->data),
                               buffer->data_size, buffer->recv_utime});
  } catch (...) {
    entry->bus->pending_ = std::current_exception();
  }
}

void LcmBus::onAnyMessage(const lcm_recv_buf_t* buffer, const char* channel, void* user) {
  static_cast<LcmBus*>(user)->countMessage(channel, buffer->data, buffer->data_size);
}

}  // namespace nadir::core
