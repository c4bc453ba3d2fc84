// The tile prefetcher: whichever way a tile's imagery comes (made ahead by the
// worker, or made on the caller's thread), it is the tile's own, and the
// worker makes the tiles of the views it is told to expect.

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "terrain/tile_prefetcher.h"
#include "tests/terrain/down_view.h"

namespace nadir::terrain {
namespace {

// Flat ground, 2048 m square, 0.5 m imagery whose pixels depend on the square
// and the pixel, so that any two tiles differ.
class PatternWorld : public World {
 public:
  double groundUp_m(double, double) const override { return 0.0; }
  void imagery(const GroundSquare& square, int size_px, cv::Mat& rgb) const override {
    rgb.create(size_px, size_px, CV_8UC3);
    const int base =
        static_cast<int>(square.north_min_m * 3 + square.east_min_m * 7 + square.size_m * 11);
    for (int r = 0; r < size_px; ++r)
      for (int c = 0; c < size_px; ++c)
        rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uchar>(base + r), static_cast<uchar>(c),
                                            static_cast<uchar>(base + r * c));
  }
  void imageryBeneathObjects(const GroundSquare& square, int size_px, cv::Mat& rgb) const override {
    imagery(square, size_px, rgb);
    rgb = cv::Scalar(255, 255, 255) - rgb;
  }
  double imageryResolution_m() const override { return 0.5; }
  double elevationResolution_m() const override { return 1.0; }
  WorldExtent extent() const override { return {-1024, 1024, -1024, 1024}; }
};

bool samePixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// The worker runs on spare cycles only: it is given time, however loaded the
// machine (the test fails only if it has not finished in two minutes).
bool waitUntilIdle(const TilePrefetcher& prefetcher) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(2);
  while (!prefetcher.idle()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

std::shared_ptr<TileTree> patternTiles() {
  TileParams params;
  params.texture_px = 64;
  return std::make_shared<TileTree>(std::make_shared<PatternWorld>(), params);
}

TEST(TilePrefetcher, TakesEachTilesOwnImageryWithoutViews) {
  const auto tiles = patternTiles();
  TilePrefetcher prefetcher(tiles, 0.0);
  const std::vector<TileId> ids = tiles->select(downView(0, 0, 100));
  ASSERT_GT(ids.size(), 4u);
  for (const TileId& id : ids) EXPECT_TRUE(samePixels(prefetcher.take(id), tiles->imagery(id)));
  const TilePrefetchStats stats = prefetcher.stats();
  EXPECT_EQ(stats.made_here, static_cast<std::int64_t>(ids.size()));
  EXPECT_EQ(stats.made_ahead, 0);
}

TEST(TilePrefetcher, MakesTheExpectedTilesAheadAndGivesTheSamePixels) {
  const auto tiles = patternTiles();
  TilePrefetcher prefetcher(tiles, 0.0);
  const LodView view = downView(300, -200, 80);
  const std::vector<TileId> ids = tiles->select(view);
  ASSERT_GT(ids.size(), 4u);
  ASSERT_LE(ids.size(), 64u);  // all held ready at once
  prefetcher.expect({view});
  ASSERT_TRUE(waitUntilIdle(prefetcher));
  for (const TileId& id : ids) EXPECT_TRUE(samePixels(prefetcher.take(id), tiles->imagery(id)));
  const TilePrefetchStats stats = prefetcher.stats();
  EXPECT_EQ(stats.made_ahead, static_cast<std::int64_t>(ids.size()));
  EXPECT_EQ(stats.taken_ready, static_cast<std::int64_t>(ids.size()));
  EXPECT_EQ(stats.made_here, 0);
  EXPECT_EQ(stats.dropped, 0);
}

TEST(TilePrefetcher, TakingWhileTheWorkerRunsGivesTheSamePixels) {
  const auto tiles = patternTiles();
  TilePrefetcher prefetcher(tiles, 0.0);
  // A flight's views expected and taken at once: some tiles are made ahead,
  // some made here, depending on the threads' timing.
  std::int64_t taken = 0;
  for (int step = 0; step < 20; ++step) {
    const double north = -600.0 + 60.0 * step;
    prefetcher.expect({downView(north + 60.0, 0, 60), downView(north + 120.0, 0, 60)});
    for (const TileId& id : tiles->select(downView(north, 0, 60))) {
      ASSERT_TRUE(samePixels(prefetcher.take(id), tiles->imagery(id))) << "step " << step;
      prefetcher.released(id.key());
      ++taken;
    }
  }
  const TilePrefetchStats stats = prefetcher.stats();
  EXPECT_EQ(stats.taken_ready + stats.made_here, taken);
}

TEST(TilePrefetcher, FineTilesComeBeneathTheObjects) {
  const auto tiles = patternTiles();
  // 2048 m root, 64 px textures: the texel is 32 m at level 0, 0.5 m at level 6.
  TilePrefetcher prefetcher(tiles, 1.0);
  const TileId fine{6, 3, 5}, coarse{4, 1, 1};
  EXPECT_TRUE(prefetcher.beneathObjects(fine));
  EXPECT_FALSE(prefetcher.beneathObjects(coarse));
  EXPECT_TRUE(samePixels(prefetcher.take(fine), tiles->imagery(fine, true)));
  EXPECT_TRUE(samePixels(prefetcher.take(coarse), tiles->imagery(coarse, false)));
}

// With room for fewer tiles than the views select, the worker stops when it is
// full rather than drop tiles the views still want; tiles no view selects any
// more make room for new ones.
TEST(TilePrefetcher, KeepsTheTilesTheLatestViewsWant) {
  const auto tiles = patternTiles();
  TilePrefetcher prefetcher(tiles, 0.0, 4);
  const LodView first = downView(-500, -500, 80), second = downView(500, 500, 80);
  ASSERT_GT(tiles->select(first).size(), 4u);
  prefetcher.expect({first});
  ASSERT_TRUE(waitUntilIdle(prefetcher));
  EXPECT_EQ(prefetcher.stats().made_ahead, 4);
  EXPECT_EQ(prefetcher.stats().dropped, 0);
  // Far away: the first view's four make room for the second's.
  prefetcher.expect({second});
  ASSERT_TRUE(waitUntilIdle(prefetcher));
  EXPECT_EQ(prefetcher.stats().made_ahead, 8);
  EXPECT_EQ(prefetcher.stats().dropped, 4);
  const std::vector<TileId> ids = tiles->select(second);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_TRUE(samePixels(prefetcher.take(ids[i]), tiles->imagery(ids[i])));
  EXPECT_EQ(prefetcher.stats().taken_ready, 4);
}

}  // namespace
}  // namespace nadir::terrain
