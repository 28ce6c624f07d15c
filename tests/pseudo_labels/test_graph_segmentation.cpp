#include <gtest/gtest.h>

#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/graph_segmentation.h"

namespace sp = sadsplat::pseudo_labels;
using sadsplat::io::Image8;

namespace {
// Left part red, right part blue, with mild deterministic noise in both.
Image8 twoColourImage(int W, int H, int edge_x) {
  Image8 im{W, H, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H * 3)};
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      std::uint8_t* p = &im.pixels[3 * (static_cast<std::size_t>(y) * W + x)];
      const int n = ((x * 7 + y * 13) % 5) - 2;
      if (x < edge_x)
        p[0] = 220 + n, p[1] = 30 + n, p[2] = 30;
      else
        p[0] = 30, p[1] = 30 + n, p[2] = 220 + n;
    }
  }
  return im;
}
}  // namespace

TEST(GraphSegmentation, HomogeneousAreasBecomeOneTargetEachAndDoNotCrossTheEdge) {
  const Image8 im = twoColourImage(64, 48, 37);
  const sp::Segmentation s = sp::graphSegmentation(im, {}, {300.0, 16, 0.0});
  ASSERT_EQ(s.region.size(), 64u * 48u);
  ASSERT_EQ(s.num_regions, 2);  // unlike SLIC (~48 regions here), size follows the content
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) EXPECT_EQ(s.region[y * 64 + x], x < 37 ? 0 : 1) << x << "," << y;
  }
  // Smoothing blurs the edge into thin strips of its own, but no region spans both sides.
  const sp::Segmentation b = sp::graphSegmentation(im, {}, {300.0, 16, 0.8});
  std::vector<std::set<bool>> sides(b.num_regions);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      if (x < 35 || x > 38) sides[b.region[y * 64 + x]].insert(x < 37);
    }
  }
  for (const auto& side : sides) EXPECT_LE(side.size(), 1u);
  EXPECT_EQ(b.region[0], b.region[20 * 64 + 30]);
  EXPECT_EQ(b.region[63], b.region[40 * 64 + 45]);
}

TEST(GraphSegmentation, MaskedPixelsHaveNoRegionAndSmallComponentsAreMerged) {
  Image8 im = twoColourImage(40, 30, 20);
  // A 3x3 grey speck inside the red part: below min_size, so it joins a neighbour.
  for (int y = 10; y < 13; ++y) {
    for (int x = 5; x < 8; ++x) {
      std::uint8_t* p = &im.pixels[3 * (y * 40 + x)];
      p[0] = p[1] = p[2] = 128;
    }
  }
  Image8 mask{40, 30, 1, std::vector<std::uint8_t>(40 * 30, 255)};
  for (int y = 0; y < 30; ++y) mask.pixels[y * 40 + 39] = 0;
  const sp::Segmentation s = sp::graphSegmentation(im, mask, {50.0, 20, 0.0});
  std::set<int> ids;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const int r = s.region[y * 40 + x];
      if (x == 39) {
        EXPECT_EQ(r, -1);
        continue;
      }
      ASSERT_GE(r, 0);
      ids.insert(r);
    }
  }
  EXPECT_EQ(static_cast<int>(ids.size()), s.num_regions);
  EXPECT_EQ(s.region[11 * 40 + 6], s.region[11 * 40 + 2]) << "the speck joined the red part";
  EXPECT_NE(s.region[11 * 40 + 2], s.region[11 * 40 + 30]);
}

TEST(GraphSegmentation, BadInputIsAClearError) {
  const Image8 im = twoColourImage(16, 12, 8);
  EXPECT_THROW(sp::graphSegmentation(im, {}, {0.0, 16, 0.8}), sadsplat::Error);
  EXPECT_THROW(sp::graphSegmentation(im, {}, {100.0, 0, 0.8}), sadsplat::Error);
  const Image8 grey{16, 12, 1, std::vector<std::uint8_t>(16 * 12, 0)};
  EXPECT_THROW(sp::graphSegmentation(grey, {}, {}), sadsplat::Error);
  const Image8 small_mask{8, 12, 1, std::vector<std::uint8_t>(8 * 12, 255)};
  EXPECT_THROW(sp::graphSegmentation(im, small_mask, {}), sadsplat::Error);
}
