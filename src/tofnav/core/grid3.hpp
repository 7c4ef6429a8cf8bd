// SPDX-License-Identifier: BSD-3-Clause
// A dense 3-D grid of values with its affine voxel index -> mm transform (CT, dense SDFs).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {

/// Voxel (i, j, k) is stored at i + nx * (j + ny * k) (i fastest), the layout of CT readers.
/// `frame_from_ijk` maps a (continuous) voxel index to mm in the grid's frame: columns 0..2 are
/// direction * spacing, column 3 is the centre of voxel (0, 0, 0); last row (0 0 0 1).
template <typename T>
class Grid3 {
 public:
  Grid3() = default;
  Grid3(const Eigen::Vector3i& dims, T fill,
        const Eigen::Matrix4d& frame_from_ijk = Eigen::Matrix4d::Identity())
      : dims_(dims), values_(CheckedSize(dims), fill), frame_from_ijk_(frame_from_ijk) {
    CheckTransform();
  }
  /// Takes ownership of `values` (nx * ny * nz of them, i fastest), e.g. a CT volume's.
  Grid3(const Eigen::Vector3i& dims, std::vector<T> values,
        const Eigen::Matrix4d& frame_from_ijk = Eigen::Matrix4d::Identity())
      : dims_(dims), values_(std::move(values)), frame_from_ijk_(frame_from_ijk) {
    Require(values_.size() == CheckedSize(dims), "Grid3: value count != nx * ny * nz");
    CheckTransform();
  }

  const Eigen::Vector3i& dims() const { return dims_; }
  std::size_t size() const { return values_.size(); }
  bool empty() const { return values_.empty(); }
  bool Contains(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < dims_.x() && j < dims_.y() && k < dims_.z();
  }
  std::size_t Index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims_.x()) *
               (static_cast<std::size_t>(j) +
                static_cast<std::size_t>(dims_.y()) * static_cast<std::size_t>(k));
  }

  /// Unchecked access.
  T& operator()(int i, int j, int k) { return values_[Index(i, j, k)]; }
  const T& operator()(int i, int j, int k) const { return values_[Index(i, j, k)]; }
  /// Bounds-checked access; throws PreconditionError outside the grid.
  const T& At(int i, int j, int k) const {
    Require(Contains(i, j, k), "Grid3: voxel outside the grid");
    return values_[Index(i, j, k)];
  }

  std::span<T> values() { return values_; }
  std::span<const T> values() const { return values_; }
  const Eigen::Matrix4d& frame_from_ijk() const { return frame_from_ijk_; }
  /// Position [mm] of a continuous voxel index.
  Eigen::Vector3d PointFromIndex(const Eigen::Vector3d& ijk) const {
    return frame_from_ijk_.topLeftCorner<3, 3>() * ijk + frame_from_ijk_.topRightCorner<3, 1>();
  }

 private:
  static std::size_t CheckedSize(const Eigen::Vector3i& dims) {
    Require((dims.array() >= 0).all(), "Grid3: dimensions must be non-negative");
    return static_cast<std::size_t>(dims.x()) * static_cast<std::size_t>(dims.y()) *
           static_cast<std::size_t>(dims.z());
  }
  void CheckTransform() const {
    Require(frame_from_ijk_.allFinite() &&
                frame_from_ijk_.row(3) == Eigen::RowVector4d(0, 0, 0, 1) &&
                frame_from_ijk_.topLeftCorner<3, 3>().determinant() != 0.0,
            "Grid3: frame_from_ijk must be finite, affine and invertible");
  }

  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<T> values_;
  Eigen::Matrix4d frame_from_ijk_ = Eigen::Matrix4d::Identity();
};

}  // namespace tofnav
