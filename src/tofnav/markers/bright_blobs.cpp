// SPDX-License-Identifier: BSD-3-Clause
// Connected components of bright pixels: threshold scan into row runs, union-find over runs.
#include "tofnav/markers/bright_blobs.hpp"

#include <algorithm>
#include <cstddef>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// Appends the runs of pixels >= threshold of one row. Markers cover a tiny part of the image, so
// blocks without a bright pixel are skipped with a branch-free maximum (vectorised).
void ScanRow(const std::uint16_t* row, int width, int v, std::uint16_t threshold,
             std::vector<PixelRun>& runs) {
  constexpr int kBlock = 32;
  int u = 0;
  while (u < width) {
    if (u + kBlock <= width) {
      std::uint16_t peak = 0;
      for (int i = 0; i < kBlock; ++i) peak = std::max(peak, row[u + i]);
      if (peak < threshold) {
        u += kBlock;
        continue;
      }
    }
    const int block_end = std::min(width, u + kBlock);
    while (u < block_end) {
      if (row[u] < threshold) {
        ++u;
        continue;
      }
      const int begin = u;
      while (u < width && row[u] >= threshold) ++u;
      runs.push_back({v, begin, u});
    }
  }
}

int Find(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    const int grand = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    parent[static_cast<std::size_t>(i)] = grand;  // path halving
    i = grand;
  }
  return i;
}

// The smaller run index becomes the root, so every root is its component's first run.
void Union(std::vector<int>& parent, int a, int b) {
  a = Find(parent, a);
  b = Find(parent, b);
  if (a == b) return;
  if (a < b) {
    parent[static_cast<std::size_t>(b)] = a;
  } else {
    parent[static_cast<std::size_t>(a)] = b;
  }
}

// Unites every run of [row, row_end) with the runs of [prev, prev_end) (the row above) that it
// touches under 8-connectivity: [p.b, p.e) meets [r.b - 1, r.e + 1).
void LinkRows(const std::vector<PixelRun>& runs, int prev, int prev_end, int row, int row_end,
              std::vector<int>& parent) {
  int j = prev;
  for (int r = row; r < row_end; ++r) {
    const PixelRun& run = runs[static_cast<std::size_t>(r)];
    while (j < prev_end && runs[static_cast<std::size_t>(j)].u_end < run.u_begin) ++j;
    for (int k = j; k < prev_end && runs[static_cast<std::size_t>(k)].u_begin <= run.u_end; ++k) {
      Union(parent, k, r);
    }
  }
}

}  // namespace

BrightBlobs FindBrightBlobs(const Image<std::uint16_t>& ab, std::uint16_t threshold) {
  Require(threshold >= 1, "FindBrightBlobs: threshold must be >= 1");
  BrightBlobs result;
  std::vector<PixelRun>& runs = result.runs;
  std::vector<int> parent;
  int prev = 0, prev_end = 0, prev_v = -2;
  for (int v = 0; v < ab.height(); ++v) {
    const int row = static_cast<int>(runs.size());
    ScanRow(&ab(0, v), ab.width(), v, threshold, runs);
    const int row_end = static_cast<int>(runs.size());
    if (row_end == row) continue;
    for (int i = row; i < row_end; ++i) parent.push_back(i);
    if (prev_v == v - 1) LinkRows(runs, prev, prev_end, row, row_end, parent);
    prev = row;
    prev_end = row_end;
    prev_v = v;
  }
  // Label components in order of their root (first run), accumulate statistics.
  const std::size_t n = runs.size();
  std::vector<int> label(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int root = Find(parent, static_cast<int>(i));
    if (root == static_cast<int>(i)) {
      label[i] = static_cast<int>(result.blobs.size());
      const PixelRun& r = runs[i];
      result.blobs.push_back({0, 0, 0, r.u_begin, r.v, r.u_end - 1, r.v, 0});
    } else {
      label[i] = label[static_cast<std::size_t>(root)];
    }
    BrightBlob& blob = result.blobs[static_cast<std::size_t>(label[i])];
    const PixelRun& r = runs[i];
    ++blob.run_count;
    blob.area_px += r.u_end - r.u_begin;
    blob.u_min = std::min(blob.u_min, r.u_begin);
    blob.u_max = std::max(blob.u_max, r.u_end - 1);
    blob.v_max = r.v;  // runs arrive in raster order
    const std::uint16_t* row = &ab(0, r.v);
    for (int u = r.u_begin; u < r.u_end; ++u) blob.ab_peak = std::max(blob.ab_peak, row[u]);
  }
  // Group the runs by component (a stable counting sort keeps raster order within each).
  int offset = 0;
  for (BrightBlob& blob : result.blobs) {
    blob.first_run = offset;
    offset += blob.run_count;
  }
  std::vector<int> cursor(result.blobs.size());
  for (std::size_t b = 0; b < result.blobs.size(); ++b) cursor[b] = result.blobs[b].first_run;
  std::vector<PixelRun> grouped(n);
  for (std::size_t i = 0; i < n; ++i) {
    grouped[static_cast<std::size_t>(cursor[static_cast<std::size_t>(label[i])]++)] = runs[i];
  }
  runs = std::move(grouped);
  return result;
}

}  // namespace tofnav
