// SPDX-License-Identifier: BSD-3-Clause
// CtVolume: a dense scalar volume (CT in HU, or MR intensity) with its voxel -> LPS mm affine.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace tofnav {

/// A 3-D scalar volume in the `image` frame (patient LPS, mm). Voxel (i, j, k) is stored at
/// values[i + nx * (j + ny * k)] (i fastest); io/ readers fill every field.
struct CtVolume {
  std::array<int, 3> dims = {0, 0, 0};  ///< (nx, ny, nz) [voxels]
  std::vector<float> values;            ///< HU (CT) or intensity (MR), rescale already applied
  /// Voxel index -> LPS [mm]: columns 0..2 are direction * spacing, column 3 is the centre of
  /// voxel (0, 0, 0). Need not be orthogonal (gantry tilt) but must be invertible.
  Eigen::Matrix4d image_from_ijk = Eigen::Matrix4d::Identity();
  std::string modality;  ///< "CT", "MR", ... or empty when the file does not say
  std::string name;      ///< series description / file name, for reports
  /// How image_from_ijk was derived, e.g. "nifti sform (code 4)"; readers set it (for logs).
  std::string geometry_source;

  int nx() const { return dims[0]; }
  int ny() const { return dims[1]; }
  int nz() const { return dims[2]; }
  /// nx * ny * nz (0 when any dimension is not positive).
  std::size_t voxel_count() const;
  /// Length of each affine column [mm]: the step between neighbouring voxels along i, j, k.
  Eigen::Vector3d spacing_mm() const;
  /// Linear index of voxel (i, j, k); no bounds check.
  std::size_t Index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims[0]) *
               (static_cast<std::size_t>(j) +
                static_cast<std::size_t>(dims[1]) * static_cast<std::size_t>(k));
  }
  bool Contains(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
  }
  /// Bounds-checked value of voxel (i, j, k); PreconditionError outside the volume.
  float at(int i, int j, int k) const;
  float& at(int i, int j, int k);
  /// Centre of voxel (i, j, k) in `image` (LPS, mm).
  Eigen::Vector3d VoxelCentre(int i, int j, int k) const;
  /// Continuous voxel coordinates of a point in `image` (LPS, mm): the inverse of image_from_ijk.
  Eigen::Vector3d PointToIjk(const Eigen::Vector3d& point_in_image) const;
  /// Throws PreconditionError unless dims are positive, values.size() == voxel_count(), and
  /// image_from_ijk is finite with last row (0 0 0 1) and an invertible 3x3 block.
  void Check() const;
};

/// The voxels first .. first + dims - 1 of `volume` (same image frame: the origin moves to voxel
/// `first`), e.g. to simulate a field of view that cuts the head. PreconditionError unless the
/// box is non-empty and inside the volume.
CtVolume CropVolume(const CtVolume& volume, const std::array<int, 3>& first,
                    const std::array<int, 3>& dims);

}  // namespace tofnav
