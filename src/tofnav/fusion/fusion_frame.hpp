// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: one frame's cleaned range, weights, pose, and the per-block kernel.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/fusion/pixel_lookup.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

/// Largest |block key| per axis: keys are packed into 21 bits each.
constexpr int kMaxBlockKey = (1 << 20) - 1;

/// The camera tables (built once) and the state of the frame being fused.
class FusionFrame {
 public:
  FusionFrame(const TsdfOptions& options, const AhatCamera& camera);

  /// Cleans the range image (invalid pixels, range limits, ROI), computes the weights and
  /// returns the keys of every block within one truncation of a valid point, in scan order
  /// (z, y, x ascending). Sets pixels_used.
  std::vector<Eigen::Vector3i> Prepare(const Image<float>& range_mm, const Rigid3d& tool_from_ahat,
                                       const Image<float>& pixel_weight);
  int pixels_used() const { return pixels_used_; }

  /// Updates one block from the prepared frame (Curless & Levoy running average); returns the
  /// number of voxels updated. Safe to call concurrently for different blocks.
  std::int64_t IntegrateBlock(const Eigen::Vector3i& key, TsdfBlock& block) const;
  /// Starts fetching the camera table entries that IntegrateBlock(key) will read first.
  void PrefetchBlock(const Eigen::Vector3i& key) const;

 private:
  void CleanRows(const Image<float>& range_mm, const Rigid3d& tool_from_ahat);
  void ComputeWeights(const Image<float>& pixel_weight);
  /// The block's voxel steps (columns) and the position of its voxel (0, 0, 0) in `ahat`.
  std::pair<Eigen::Matrix3f, Eigen::Vector3f> BlockInAhat(const Eigen::Vector3i& key) const;

  TsdfOptions options_;
  PixelLookup lookup_;
  int width_ = 0;
  int height_ = 0;
  float truncation_mm_ = 0.0f;
  float max_step_mm_ = 0.0f;  // largest range step between neighbouring pixels on one surface
  std::vector<std::array<float, 3>> rays_;  // unit rays in `ahat`; zero where invalid
  // Per frame:
  std::vector<float> range_mm_;                        // cleaned, 0 = unusable
  std::vector<std::array<float, 3>> points_;           // in `tool` where range_mm_ > 0
  std::vector<float> weight_;                          // per pixel; empty when every weight is 1
  std::vector<std::array<float, 3>> row_lo_, row_hi_;  // per-row bounds of points_
  std::vector<int> row_used_;                          // per-row count of usable pixels
  std::vector<std::pair<std::size_t, std::size_t>> row_span_;  // per row: usable in [first, second)
  std::vector<std::uint8_t> block_mask_;  // touched blocks in the frame's key box
  Eigen::Matrix3f ahat_from_tool_rotation_ = Eigen::Matrix3f::Identity();
  Eigen::Vector3f ahat_from_tool_translation_ = Eigen::Vector3f::Zero();
  std::array<float, 3> camera_in_tool_{};
  Eigen::Vector3i roi_lo_vox_ = Eigen::Vector3i::Constant(-(kMaxBlockKey + 1) * kTsdfBlockSide);
  Eigen::Vector3i roi_hi_vox_ = Eigen::Vector3i::Constant(kMaxBlockKey * kTsdfBlockSide);
  int pixels_used_ = 0;
  bool use_avx2_ = false;  // the CPU runs the eight-lane row update
};

}  // namespace tofnav
