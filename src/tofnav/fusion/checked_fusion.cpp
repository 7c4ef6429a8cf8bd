// SPDX-License-Identifier: BSD-3-Clause
// Checked fusion: the per-pixel gate (pixels that contradict a well-observed surface) and the
// check, gate and integration of one frame.
#include <algorithm>
#include <atomic>
#include <cmath>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/fusion/model_check.hpp"
#include "tofnav/fusion/tsdf_sample.hpp"

namespace tofnav {

std::size_t GateInconsistentPixels(const TsdfVolume& volume, Image<float>& range_mm,
                                   const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                   const ModelCheckOptions& options) {
  options.Check();
  Require(range_mm.width() == camera.width() && range_mm.height() == camera.height(),
          "GateInconsistentPixels: the range image must have the camera's size");
  const double truncation_mm = volume.options().truncation_mm();
  // A voxel this close to +truncation was seen as free space (TSDF values are clamped there).
  const double free_mm = 0.99 * truncation_mm;
  // The TSDF knows distances up to the truncation: a wider gate is the free-space test alone.
  const double gate_mm = std::min(options.gate_mm, free_mm);
  const Eigen::Matrix3d rotation = tool_from_ahat.RotationMatrix();
  std::atomic<std::size_t> dropped{0};
  ParallelFor(0, camera.height(), [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    TsdfReader reader(volume);
    std::size_t count = 0;
    for (int u = 0; u < camera.width(); ++u) {
      const float r = range_mm(u, v);
      if (!(r > 0.0f) || !camera.IsValid(u, v)) continue;
      const Eigen::Vector3d ray = rotation * camera.PixelRay(u, v).cast<double>();
      const Eigen::Vector3d p = tool_from_ahat.translation + static_cast<double>(r) * ray;
      bool drop = false;
      if (const auto sample = reader.Sample(p, options.min_model_weight)) {
        // Off a well-observed surface by more than the gate: in front (an occluder such as a
        // hand, a mixed pixel at its edge) or behind (a range too long: multipath).
        drop = std::abs(sample->distance_mm) >= gate_mm;
      } else if (const auto voxel = reader.NearestVoxel(p, options.min_model_weight)) {
        drop = voxel->distance_mm >= free_mm;  // in well-observed free space
      } else if (const auto nearer =
                     reader.NearestVoxel(p - truncation_mm * ray, options.min_model_weight)) {
        // Unobserved at the point, but one truncation nearer the camera lies the inside of a
        // well-observed surface: the point is more than a truncation behind it.
        drop = nearer->distance_mm <= 0.0;
      }
      if (drop) {
        range_mm(u, v) = 0.0f;
        ++count;
      }
    }
    dropped += count;
  });
  return dropped.load();
}

CheckedIntegration IntegrateChecked(TsdfVolume& volume, Image<float> range_mm,
                                    const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                    const Image<float>& pixel_weight,
                                    const ModelCheckOptions& options) {
  options.Check();
  CheckedIntegration out;
  out.check.tool_from_ahat = tool_from_ahat;
  if (options.enabled && volume.frames_integrated() >= options.warmup_frames) {
    out.check = CheckFrameAgainstModel(volume, range_mm, camera, tool_from_ahat, options);
    if (out.check.verdict == ModelVerdict::kRejectedResidual ||
        out.check.verdict == ModelVerdict::kRejectedOffset) {
      return out;
    }
    if (options.gate_pixels) {
      out.pixels_gated =
          GateInconsistentPixels(volume, range_mm, camera, out.check.tool_from_ahat, options);
    }
  }
  volume.Integrate(range_mm, out.check.tool_from_ahat, pixel_weight);
  out.fused = true;
  return out;
}

}  // namespace tofnav
