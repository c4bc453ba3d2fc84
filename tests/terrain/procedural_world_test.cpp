#include "terrain/procedural_world.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "core/params.h"

namespace nadir::terrain {
namespace {

// The default world (seed 1) is built once: construction calibrates the
// forest's mean colour, which takes a moment.
const ProceduralWorld& defaultWorld() {
  static const ProceduralWorld world{ProceduralWorldParams{}};
  return world;
}

cv::Mat render(const World& world, double north_min, double east_min, double size_m, int size_px) {
  cv::Mat rgb;
  world.imagery(GroundSquare{north_min, east_min, size_m}, size_px, rgb);
  return rgb;
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         cv::countNonZero(cv::Mat(a != b).reshape(1)) == 0;
}

// Squares spread over the world at a given pixel size: fields, forest,
// rivers, roads and villages all turn up among them.
std::vector<GroundSquare> spreadSquares(double size_m) {
  std::vector<GroundSquare> squares;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      squares.push_back({-9000.0 + 4100.0 * i, -8700.0 + 4050.0 * j, size_m});
    }
  }
  return squares;
}

// Smallest standard deviation of the grey level over the 32 x 32 blocks.
double minBlockStdDev(const cv::Mat& rgb) {
  cv::Mat grey;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  double lowest = 1e9;
  for (int r = 0; r + 32 <= grey.rows; r += 32) {
    for (int c = 0; c + 32 <= grey.cols; c += 32) {
      cv::Scalar mean, sd;
      cv::meanStdDev(grey(cv::Rect(c, r, 32, 32)), mean, sd);
      lowest = std::min(lowest, sd[0]);
    }
  }
  return lowest;
}

// The same seed gives bit-identical imagery and heights from two worlds.
TEST(ProceduralWorld, SameSeedSameWorld) {
  const ProceduralWorld a{ProceduralWorldParams{}};
  const ProceduralWorld& b = defaultWorld();
  EXPECT_TRUE(identical(render(a, 120.0, -340.0, 76.8, 256), render(b, 120.0, -340.0, 76.8, 256)));
  EXPECT_TRUE(identical(render(a, -5000.0, -5000.0, 10240.0, 256),
                        render(b, -5000.0, -5000.0, 10240.0, 256)));
  for (int i = 0; i < 50; ++i) {
    const double n = -9000.0 + 371.3 * i, e = 8000.0 - 297.1 * i;
    EXPECT_EQ(a.groundUp_m(n, e), b.groundUp_m(n, e));
  }
}

// Different seeds give different imagery and heights.
TEST(ProceduralWorld, DifferentSeedDifferentWorld) {
  ProceduralWorldParams params;
  params.seed = 2;
  const ProceduralWorld other{params};
  const cv::Mat a = render(defaultWorld(), -400.0, 300.0, 512.0, 256);
  const cv::Mat b = render(other, -400.0, 300.0, 512.0, 256);
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  EXPECT_GT(cv::mean(diff.reshape(1))[0], 10.0);
  int differing = 0;
  for (int i = 0; i < 20; ++i) {
    const double n = -9000.0 + 911.0 * i, e = 7000.0 - 650.0 * i;
    if (std::abs(defaultWorld().groundUp_m(n, e) - other.groundUp_m(n, e)) > 0.5) ++differing;
  }
  EXPECT_GE(differing, 15);
}

