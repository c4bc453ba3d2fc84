#include "core/worker_bus.h"

#include <utility>

#include "core/stage_times.h"

namespace nadir::core {

WorkerBus::WorkerBus(Bus& bus, std::set<std::string> paced_channels)
    : bus_(bus),
      paced_channels_(paced_channels.begin(), paced_channels.end()),
      owner_(std::this_thread::get_id()) {
  worker_ = std::thread([this] { work(); });
}

WorkerBus::~WorkerBus() {
  // No more messages for the node: its subscriptions on the bus below go first.
  subscriptions_.clear();
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

std::string WorkerBus::url() const { return bus_.url(); }

bool WorkerBus::handle(std::chrono::milliseconds /*timeout*/) { return false; }

void WorkerBus::addSubscription(const Handler& handler) {
  if (std::this_thread::get_id() != owner_) {
    throw BusError("a node on a worker bus subscribes to '" + handler.channel_regex +
                   "' from its handler: subscribe in its constructor");
  }
  auto callback = std::make_shared<const RawHandler>(handler.callback);
  subscriptions_.emplace(
      handler.id, bus_.subscribe(handler.channel_regex,
                                 [this, callback](const RawMessage& raw) { give(callback, raw); }));
}

void WorkerBus::removeSubscription(int id) {
  if (std::this_thread::get_id() != owner_) {
    throw BusError(
        "a node on a worker bus unsubscribes from its handler: keep its "
        "subscriptions for its life");
  }
  // The handler may be running: wait for it before the node goes.
  waitIdle();
  subscriptions_.erase(id);
}

void WorkerBus::send(std::string_view channel, const void* data, std::size_t size,
                     std::int64_t event_utime) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  if (std::this_thread::get_id() == owner_) {
    bus_.publish(channel, data, size, event_utime);
    return;
  }
  const std::lock_guard lock(mutex_);
  outbox_.push_back(
      {std::string(channel), std::vector<std::uint8_t>(bytes, bytes + size), event_utime});
}

void WorkerBus::give(const std::shared_ptr<const RawHandler>& handler, const RawMessage& raw) {
  if (paced_channels_.find(raw.channel) != paced_channels_.end()) sync();
  {
    const std::lock_guard lock(mutex_);
    queue_.push_back({handler, std::string(raw.channel),
                      std::vector<std::uint8_t>(raw.data, raw.data + raw.size), raw.recv_utime});
  }
  changed_.notify_all();
}

void WorkerBus::waitIdle() {
  const ScopedStage stage("wait for a node");
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

void WorkerBus::sync() {
  waitIdle();
  std::vector<Outgoing> outgoing;
  std::exception_ptr failure;
  {
    const std::lock_guard lock(mutex_);
    outgoing.swap(outbox_);
    failure = std::exchange(failure_, nullptr);
  }
  // The node that failed stays failed: what comes after is dropped (work()).
  if (failure) std::rethrow_exception(failure);
  for (const Outgoing& message : outgoing)
    bus_.publish(message.channel, message.bytes.data(), message.bytes.size(), message.event_utime);
}

void WorkerBus::work() {
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    Message message = std::move(queue_.front());
    queue_.pop_front();
    // After a handler threw, the node is in no state to go on: the rest is dropped.
    const bool failed = failed_;
    busy_ = true;
    lock.unlock();
    std::exception_ptr failure;
    try {
      if (!failed) {
        (*message.handler)(RawMessage{message.channel, message.bytes.data(), message.bytes.size(),
                                      message.recv_utime});
      }
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    if (failure && !failed_) {
      failed_ = true;
      failure_ = failure;
    }
    busy_ = false;
    changed_.notify_all();
  }
}

}  // namespace nadir::core
