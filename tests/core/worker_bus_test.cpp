// A node on a worker bus: its handlers run on another thread in the order the
// messages came, and what it publishes reaches the bus below at the sync
// points only (a paced message, sync()), so the message sequence on the bus
// below is the same however long the handlers take.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/bus.h"
#include "core/worker_bus.h"

namespace nadir::core {
namespace {

void publishText(Bus& bus, const std::string& channel, const std::string& text) {
  bus.publish(channel, text.data(), text.size(), 0);
}

std::string textOf(const RawMessage& raw) {
  return std::string(reinterpret_cast<const char*>(raw.data), raw.size);
}

// Runs IN a, FRAME 1, IN b, IN c, FRAME 2 past a node that answers each on
// OUT, its handlers taking 0-3 ms drawn from seed; returns what the bus below
// carried, in order.
std::vector<std::string> sequenceWithHandlerDelays(unsigned seed) {
  auto bus = openBus("memq://");
  std::vector<std::string> carried;
  Subscription recorder = bus->subscribe(".*", [&](const RawMessage& raw) {
    carried.push_back(std::string(raw.channel) + " " + textOf(raw));
  });
  WorkerBus worker(*bus, {"FRAME"});
  std::mt19937 random(seed);
  std::vector<int> delays_ms;
  for (int i = 0; i < 5; ++i) delays_ms.push_back(static_cast<int>(random() % 4));
  std::size_t handled = 0;
  Subscription node = worker.subscribe("IN|FRAME", [&](const RawMessage& raw) {
    std::this_thread::sleep_for(std::chrono::milliseconds(delays_ms[handled++ % 5]));
    publishText(worker, "OUT", "after " + textOf(raw));
  });
  const auto deliver = [&] {
    while (bus->handle(std::chrono::milliseconds(0))) {
    }
  };
  for (const auto& [channel, text] : std::vector<std::pair<std::string, std::string>>{
           {"IN", "a"}, {"FRAME", "1"}, {"IN", "b"}, {"IN", "c"}, {"FRAME", "2"}}) {
    publishText(*bus, channel, text);
    deliver();
  }
  worker.sync();
  deliver();
  return carried;
}

TEST(WorkerBus, OutputsReachTheBusAtTheSyncPointsWhateverTheHandlersTake) {
  // Worked out from the rules: IN a's answer goes out when FRAME 1 comes;
  // FRAME 1's, IN b's and IN c's when FRAME 2 comes; FRAME 2's at sync().
  const std::vector<std::string> expected = {
      "IN a",    "FRAME 1",     "OUT after a", "IN b",        "IN c",
      "FRAME 2", "OUT after 1", "OUT after b", "OUT after c", "OUT after 2"};
  for (unsigned seed : {1u, 2u, 3u}) EXPECT_EQ(sequenceWithHandlerDelays(seed), expected) << seed;
}

TEST(WorkerBus, HandlersRunOnTheWorkerThread) {
  auto bus = openBus("memq://");
  WorkerBus worker(*bus, {});
  std::thread::id handler_thread;
  Subscription node = worker.subscribe(
      "IN", [&](const RawMessage&) { handler_thread = std::this_thread::get_id(); });
  publishText(*bus, "IN", "x");
  while (bus->handle(std::chrono::milliseconds(0))) {
  }
  worker.sync();
  EXPECT_NE(handler_thread, std::thread::id());
  EXPECT_NE(handler_thread, std::this_thread::get_id());
}

TEST(WorkerBus, AHandlersExceptionIsRethrownAtTheNextSync) {
  auto bus = openBus("memq://");
  WorkerBus worker(*bus, {});
  int calls = 0;
  Subscription node = worker.subscribe("IN", [&](const RawMessage&) {
    ++calls;
    throw std::runtime_error("bad frame");
  });
  publishText(*bus, "IN", "x");
  publishText(*bus, "IN", "y");
  while (bus->handle(std::chrono::milliseconds(0))) {
  }
  EXPECT_THROW(
      {
        try {
          worker.sync();
        } catch (const std::runtime_error& error) {
          EXPECT_STREQ(error.what(), "bad frame");
          throw;
        }
      },
      std::runtime_error);
  // The node failed: what came after is not given to it.
  EXPECT_EQ(calls, 1);
}

TEST(WorkerBus, SubscribingFromAHandlerIsRefused) {
  auto bus = openBus("memq://");
  WorkerBus worker(*bus, {});
  Subscription late;
  Subscription node = worker.subscribe(
      "IN", [&](const RawMessage&) { late = worker.subscribe("LATE", [](const RawMessage&) {}); });
  publishText(*bus, "IN", "x");
  while (bus->handle(std::chrono::milliseconds(0))) {
  }
  EXPECT_THROW(worker.sync(), BusError);
}

}  // namespace
}  // namespace nadir::core