// Squares come out the same whatever was asked before and from any thread.
TEST(ProceduralWorld, IndependentOfOrderAndThreads) {
  const ProceduralWorld& world = defaultWorld();
  const GroundSquare a{300.0, -700.0, 76.8}, b{4100.0, -3100.0, 384.0}, c{-6000.0, 2000.0, 2560.0};
  cv::Mat ra, rb, rc;
  world.imagery(a, 256, ra);
  world.imagery(b, 256, rb);
  world.imagery(c, 300, rc);

  cv::Mat rc2, rb2, ra2;  // reversed order
  world.imagery(c, 300, rc2);
  world.imagery(b, 256, rb2);
  world.imagery(a, 256, ra2);
  EXPECT_TRUE(identical(ra, ra2));
  EXPECT_TRUE(identical(rb, rb2));
  EXPECT_TRUE(identical(rc, rc2));

  cv::Mat ta, tb, tc;  // concurrently, while the main thread asks for another square
  std::thread t1([&] { world.imagery(a, 256, ta); });
  std::thread t2([&] { world.imagery(b, 256, tb); });
  std::thread t3([&] { world.imagery(c, 300, tc); });
  cv::Mat other;
  world.imagery({-100.0, -100.0, 200.0}, 256, other);
  t1.join();
  t2.join();
  t3.join();
  EXPECT_TRUE(identical(ra, ta));
  EXPECT_TRUE(identical(rb, tb));
  EXPECT_TRUE(identical(rc, tc));

  // A square cut into several blocks, rendered by one thread and by four.
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  cv::Mat one_thread;
  world.imagery({-2000.0, 1500.0, 600.0}, 600, one_thread);
  cv::setNumThreads(4);
  cv::Mat four_threads;
  world.imagery({-2000.0, 1500.0, 600.0}, 600, four_threads);
  cv::setNumThreads(threads);
  EXPECT_TRUE(identical(one_thread, four_threads));

  std::vector<double> h1, h2(40);
  for (int i = 0; i < 40; ++i) h1.push_back(world.groundUp_m(37.0 * i - 700.0, 900.0 - 53.0 * i));
  std::thread t4([&] {
    for (int i = 39; i >= 0; --i) h2[i] = world.groundUp_m(37.0 * i - 700.0, 900.0 - 53.0 * i);
  });
  t4.join();
  EXPECT_EQ(h1, h2);
}

// A square is the same pixels as the matching part of a larger square at the
// same pixel size: tiles meet without seams.
TEST(ProceduralWorld, TilesMatchTheLargerSquare) {
  const ProceduralWorld& world = defaultWorld();
  for (const auto& [n, e] : {std::pair{100.0, 200.0}, {4140.0, -3164.0}, {-2500.0, 3000.0}}) {
    const cv::Mat big = render(world, n, e, 153.6, 512);
    // The north-east quarter: rows 0..255, columns 256..511.
    const cv::Mat quarter = render(world, n + 76.8, e + 76.8, 76.8, 256);
    cv::Mat diff;
    cv::absdiff(big(cv::Rect(256, 0, 256, 256)), quarter, diff);
    double max_diff = 0.0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
    EXPECT_LE(max_diff, 2.0) << "at " << n << ", " << e;
    EXPECT_LE(cv::countNonZero(diff.reshape(1)), 200) << "at " << n << ", " << e;
  }
}

// Heights are continuous: no step over 1 cm, slopes under 45 deg at 1 m.
TEST(ProceduralWorld, HeightIsContinuous) {
  const ProceduralWorld& world = defaultWorld();
  double max_step_cm = 0.0, max_slope = 0.0;
  for (int i = 0; i < 4000; ++i) {
    const double n = -9500.0 + 4.7513 * i, e = 9000.0 - 4.3217 * i;
    const double h = world.groundUp_m(n, e);
    max_step_cm = std::max({max_step_cm, std::abs(world.groundUp_m(n + 0.01, e) - h),
                            std::abs(world.groundUp_m(n, e + 0.01) - h)});
    max_slope = std::max({max_slope, std::abs(world.groundUp_m(n + 1.0, e) - h),
                          std::abs(world.groundUp_m(n, e + 1.0) - h)});
  }
  EXPECT_LT(max_step_cm, 0.01);
  EXPECT_LT(max_slope, 1.0);
}

