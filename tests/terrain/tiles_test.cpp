// The tile quadtree: level-of-detail selection and the mesh cache's budget.

#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "terrain/tiles.h"
#include "tests/terrain/down_view.h"

namespace nadir::terrain {
namespace {

// Gentle sine hills, 1024 m square, 0.5 m imagery.
class HillWorld : public World {
 public:
  double groundUp_m(double north_m, double east_m) const override {
    return 10.0 * std::sin(north_m / 50.0) * std::cos(east_m / 70.0);
  }
  void imagery(const GroundSquare&, int size_px, cv::Mat& rgb) const override {
    rgb = cv::Mat(size_px, size_px, CV_8UC3, cv::Scalar(100, 120, 80));
  }
  double imageryResolution_m() const override { return 0.5; }
  double elevationResolution_m() const override { return 1.0; }
  WorldExtent extent() const override { return {-512, 512, -512, 512}; }
};

// The root covers the extent; the finest level has texels at the imagery resolution:
// 1024 m / 2^level / 256 px <= 0.5 m -> level 3.
TEST(TileTree, LevelsFollowTheImageryResolution) {
  TileParams params;
  params.texture_px = 256;
  TileTree tree(std::make_shared<HillWorld>(), params);
  EXPECT_EQ(tree.rootSquare().size_m, 1024.0);
  EXPECT_EQ(tree.maxLevel(), 3);
  const GroundSquare sq = tree.squareOf({2, 1, 3});
  EXPECT_EQ(sq.size_m, 256.0);
  EXPECT_EQ(sq.east_min_m, -512.0 + 256.0);
  EXPECT_EQ(sq.north_min_m, -512.0 + 768.0);
}

// Low over the ground the finest tiles are chosen under the camera; from high up
// fewer, coarser tiles; and the same view always selects the same tiles.
TEST(TileTree, SelectionRefinesWithProximityAndRepeats) {
  TileParams params;
  params.texture_px = 256;
  TileTree tree(std::make_shared<HillWorld>(), params);
  const std::vector<TileId> low = tree.select(downView(10.0, 20.0, 30.0));
  ASSERT_FALSE(low.empty());
  int tiles_under = 0;
  for (const TileId& id : low) {
    const GroundSquare sq = tree.squareOf(id);
    const bool under = sq.north_min_m <= 10.0 && 10.0 <= sq.north_min_m + sq.size_m &&
                       sq.east_min_m <= 20.0 && 20.0 <= sq.east_min_m + sq.size_m;
    if (under) {
      EXPECT_EQ(id.level, tree.maxLevel());
      ++tiles_under;
    }
  }
  EXPECT_EQ(tiles_under, 1);
  const std::vector<TileId> high = tree.select(downView(10.0, 20.0, 5000.0));
  ASSERT_FALSE(high.empty());
  for (const TileId& id : high) EXPECT_LT(id.level, tree.maxLevel());
  EXPECT_EQ(tree.select(downView(10.0, 20.0, 30.0)), low);
}

// A tile's mesh error is the largest gap between the mesh and the ground midway
// between its vertices, and meshes carry the hills' heights.
TEST(TileTree, GeometryHeightsAndError) {
  TileParams params;
  params.mesh_quads = 4;
  TileTree tree(std::make_shared<HillWorld>(), params);
  const auto root = tree.geometry({0, 0, 0});
  ASSERT_EQ(root->vertices_per_edge, 5);
  // Vertex (row 2, column 2) is the root's centre (0, 0): height 0.
  EXPECT_NEAR(root->height_up_m[2 * 5 + 2], 0.0, 1e-6);
  EXPECT_LE(root->max_up_m, 10.0f);
  EXPECT_GE(root->min_up_m, -10.0f);
  // 256 m between vertices over hills of 10 m and wavelengths of 300-450 m: metres of error.
  EXPECT_GT(root->geometric_error_m, 1.0f);
  const auto fine = tree.geometry({3, 4, 4});
  EXPECT_LT(fine->geometric_error_m, root->geometric_error_m);
}

// The mesh cache never holds more than its budget, however many tiles are asked for.
TEST(TileTree, GeometryCacheRespectsItsBudget) {
  TileParams params;
  params.mesh_quads = 64;  // about 17 kB a tile
  params.geometry_cache_mib = 1.0;
  TileTree tree(std::make_shared<HillWorld>(), params);
  for (int ix = 0; ix < 8; ++ix) {
    for (int iy = 0; iy < 8; ++iy) {
      (void)tree.geometry({3, ix, iy});
      EXPECT_LE(tree.geometryCacheBytes(), 1024u * 1024u);
    }
  }
  EXPECT_GT(tree.geometryCacheEntries(), 10u);
  EXPECT_LT(tree.geometryCacheEntries(), 64u);
}

}  // namespace
}  // namespace nadir::terrain
