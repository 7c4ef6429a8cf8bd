// SPDX-License-Identifier: BSD-3-Clause
// Projective TSDF fusion of AHAT range frames in the tool frame (Sec. III-B), sparse 8^3 blocks.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/fusion/block_index.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

enum class TsdfWeighting {
  kConstant,   // every observation weighs 1
  kIncidence,  // cos(incidence angle) of the pixel's surface normal, floored
};
/// How a voxel reads the range image. Either way the four pixels around its projection must be
/// valid and within max_range_step_mm of each other (one surface), else the frame skips it.
enum class TsdfDepthSampling {
  kNearest,   // range of the nearest pixel
  kBilinear,  // bilinear interpolation of the four
};

struct TsdfOptions {
  double voxel_size_mm = 1.0;    // Sec. IV-B
  double truncation_vox = 4.0;   // half-width of the signed-distance band [voxels]
  double max_weight = 128.0;     // running-average cap (dimensionless; a frame adds 1 by default)
  double min_range_mm = 100.0;   // pixels nearer than this are ignored
  double max_range_mm = 1000.0;  // AHAT range aliases near 1 m
  TsdfWeighting weighting = TsdfWeighting::kConstant;
  double min_incidence_weight = 0.1;  // floor of the kIncidence weight (dimensionless)
  TsdfDepthSampling sampling = TsdfDepthSampling::kBilinear;
  /// Neighbouring pixels whose ranges differ by more than this are on different surfaces: no
  /// voxel samples across them, and they do not form normals (kIncidence) [mm].
  double max_range_step_mm = 10.0;
  /// Region of interest in `tool` [mm]: pixels whose point falls outside are dropped, voxels
  /// outside are never updated. Empty: unbounded.
  std::optional<Eigen::AlignedBox3d> roi_in_tool;

  double truncation_mm() const { return truncation_vox * voxel_size_mm; }
  void Check() const;  // throws PreconditionError naming the bad field
};

struct IntegrateResult {
  bool integrated = false;   // false when the frame had no pose and was skipped
  int pixels_used = 0;       // valid pixels within the range limits and the ROI
  int blocks_touched = 0;    // blocks this frame updated
  int blocks_allocated = 0;  // of which were new
  std::int64_t voxels_updated = 0;
};

constexpr int kTsdfBlockSide = 8;
/// Index of a block's last voxel along an axis.
constexpr int kTsdfBlockLast = kTsdfBlockSide - 1;
constexpr int kTsdfBlockVoxels = kTsdfBlockSide * kTsdfBlockSide * kTsdfBlockSide;

/// Voxel (x, y, z) of a block is entry x + 8 * (y + 8 * z).
struct TsdfBlock {
  /// Signed distance along the ray divided by the truncation, in [-1, 1]; positive in front of
  /// the surface (outside), negative behind it.
  std::array<float, kTsdfBlockVoxels> tsdf;
  std::array<float, kTsdfBlockVoxels> weight;  // 0: never observed
};

struct TsdfVoxel {
  double distance_mm = 0.0;  // signed distance, truncated
  double weight = 0.0;
};

class FusionFrame;

/// Curless & Levoy (1996) running-average TSDF with voxel hashing (Niessner et al. 2013) in the
/// tool frame: voxel (i, j, k) is centred at (i, j, k) * voxel_size_mm in `tool`, and block key
/// b holds voxels 8 b .. 8 b + 7. A frame updates only the blocks within one truncation of its
/// points, each block by one task, so the result does not depend on the thread count.
class TsdfVolume {
 public:
  /// Throws PreconditionError on bad options.
  TsdfVolume(const TsdfOptions& options, const AhatCamera& camera);
  ~TsdfVolume();
  TsdfVolume(TsdfVolume&&) noexcept;
  TsdfVolume& operator=(TsdfVolume&&) noexcept;

  /// Fuses one frame.
  /// @param range_mm        corrected range along each pixel's ray [mm], 0 = invalid; the
  ///                        camera's size
  /// @param tool_from_ahat  camera pose in the tool frame; nullopt when the tool was not tracked
  ///                        (status not ok): the frame is skipped and counted
  /// @param pixel_weight    optional per-pixel weight (e.g. from AB noise), multiplied in;
  ///                        empty or the camera's size
  IntegrateResult Integrate(const Image<float>& range_mm,
                            const std::optional<Rigid3d>& tool_from_ahat,
                            const Image<float>& pixel_weight = {});
  /// Raw AHAT codes: 0 and codes >= kAhatInvalidRange are invalid.
  IntegrateResult Integrate(const Image<std::uint16_t>& range_mm,
                            const std::optional<Rigid3d>& tool_from_ahat,
                            const Image<float>& pixel_weight = {});

  const TsdfOptions& options() const { return options_; }
  int frames_integrated() const { return frames_integrated_; }
  int frames_skipped() const { return frames_skipped_; }

  std::size_t block_count() const { return keys_.size(); }
  /// Keys in allocation order; block(i) belongs to block_keys()[i].
  std::span<const Eigen::Vector3i> block_keys() const { return keys_; }
  const TsdfBlock& block(std::size_t i) const { return blocks_[i]; }
  /// Index of the block with `key`, or nullopt when it was never touched.
  std::optional<std::size_t> FindBlock(const Eigen::Vector3i& key) const;
  /// The voxel with global index `index`; nullopt when unobserved (weight 0).
  std::optional<TsdfVoxel> Voxel(const Eigen::Vector3i& index) const;

 private:
  TsdfOptions options_;
  std::unique_ptr<FusionFrame> frame_;  // camera tables and per-frame scratch
  std::vector<Eigen::Vector3i> keys_;
  std::vector<TsdfBlock> blocks_;
  BlockIndex index_;  // packed key -> block
  int frames_integrated_ = 0;
  int frames_skipped_ = 0;
};

}  // namespace tofnav
