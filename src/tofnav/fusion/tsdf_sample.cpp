// SPDX-License-Identifier: BSD-3-Clause
// Reading the fused model back: voxels and trilinear samples with their gradient.
#include "tofnav/fusion/tsdf_sample.hpp"

#include <cmath>

#include "tofnav/fusion/fusion_frame.hpp"

namespace tofnav {
namespace {

int FloorDiv(int a) { return a / kTsdfBlockSide - (a % kTsdfBlockSide < 0 ? 1 : 0); }

}  // namespace

std::optional<TsdfVoxel> TsdfReader::Voxel(const Eigen::Vector3i& index, double min_weight) {
  const Eigen::Vector3i key(FloorDiv(index.x()), FloorDiv(index.y()), FloorDiv(index.z()));
  if (key != cached_key_) {
    cached_key_ = key;
    cached_block_ = volume_.FindBlock(key);
  }
  if (!cached_block_) return std::nullopt;
  const Eigen::Vector3i local = index - kTsdfBlockSide * key;
  const auto entry = static_cast<std::size_t>(
      local.x() + kTsdfBlockSide * (local.y() + kTsdfBlockSide * local.z()));
  const TsdfBlock& block = volume_.block(*cached_block_);
  const float weight = block.weight[entry];
  if (!(weight > 0.0f) || weight < min_weight) return std::nullopt;
  return TsdfVoxel{block.tsdf[entry] * volume_.options().truncation_mm(), weight};
}

std::optional<TsdfVoxel> TsdfReader::NearestVoxel(const Eigen::Vector3d& point_in_tool,
                                                  double min_weight) {
  const Eigen::Vector3d g = point_in_tool / volume_.options().voxel_size_mm;
  if (!(g.cwiseAbs().maxCoeff() < kMaxBlockKey * kTsdfBlockSide)) return std::nullopt;
  return Voxel(
      Eigen::Vector3i(static_cast<int>(std::lround(g.x())), static_cast<int>(std::lround(g.y())),
                      static_cast<int>(std::lround(g.z()))),
      min_weight);
}

std::optional<TsdfSample> TsdfReader::Sample(const Eigen::Vector3d& point_in_tool,
                                             double min_weight) {
  const double voxel_mm = volume_.options().voxel_size_mm;
  const Eigen::Vector3d g = point_in_tool / voxel_mm;  // voxel i is centred at i * voxel
  if (!(g.cwiseAbs().maxCoeff() < kMaxBlockKey * kTsdfBlockSide - 1)) return std::nullopt;
  const Eigen::Vector3d base = g.array().floor();
  const Eigen::Vector3i i0 = base.cast<int>();
  const Eigen::Vector3d f = g - base;  // position in the cell, [0, 1)^3
  double d[8];                         // corners c = x | y << 1 | z << 2
  for (int c = 0; c < 8; ++c) {
    const std::optional<TsdfVoxel> voxel =
        Voxel(i0 + Eigen::Vector3i(c & 1, (c >> 1) & 1, (c >> 2) & 1), min_weight);
    if (!voxel) return std::nullopt;
    d[c] = voxel->distance_mm;
  }
  // Trilinear interpolation along x, then y, then z; the gradient is its exact derivative.
  const double x00 = d[0] + f.x() * (d[1] - d[0]), x10 = d[2] + f.x() * (d[3] - d[2]);
  const double x01 = d[4] + f.x() * (d[5] - d[4]), x11 = d[6] + f.x() * (d[7] - d[6]);
  const double y0 = x00 + f.y() * (x10 - x00), y1 = x01 + f.y() * (x11 - x01);
  TsdfSample s;
  s.distance_mm = y0 + f.z() * (y1 - y0);
  const double dx00 = d[1] - d[0], dx10 = d[3] - d[2], dx01 = d[5] - d[4], dx11 = d[7] - d[6];
  const double dx0 = dx00 + f.y() * (dx10 - dx00), dx1 = dx01 + f.y() * (dx11 - dx01);
  s.gradient.x() = dx0 + f.z() * (dx1 - dx0);
  s.gradient.y() = (x10 - x00) + f.z() * ((x11 - x01) - (x10 - x00));
  s.gradient.z() = y1 - y0;
  s.gradient /= voxel_mm;
  return s;
}

}  // namespace tofnav
