// SPDX-License-Identifier: BSD-3-Clause
// Closed meshes on voxel grids: partial-volume coverage and depth below the surface.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav::sim {

/// Cubic voxels along the mesh frame's axes: voxel (i, j, k) is centred at
/// origin + spacing_mm (i, j, k) and stored at Index(i, j, k) (i fastest).
struct VoxelGrid {
  std::array<int, 3> dims = {0, 0, 0};
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // centre of voxel (0, 0, 0)
  double spacing_mm = 1.0;
  std::size_t size() const;
  std::size_t Index(int i, int j, int k) const;
  /// Voxel whose cell (centre +- spacing / 2) contains coordinate x along `axis`.
  int Cell(int axis, double x) const;
};

/// The grid over the mesh's bounding box plus `margin_mm`, its origin on a multiple of the
/// spacing. PreconditionError when it would exceed `max_voxels`.
VoxelGrid GridAroundMesh(const TriangleMesh& mesh, double spacing_mm, double margin_mm,
                         std::int64_t max_voxels);

/// Fraction of each voxel inside the closed mesh: along x exact (the crossings of each sub-row
/// pair up into inside intervals), subsamples^2 sub-rows per voxel in y and z.
std::vector<float> MeshInsideFraction(const TriangleMesh& mesh, const VoxelGrid& grid,
                                      int subsamples);

/// Squared distance [mm^2] from each voxel centre to the nearest voxel centre whose fraction is
/// below 0.5 (0 for those), by the separable transform of Felzenszwalb & Huttenlocher 2012.
std::vector<double> SquaredDistanceToOutside(const std::vector<float>& fraction,
                                             const VoxelGrid& grid);

}  // namespace tofnav::sim
