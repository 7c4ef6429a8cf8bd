// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: frame cleaning, per-pixel weights and touched-block marking.
#include "tofnav/fusion/fusion_frame.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/fusion/block_marking.hpp"
#include "tofnav/fusion/tsdf_kernel.hpp"

namespace tofnav {
namespace {

constexpr std::int64_t kRowsPerTask = 8;
constexpr std::int64_t kMaxMaskBlocks = std::int64_t{1} << 27;  // 128 MB of touched-block flags

int FloorDiv(int a, int b) { return a / b - (a % b < 0 ? 1 : 0); }  // rounds towards -inf

/// Index range [lo, hi] of the voxels within `truncation` of coordinate c, in mm.
int LowVoxel(float c, float truncation, float voxel) {
  return static_cast<int>(std::ceil((c - truncation) / voxel));
}
int HighVoxel(float c, float truncation, float voxel) {
  return static_cast<int>(std::floor((c + truncation) / voxel));
}

// The per-pixel loops below use plain floats rather than Eigen: they touch 262144 pixels per
// frame and must stay fast in unoptimised test builds too.
using Vec3 = std::array<float, 3>;
Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
float Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

}  // namespace

FusionFrame::FusionFrame(const TsdfOptions& options, const AhatCamera& camera)
    : options_(options),
      lookup_(camera),
      width_(camera.width()),
      height_(camera.height()),
      truncation_mm_(static_cast<float>(options.truncation_mm())),
      max_step_mm_(static_cast<float>(options.max_range_step_mm)),
      use_avx2_(CpuHasAvx2()) {
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  rays_.assign(n, Vec3{0.0f, 0.0f, 0.0f});
  for (int v = 0; v < height_; ++v) {
    for (int u = 0; u < width_; ++u) {
      if (!camera.IsValid(u, v)) continue;
      const Eigen::Vector3f& ray = camera.PixelRay(u, v);
      rays_[static_cast<std::size_t>(v * width_ + u)] = {ray.x(), ray.y(), ray.z()};
    }
  }
  range_mm_.assign(n, 0.0f);
  points_.assign(n, Vec3{0.0f, 0.0f, 0.0f});
  row_lo_.resize(static_cast<std::size_t>(height_));
  row_used_.resize(static_cast<std::size_t>(height_));
  row_span_.resize(static_cast<std::size_t>(height_));
  row_hi_.resize(static_cast<std::size_t>(height_));
  if (options.roi_in_tool) {
    const double voxel = options.voxel_size_mm;
    roi_lo_vox_ = (options.roi_in_tool->min() / voxel).array().ceil().cast<int>();
    roi_hi_vox_ = (options.roi_in_tool->max() / voxel).array().floor().cast<int>();
  }
}

void FusionFrame::CleanRows(const Image<float>& range_mm, const Rigid3d& tool_from_ahat) {
  const Eigen::Matrix3f r = tool_from_ahat.RotationMatrix().cast<float>();
  const Eigen::Vector3f t = tool_from_ahat.translation.cast<float>();
  const float m[9] = {r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1),
                      r(1, 2), r(2, 0), r(2, 1), r(2, 2)};
  camera_in_tool_ = {t.x(), t.y(), t.z()};
  const auto min_range = static_cast<float>(options_.min_range_mm);
  const auto max_range = static_cast<float>(options_.max_range_mm);
  Vec3 roi_lo{-INFINITY, -INFINITY, -INFINITY}, roi_hi{INFINITY, INFINITY, INFINITY};
  if (options_.roi_in_tool) {
    for (int a = 0; a < 3; ++a) {
      roi_lo[static_cast<std::size_t>(a)] = static_cast<float>(options_.roi_in_tool->min()[a]);
      roi_hi[static_cast<std::size_t>(a)] = static_cast<float>(options_.roi_in_tool->max()[a]);
    }
  }
  const float* input = range_mm.data();
  ParallelFor(
      0, height_,
      [&](std::int64_t row) {
        const auto v = static_cast<std::size_t>(row);
        Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
        int used = 0;
        std::size_t first = (v + 1) * static_cast<std::size_t>(width_), last = 0;
        for (std::size_t i = v * static_cast<std::size_t>(width_);
             i < (v + 1) * static_cast<std::size_t>(width_); ++i) {
          const float d = input[i];
          const Vec3& ray = rays_[i];
          range_mm_[i] = 0.0f;
          // The comparisons are false for NaN; invalid camera pixels have a zero ray.
          if (!(d >= min_range && d <= max_range) || ray[2] == 0.0f) continue;
          const Vec3 c{d * ray[0], d * ray[1], d * ray[2]};
          const Vec3 p{m[0] * c[0] + m[1] * c[1] + m[2] * c[2] + camera_in_tool_[0],
                       m[3] * c[0] + m[4] * c[1] + m[5] * c[2] + camera_in_tool_[1],
                       m[6] * c[0] + m[7] * c[1] + m[8] * c[2] + camera_in_tool_[2]};
          bool inside = true;
          for (std::size_t a = 0; a < 3; ++a) inside &= p[a] >= roi_lo[a] && p[a] <= roi_hi[a];
          if (!inside) continue;
          range_mm_[i] = d;
          points_[i] = p;
          ++used;
          first = std::min(first, i);
          last = i;
          for (std::size_t a = 0; a < 3; ++a)
            lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
        }
        row_used_[v] = used;
        row_span_[v] = {first, used > 0 ? last + 1 : first};
        row_lo_[v] = lo;
        row_hi_[v] = hi;
      },
      kRowsPerTask);
}

