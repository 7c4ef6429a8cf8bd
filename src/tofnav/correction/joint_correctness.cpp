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
                                           const CorrectnessOptions& options) {
  JointCorrectness out;
  out.image_from_tool = image_from_tool_guess;
  Points3d head_in_tool;
  std::vector<std::size_t> first_head;  // per frame: its first sample in head_in_tool
  for (const int f : frame_indices) {
    const IdentificationFrame& frame = frames[static_cast<std::size_t>(f)];
    const Rigid3d& tool_from_ahat = ToolFromAhat(frame);
    first_head.push_back(head_in_tool.size());
    for (const SurfaceSample& s : frame.head) {
      head_in_tool.push_back(tool_from_ahat * CorrectedPoint(s, model));
    }
  }
  if (static_cast<int>(head_in_tool.size()) >= options.icp.min_correspondences) {
    // Frames disagree a little (tracking noise), so the steps settle above the per-frame
    // tolerances: an ICP stopped by its iteration limit is still taken if it kept its matches.
    IcpOptions icp_options = options.icp;
    icp_options.max_iterations_per_level = std::max(icp_options.max_iterations_per_level, 60);
    const IcpResult icp =
        AlignPointToPlane(head_in_tool, {}, skin_in_image, image_from_tool_guess, icp_options);
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
      out.head_distances[c].push_back(
          SkinSignedDistance(skin_in_image, out.image_from_tool * head_in_tool[first_head[c] + i],
                             options.max_distance_mm));
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
