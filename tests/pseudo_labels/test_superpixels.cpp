#include <gtest/gtest.h>

#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/superpixels.h"

namespace sp = sadsplat::pseudo_labels;
using sadsplat::io::Image8;

namespace {
// Left half red, right half blue; the boundary at x = 37 is not on the seed grid.
Image8 twoColourImage(int W, int H) {
  Image8 im{W, H, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H * 3)};
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      std::uint8_t* p = &im.pixels[3 * (static_cast<std::size_t>(y) * W + x)];
      if (x < 37)
        p[0] = 220, p[1] = 30, p[2] = 30;
      else
        p[0] = 30, p[1] = 30, p[2] = 220;
    }
  }
  return im;
}
}  // namespace

TEST(Superpixels, RegionsDoNotCrossAStrongColourEdge) {
  const Image8 im = twoColourImage(64, 48);
  const sp::Segmentation s = sp::slicSuperpixels(im, {}, {8, 10.0, 10});
  ASSERT_EQ(s.region.size(), 64u * 48u);
  std::vector<std::set<bool>> sides(s.num_regions);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      const int r = s.region[y * 64 + x];
      ASSERT_GE(r, 0);
      ASSERT_LT(r, s.num_regions);
      sides[r].insert(x < 37);
    }
  }
  for (int r = 0; r < s.num_regions; ++r) EXPECT_EQ(sides[r].size(), 1u) << "region " << r;
  // About one region per 8x8 cell (48 cells); the edge can add a few.
  EXPECT_GE(s.num_regions, 40);
  EXPECT_LE(s.num_regions, 70);
}

TEST(Superpixels, RegionsAreConnectedAndMaskedPixelsHaveNone) {
  Image8 im = twoColourImage(40, 30);
  Image8 mask{40, 30, 1, std::vector<std::uint8_t>(40 * 30, 255)};
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 6; ++x) mask.pixels[y * 40 + x] = 0;
  }
  const sp::Segmentation s = sp::slicSuperpixels(im, mask, {6, 10.0, 5});
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 6; ++x) EXPECT_EQ(s.region[y * 40 + x], -1);
  }
  // Connectivity: flood fill from the first pixel of each region reaches all its pixels.
  for (int r = 0; r < s.num_regions; ++r) {
    std::vector<int> stack, seen(40 * 30, 0);
    int total = 0, first = -1;
    for (int i = 0; i < 40 * 30; ++i) {
      if (s.region[i] == r) {
        ++total;
        if (first < 0) first = i;
      }
    }
    ASSERT_GE(first, 0) << "region ids are compact";
    int reached = 0;
    stack.push_back(first);
    seen[first] = 1;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      ++reached;
      const int x = i % 40, y = i / 40;
      const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
      for (const auto& n : nb) {
        if (n[0] < 0 || n[1] < 0 || n[0] >= 40 || n[1] >= 30) continue;
        const int j = n[1] * 40 + n[0];
        if (!seen[j] && s.region[j] == r) seen[j] = 1, stack.push_back(j);
      }
    }
    EXPECT_EQ(reached, total) << "region " << r;
  }
}

TEST(Superpixels, BadInputIsAnError) {
  const Image8 im = twoColourImage(16, 16);
  EXPECT_THROW(sp::slicSuperpixels(im, {}, {1, 10.0, 5}), sadsplat::Error);
  Image8 mask{8, 8, 1, std::vector<std::uint8_t>(64, 255)};
  EXPECT_THROW(sp::slicSuperpixels(im, mask), sadsplat::Error);
  Image8 grey{16, 16, 1, std::vector<std::uint8_t>(256, 0)};
  EXPECT_THROW(sp::slicSuperpixels(grey, {}), sadsplat::Error);
}

TEST(Superpixels, LabOfKnownColours) {
  float lab[3];
  sp::srgbToLab(255, 255, 255, lab);
  EXPECT_NEAR(lab[0], 100.0, 0.05);
  EXPECT_NEAR(lab[1], 0.0, 0.05);
  EXPECT_NEAR(lab[2], 0.0, 0.05);
  sp::srgbToLab(255, 0, 0, lab);  // reference CIELab of sRGB red: (53.24, 80.09, 67.20)
  EXPECT_NEAR(lab[0], 53.24, 0.1);
  EXPECT_NEAR(lab[1], 80.09, 0.2);
  EXPECT_NEAR(lab[2], 67.20, 0.2);
}