// Heights stay within the documented [-0.65, 0.7] * relief_m and use a good
// part of it; a world without relief is flat at the origin plane.
TEST(ProceduralWorld, HeightsWithinTheDocumentedRange) {
  const ProceduralWorld& world = defaultWorld();
  const double relief = world.params().relief_m;
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) {
      const double h = world.groundUp_m(-10000.0 + 200.0 * i, -10000.0 + 200.0 * j);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  }
  EXPECT_GE(lo, -0.65 * relief);
  EXPECT_LE(hi, 0.7 * relief);
  RecordProperty("height_range_m", std::to_string(lo) + " .. " + std::to_string(hi));
  EXPECT_GT(hi - lo, 0.5 * relief);

  ProceduralWorldParams flat;
  flat.relief_m = 0.0;
  const ProceduralWorld flat_world{flat};
  for (int i = 0; i < 20; ++i) EXPECT_EQ(flat_world.groundUp_m(500.0 * i - 5000.0, 300.0 * i), 0.0);
}

// Rivers in the imagery lie in valleys of the heights: water-coloured pixels
// are below the ground 200 m around them.
TEST(ProceduralWorld, RiversRunInValleys) {
  const ProceduralWorld& world = defaultWorld();
  int water = 0, in_valley = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const double n0 = -9500.0 + 4800.0 * i, e0 = -9500.0 + 4800.0 * j;
      const double size = 3000.0, px = size / 600;
      const cv::Mat rgb = render(world, n0, e0, size, 600);
      for (int r = 2; r < rgb.rows; r += 5) {
        for (int c = 2; c < rgb.cols; c += 5) {
          const cv::Vec3b v = rgb.at<cv::Vec3b>(r, c);
          const double red = v[0], green = v[1], blue = v[2];
          // Dark blue-green water, unlike vegetation (blue far below green).
          if (!(green < 95.0 && red < green - 3.0 && blue > 0.88 * green)) continue;
          ++water;
          const double n = n0 + size - (r + 0.5) * px, e = e0 + (c + 0.5) * px;
          std::vector<double> ring;
          for (int k = 0; k < 8; ++k) {
            const double a = k * 3.14159265358979 / 4.0;
            ring.push_back(world.groundUp_m(n + 200.0 * std::cos(a), e + 200.0 * std::sin(a)));
          }
          std::nth_element(ring.begin(), ring.begin() + 4, ring.end());
          if (world.groundUp_m(n, e) < ring[4]) ++in_valley;
        }
      }
    }
  }
  RecordProperty("water_samples", water);
  RecordProperty("in_valley", in_valley);
  ASSERT_GT(water, 100);
  EXPECT_GT(in_valley, 0.9 * water);
}

// Outside the extent the height is the nearest edge's.
TEST(ProceduralWorld, HeightOutsideExtentIsTheEdges) {
  const ProceduralWorld& world = defaultWorld();
  EXPECT_EQ(world.groundUp_m(12000.0, 345.0), world.groundUp_m(10000.0, 345.0));
  EXPECT_EQ(world.groundUp_m(-200.0, -15000.0), world.groundUp_m(-200.0, -10000.0));
  EXPECT_EQ(world.groundUp_m(1e7, 1e7), world.groundUp_m(10000.0, 10000.0));
}

// Every 32 x 32 block has texture, at 0.3 m/px and at 5 m/px, all over the world.
TEST(ProceduralWorld, TextureEverywhere) {
  const ProceduralWorld& world = defaultWorld();
  for (const double size_m : {76.8, 1280.0}) {
    double lowest = 1e9;
    for (const GroundSquare& square : spreadSquares(size_m)) {
      cv::Mat rgb;
      world.imagery(square, 256, rgb);
      const double s = minBlockStdDev(rgb);
      EXPECT_GT(s, 1.5) << "square at " << square.north_min_m << ", " << square.east_min_m << ", "
                        << size_m / 256 << " m/px";
      lowest = std::min(lowest, s);
    }
    RecordProperty("min_block_stddev_at_" + std::to_string(static_cast<int>(size_m)) + "m",
                   std::to_string(lowest));
  }
}

