#include "terrain/tile_prefetcher.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>

namespace nadir::terrain {

TilePrefetcher::TilePrefetcher(std::shared_ptr<TileTree> tiles, double beneath_objects_max_texel_m,
                               int max_ready)
    : tiles_(std::move(tiles)),
      beneath_objects_max_texel_m_(beneath_objects_max_texel_m),
      max_ready_(static_cast<std::size_t>(std::max(max_ready, 1))) {
  worker_ = std::thread([this] { work(); });
}

TilePrefetcher::~TilePrefetcher() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

bool TilePrefetcher::beneathObjects(const TileId& id) const {
  return tiles_->beneathObjects(id, beneath_objects_max_texel_m_);
}

void TilePrefetcher::expect(std::vector<LodView> views) {
  {
    const std::lock_guard lock(mutex_);
    views_ = std::move(views);
  }
  changed_.notify_all();
}

void TilePrefetcher::released(std::uint64_t tile_key) {
  const std::lock_guard lock(mutex_);
  held_.erase(tile_key);
}

cv::Mat TilePrefetcher::take(const TileId& id) {
  const std::uint64_t key = id.key();
  {
    const std::lock_guard lock(mutex_);
    held_.insert(key);
    const auto found = ready_.find(key);
    if (found != ready_.end()) {
      cv::Mat rgb = std::move(found->second);
      ready_.erase(found);
      ready_order_.erase(std::find(ready_order_.begin(), ready_order_.end(), key));
      ++stats_.taken_ready;
      return rgb;
    }
    ++stats_.made_here;
  }
  return tiles_->imagery(id, beneathObjects(id));
}

TilePrefetchStats TilePrefetcher::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

bool TilePrefetcher::idle() const {
  const std::lock_guard lock(mutex_);
  return !working_ && !views_.has_value();
}

bool TilePrefetcher::makeRoom() {
  for (auto it = ready_order_.begin(); it != ready_order_.end(); ++it) {
    if (wanted_.count(*it) != 0) continue;
    ready_.erase(*it);
    ready_order_.erase(it);
    ++stats_.dropped;
    return true;
  }
  return false;
}

void TilePrefetcher::work() {
  // Only spare cycles: the frame being drawn comes first.
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  std::unique_lock lock(mutex_);
  while (true) {
    working_ = false;
    changed_.notify_all();
    changed_.wait(lock, [this] { return stopping_ || views_.has_value(); });
    if (stopping_) return;
    const std::vector<LodView> views = std::move(*views_);
    views_.reset();
    working_ = true;
    lock.unlock();
    // What the views select, soonest view first, each tile once. A failure
    // here or in making a tile is left for the caller to meet: it makes the
    // tile itself.
    std::vector<TileId> wanted;
    std::unordered_set<std::uint64_t> wanted_keys;
    try {
      for (const LodView& view : views) {
        for (const TileId& id : tiles_->select(view))
          if (wanted_keys.insert(id.key()).second) wanted.push_back(id);
      }
    } catch (...) {
      wanted.clear();
    }
    lock.lock();
    wanted_ = std::move(wanted_keys);
    for (const TileId& id : wanted) {
      // New views: plan again from them.
      if (stopping_ || views_.has_value()) break;
      const std::uint64_t key = id.key();
      if (held_.count(key) != 0 || ready_.count(key) != 0) continue;
      if (ready_.size() >= max_ready_ && !makeRoom()) break;
      lock.unlock();
      cv::Mat rgb;
      try {
        rgb = tiles_->imagery(id, beneathObjects(id));
      } catch (...) {
      }
      lock.lock();
      if (rgb.empty()) continue;
      ++stats_.made_ahead;
      if (held_.count(key) != 0) {  // the caller made it meanwhile
        ++stats_.dropped;
        continue;
      }
      ready_.emplace(key, std::move(rgb));
      ready_order_.push_back(key);
    }
  }
}

}  // namespace nadir::terrain
