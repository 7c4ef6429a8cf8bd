// SPDX-License-Identifier: BSD-3-Clause
// Beyond the paper: Eq. (5) with one skin placement for every frame, through the tracked
// reference tool, and the head surface itself measured against the skin (docs/correction.md 2).
#include "tofnav/correction/joint_correctness.hpp"

#include <algorithm>
#include <stdexcept>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/registration/icp.hpp"

namespace tofnav {
namespace {

const Rigid3d& ToolFromAhat(const IdentificationFrame& frame) {
  if (!frame.tool_from_ahat) {
    throw std::invalid_argument("JointCorrectnessDistances: a frame has no reference-tool pose");
  }
  return *frame.tool_from_ahat;
}

}  // namespace

JointCorrectness JointCorrectnessDistances(std::span<const IdentificationFrame> frames,
                                           std::span<const int> frame_indices,
                                           const DepthErrorModel& model,
                                           const SurfaceIndex& skin_in_image,
                                           const Rigid3d& image_from_tool_guess,
                                           const CorrectnessOptions& options,
                                           IcpNeighbourCache* icp_cache) {
  JointCorrectness out;
  out.image_from_tool = image_from_tool_guess;
  std::vector<std::size_t> first_head;  // per frame: its first sample in head_in_tool
  std::size_t head_count = 0;
  for (const int f : frame_indices) {
    first_head.push_back(head_count);
    head_count += frames[static_cast<std::size_t>(f)].head.size();
  }
  Points3d head_in_tool(head_count);
  ParallelFor(0, std::ssize(frame_indices), [&](std::int64_t ci) {
    const auto c = static_cast<std::size_t>(ci);
    const IdentificationFrame& frame = frames[static_cast<std::size_t>(frame_indices[c])];
    const Rigid3d& tool_from_ahat = ToolFromAhat(frame);
    for (std::size_t i = 0; i < frame.head.size(); ++i) {
      head_in_tool[first_head[c] + i] = tool_from_ahat * CorrectedPoint(frame.head[i], model);
    }
  });
  if (static_cast<int>(head_in_tool.size()) >= options.icp.min_correspondences) {
    // Frames disagree a little (tracking noise), so the steps settle above the per-frame
    // tolerances: an ICP stopped by its iteration limit is still taken if it kept its matches.
    IcpOptions icp_options = options.icp;
    icp_options.max_iterations_per_level = std::max(icp_options.max_iterations_per_level, 60);
    const IcpResult icp = AlignPointToPlane(head_in_tool, {}, skin_in_image, image_from_tool_guess,
                                            icp_options, icp_cache);
    out.converged = icp.converged;
    if (icp.correspondences >= options.icp.min_correspondences) {
      out.image_from_tool = icp.target_from_source;
    }
  }
  out.marker_distances.resize(frame_indices.size());
  out.head_distances.resize(frame_indices.size());
  ParallelFor(0, std::ssize(frame_indices), [&](std::int64_t ci) {  // per evaluation: the hot path
    const auto c = static_cast<std::size_t>(ci);
    const IdentificationFrame& frame = frames[static_cast<std::size_t>(frame_indices[c])];
    const Rigid3d image_from_ahat = out.image_from_tool * ToolFromAhat(frame);
    for (const Eigen::Vector3d& m : frame.marker_points) {
      out.marker_distances[c].push_back(
          SkinSignedDistance(skin_in_image, image_from_ahat * m, options.max_distance_mm));
    }
    for (std::size_t i = 0; i < frame.head.size(); ++i) {
      // The ICP's last answers were taken at its final pose: most still hold exactly.
      const std::size_t k = first_head[c] + i;
      const Eigen::Vector3d p = out.image_from_tool * head_in_tool[k];
      const std::optional<std::uint32_t> known =
          icp_cache != nullptr ? icp_cache->KnownNearest(k, p) : std::nullopt;
      out.head_distances[c].push_back(
          known ? SkinSignedDistanceTo(skin_in_image, *known, p, options.max_distance_mm)
                : SkinSignedDistance(skin_in_image, p, options.max_distance_mm));
    }
  });
  return out;
}

std::optional<Rigid3d> MeanImageFromTool(std::span<const IdentificationFrame> frames,
                                         std::span<const int> frame_indices,
                                         std::span<const Rigid3d> image_from_ahat) {
  if (image_from_ahat.size() != frame_indices.size()) {
    throw std::invalid_argument("MeanImageFromTool: one image_from_ahat per frame index");
  }
  Eigen::Vector4d quaternion_sum = Eigen::Vector4d::Zero();
  Eigen::Vector3d translation_sum = Eigen::Vector3d::Zero();
  std::optional<Eigen::Quaterniond> first;
  int count = 0;
  for (std::size_t c = 0; c < frame_indices.size(); ++c) {
    const IdentificationFrame& frame = frames[static_cast<std::size_t>(frame_indices[c])];
    if (!frame.tool_from_ahat) continue;
    const Rigid3d image_from_tool = image_from_ahat[c] * frame.tool_from_ahat->Inverse();
    Eigen::Quaterniond q = image_from_tool.rotation;
    if (!first) first = q;
    if (first->dot(q) < 0.0) q.coeffs() = -q.coeffs();  // one hemisphere: q and -q are one rotation
    quaternion_sum += q.coeffs();
    translation_sum += image_from_tool.translation;
    ++count;
  }
  if (count == 0) return std::nullopt;
  Eigen::Quaterniond mean;
  mean.coeffs() = quaternion_sum;
  return Rigid3d(mean.normalized(), translation_sum / count);
}

}  // namespace tofnav
