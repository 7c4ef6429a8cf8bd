// SPDX-License-Identifier: BSD-3-Clause
// Where the CT skin is in each identification frame: one surface registration, then head poses.
#include "tofnav/correction/initial_pose.hpp"

#include <Eigen/Geometry>
#include <stdexcept>

namespace tofnav {

void InitialPoseOptions::Check() const {
  if (merged_frames < 1) throw std::invalid_argument("InitialPoseOptions::merged_frames >= 1");
  if (min_tool_frames < 1) throw std::invalid_argument("InitialPoseOptions::min_tool_frames >= 1");
  registration.Check();
}

bool PlacementsDiffer(const MergedPlacement& a, const MergedPlacement& b, double max_angle_rad,
                      double max_shift_mm) {
  if (a.through_tool != b.through_tool) return false;
  const Rigid3d relative = a.image_from_merged.Inverse() * b.image_from_merged;
  return Eigen::AngleAxisd(relative.rotation).angle() > max_angle_rad ||
         relative.translation.norm() > max_shift_mm;
}

InitialPoseResult InitialImageFromAhat(std::span<const IdentificationFrame> frames,
                                       const SurfaceIndex& skin_in_image,
                                       const DepthErrorModel& model,
                                       const InitialPoseOptions& options,
                                       const std::optional<MergedPlacement>& guess) {
  options.Check();
  // Frames are merged through the reference tool where enough of them have its pose: the head is
  // rigid with the tool, while in `world` a slowly moving patient smears the merged cloud (1 mm/s
  // over a 13 s recording, docs/correction.md 2.3). Otherwise through the rig poses.
  int with_tool = 0;
  for (const IdentificationFrame& f : frames) {
    if (f.tool_from_ahat && !f.head.empty()) ++with_tool;
  }
  const bool through_tool = with_tool >= options.min_tool_frames;
  auto merged_pose = [&](const IdentificationFrame& f) {
    return through_tool ? f.tool_from_ahat : f.world_from_ahat;
  };
  std::vector<int> posed;
  int reference = -1;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!merged_pose(frames[i]) || frames[i].head.empty()) continue;
    posed.push_back(static_cast<int>(i));
    if (reference < 0 ||
        frames[i].head.size() > frames[static_cast<std::size_t>(reference)].head.size()) {
      reference = static_cast<int>(i);
    }
  }
  if (reference < 0) {
    throw std::invalid_argument("InitialImageFromAhat: no frame has a pose and head samples");
  }
  const IdentificationFrame& ref = frames[static_cast<std::size_t>(reference)];
  const Rigid3d ref_from_merged = merged_pose(ref)->Inverse();
  PointCloud head_in_ref;
  for (int k : EvenSubsample(static_cast<int>(posed.size()), options.merged_frames)) {
    const IdentificationFrame& f =
        frames[static_cast<std::size_t>(posed[static_cast<std::size_t>(k)])];
    const Rigid3d ref_from_f = ref_from_merged * *merged_pose(f);
    for (const SurfaceSample& s : f.head) {
      head_in_ref.points.push_back(ref_from_f * CorrectedPoint(s, model));
    }
  }
  RegisterSurfaceOptions reg = options.registration;
  reg.source_normals.viewpoint = Eigen::Vector3d::Zero();  // the reference camera
  InitialPoseResult out;
  out.reference_frame = reference;
  out.through_tool = through_tool;
  std::optional<Rigid3d> ref_from_image_guess;
  if (guess && guess->through_tool == through_tool) {
    ref_from_image_guess = (guess->image_from_merged * *merged_pose(ref)).Inverse();
  }
  out.registration = RegisterSurface(head_in_ref, skin_in_image, {}, reg, ref_from_image_guess);
  const Rigid3d image_from_ref = out.registration.tool_from_image.Inverse();
  const Rigid3d image_from_merged = image_from_ref * ref_from_merged;
  out.image_from_merged = image_from_merged;
  // Frames without the tool's pose go through the rig poses, as good as the patient is still.
  std::optional<Rigid3d> image_from_world;
  if (ref.world_from_ahat) image_from_world = image_from_ref * ref.world_from_ahat->Inverse();
  out.image_from_ahat.resize(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const IdentificationFrame& f = frames[i];
    if (through_tool && f.tool_from_ahat) {
      out.image_from_ahat[i] = image_from_merged * *f.tool_from_ahat;
    } else if (f.world_from_ahat && image_from_world) {
      out.image_from_ahat[i] = *image_from_world * *f.world_from_ahat;
    }
  }
  return out;
}

BestStartPlacement InitialImageFromBestStart(std::span<const IdentificationFrame> frames,
                                             const SurfaceIndex& skin_in_image,
                                             std::span<const DepthErrorModel> starts,
                                             const InitialPoseOptions& options,
                                             std::span<const MergedPlacement> guesses) {
  if (starts.empty()) throw std::invalid_argument("InitialImageFromBestStart: no start model");
  BestStartPlacement best;
  for (std::size_t i = 0; i < starts.size() + guesses.size(); ++i) {
    const bool guessed = i >= starts.size();
    InitialPoseResult pose =
        InitialImageFromAhat(frames, skin_in_image, guessed ? starts.front() : starts[i], options,
                             guessed ? std::optional(guesses[i - starts.size()]) : std::nullopt);
    best.inlier_fractions.push_back(pose.registration.icp.inlier_fraction);
    if (best.start < 0 ||
        pose.registration.icp.inlier_fraction > best.pose.registration.icp.inlier_fraction) {
      best.pose = std::move(pose);
      best.start = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace tofnav
