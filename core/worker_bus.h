#pragma once
// A node on its own thread in a process that runs many (`nadir run`), with
// the same results whatever the threads' timing (docs/architecture.md):
//
// - the node's handlers run on a worker thread, one message at a time, in
//   the order the messages came on the bus below;
// - what the node publishes from its handlers is held, and published on the
//   bus below only at a sync point, from the thread that handles that bus;
// - a message on a paced channel (a camera's frames) is a sync point: before
//   the node is given it, everything given before has been handled and what
//   that published is on the bus below. sync() is one too.
//
// So while the node works on frame N, the rest of the process goes on (the
// camera renders frame N+1), and the node's outputs for frame N reach the
// others at a fixed place in the message sequence: with frame N+1.

#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "core/bus.h"

namespace nadir::core {

class WorkerBus final : public Bus {
 public:
  // Subscribe and unsubscribe through this from the thread that handles bus
  // (the node's constructor and destructor); paced_channels are exact channel
  // names. What the node published that no sync point sent is dropped with it.
  WorkerBus(Bus& bus, std::set<std::string> paced_channels);
  ~WorkerBus() override;

  // Waits until the node has handled every message given to it, then
  // publishes on the bus below what it published meanwhile. Rethrows the
  // first exception a handler threw.
  void sync();

  std::string url() const override;
  // The node's messages come from the bus below: nothing to handle here.
  bool handle(std::chrono::milliseconds timeout) override;

 private:
  struct Message {
    std::shared_ptr<const RawHandler> handler;
    std::string channel;
    std::vector<std::uint8_t> bytes;
    std::int64_t recv_utime = 0;
  };
  struct Outgoing {
    std::string channel;
    std::vector<std::uint8_t> bytes;
    std::int64_t event_utime = 0;
  };
  void send(std::string_view channel, const void* data, std::size_t size,
            std::int64_t event_utime) override;
  void addSubscription(const Handler& handler) override;
  void removeSubscription(int id) override;
  void give(const std::shared_ptr<const RawHandler>& handler, const RawMessage& raw);
  void waitIdle();
  void work();

  Bus& bus_;
  const std::set<std::string, std::less<>> paced_channels_;
  const std::thread::id owner_;
  std::unordered_map<int, Subscription> subscriptions_;  // on bus_, by this bus's id

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Message> queue_;
  bool busy_ = false;
  bool stopping_ = false;
  std::vector<Outgoing> outbox_;
  bool failed_ = false;
  std::exception_ptr failure_;  // the first failure, until sync() rethrows it
  std::thread worker_;
};

}  // namespace nadir::core