// The mean colour is earthy: green and brown dominate, muted, mid-grey bright.
TEST(ProceduralWorld, MeanColourIsEarthy) {
  const ProceduralWorld& world = defaultWorld();
  for (const GroundSquare& square :
       {GroundSquare{-1000.0, -1000.0, 2000.0}, GroundSquare{-10000.0, -10000.0, 20000.0}}) {
    cv::Mat rgb;
    world.imagery(square, 512, rgb);
    const cv::Scalar m = cv::mean(rgb);
    const double r = m[0], g = m[1], b = m[2];
    EXPECT_GT(g, b + 15.0);
    EXPECT_GT(r, b + 10.0);
    EXPECT_LT(std::abs(r - g), 25.0);
    const double saturation = (std::max({r, g, b}) - std::min({r, g, b})) / std::max({r, g, b});
    EXPECT_LT(saturation, 0.45);
    EXPECT_GT(g, 60.0);
    EXPECT_LT(g, 170.0);
  }
}

// A coarse square looks like the area average of the fine one: a 512 m square
// at 128 px (4 m/px) against the same at 1024 px (0.5 m/px) shrunk with
// INTER_AREA. Means agree within 4 grey levels; the mean absolute difference,
// which includes crown and crop texture too fine to be drawn alike at both
// sizes, stays under 14.
TEST(ProceduralWorld, CoarseIsTheAverageOfFine) {
  const ProceduralWorld& world = defaultWorld();
  double sum_mad = 0.0;
  int n = 0;
  for (const GroundSquare& square :
       {GroundSquare{100.0, 200.0, 512.0}, GroundSquare{4140.0, -3164.0, 512.0},
        GroundSquare{-2500.0, 3000.0, 512.0}, GroundSquare{-8000.0, 4800.0, 512.0},
        GroundSquare{6100.0, -7000.0, 512.0}}) {
    cv::Mat coarse, fine, shrunk, diff;
    world.imagery(square, 128, coarse);
    world.imagery(square, 1024, fine);
    cv::resize(fine, shrunk, cv::Size(128, 128), 0, 0, cv::INTER_AREA);
    cv::absdiff(coarse, shrunk, diff);
    const double mad = cv::mean(diff.reshape(1))[0];
    const double mean_diff = cv::mean(coarse.reshape(1))[0] - cv::mean(shrunk.reshape(1))[0];
    EXPECT_LT(mad, 14.0) << "at " << square.north_min_m << ", " << square.east_min_m;
    EXPECT_LT(std::abs(mean_diff), 4.0) << "at " << square.north_min_m << ", " << square.east_min_m;
    sum_mad += mad;
    ++n;
  }
  EXPECT_LT(sum_mad / n, 10.0);
}

// The extent is the configured square around the origin; resolutions as documented.
TEST(ProceduralWorld, ExtentAndResolutions) {
  const ProceduralWorld& world = defaultWorld();
  const WorldExtent e = world.extent();
  EXPECT_EQ(e.north_min_m, -10000.0);
  EXPECT_EQ(e.north_max_m, 10000.0);
  EXPECT_EQ(e.east_min_m, -10000.0);
  EXPECT_EQ(e.east_max_m, 10000.0);
  EXPECT_EQ(world.imageryResolution_m(), 0.3);
  EXPECT_GE(world.elevationResolution_m(), 2.0);
  EXPECT_LE(world.elevationResolution_m(), 10.0);

  ProceduralWorldParams params;
  params.size_m = 3000.0;
  params.imagery_resolution_m = 0.5;
  const ProceduralWorld small{params};
  EXPECT_EQ(small.extent().north_max_m, 1500.0);
  EXPECT_EQ(small.extent().east_min_m, -1500.0);
  EXPECT_EQ(small.imageryResolution_m(), 0.5);
}