void FusionFrame::ComputeWeights(const Image<float>& pixel_weight) {
  const bool incidence = options_.weighting == TsdfWeighting::kIncidence;
  if (!incidence && pixel_weight.empty()) {
    weight_.clear();  // every weight is 1
    return;
  }
  weight_.assign(range_mm_.size(), 0.0f);
  const auto floor_weight = static_cast<float>(options_.min_incidence_weight);
  ParallelFor(
      0, height_,
      [&](std::int64_t row) {
        const int v = static_cast<int>(row);
        for (int u = 0; u < width_; ++u) {
          const std::size_t i = static_cast<std::size_t>(v * width_ + u);
          if (range_mm_[i] <= 0.0f) continue;
          // A neighbour helps estimate the normal when valid and on the same surface.
          const auto neighbour = [&](int du, int dv) -> const Vec3& {
            const int u2 = u + du, v2 = v + dv;
            if (u2 < 0 || v2 < 0 || u2 >= width_ || v2 >= height_) return points_[i];
            const std::size_t j = static_cast<std::size_t>(v2 * width_ + u2);
            const bool same_surface =
                range_mm_[j] > 0.0f && std::abs(range_mm_[j] - range_mm_[i]) <= max_step_mm_;
            return same_surface ? points_[j] : points_[i];
          };
          float w = 1.0f;
          if (incidence) {
            // Central differences where both neighbours are usable, else one-sided.
            const Vec3 normal = Cross(Sub(neighbour(1, 0), neighbour(-1, 0)),
                                      Sub(neighbour(0, 1), neighbour(0, -1)));
            const Vec3 view = Sub(points_[i], camera_in_tool_);
            const float scale = std::sqrt(Dot(normal, normal) * Dot(view, view));
            const float cosine = scale > 0.0f ? std::abs(Dot(normal, view)) / scale : 0.0f;
            w = std::max(cosine, floor_weight);
          }
          if (!pixel_weight.empty()) {
            const float external = pixel_weight(u, v);
            w = external > 0.0f ? w * external : 0.0f;  // NaN counts as 0
          }
          weight_[i] = w;
        }
      },
      kRowsPerTask);
}

