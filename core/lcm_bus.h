#pragma once
// A Bus over LCM's C library: udpm:// (UDP multicast) and memq:// (in-process).

#include <exception>
#include <map>
#include <memory>
#include <string>

#include "core/bus.h"

typedef struct _lcm_t lcm_t;
typedef struct _lcm_subscription_t lcm_subscription_t;
typedef struct _lcm_recv_buf_t lcm_recv_buf_t;

namespace nadir::core {

class LcmBus final : public Bus {
 public:
  // Throws BusError naming the URL when LCM cannot open it. queue_capacity:
  // messages each subscription holds while handlers are busy (LCM drops the oldest beyond).
  explicit LcmBus(const std::string& url, int queue_capacity = BusParams::kDefaultQueueCapacity);
  ~LcmBus() override;

  std::string url() const override { return url_; }
  void send(std::string_view channel, const void* data, std::size_t size,
            std::int64_t event_utime) override;
  bool handle(std::chrono::milliseconds timeout) override;

 private:
  struct Entry;
  void addSubscription(const Handler& handler) override;
  void removeSubscription(int id) override;
  static void onMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user);
  static void onAnyMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user);

  std::string url_;
  int queue_capacity_;
  lcm_t* lcm_ = nullptr;
  lcm_subscription_t* counter_ = nullptr;
  std::map<int, std::unique_ptr<Entry>> entries_;
  // First exception thrown by a handler during the current dispatch.
  std::exception_ptr pending_;
};

}  // namespace nadir::core