// Out-of-range parameters are refused, in code and in YAML.
TEST(ProceduralWorld, BadParametersRejected) {
  const auto refused = [](auto change) {
    ProceduralWorldParams params;
    change(params);
    EXPECT_THROW(ProceduralWorld{params}, core::ParamError);
  };
  refused([](ProceduralWorldParams& p) { p.relief_m = -5.0; });
  refused([](ProceduralWorldParams& p) { p.imagery_resolution_m = 3.0; });
  refused([](ProceduralWorldParams& p) { p.texture_strength = -0.5; });
  refused([](ProceduralWorldParams& p) { p.sun_elevation_deg = 5.0; });
  refused([](ProceduralWorldParams& p) { p.forest_fraction = 1.5; });
  refused([](ProceduralWorldParams& p) { p.road_density = -0.1; });
  refused([](ProceduralWorldParams& p) { p.seed = -1; });
  refused([](ProceduralWorldParams& p) { p.size_m = std::nan(""); });

  ProceduralWorldParams params;
  const auto visit = [&params](core::ParamVisitor& v) { params.visit(v); };
  EXPECT_THROW(core::applyYamlText("sun_azimuth_deg: 400\n", "test.yaml", visit), core::ParamError);
  EXPECT_THROW(core::applyYamlText("field_size: 100\n", "test.yaml", visit), core::ParamError);
  core::applyYamlText("seed: 7\nrelief_m: 60\n", "test.yaml", visit);
  EXPECT_EQ(params.seed, 7);
  EXPECT_EQ(params.relief_m, 60.0);
}

// Degenerate requests are refused; odd sizes and one-pixel squares work.
TEST(ProceduralWorld, ImageryArguments) {
  const ProceduralWorld& world = defaultWorld();
  cv::Mat rgb;
  EXPECT_THROW(world.imagery({0.0, 0.0, 100.0}, 0, rgb), std::invalid_argument);
  EXPECT_THROW(world.imagery({0.0, 0.0, 0.0}, 16, rgb), std::invalid_argument);
  EXPECT_THROW(world.imagery({std::nan(""), 0.0, 10.0}, 16, rgb), std::invalid_argument);
  world.imagery({0.0, 0.0, 100.0}, 1, rgb);
  EXPECT_EQ(rgb.rows, 1);
  EXPECT_EQ(rgb.type(), CV_8UC3);
  world.imagery({-50.0, 20.0, 333.0}, 301, rgb);
  EXPECT_EQ(rgb.rows, 301);
  EXPECT_EQ(rgb.cols, 301);
}

