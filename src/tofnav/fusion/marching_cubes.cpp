// SPDX-License-Identifier: BSD-3-Clause
// Marching cubes over the TSDF's blocks or a dense grid: both are loaded as 8^3 bricks.
#include "tofnav/fusion/marching_cubes.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/fusion/brick_mesher.hpp"

namespace tofnav {
namespace {

static_assert(kTsdfBlockSide == kBrickSide, "TSDF blocks are the mesher's bricks");

/// Fills a brick's samples from the TSDF block with the same key and its +x, +y, +z neighbours
/// (the far corners of the brick's last cells), missing blocks giving invalid samples.
void LoadTsdfBrick(const TsdfVolume& volume, const Eigen::Vector3i& key, double min_weight,
                   BrickSamples& samples) {
  std::array<const TsdfBlock*, 8> blocks{};  // by offset bits x | y << 1 | z << 2
  for (int bits = 0; bits < 8; ++bits) {
    const std::optional<std::size_t> id =
        volume.FindBlock(key + Eigen::Vector3i(bits & 1, (bits >> 1) & 1, (bits >> 2) & 1));
    blocks[static_cast<std::size_t>(bits)] = id ? &volume.block(*id) : nullptr;
  }
  const auto threshold = static_cast<float>(min_weight);
  for (int z = 0; z < kBrickSamplesSide; ++z) {
    for (int y = 0; y < kBrickSamplesSide; ++y) {
      // x = 0..7 come from one block, x = 8 from its +x neighbour.
      const int row_bits = (y == kBrickSide ? 2 : 0) | (z == kBrickSide ? 4 : 0);
      const auto entry = static_cast<std::size_t>(
          kTsdfBlockSide * ((y % kBrickSide) + kTsdfBlockSide * (z % kBrickSide)));
      const auto s = static_cast<std::size_t>(kBrickSamplesSide * (y + kBrickSamplesSide * z));
      const TsdfBlock* block = blocks[static_cast<std::size_t>(row_bits)];
      const TsdfBlock* next = blocks[static_cast<std::size_t>(row_bits | 1)];
      for (std::size_t x = 0; x < kBrickSide; ++x) {
        samples.value[s + x] = block != nullptr ? block->tsdf[entry + x] : 0.0f;
        samples.valid[s + x] = block != nullptr && block->weight[entry + x] > threshold ? 1 : 0;
      }
      samples.value[s + kBrickSide] = next != nullptr ? next->tsdf[entry] : 0.0f;
      samples.valid[s + kBrickSide] = next != nullptr && next->weight[entry] > threshold ? 1 : 0;
    }
  }
}

/// Fills a tile's samples from the grid; lattice points outside the grid are invalid.
void LoadGridBrick(const Grid3<float>& grid, const Eigen::Vector3i& key, float iso,
                   BrickSamples& samples) {
  const Eigen::Vector3i first = kBrickSide * key;
  for (int z = 0; z < kBrickSamplesSide; ++z) {
    for (int y = 0; y < kBrickSamplesSide; ++y) {
      for (int x = 0; x < kBrickSamplesSide; ++x) {
        const auto s =
            static_cast<std::size_t>(x + kBrickSamplesSide * (y + kBrickSamplesSide * z));
        const int i = first.x() + x, j = first.y() + y, k = first.z() + z;
        const bool inside = grid.Contains(i, j, k);
        samples.value[s] = inside ? grid(i, j, k) - iso : 0.0f;
        samples.valid[s] = inside && std::isfinite(samples.value[s]) ? 1 : 0;
      }
    }
  }
}

/// Tiles whose samples hold finite values on both sides of the iso value, in (z, y, x) order.
/// A tile owns the edges leaving its lattice points 8 key .. 8 key + 7, so every lattice point
/// needs an owner: ceil(dims / 8) tiles per axis, not ceil(cells / 8). When dims - 1 is a multiple
/// of 8 the last tile holds only the grid's last layer, whose in-layer edges cross wherever the
/// surface meets that border (a head cut by the field of view; docs/registration.md 1.).
std::vector<Eigen::Vector3i> ActiveTiles(const Grid3<float>& grid, float iso) {
  const Eigen::Vector3i tiles = (grid.dims().array().max(0) + kBrickSide - 1) / kBrickSide;
  const std::size_t count = static_cast<std::size_t>(tiles.x()) *
                            static_cast<std::size_t>(tiles.y()) *
                            static_cast<std::size_t>(tiles.z());
  std::vector<std::uint8_t> active(count, 0);
  ParallelFor(0, static_cast<std::int64_t>(count), [&](std::int64_t t) {
    const Eigen::Vector3i key(static_cast<int>(t % tiles.x()),
                              static_cast<int>((t / tiles.x()) % tiles.y()),
                              static_cast<int>(t / (std::int64_t{tiles.x()} * tiles.y())));
    const Eigen::Vector3i lo = kBrickSide * key;
    const Eigen::Vector3i hi = (lo + Eigen::Vector3i::Constant(kBrickSide))
                                   .cwiseMin(grid.dims() - Eigen::Vector3i::Ones());
    bool below = false, above = false;
    for (int k = lo.z(); k <= hi.z() && !(below && above); ++k) {
      for (int j = lo.y(); j <= hi.y(); ++j) {
        for (int i = lo.x(); i <= hi.x(); ++i) {
          const float v = grid(i, j, k);
          below |= v < iso;  // false for NaN
          above |= v >= iso;
        }
      }
    }
    active[static_cast<std::size_t>(t)] = below && above ? 1 : 0;
  });
  std::vector<Eigen::Vector3i> keys;
  for (std::size_t t = 0; t < count; ++t) {
    if (active[t] == 0) continue;
    const auto i = static_cast<std::int64_t>(t);
    keys.emplace_back(static_cast<int>(i % tiles.x()),
                      static_cast<int>((i / tiles.x()) % tiles.y()),
                      static_cast<int>(i / (std::int64_t{tiles.x()} * tiles.y())));
  }
  return keys;
}

}  // namespace

void TsdfMeshOptions::Check() const {
  Require(std::isfinite(min_weight) && min_weight >= 0.0,
          "TsdfMeshOptions::min_weight must be >= 0");
}

void GridIsoSurfaceOptions::Check() const {
  Require(std::isfinite(iso_value), "GridIsoSurfaceOptions::iso_value must be finite");
}

TriangleMesh ExtractIsoSurface(const TsdfVolume& volume, const TsdfMeshOptions& options) {
  options.Check();
  BrickLattice lattice;
  lattice.keys.assign(volume.block_keys().begin(), volume.block_keys().end());
  std::sort(lattice.keys.begin(), lattice.keys.end(), BrickKeyLess);
  lattice.load = [&](std::size_t i, BrickSamples& samples) {
    LoadTsdfBrick(volume, lattice.keys[i], options.min_weight, samples);
  };
  lattice.linear = volume.options().voxel_size_mm * Eigen::Matrix3d::Identity();
  return MeshBricks(lattice);
}

TriangleMesh ExtractIsoSurface(const Grid3<float>& grid, const GridIsoSurfaceOptions& options) {
  options.Check();
  BrickLattice lattice;
  lattice.keys = ActiveTiles(grid, options.iso_value);
  lattice.load = [&](std::size_t i, BrickSamples& samples) {
    LoadGridBrick(grid, lattice.keys[i], options.iso_value, samples);
  };
  lattice.linear = grid.frame_from_ijk().topLeftCorner<3, 3>();
  lattice.offset = grid.frame_from_ijk().topRightCorner<3, 1>();
  // Below-iso outside reverses the orientation, and so does a mirroring index -> mm transform.
  lattice.flip =
      (options.outside == IsoSurfaceOutside::kBelow) != (lattice.linear.determinant() < 0.0);
  return MeshBricks(lattice);
}

}  // namespace tofnav
