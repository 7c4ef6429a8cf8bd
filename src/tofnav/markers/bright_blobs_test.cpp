// SPDX-License-Identifier: BSD-3-Clause
// Run-length connected components against hand-made cases and a flood-fill oracle.
#include "tofnav/markers/bright_blobs.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace tofnav {
namespace {

constexpr std::uint16_t kOn = 2000, kThreshold = 1000;

Image<std::uint16_t> FromRows(const std::vector<std::string>& rows) {
  Image<std::uint16_t> image(static_cast<int>(rows[0].size()), static_cast<int>(rows.size()));
  for (int v = 0; v < image.height(); ++v) {
    for (int u = 0; u < image.width(); ++u) {
      image(u, v) = rows[static_cast<std::size_t>(v)][static_cast<std::size_t>(u)] == '#' ? kOn : 0;
    }
  }
  return image;
}

// Label image by an 8-connected flood fill: the oracle.
std::vector<int> FloodLabels(const Image<std::uint16_t>& image, int& count) {
  std::vector<int> label(image.size(), -1);
  count = 0;
  const int w = image.width(), h = image.height();
  for (int start = 0; start < w * h; ++start) {
    if (image.pixels()[static_cast<std::size_t>(start)] < kThreshold ||
        label[static_cast<std::size_t>(start)] >= 0) {
      continue;
    }
    std::vector<int> stack = {start};
    label[static_cast<std::size_t>(start)] = count;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const int u = p % w + du, v = p / w + dv;
          if (!image.Contains(u, v) || image(u, v) < kThreshold) continue;
          int& l = label[static_cast<std::size_t>(v * w + u)];
          if (l < 0) {
            l = count;
            stack.push_back(v * w + u);
          }
        }
      }
    }
    ++count;
  }
  return label;
}

TEST(FindBrightBlobs, JoinsDiagonalsAndLateMergingBranches) {
  const Image<std::uint16_t> image = FromRows({
      "#...#.....",  // two branches of a U, joined two rows below
      "#...#..##.",
      "#####...#.",
      ".........#",  // diagonal neighbour of the blob on the right
      "..........",
      "...##.....",
  });
  const BrightBlobs blobs = FindBrightBlobs(image, kThreshold);
  ASSERT_EQ(blobs.blobs.size(), 3u);
  EXPECT_EQ(blobs.blobs[0].area_px, 9);  // the U
  EXPECT_EQ(blobs.blobs[0].u_max, 4);
  EXPECT_EQ(blobs.blobs[0].v_max, 2);
  EXPECT_EQ(blobs.blobs[1].area_px, 4);  // the hook with its diagonal pixel
  EXPECT_EQ(blobs.blobs[1].u_min, 7);
  EXPECT_EQ(blobs.blobs[1].u_max, 9);
  EXPECT_EQ(blobs.blobs[2].area_px, 2);
  EXPECT_EQ(blobs.blobs[2].ab_peak, kOn);
  int runs = 0;
  for (const BrightBlob& b : blobs.blobs) runs += b.run_count;
  EXPECT_EQ(runs, static_cast<int>(blobs.runs.size()));
}

TEST(FindBrightBlobs, HandlesEmptyAndFullySaturatedImages) {
  EXPECT_TRUE(FindBrightBlobs(Image<std::uint16_t>(64, 64, 0), kThreshold).blobs.empty());
  const BrightBlobs full = FindBrightBlobs(Image<std::uint16_t>(70, 40, 65535), kThreshold);
  ASSERT_EQ(full.blobs.size(), 1u);
  EXPECT_EQ(full.blobs[0].area_px, 70 * 40);
  EXPECT_EQ(full.blobs[0].run_count, 40);
  EXPECT_THROW(FindBrightBlobs(Image<std::uint16_t>(8, 8, 0), 0), std::invalid_argument);
}

TEST(FindBrightBlobs, MatchesAFloodFillOnRandomImages) {
  std::mt19937_64 rng(11);
  for (const double density : {0.05, 0.3, 0.55}) {
    std::bernoulli_distribution on(density);
    Image<std::uint16_t> image(97, 61);  // width not a multiple of the scan block
    for (std::uint16_t& p : image.pixels()) p = on(rng) ? kOn : 999;
    int count = 0;
    const std::vector<int> oracle = FloodLabels(image, count);
    const BrightBlobs blobs = FindBrightBlobs(image, kThreshold);
    ASSERT_EQ(static_cast<int>(blobs.blobs.size()), count) << density;
    // Same partition: each blob's pixels carry one oracle label, and areas agree.
    for (const BrightBlob& blob : blobs.blobs) {
      const PixelRun& first = blobs.runs[static_cast<std::size_t>(blob.first_run)];
      const int expected = oracle[static_cast<std::size_t>(first.v * 97 + first.u_begin)];
      int area = 0;
      for (int r = blob.first_run; r < blob.first_run + blob.run_count; ++r) {
        const PixelRun& run = blobs.runs[static_cast<std::size_t>(r)];
        for (int u = run.u_begin; u < run.u_end; ++u) {
          ASSERT_EQ(oracle[static_cast<std::size_t>(run.v * 97 + u)], expected);
          ++area;
        }
      }
      EXPECT_EQ(area, blob.area_px);
      EXPECT_EQ(static_cast<int>(std::count(oracle.begin(), oracle.end(), expected)), area);
    }
  }
}

}  // namespace
}  // namespace tofnav