// texture_strength scales the texture inside the fields only: the same
// 200 m of fields (no forest, hedge, road or building) at 0.3 keeps less than
// half the mean pixel-to-pixel difference it has at 1, and the fields' mean
// brightness within 2 counts.
TEST(ProceduralWorld, TextureStrengthScalesTheTextureInsideTheFields) {
  const auto imageAt = [](double strength) {
    ProceduralWorldParams params;
    params.forest_fraction = 0.0;
    params.hedge_fraction = 0.0;
    params.road_density = 0.0;
    params.buildings_per_km2 = 0.0;
    params.river_spacing_m = 50000.0;
    params.texture_strength = strength;
    const ProceduralWorld world(params);
    cv::Mat rgb;
    world.imagery(GroundSquare{-100.0, -100.0, 200.0}, 512, rgb);
    cv::Mat gray;
    cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
    return gray;
  };
  const auto meanStep = [](const cv::Mat& gray) {
    cv::Mat dx;
    cv::absdiff(gray.colRange(1, gray.cols), gray.colRange(0, gray.cols - 1), dx);
    return cv::mean(dx)[0];
  };
  const cv::Mat full = imageAt(1.0), weak = imageAt(0.3);
  EXPECT_LT(meanStep(weak), 0.5 * meanStep(full));
  EXPECT_NEAR(cv::mean(weak)[0], cv::mean(full)[0], 2.0);
}

}  // namespace
// The objects standing on the ground: the four quarters of a square hold
// exactly the objects of the whole, each once and inside its quarter; trees
// have the heights the imagery's shadows were cast with (broadleaf 10-18 m,
// conifers 14-22 m) and crowns of 3.2-5.2 m and 1.8-2.9 m times 0.9-1.3
// (hedgerow and field-edge trees); buildings are 6-9 m tall; every object
// stands on the ground below its centre.
TEST(ProceduralWorld, ObjectsStandOnTheGroundOncePerSquare) {
  const ProceduralWorld& world = defaultWorld();
  // 1 km north-east of the origin: forest, fields, hedges and farmsteads.
  const GroundSquare whole{500.0, 500.0, 1000.0};
  const std::vector<GroundObject> all = world.objects(whole);
  std::size_t in_quarters = 0;
  int trees = 0, buildings = 0;
  for (int q = 0; q < 4; ++q) {
    const GroundSquare quarter{500.0 + 500.0 * (q / 2), 500.0 + 500.0 * (q % 2), 500.0};
    const std::vector<GroundObject> part = world.objects(quarter);
    in_quarters += part.size();
    for (const GroundObject& o : part) {
      EXPECT_GE(o.north_m, quarter.north_min_m);
      EXPECT_LT(o.north_m, quarter.north_min_m + quarter.size_m);
      EXPECT_GE(o.east_m, quarter.east_min_m);
      EXPECT_LT(o.east_m, quarter.east_min_m + quarter.size_m);
      EXPECT_DOUBLE_EQ(o.base_up_m, world.groundUp_m(o.north_m, o.east_m));
      switch (o.kind) {
        case GroundObject::Kind::kBroadleaf:
          ++trees;
          EXPECT_GE(o.height_m, 10.0);
          EXPECT_LE(o.height_m, 18.0);
          EXPECT_GE(o.half_length_m, 3.2 * 0.9);
          EXPECT_LE(o.half_length_m, 5.2 * 1.3);
          break;
        case GroundObject::Kind::kConifer:
          ++trees;
          EXPECT_GE(o.height_m, 14.0);
          EXPECT_LE(o.height_m, 22.0);
          EXPECT_GE(o.half_length_m, 1.8 * 0.9);
          EXPECT_LE(o.half_length_m, 2.9 * 1.3);
          break;
        case GroundObject::Kind::kBuilding:
          ++buildings;
          EXPECT_GE(o.height_m, 6.0);
          EXPECT_LE(o.height_m, 9.0);
          EXPECT_GT(o.half_length_m, 0.0);
          break;
      }
    }
  }
  EXPECT_EQ(in_quarters, all.size());
  std::printf("1 km square: %d trees, %d buildings\n", trees, buildings);
  EXPECT_GT(trees, 100);
  EXPECT_GT(buildings, 0);
  // The same square asked again gives the same objects in the same order.
  const std::vector<GroundObject> again = world.objects(whole);
  ASSERT_EQ(again.size(), all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(again[i].north_m, all[i].north_m);
    EXPECT_EQ(again[i].height_m, all[i].height_m);
  }
}

// The imagery beneath the objects leaves out crowns and roofs and keeps the
// rest: over open field away from every object it is the imagery itself,
// and over the square as a whole it differs where the tops were.
TEST(ProceduralWorld, ImageryBeneathObjectsLeavesOutTheirTops) {
  const ProceduralWorld& world = defaultWorld();
  const GroundSquare square{-200.0, -200.0, 400.0};
  cv::Mat with_tops, beneath;
  world.imagery(square, 800, with_tops);
  world.imageryBeneathObjects(square, 800, beneath);
  cv::Mat differs;
  cv::absdiff(with_tops, beneath, differs);
  cv::cvtColor(differs, differs, cv::COLOR_RGB2GRAY);
  const int changed = cv::countNonZero(differs > 2);
  EXPECT_GT(changed, 0);
  // Every changed pixel lies within a crown's or roof's reach of an object.
  const std::vector<GroundObject> objects = world.objects(GroundSquare{-250.0, -250.0, 500.0});
  cv::Mat near_object = cv::Mat::zeros(800, 800, CV_8U);
  for (const GroundObject& o : objects) {
    const double reach_m = std::hypot(o.half_length_m, o.half_width_m) * 1.2 + 1.0;
    const cv::Point centre(
        static_cast<int>((o.east_m - square.east_min_m) * 2.0),
        static_cast<int>((square.north_min_m + square.size_m - o.north_m) * 2.0));
    cv::circle(near_object, centre, static_cast<int>(reach_m * 2.0) + 1, 255, cv::FILLED);
  }
  cv::Mat far_and_changed = (differs > 2) & (near_object == 0);
  EXPECT_EQ(cv::countNonZero(far_and_changed), 0);
}

}  // namespace nadir::terrain
