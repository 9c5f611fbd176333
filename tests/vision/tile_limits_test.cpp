// The per-pixel limits interpolated between tile thresholds (tile_thresholds.h, private to the
// detector) against the rule written out pixel by pixel: the SIMD paths must give every byte the
// scalar rule gives, at every width (multiples of the vector width and not).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <random>

#include "tile_thresholds.h"

namespace arbci::vision {
namespace {

// Pixel k of a tile lies between its centre and a neighbour's: the neighbour's weight in eighths,
// from the distance of the pixel's centre to the tile's centre, in tiles.
int farEighths(int k, int tile) {
  return std::abs(2 * k + 1 - tile) * 4 / tile;
}

int neighbour(int t, int k, int tile, int count) {
  return 2 * k < tile ? std::max(0, t - 1) : std::min(count - 1, t + 1);
}

// Along x within a tile row, then along y between two such rows, each rounded.
std::uint8_t expected(const TileThresholds& tiles, int x, int y) {
  const int tile = tiles.tile;
  auto alongX = [&](int ty) {
    const int t = x / tile, k = x % tile, far = farEighths(k, tile);
    const int other = neighbour(t, k, tile, tiles.cols);
    return ((8 - far) * tiles.at(t, ty) + far * tiles.at(other, ty) + 4) >> 3;
  };
  const int t = y / tile, k = y % tile, far = farEighths(k, tile);
  const int other = neighbour(t, k, tile, tiles.rows);
  return static_cast<std::uint8_t>(((8 - far) * alongX(t) + far * alongX(other) + 4) >> 3);
}

TEST(TileLimits, EveryPixelFollowsTheBilinearRuleAtAnyWidth) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> value(0, 255);
  for (const int tile : {2, 4}) {
    for (const int cols : {1, 2, 3, 8, 9, 10, 17, 18, 33, 40, 161}) {
      TileThresholds tiles;
      tiles.tile = tile;
      tiles.cols = cols;
      tiles.rows = 5;
      tiles.limit.resize(static_cast<size_t>(cols) * tiles.rows);
      for (auto& v : tiles.limit) v = static_cast<std::uint8_t>(value(random));
      // Extremes side by side, where a 16-bit sum would overflow a byte.
      tiles.limit[0] = 255;
      if (cols > 1) tiles.limit[1] = 0;
      const cv::Size size(cols * tile, tiles.rows * tile);
      cv::Mat limits;
      interpolateLimits(tiles, size, limits);
      int wrong = 0;
      for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
          wrong += limits.at<std::uint8_t>(y, x) != expected(tiles, x, y);
      EXPECT_EQ(wrong, 0) << "tile " << tile << " px, " << cols << " tiles a row";
    }
  }
}

}  // namespace
}  // namespace arbci::vision
