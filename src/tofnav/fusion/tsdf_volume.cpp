// SPDX-License-Identifier: BSD-3-Clause
// Projective TSDF fusion of AHAT range frames in the tool frame: block bookkeeping.
#include "tofnav/fusion/tsdf_volume.hpp"

#include <cmath>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/fusion/fusion_frame.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

std::uint64_t PackKey(const Eigen::Vector3i& key) {
  constexpr std::int64_t kOffset = kMaxBlockKey + 1;  // keys lie in [-kOffset, kOffset)
  const auto field = [](int c) { return static_cast<std::uint64_t>(c + kOffset); };
  return (field(key.x()) << 42) | (field(key.y()) << 21) | field(key.z());
}

TsdfBlock EmptyBlock() {
  TsdfBlock block;
  block.tsdf.fill(1.0f);
  block.weight.fill(0.0f);
  return block;
}

}  // namespace

void TsdfOptions::Check() const {
  Require(std::isfinite(voxel_size_mm) && voxel_size_mm > 0.0,
          "TsdfOptions::voxel_size_mm must be > 0");
  Require(std::isfinite(truncation_vox) && truncation_vox > 0.0 && truncation_vox <= 64.0,
          "TsdfOptions::truncation_vox must be in (0, 64]");
  Require(std::isfinite(max_weight) && max_weight > 0.0, "TsdfOptions::max_weight must be > 0");
  Require(std::isfinite(min_range_mm) && min_range_mm >= 0.0,
          "TsdfOptions::min_range_mm must be >= 0");
  Require(std::isfinite(max_range_mm) && max_range_mm > min_range_mm,
          "TsdfOptions::max_range_mm must be > min_range_mm");
  Require(std::isfinite(max_range_step_mm) && max_range_step_mm > 0.0,
          "TsdfOptions::max_range_step_mm must be > 0");
  Require(min_incidence_weight >= 0.0 && min_incidence_weight <= 1.0,
          "TsdfOptions::min_incidence_weight must be in [0, 1]");
  if (roi_in_tool) {
    Require(
        roi_in_tool->min().allFinite() && roi_in_tool->max().allFinite() && !roi_in_tool->isEmpty(),
        "TsdfOptions::roi_in_tool must be a finite, non-empty box");
    const double limit = kMaxBlockKey * kTsdfBlockSide * voxel_size_mm;
    Require(roi_in_tool->min().cwiseAbs().maxCoeff() < limit &&
                roi_in_tool->max().cwiseAbs().maxCoeff() < limit,
            "TsdfOptions::roi_in_tool is too far from the tool origin");
  }
}

TsdfVolume::TsdfVolume(const TsdfOptions& options, const AhatCamera& camera) : options_(options) {
  options.Check();
  frame_ = std::make_unique<FusionFrame>(options, camera);
}

TsdfVolume::~TsdfVolume() = default;
TsdfVolume::TsdfVolume(TsdfVolume&&) noexcept = default;
TsdfVolume& TsdfVolume::operator=(TsdfVolume&&) noexcept = default;

IntegrateResult TsdfVolume::Integrate(const Image<float>& range_mm,
                                      const std::optional<Rigid3d>& tool_from_ahat,
                                      const Image<float>& pixel_weight) {
  if (!tool_from_ahat) {  // the tool was not tracked: no pose to fuse with
    ++frames_skipped_;
    return {};
  }
  const std::vector<Eigen::Vector3i> touched =
      frame_->Prepare(range_mm, *tool_from_ahat, pixel_weight);
  IntegrateResult result;
  result.integrated = true;
  result.pixels_used = frame_->pixels_used();
  result.blocks_touched = static_cast<int>(touched.size());
  // Find or allocate the blocks serially in scan order, so ids are deterministic. The flat index
  // makes this a few microseconds, less than waking the workers for a parallel pass.
  std::vector<std::size_t> ids(touched.size());
  for (std::size_t i = 0; i < touched.size(); ++i) {
    ids[i] = index_.Insert(PackKey(touched[i]), blocks_.size());
    if (ids[i] == blocks_.size()) {
      keys_.push_back(touched[i]);
      blocks_.push_back(EmptyBlock());
      ++result.blocks_allocated;
    }
  }
  // Parallel: each block is updated by exactly one task. A task mostly takes the next block
  // next: its 4 KB are fetched while this one is set up and updated (blocks live in scattered
  // memory that other work has often evicted; about 8 % per frame measured side by side).
  std::vector<std::int64_t> updated(touched.size(), 0);
  ParallelFor(0, static_cast<std::int64_t>(touched.size()), [&](std::int64_t i) {
    const auto k = static_cast<std::size_t>(i);
    if (k + 1 < ids.size()) {
      const auto* next = reinterpret_cast<const char*>(&blocks_[ids[k + 1]]);
      constexpr std::size_t kCacheLine = 64;
      for (std::size_t b = 0; b < sizeof(TsdfBlock); b += kCacheLine)
        __builtin_prefetch(next + b, 1);
      frame_->PrefetchBlock(touched[k + 1]);
    }
    updated[k] = frame_->IntegrateBlock(touched[k], blocks_[ids[k]]);
  });
  for (const std::int64_t n : updated) result.voxels_updated += n;
  ++frames_integrated_;
  return result;
}

IntegrateResult TsdfVolume::Integrate(const Image<std::uint16_t>& range_mm,
                                      const std::optional<Rigid3d>& tool_from_ahat,
                                      const Image<float>& pixel_weight) {
  Image<float> range(range_mm.width(), range_mm.height());
  for (std::size_t i = 0; i < range_mm.size(); ++i) {
    const std::uint16_t code = range_mm.pixels()[i];
    range.pixels()[i] = code >= kAhatInvalidRange ? 0.0f : static_cast<float>(code);
  }
  return Integrate(range, tool_from_ahat, pixel_weight);
}

std::optional<std::size_t> TsdfVolume::FindBlock(const Eigen::Vector3i& key) const {
  if (key.cwiseAbs().maxCoeff() > kMaxBlockKey) return std::nullopt;
  const std::size_t id = index_.Find(PackKey(key));
  if (id == BlockIndex::kMissing) return std::nullopt;
  return id;
}

std::optional<TsdfVoxel> TsdfVolume::Voxel(const Eigen::Vector3i& index) const {
  const auto floor_div = [](int a) {  // rounds towards -inf
    return a / kTsdfBlockSide - (a % kTsdfBlockSide < 0 ? 1 : 0);
  };
  const Eigen::Vector3i key(floor_div(index.x()), floor_div(index.y()), floor_div(index.z()));
  const std::optional<std::size_t> id = FindBlock(key);
  if (!id) return std::nullopt;
  const Eigen::Vector3i local = index - kTsdfBlockSide * key;
  const auto entry = static_cast<std::size_t>(
      local.x() + kTsdfBlockSide * (local.y() + kTsdfBlockSide * local.z()));
  const TsdfBlock& b = blocks_[*id];
  if (b.weight[entry] <= 0.0f) return std::nullopt;
  return TsdfVoxel{b.tsdf[entry] * options_.truncation_mm(), b.weight[entry]};
}

}  // namespace tofnav
