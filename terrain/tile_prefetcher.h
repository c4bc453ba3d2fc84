#pragma once
// Tile imagery made ahead of need on a worker thread, for the views a camera
// is expected to see next. A tile's imagery is a pure function of the tile
// (TileTree::imagery), so which thread makes it, and when, cannot change a
// pixel: a frame that needs a tile takes it if it is made, and makes it
// itself otherwise (docs/rendering.md). It never waits for the worker, which
// runs on spare cycles only.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "terrain/tiles.h"

namespace nadir::terrain {

struct TilePrefetchStats {
  std::int64_t taken_ready = 0;  // made ahead and taken
  std::int64_t made_here = 0;    // not made yet when needed: made on the caller's thread
  std::int64_t made_ahead = 0;   // made by the worker
  std::int64_t dropped = 0;      // made ahead, then not wanted (made here meanwhile, or room)
};

class TilePrefetcher {
 public:
  // beneath_objects_max_texel_m: tiles whose texel is at most this are made
  // as World::imageryBeneathObjects (TileTree::beneathObjects); 0: none.
  // max_ready: tiles made and not yet taken that are kept (those the latest
  // views no longer select go first).
  TilePrefetcher(std::shared_ptr<TileTree> tiles, double beneath_objects_max_texel_m,
                 int max_ready = 64);
  ~TilePrefetcher();
  TilePrefetcher(const TilePrefetcher&) = delete;
  TilePrefetcher& operator=(const TilePrefetcher&) = delete;

  // The views expected next, soonest first: the worker makes the tiles they
  // select that are neither held by the caller nor made. Replaces the views
  // given before.
  void expect(std::vector<LodView> views);
  // Whether a tile is drawn over 3D objects (see the constructor).
  bool beneathObjects(const TileId& id) const;
  // A tile's imagery, as TileTree::imagery(id, beneathObjects(id)). The
  // caller holds it from then on: the worker does not make it again until
  // released(id.key()).
  cv::Mat take(const TileId& id);
  void released(std::uint64_t tile_key);

  TilePrefetchStats stats() const;
  // Nothing to make: the views given are all made (or held, or no room).
  bool idle() const;

 private:
  void work();
  // Drops the oldest tile made that the latest views do not select; false if
  // every tile made is wanted. mutex_ held.
  bool makeRoom();

  std::shared_ptr<TileTree> tiles_;
  double beneath_objects_max_texel_m_;
  std::size_t max_ready_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool stopping_ = false;
  std::optional<std::vector<LodView>> views_;  // new views for the worker
  std::unordered_set<std::uint64_t> held_;
  std::unordered_map<std::uint64_t, cv::Mat> ready_;
  std::deque<std::uint64_t> ready_order_;  // oldest first
  bool working_ = false;
  std::unordered_set<std::uint64_t> wanted_;  // what the latest views select
  TilePrefetchStats stats_;
  std::thread worker_;
};

}  // namespace nadir::terrain
