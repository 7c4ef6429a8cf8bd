// SPDX-License-Identifier: BSD-3-Clause
// CtVolume helpers: indexing, voxel centres and the validity check.
#include "tofnav/imaging/ct_volume.hpp"

#include <Eigen/LU>
#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// A 3x3 block whose determinant is this small relative to the product of its column lengths is
// treated as singular (columns nearly coplanar): dimensionless.
constexpr double kMinRelativeDeterminant = 1e-9;

}  // namespace

std::size_t CtVolume::voxel_count() const {
  if (dims[0] <= 0 || dims[1] <= 0 || dims[2] <= 0) return 0;
  return static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
         static_cast<std::size_t>(dims[2]);
}

Eigen::Vector3d CtVolume::spacing_mm() const {
  return image_from_ijk.topLeftCorner<3, 3>().colwise().norm().transpose();
}

float CtVolume::at(int i, int j, int k) const {
  Require(Contains(i, j, k) && values.size() == voxel_count(), "voxel outside the volume");
  return values[Index(i, j, k)];
}

float& CtVolume::at(int i, int j, int k) {
  Require(Contains(i, j, k) && values.size() == voxel_count(), "voxel outside the volume");
  return values[Index(i, j, k)];
}

Eigen::Vector3d CtVolume::VoxelCentre(int i, int j, int k) const {
  return image_from_ijk.topLeftCorner<3, 3>() * Eigen::Vector3d(i, j, k) +
         image_from_ijk.topRightCorner<3, 1>();
}

Eigen::Vector3d CtVolume::PointToIjk(const Eigen::Vector3d& point_in_image) const {
  return image_from_ijk.topLeftCorner<3, 3>().partialPivLu().solve(
      point_in_image - image_from_ijk.topRightCorner<3, 1>());
}

void CtVolume::Check() const {
  Require(dims[0] > 0 && dims[1] > 0 && dims[2] > 0, "volume dimensions must be positive");
  Require(values.size() == voxel_count(), "volume values.size() must equal nx * ny * nz");
  Require(image_from_ijk.allFinite(), "image_from_ijk must be finite");
  Require(image_from_ijk.row(3) == Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0),
          "image_from_ijk last row must be (0 0 0 1)");
  const Eigen::Matrix3d block = image_from_ijk.topLeftCorner<3, 3>();
  const double scale = block.col(0).norm() * block.col(1).norm() * block.col(2).norm();
  Require(scale > 0.0 && std::abs(block.determinant()) > kMinRelativeDeterminant * scale,
          "image_from_ijk must be invertible (non-zero, non-coplanar columns)");
}

CtVolume CropVolume(const CtVolume& volume, const std::array<int, 3>& first,
                    const std::array<int, 3>& dims) {
  volume.Check();
  for (std::size_t a = 0; a < 3; ++a) {
    Require(first[a] >= 0 && dims[a] > 0 && dims[a] <= volume.dims[a] - first[a],
            "CropVolume: the box must be non-empty and inside the volume");
  }
  CtVolume crop = volume;
  crop.dims = dims;
  crop.image_from_ijk.topRightCorner<3, 1>() = volume.VoxelCentre(first[0], first[1], first[2]);
  crop.values.resize(crop.voxel_count());
  for (int k = 0; k < dims[2]; ++k) {
    for (int j = 0; j < dims[1]; ++j) {
      for (int i = 0; i < dims[0]; ++i) {
        crop.values[crop.Index(i, j, k)] =
            volume.values[volume.Index(first[0] + i, first[1] + j, first[2] + k)];
      }
    }
  }
  return crop;
}

}  // namespace tofnav