std::vector<Eigen::Vector3i> FusionFrame::Prepare(const Image<float>& range_mm,
                                                  const Rigid3d& tool_from_ahat,
                                                  const Image<float>& pixel_weight) {
  Require(range_mm.width() == width_ && range_mm.height() == height_,
          "TsdfVolume::Integrate: range image size differs from the camera's");
  Require(
      pixel_weight.empty() || (pixel_weight.width() == width_ && pixel_weight.height() == height_),
      "TsdfVolume::Integrate: pixel_weight must be empty or the camera's size");
  const Rigid3d ahat_from_tool = tool_from_ahat.Inverse();
  ahat_from_tool_rotation_ = ahat_from_tool.RotationMatrix().cast<float>();
  ahat_from_tool_translation_ = ahat_from_tool.translation.cast<float>();
  CleanRows(range_mm, tool_from_ahat);
  ComputeWeights(pixel_weight);
  pixels_used_ = 0;
  for (const int n : row_used_) pixels_used_ += n;
  if (pixels_used_ == 0) return {};

  // Bounds of the touched blocks: the points' box grown by the truncation, within the ROI.
  const auto voxel = static_cast<float>(options_.voxel_size_mm);
  const float truncation = truncation_mm_;
  Eigen::Vector3i key_lo, key_hi;
  for (std::size_t a = 0; a < 3; ++a) {
    float lo = INFINITY, hi = -INFINITY;
    for (std::size_t v = 0; v < row_lo_.size(); ++v) {
      lo = std::min(lo, row_lo_[v][a]);
      hi = std::max(hi, row_hi_[v][a]);
    }
    const float limit = static_cast<float>(kMaxBlockKey * kTsdfBlockSide) * voxel;
    Require(std::abs(lo) < limit && std::abs(hi) < limit,
            "TsdfVolume::Integrate: points too far from the tool origin for the block keys");
    const int axis = static_cast<int>(a);
    const int vox_lo = std::max(LowVoxel(lo, truncation, voxel), roi_lo_vox_[axis]);
    const int vox_hi = std::min(HighVoxel(hi, truncation, voxel), roi_hi_vox_[axis]);
    if (vox_lo > vox_hi) return {};
    key_lo[axis] = FloorDiv(vox_lo, kTsdfBlockSide);
    key_hi[axis] = FloorDiv(vox_hi, kTsdfBlockSide);
  }
  const Eigen::Vector3i dims = key_hi - key_lo + Eigen::Vector3i::Ones();
  const std::int64_t mask_size = std::int64_t{dims.x()} * dims.y() * dims.z();
  Require(mask_size <= kMaxMaskBlocks,
          "TsdfVolume::Integrate: one frame spans too many blocks; set roi_in_tool or a larger "
          "voxel_size_mm");
  block_mask_.assign(static_cast<std::size_t>(mask_size), 0);

  // Mark every block whose voxels come within one truncation of a point: the ball around the
  // point holds the ray segment [d - truncation, d + truncation] where the kernel's signed
  // distance is not clamped. (A cube around the point, marked before, also took up to 12 %
  // more blocks, mostly behind the surface, where nothing is updated.)
  const BlockMarker marker{block_mask_.data(),
                           dims.x(),
                           std::int64_t{dims.x()} * dims.y(),
                           {key_lo.x(), key_lo.y(), key_lo.z()},
                           {roi_lo_vox_.x(), roi_lo_vox_.y(), roi_lo_vox_.z()},
                           {roi_hi_vox_.x(), roi_hi_vox_.y(), roi_hi_vox_.z()},
                           truncation,
                           1.0f / voxel};  // exact for the usual power-of-two voxel sizes
  ParallelFor(
      0, height_,
      [&](std::int64_t row) {
        const auto [first, last] = row_span_[static_cast<std::size_t>(row)];
        if (use_avx2_) {
          MarkBlocksAvx2(marker, range_mm_.data(), points_.data(), first, last);
        } else {
          MarkBlocks(marker, range_mm_.data(), points_.data(), first, last);
        }
      },
      kRowsPerTask);

  std::vector<Eigen::Vector3i> keys;
  std::size_t m = 0;
  for (int z = 0; z < dims.z(); ++z) {
    for (int y = 0; y < dims.y(); ++y) {
      for (int x = 0; x < dims.x(); ++x, ++m) {
        if (block_mask_[m] != 0) keys.push_back(key_lo + Eigen::Vector3i(x, y, z));
      }
    }
  }
  return keys;
}

}  // namespace tofnav
